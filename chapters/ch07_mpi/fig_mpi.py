"""Figure: bytes each rank sent against the traffic model, load imbalance, memory per rank,
frame times with the model beyond them, and compositing time and bytes against image size."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import NullFormatter

from chapters.common import figure_path, read_json, result_path, save_figure

OBJECT = ("direct-send", "binary-swap", "radix-k")
COLOURS = {"direct-send": "C3", "binary-swap": "C0", "radix-k": "C1", "image": "C2",
           "image-interleaved": "C4"}


def main():
    data = read_json(result_path(__file__, "mpi.json"))
    ortho = data["settings"]["orbit"]
    fig, axes = plt.subplots(3, 2, figsize=(10, 11.5), layout="tight")
    panels = axes.ravel()
    ax = panels[0]
    for key in (*OBJECT, "image", "image-interleaved"):
        sim, meas = [], []
        for e in data["equality"][1:]:
            case = next(c for c in e["cases"] if c["compositing"] == key and
                        c["balance"] in ("even", None) and c["orbit"] == ortho)
            field = "voxels" if key.startswith("image") else "composite"
            meas += [r["bytes"][field] for r in case["ranks"]]
            sim += e["simulated"][key]
        ax.loglog(np.array(sim) / 1e3, np.array(meas) / 1e3, "o", ms=3, alpha=0.6,
                  color=COLOURS[key], label=key.replace("-", " "))
    lims = ax.get_xlim()
    ax.plot(lims, lims, color="0.5", lw=0.8, ls=":")
    ax.set_xlabel("traffic module, kB per rank")
    ax.set_ylabel("sent by the MPI renderer, kB per rank")
    ax.set_title("Bytes per rank, 2-12 ranks", fontsize=10)
    ax.legend(fontsize=7)
    ax = panels[1]
    groups = [(b["scene"], b["ranks"]) for b in data["balance"]]
    keys = ("even", "interleaved", "work", "image", "image-interleaved")
    width = 0.8 / len(keys)
    for i, key in enumerate(keys):
        values = [data["summary"]["imbalance"][f"{s} {p} {key}"] for s, p in groups]
        label = {"work": "work-sized split (new)", "image": "image tiles",
                 "image-interleaved": "image, interleaved tiles"}.get(key, f"{key} bricks")
        ax.bar(np.arange(len(groups)) + (i - 2) * width, values, width, label=label)
    ax.axhline(1.0, color="0.5", lw=0.8)
    ax.set_xticks(range(len(groups)), [f"{s}\n{p} ranks" for s, p in groups])
    ax.set_ylabel("max / mean ray samples per rank")
    ax.set_title("Load imbalance (1 is perfect)", fontsize=10)
    ax.legend(fontsize=7)
    ax = panels[2]
    memory = data["memory"]
    ranks = np.arange(memory["ranks"])
    ax.bar(ranks, np.array(memory["peak"]) / 2**20, color="C1", label="peak during the frame")
    ax.bar(ranks, np.array(memory["resident"]) / 2**20, color="0.6",
           label="resident before it (libraries)")
    ax.axhline(memory["volume_bytes"] / 2**20, color="k", ls="--",
               label=f"the volume ({memory['samples']}$^3$ float32)")
    ax.set_xlabel("rank")
    ax.set_ylabel("MiB")
    ax.set_title(f"Memory per rank, {memory['ranks']} ranks reading a .npy file", fontsize=10)
    ax.legend(fontsize=7)
    ax = panels[3]
    times = data["summary"]["times"]
    for name in OBJECT:
        measured = [(t["ranks"], times[f"{name} {t['ranks']}"]) for t in data["timing"]]
        p = np.array([r for r, _ in measured])
        med = np.array([m["median"] for _, m in measured])
        err = np.array([[m["median"] - m["least"] for _, m in measured],
                        [m["most"] - m["median"] for _, m in measured]])
        ax.errorbar(p, med, yerr=err, fmt="D", color=COLOURS[name], ms=5,
                    label=f"{name} measured")
        rows = data["prediction"]["rows"][name]
        ax.plot([r["ranks"] for r in rows], [r["frame_s"] for r in rows], "-",
                color=COLOURS[name], lw=1, label=f"{name} model")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.axvspan(2.5, 8.5, color="0.9", zorder=0)
    ax.set_xlabel("ranks (shaded: oversubscribed on 2 cores)")
    ax.set_ylabel("seconds per frame")
    ax.set_title("Frame time: medians (bars: least to most) and model", fontsize=10)
    ax.legend(fontsize=7)
    for ax, key, label in ((panels[4], "seconds", "median ms per frame"),
                           (panels[5], "bytes", "most MB sent by a rank")):
        for run, style in zip(data["compositing"], ("-o", "--s", ":^"), strict=False):
            for name in OBJECT:
                sel = [c for c in run["cases"] if c["compositing"] == name]
                widths = [c["width"] for c in sel]
                values = [c["seconds"] * 1e3 if key == "seconds" else max(c["bytes"]) / 1e6
                          for c in sel]
                ax.loglog(widths, values, style, color=COLOURS[name], ms=4,
                          label=f"{name}, {run['ranks']} ranks")
        ax.set_xlabel("image width (pixels)")
        ax.set_ylabel(label)
        ax.set_xticks([256, 512, 1024, 2048], ["256", "512", "1024", "2048"])
        ax.set_title("Compositing alone against image size", fontsize=10)
    panels[4].legend(fontsize=6, ncol=2)
    for ax in axes.ravel():
        ax.grid(True, which="both", alpha=0.3)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_minor_formatter(NullFormatter())
    save_figure(fig, figure_path(__file__, "mpi.png"))


if __name__ == "__main__":
    main()
