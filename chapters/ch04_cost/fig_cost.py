"""Figures: the cost model against measurement, the regime map (which method is cheapest per
reconstructed point and per frame), and run time against error with the Pareto front."""

import matplotlib.pyplot as plt
import numpy as np

import vrlib
from chapters.ch04_cost import _merged
from chapters.common import figure_path, read_json, result_path, save_figure

COLOURS = {method: f"C{i}" for i, method in enumerate(vrlib.METHODS)}
MARKERS = dict(zip(vrlib.filters.STANDARD, "sov*PD^<>hX", strict=False))


def model_fit():
    fig, ax = plt.subplots(figsize=(5.5, 5), layout="tight")
    for index, record in enumerate(_merged.machines(__file__)):
        rows, _ = _merged.fitted(record)
        for backend in sorted({r["backend"] for r in rows}):
            here = [r for r in rows if r["backend"] == backend]
            ax.loglog([r["seconds"] for r in here], [r["predicted"] for r in here],
                      "os^v"[index % 4], ms=4, alpha=0.8,
                      label=f"{record['machine']['id'][:28]}: {backend}")
    lims = ax.get_xlim()
    ax.plot(lims, lims, color="0.5", lw=0.8)
    ax.set_xlabel("measured frame time (s)")
    ax.set_ylabel("model: c_op ops + c_pt points + c_0 (s)")
    ax.legend(fontsize=7)
    ax.set_title("Cost model fitted per machine and backend")
    save_figure(fig, figure_path(__file__, "model_fit.png"))
    plt.close(fig)


def regimes():
    data = read_json(result_path(__file__, "regimes.json"))
    scenes, ms, methods = data["scenes"], data["pixels_per_voxel"], data["methods"]
    # One panel above the other: each cell's three lines need a quarter of the page's width.
    fig, axes = plt.subplots(2, 1, figsize=(8, 7.5), layout="tight")
    for ax, key, title in [(axes[0], "ns_per_point", "ns per reconstructed point"),
                           (axes[1], "seconds", "frame time (ms)")]:
        cheapest = np.zeros((len(scenes), len(ms)), int)
        for i, scene in enumerate(scenes):
            for j, m in enumerate(ms):
                here = {r["method"]: r[key] for r in data["rows"]
                        if r["scene"] == scene and r["m"] == m}
                best = min(here, key=here.get)
                cheapest[i, j] = methods.index(best)
                text = "\n".join(f"{k}: {v * (1e3 if key == 'seconds' else 1):.3g}"
                                 for k, v in here.items())
                ax.text(j, i, text, ha="center", va="center")
        colours = [COLOURS[m] for m in methods]
        from matplotlib.colors import ListedColormap

        ax.imshow(cheapest, cmap=ListedColormap(colours), alpha=0.35, aspect="auto",
                  vmin=-0.5, vmax=len(methods) - 0.5)
        ax.set_xticks(range(len(ms)), [f"m = {m:g}" for m in ms])
        frac = {r["scene"]: r["visible_fraction"] for r in data["rows"]}
        ax.set_yticks(range(len(scenes)), [f"{s} ({frac[s]:.0%} visible)" for s in scenes])
        ax.set_title(f"Cheapest by {title} (cell colour)")
    handles = [plt.Rectangle((0, 0), 1, 1, color=COLOURS[m], alpha=0.35) for m in methods]
    fig.legend(handles, methods, loc="lower center", ncol=len(methods))
    fig.get_layout_engine().set(rect=(0, 0.05, 1, 1))
    save_figure(fig, figure_path(__file__, "regimes.png"))
    plt.close(fig)


def pareto():
    data = read_json(result_path(__file__, "pareto.json"))
    fig, ax = plt.subplots(figsize=(10, 5.5), layout="tight")
    for r in data["rows"]:
        size = {None: 40, 1.0: 25, 0.5: 45, 0.25: 70}[r["step"]]
        if r["method"] in COLOURS:
            ax.scatter(r["seconds"], r["rmse"], s=size, color=COLOURS[r["method"]],
                       marker=MARKERS[r["filter"]], alpha=0.8, edgecolors="none")
        else:  # the classified shear-warp
            ax.scatter(r["seconds"], r["rmse"], s=60, facecolors="none",
                       edgecolors=COLOURS["shearwarp"], marker="s", lw=1.2)
    for key, colour, style, label in [("front", "k", "-", "vrlib's Pareto front"),
                                      ("front_all", "0.45", "--", "front over every point, "
                                                                  "peers included")]:
        front = sorted(data.get(key, []), key=lambda r: r["seconds"])
        ax.step([r["seconds"] for r in front], [r["rmse"] for r in front], where="post",
                color=colour, ls=style, lw=1.0, label=label)
    timed = [p for p in data["peers"] if p["seconds"] is not None]
    for p, marker in zip(timed, ["X", "x", "+", "h", "H"], strict=False):
        label = p["renderer"] + ("" if p["step"] is None else f", step {p['step']:g}")
        ax.scatter(p["seconds"], p["rmse"], s=90, color="k", marker=marker, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("frame time (s, all threads; best of 3)")
    ax.set_ylabel("rmse against the reference")
    for method, colour in COLOURS.items():
        ax.scatter([], [], color=colour, label=method)
    ax.scatter([], [], facecolors="none", edgecolors=COLOURS["shearwarp"], marker="s",
               label="shearwarp, classified (vrlib.classify)")
    for filt, marker in MARKERS.items():
        ax.scatter([], [], color="0.4", marker=marker, label=filt)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    ax.set_title(f"Marschner-Lobb {data['n']}^3 into {data['size']}^2: time against error "
                 "(marker size: step)")
    save_figure(fig, figure_path(__file__, "pareto.png"))
    plt.close(fig)


def main():
    model_fit()
    regimes()
    pareto()


if __name__ == "__main__":
    main()
