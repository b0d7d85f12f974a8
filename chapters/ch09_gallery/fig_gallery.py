"""Figures: the gallery grid (every method, with difference images), the colour scenes of the
real volumes (every method, with colour differences) and the turntable GIF."""

import imageio.v3 as iio
import matplotlib.pyplot as plt
import numpy as np

import vrlib
from chapters.common import figure_path, read_json, result_path, save_figure, write_csv
from vrlib.atomic import atomic_path

METHODS = list(vrlib.METHODS)


def colour_figure(colour):
    """Each colour scene by every method over the finest ray cast, with the mean RGB difference
    below on one symmetric scale per scene."""
    images = np.load(result_path(__file__, "colour.npz"))
    scenes = colour["scenes"]
    fig, axes = plt.subplots(2 * len(scenes), len(METHODS) + 1, layout="constrained",
                             figsize=(1.6 * (len(METHODS) + 1), 1.75 * 2 * len(scenes)))
    for s, scene in enumerate(scenes):
        reference = images[f"{scene}/reference"]
        top, bottom = axes[2 * s], axes[2 * s + 1]
        top[0].imshow(np.clip(reference, 0, 1), interpolation="nearest")
        top[0].set_title(f"{scene}\nray casting, step 1/8", fontsize=6)
        bottom[0].axis("off")
        diffs = {m: images[f"{scene}/{m}"].mean(axis=-1) - reference.mean(axis=-1)
                 for m in METHODS}
        bound = max(max(float(np.abs(d).max()) for d in diffs.values()), 1e-12)
        for m, method in enumerate(METHODS, start=1):
            top[m].imshow(np.clip(images[f"{scene}/{method}"], 0, 1), interpolation="nearest")
            err = colour["errors"][scene][method]
            top[m].set_title(f"{method}\nrmse {err['rmse']:.1e}", fontsize=6)
            shown = bottom[m].imshow(diffs[method], cmap="RdBu_r", vmin=-bound, vmax=bound,
                                     interpolation="nearest")
        fig.colorbar(shown, ax=bottom[1:], shrink=0.9, aspect=12).ax.tick_params(labelsize=6)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    save_figure(fig, figure_path(__file__, "colour.png"))
    rows = [[scene, *(f"{colour['errors'][scene][m]['rmse']:.1e} "
                      f"({colour['errors'][scene][m]['seconds']:.2f} s)" for m in METHODS)]
            for scene in scenes]
    write_csv(figure_path(__file__, "colour.csv"), ["scene", *METHODS], rows)


def main():
    info = read_json(result_path(__file__, "gallery.json"))
    images = np.load(result_path(__file__, "gallery.npz"))
    scenes = info["scenes"]
    fig, axes = plt.subplots(2 * len(scenes), len(METHODS) + 1,
                             figsize=(2.2 * (len(METHODS) + 1), 2.3 * 2 * len(scenes)))
    for s, scene in enumerate(scenes):
        reference = images[f"{scene}/reference"]
        top, bottom = axes[2 * s], axes[2 * s + 1]
        top[0].imshow(np.clip(reference[..., :3], 0, 1), interpolation="nearest")
        top[0].set_title(f"{scene}\n{info['errors'][scene]['reference']}", fontsize=7)
        bottom[0].axis("off")
        for m, method in enumerate(METHODS, start=1):
            rgba = images[f"{scene}/{method}"]
            top[m].imshow(np.clip(rgba[..., :3], 0, 1), interpolation="nearest")
            err = info["errors"][scene][method]
            top[m].set_title(f"{method}\nrmse {err['rmse']:.1e}", fontsize=7)
            diff = rgba[..., 3] - reference[..., 3]
            bound = max(float(np.abs(diff).max()), 1e-12)
            bottom[m].imshow(diff, cmap="RdBu_r", vmin=-bound, vmax=bound,
                             interpolation="nearest")
            bottom[m].set_title(f"difference (+-{bound:.1e})", fontsize=7)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    save_figure(fig, figure_path(__file__, "gallery.png"))
    colour_figure(info["colour"])
    frames = np.load(result_path(__file__, "turntable.npz"))["frames"]
    pixels = np.round(np.clip(frames, 0.0, 1.0) * 255).astype(np.uint8)
    with atomic_path(figure_path(__file__, "turntable.gif")) as tmp:
        iio.imwrite(tmp, pixels, extension=".gif", duration=80, loop=0)


if __name__ == "__main__":
    main()
