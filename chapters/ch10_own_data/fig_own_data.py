"""Figures of the "Your own data" page: transfer-function kinds on the real volumes, and the
anisotropic volume by every method."""

import matplotlib.pyplot as plt
import numpy as np

import vrlib
from chapters.common import figure_path, read_json, result_path, save_figure


def _show(ax, rgba, title):
    ax.imshow(np.clip(rgba[..., :3], 0, 1), interpolation="nearest")
    ax.set_title(title, fontsize=7)
    ax.set_xticks([])
    ax.set_yticks([])


def main():
    info = read_json(result_path(__file__, "own_data.json"))
    images = np.load(result_path(__file__, "images.npz"))
    panels = [(images[f"tf/{row['name']}"], row["name"].replace(", ", ",\n", 1))
              for row in info["transfer_functions"]]
    if info["brainsmall"]["available"]:  # with Debian's libvolpack1-dev installed
        panels.append((images["brainsmall"], "VolPack's brainsmall.den,\nauto, bone, shaded"))
    fig, axes = plt.subplots(3, 3, figsize=(7.2, 7.6), layout="tight")
    for ax in axes.ravel()[len(panels):]:
        ax.axis("off")
    for ax, (rgba, title) in zip(axes.ravel(), panels, strict=False):
        _show(ax, rgba, title)
    save_figure(fig, figure_path(__file__, "transfer_functions.png"))

    methods = list(vrlib.METHODS)
    fig, axes = plt.subplots(2, len(methods) + 1, figsize=(8.4, 3.2), layout="tight")
    _show(axes[0, 0], images["aniso/reference"], "ray cast, step 1/8")
    axes[1, 0].axis("off")
    reference = images["aniso/reference"]
    for m, method in enumerate(methods, start=1):
        rgba = images[f"aniso/{method}"]
        rmse = info["anisotropic"]["methods"][method]["rmse"]
        _show(axes[0, m], rgba, f"{method}\nrmse {rmse:.1e}")
        diff = rgba[..., 3] - reference[..., 3]
        bound = max(float(np.abs(diff).max()), 1e-12)
        axes[1, m].imshow(diff, cmap="RdBu_r", vmin=-bound, vmax=bound, interpolation="nearest")
        axes[1, m].set_title(f"opacity difference\n+-{bound:.1e}", fontsize=7)
        axes[1, m].set_xticks([])
        axes[1, m].set_yticks([])
    save_figure(fig, figure_path(__file__, "anisotropic.png"))


if __name__ == "__main__":
    main()
