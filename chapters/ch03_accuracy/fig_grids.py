"""Figures: Marschner-Lobb renders by every method and filter beside the reference, and
difference images for a small blob and for Marschner-Lobb."""

import matplotlib.pyplot as plt
import numpy as np

from chapters.common import figure_path, read_json, result_path, save_figure


def grid(images, data, case, difference, name, title):
    methods, filters = data["methods"], data["filters"]
    ref = images[f"{case}|reference"]
    fig, axes = plt.subplots(len(methods), len(filters) + 1,
                             figsize=(1.7 * (len(filters) + 1), 1.75 * len(methods)))
    limit = max(float(np.abs(images[f"{case}|{m}|{f}"] - ref).max())
                for m in methods for f in filters) if difference else 1.0
    for row, method in enumerate(methods):
        axes[row, 0].imshow(ref, cmap="gray", vmin=0, vmax=max(ref.max(), 1e-12))
        axes[row, 0].set_ylabel(method, fontsize=9)
        for col, filt in enumerate(filters, start=1):
            img = images[f"{case}|{method}|{filt}"]
            if difference:
                shown = axes[row, col].imshow(img - ref, cmap="RdBu_r", vmin=-limit,
                                              vmax=limit)
            else:
                axes[row, col].imshow(img, cmap="gray", vmin=0, vmax=max(ref.max(), 1e-12))
            if row == 0:
                axes[row, col].set_title(filt, fontsize=9)
        axes[0, 0].set_title("reference", fontsize=9)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    if difference:
        fig.colorbar(shown, ax=axes, shrink=0.6, label="render - reference (alpha)")
    fig.suptitle(title, fontsize=10)
    save_figure(fig, figure_path(__file__, name))
    plt.close(fig)


def main():
    data = read_json(result_path(__file__, "accuracy.json"))
    images = np.load(result_path(__file__, "images.npz"))
    grid(images, data, "marschner-lobb|41|0", False, "marschner_lobb.png",
         "Marschner-Lobb sampled at 41^3: every method and filter")
    grid(images, data, "marschner-lobb|41|0", True, "marschner_lobb_difference.png",
         "Marschner-Lobb at 41^3: render minus reference")
    grid(images, data, "blob s=0.08|24|0", True, "blob_difference.png",
         "Gaussian blob of s = 0.08 (1.15 samples) at 24^3: render minus reference")


if __name__ == "__main__":
    main()
