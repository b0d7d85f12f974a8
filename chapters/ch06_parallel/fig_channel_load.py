"""Figure: channel loads against the node count at constant image size, and the simulated
frame bytes against the analytic model."""

import matplotlib.pyplot as plt
import numpy as np

from chapters.common import figure_path, read_json, result_path, save_figure

STYLE = {"object slabs": ("C0", "o"), "object shafts": ("C1", "s"),
         "object blocks": ("C2", "^"), "object blocks interleaved": ("C2", "v"),
         "object blocks binary swap": ("C4", "D"), "binary swap full screen": ("C4", "x"),
         "object blocks dynamic": ("C2", "P"), "image static": ("C3", "P"),
         "image static interleaved": ("C3", "X"), "image dynamic": ("C5", "*"),
         "image dynamic interleaved": ("C5", "h")}


def series(rows, name, torus, key):
    sel = [r for r in rows if r["class"] == name and r["torus"] == torus]
    return np.array([r["nodes"] for r in sel]), np.array([r[key] for r in sel])


def main():
    data = read_json(result_path(__file__, "network.json"))
    rows = data["rows"]
    fig, axes = plt.subplots(2, 2, figsize=(10, 8), layout="tight")
    panels = [(axes[0, 0], False, "max", "busiest channel, mesh"),
              (axes[0, 1], False, "mean", "mean channel, mesh"),
              (axes[1, 0], True, "max", "busiest channel, torus")]
    for ax, torus, key, title in panels:
        for name, (colour, marker) in STYLE.items():
            p, v = series(rows, name, torus, key)
            ls = "--" if "interleaved" in name or "full" in name else "-"
            ax.loglog(p, v / 1e3, ls, color=colour, marker=marker, ms=5, label=name)
        ax.set_xlabel("nodes P")
        ax.set_ylabel("kB per frame")
        ax.set_title(f"{title} ({data['width']}$^2$ image, N$^3$ = P x "
                     f"{round(data['voxels_per_node'] ** (1 / 3))}$^3$)", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].legend(fontsize=7.5)
    ax = axes[1, 1]
    for name in ("object slabs", "object shafts", "object blocks", "image static",
                 "image dynamic"):
        colour, marker = STYLE[name]
        p, total = series(rows, name, False, "total")
        _, cauchy = series(rows, name, False, "cauchy")
        _, exact = series(rows, name, False, "exact")
        ax.loglog(p, total / 1e6, marker, color=colour, ms=6, label=f"{name}: simulated")
        ax.loglog(p, cauchy / 1e6, "-", color=colour, lw=1)
        if name.startswith("object"):
            ax.loglog(p, exact / 1e6, ":", color=colour, lw=1.5)
    ax.set_xlabel("nodes P")
    ax.set_ylabel("MB per frame (all nodes)")
    ax.set_title("Simulated (markers) vs model: Cauchy mean (solid), the views' bounding "
                 "rectangles (dotted)", fontsize=9)
    ax.legend(fontsize=7.5)
    ax.grid(True, which="both", alpha=0.3)
    save_figure(fig, figure_path(__file__, "channel_load.png"))


if __name__ == "__main__":
    main()
