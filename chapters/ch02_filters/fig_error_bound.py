"""Figure: worst-case error E(sigma/h) against feature size, measured (solid) and the Fourier
bound (dashed), in 1-D and 3-D, for every filter."""

import matplotlib.pyplot as plt
import numpy as np

from chapters.common import figure_path, read_json, result_path, save_figure


def main():
    data = read_json(result_path(__file__, "error_bound.json"))
    ratios = np.array(data["ratios"])
    fig, axes = plt.subplots(1, 2, figsize=(9, 4), sharey=True, layout="tight")
    for ax, dims in zip(axes, ("1d", "3d"), strict=True):
        for index, (label, s) in enumerate(data["sweep"].items()):
            colour = f"C{index}"
            ax.loglog(ratios, s[f"measured_{dims}"], "-", color=colour, lw=1.5, label=label)
            bound = np.array(s[f"bound_{dims}"], float)
            if np.all(np.isfinite(bound)):
                ax.loglog(ratios, bound, "--", color=colour, lw=0.9)
        for target in data["targets"]:
            ax.axhline(target, color="0.6", lw=0.6, ls=":")
        ax.set_xlabel(r"feature size $\sigma / h$ (samples)")
        ax.set_title(f"{dims.upper()}", fontsize=10)
        ax.set_xticks([0.5, 1, 2, 4], ["0.5", "1", "2", "4"])
        ax.xaxis.set_minor_formatter(plt.NullFormatter())
        ax.set_ylim(1e-5, 1.2)
        ax.grid(True, which="major", lw=0.3)
    axes[0].set_ylabel(r"$E(\sigma/h) = \max |R - f| / f(0)$")
    axes[0].legend(fontsize=8)
    fig.suptitle("Measured worst case (solid) and Fourier bound (dashed)", fontsize=10)
    save_figure(fig, figure_path(__file__, "error_bound.png"))


if __name__ == "__main__":
    main()
