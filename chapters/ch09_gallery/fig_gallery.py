"""Figures: the gallery grid (every method, with difference images), the colour scenes of the
real volumes (every method, with colour differences) and the turntable GIF."""

import textwrap

import imageio.v3 as iio
import matplotlib.pyplot as plt
import numpy as np

import vrlib
from chapters.common import figure_path, read_json, result_path, save_figure, write_csv
from vrlib.atomic import atomic_path

METHODS = list(vrlib.METHODS)


def method_grid(rows, path, label):
    """One pair of rows per scene: the reference and each method's image, and below each
    method its difference from the reference on one symmetric scale per scene, with a colour
    bar. ``rows`` is ``[(reference title, reference image, [(title, image, difference)])]``."""
    fig, axes = plt.subplots(2 * len(rows), len(METHODS) + 1, layout="constrained",
                             figsize=(1.6 * (len(METHODS) + 1), 1.75 * 2 * len(rows)))
    for (title, reference, panels), top, bottom in zip(rows, axes[::2], axes[1::2],
                                                      strict=True):
        top[0].imshow(np.clip(reference, 0, 1), interpolation="nearest")
        top[0].set_title(title, fontsize=6)
        bottom[0].axis("off")
        bound = max(max(float(np.abs(diff).max()) for _, _, diff in panels), 1e-12)
        for m, (name, image, diff) in enumerate(panels, start=1):
            top[m].imshow(np.clip(image, 0, 1), interpolation="nearest")
            top[m].set_title(name, fontsize=6)
            shown = bottom[m].imshow(diff, cmap="RdBu_r", vmin=-bound, vmax=bound,
                                     interpolation="nearest")
        bar = fig.colorbar(shown, ax=bottom[1:], shrink=0.9, aspect=12)
        bar.set_label(label, fontsize=6)
        bar.ax.tick_params(labelsize=6)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    save_figure(fig, path)


def main():
    info = read_json(result_path(__file__, "gallery.json"))
    images = np.load(result_path(__file__, "gallery.npz"))
    rows = []
    for scene in info["scenes"]:
        reference, errors = images[f"{scene}/reference"], info["errors"][scene]
        rows.append((f"{textwrap.fill(scene, 24)}\n{errors['reference']}", reference[..., :3], [
            (f"{m}\nrmse {errors[m]['rmse']:.1e}", images[f"{scene}/{m}"][..., :3],
             images[f"{scene}/{m}"][..., 3] - reference[..., 3]) for m in METHODS]))
    method_grid(rows, figure_path(__file__, "gallery.png"), "opacity - reference")
    colour, images = info["colour"], np.load(result_path(__file__, "colour.npz"))
    rows = []
    for scene in colour["scenes"]:
        reference, errors = images[f"{scene}/reference"], colour["errors"][scene]
        # (the scene's name wrapped to its column: it would run into the next title)
        rows.append((f"{textwrap.fill(scene, 24)}\nray casting, step 1/8", reference, [
            (f"{m}\nrmse {errors[m]['rmse']:.1e}", images[f"{scene}/{m}"],
             (images[f"{scene}/{m}"] - reference).mean(axis=-1)) for m in METHODS]))
    method_grid(rows, figure_path(__file__, "colour.png"), "colour - reference\n(mean of RGB)")
    write_csv(figure_path(__file__, "colour.csv"), ["scene", *METHODS], [
        [scene, *(f"{e[m]['rmse']:.1e} ({e[m]['seconds']:.2f} s)" for m in METHODS)]
        for scene, e in colour["errors"].items()])
    frames = np.load(result_path(__file__, "turntable.npz"))["frames"]
    pixels = np.round(np.clip(frames, 0.0, 1.0) * 255).astype(np.uint8)
    with atomic_path(figure_path(__file__, "turntable.gif")) as tmp:
        iio.imwrite(tmp, pixels, extension=".gif", duration=80, loop=0)


if __name__ == "__main__":
    main()
