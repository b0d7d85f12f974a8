"""Figures: the gallery grid (every method, with difference images) and the turntable GIF."""

import imageio.v3 as iio
import matplotlib.pyplot as plt
import numpy as np

import vrlib
from chapters.common import figure_path, read_json, result_path, save_figure
from vrlib.atomic import atomic_path

METHODS = list(vrlib.METHODS)


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
    frames = np.load(result_path(__file__, "turntable.npz"))["frames"]
    pixels = np.round(np.clip(frames, 0.0, 1.0) * 255).astype(np.uint8)
    with atomic_path(figure_path(__file__, "turntable.gif")) as tmp:
        iio.imwrite(tmp, pixels, extension=".gif", duration=80, loop=0)


if __name__ == "__main__":
    main()
