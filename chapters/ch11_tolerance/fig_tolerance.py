"""Figures: the promise of ``tolerance=`` (error achieved against error asked, time against
the fastest fixed setting; the error seen along and near the lattice) and pre-integration
against point sampling on steep transfer functions."""

import textwrap

import matplotlib.pyplot as plt
import numpy as np

from chapters.common import figure_path, read_json, result_path, save_figure

MARKERS = "osD^v<>ph"


def promise_figure():
    data = read_json(result_path(__file__, "promise.json"))
    cases = [c for c in data["cases"] if "rmse" in c]
    scenes = list(dict.fromkeys(c["scene"] for c in cases))
    labels = {c["scene"]: c["label"] for c in cases}
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.4), layout="tight")
    for i, scene in enumerate(scenes):
        for view, fill in (("orthographic", "full"), ("along x", "left"),
                           ("perspective", "none")):
            sel = [c for c in cases if c["scene"] == scene and c["view"] == view]
            if not sel:
                continue
            jitter = 1.0 + 0.06 * (i - len(scenes) / 2)
            kwargs = dict(marker=MARKERS[i % len(MARKERS)], color=f"C{i}", ls="none", ms=5,
                          fillstyle=fill)
            left.loglog([c["tolerance"] * jitter for c in sel], [c["rmse"] for c in sel],
                        label=labels[scene] if fill == "full" else None, **kwargs)
            right.semilogx([c["tolerance"] * jitter for c in sel],
                           [c["ratio"] if c["ratio"] is not None else np.nan for c in sel],
                           **kwargs)
            again = [c["alternated"]["ratio"] if c.get("alternated") else np.nan for c in sel]
            right.semilogx([c["tolerance"] * jitter for c in sel], again, "x", color="k", ms=4,
                           label="timed again in turn (medians)" if i == 0 and fill == "full"
                           else None)
    span = np.array([5e-5, 2e-2])
    left.loglog(span, span, "k-", lw=1, label="error = tolerance")
    left.set_xlabel("tolerance asked (rmse)")
    left.set_ylabel("rmse achieved against the exact image")
    left.set_title(f"Error achieved ({data['summary']['kept']} of "
                   f"{data['summary']['cases']} kept; half filled: along x; hollow: "
                   "perspective)", fontsize=10)
    left.legend(fontsize=7, loc="upper left")
    right.axhline(1.5, color="k", lw=1, ls="--")
    right.axhline(1.0, color="k", lw=0.5)
    right.set_xlabel("tolerance asked (rmse)")
    right.set_ylabel("time / fastest fixed setting that meets it")
    right.set_title("Time, pilot included, against a grid search", fontsize=10)
    right.legend(fontsize=7, loc="upper left")
    for ax in (left, right):
        ax.grid(True, which="both", alpha=0.3)
    save_figure(fig, figure_path(__file__, "promise.png"))


def views_figure():
    data = read_json(result_path(__file__, "views.json"))
    cases = [c for c in data["cases"] if "rmse" in c]
    views = [name for name, _ in data["views"]]
    scenes = list(dict.fromkeys(c["scene"] for c in data["cases"]))
    labels = {c["scene"]: c["label"] for c in data["cases"]}
    fig, ax = plt.subplots(figsize=(11, 4.4), layout="tight")
    for i, scene in enumerate(scenes):
        for tolerance, fill in zip(data["tolerances"], ("full", "none"), strict=True):
            sel = [c for c in cases if c["scene"] == scene and c["tolerance"] == tolerance]
            ax.semilogy([views.index(c["view"]) + 0.08 * (i - len(scenes) / 2) for c in sel],
                        [c["rmse"] / c["tolerance"] for c in sel],
                        marker=MARKERS[i % len(MARKERS)], color=f"C{i}", ls="none", ms=5,
                        fillstyle=fill, label=labels[scene] if fill == "full" else None)
    ax.axhline(1.0, color="k", lw=1, label="error = tolerance")
    ax.set_xticks(range(len(views)), [textwrap.fill(v, 10) for v in views], fontsize=8)
    ax.set_ylabel("rmse achieved / tolerance asked")
    summary = data["summary"]
    ax.set_title(f"Views along and near the lattice, {data['size']}^2: {summary['kept']} of "
                 f"{summary['cases']} kept, {summary['refused']} refused (filled: "
                 f"{data['tolerances'][0]:g}; hollow: {data['tolerances'][1]:g})",
                 fontsize=10)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.grid(True, which="both", alpha=0.3)
    save_figure(fig, figure_path(__file__, "views.png"))


def preintegration_figure():
    data = read_json(result_path(__file__, "preintegration.json"))
    rows = data["rows"]
    fig, axes = plt.subplots(2, 3, figsize=(11, 7), sharey=False, layout="tight")
    axes = axes.ravel()
    styles = {"point, lattice ends": "--o", "point, exact ends": ":s",
              "pre-integrated": "-D"}
    for ax, row in zip(axes, rows, strict=False):
        for name, curve in row["curves"].items():
            ax.loglog(curve["samples"], curve["rmse"], styles[name], ms=3, label=name)
        ax.set_title(row["scene"], fontsize=9)
        ax.set_xlabel("samples")
        ax.set_ylabel("rmse")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    ax = axes[len(rows)]
    for i, row in enumerate(rows):
        ratios = [np.nan if r is None else r for r in row["sample_ratio"]]
        ax.semilogx(data["steps"], ratios, "-" + MARKERS[i], ms=4, label=_short(row["scene"]))
    ax.axhline(4.0, color="k", lw=1, ls="--")
    ax.set_xlabel("step of point sampling (voxels)")
    ax.set_ylabel("samples saved at its error")
    ax.set_title("Point samples / pre-integrated samples", fontsize=9)
    ax.legend(loc="upper right")
    ax.grid(True, which="both", alpha=0.3)
    for extra in axes[len(rows) + 1:]:
        extra.set_visible(False)
    save_figure(fig, figure_path(__file__, "preintegration.png"))


def _short(scene):
    """'Marschner-Lobb 41^3, peak 3% wide' -> 'Marschner-Lobb, 3%' (the panels name it)."""
    field, peak = scene.split(", ")
    return f"{field.rsplit(' ', 1)[0]}, {peak.split()[1]}"


def main():
    promise_figure()
    views_figure()
    preintegration_figure()


if __name__ == "__main__":
    main()
