"""Figure: the sharp-edged sphere by each method and splatting mode, and their errors; table:
each mode's cost per reconstructed point."""

import matplotlib.pyplot as plt
import numpy as np

from chapters.common import figure_path, read_json, result_path, save_figure, write_csv


def main():
    images = np.load(result_path(__file__, "sheet_vs_direct.npz"))
    summary = read_json(result_path(__file__, "sheet_vs_direct.json"))
    ref = images["reference"]
    renders = ["raycast", *summary["modes"]]
    fig, axes = plt.subplots(2, len(renders) + 1, figsize=(3 * (len(renders) + 1), 6.4))
    for ax, name in zip(axes[0], ["reference", *renders], strict=True):
        ax.imshow(images[name], cmap="gray", vmin=0, vmax=1)
        title = name if name == "reference" else f"{name}: rmse {summary[name]['rmse']:.3f}"
        ax.set_title(title, fontsize=10)
    span = max(np.abs(images[n] - ref).max() for n in renders)
    for ax, name in zip(axes[1], renders, strict=False):
        shown = ax.imshow(images[name] - ref, cmap="RdBu_r", vmin=-span, vmax=span)
        ax.set_title(f"{name} - reference", fontsize=10)
    axes[1, -1].imshow(images["sheet"] - images["direct"], cmap="RdBu_r", vmin=-span,
                       vmax=span)
    axes[1, -1].set_title("sheet - direct", fontsize=10)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    fig.colorbar(shown, ax=axes[1].tolist(), shrink=0.8, label="alpha difference")
    save_figure(fig, figure_path(__file__, "sheet_vs_direct.png"))
    write_csv(figure_path(__file__, "splat_modes.csv"),
              ["scene", "filter", "mode", "ms per frame", "footprints drawn",
               "reconstructed points", "ns per point"],
              [[r["scene"], r["filter"], r["mode"], f"{1e3 * r['seconds']:.1f}",
                r["footprints"], r["points"], f"{r['ns_per_point']:.1f}"]
               for r in summary["cost"]["rows"]])


if __name__ == "__main__":
    main()
