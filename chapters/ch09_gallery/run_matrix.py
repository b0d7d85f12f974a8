"""What each method renders: methods x scene features x projections, every cell either an
image compared with the ray caster's or the method's own refusal.

Five methods (ray casting, splatting, three- and two-pass shearing, shear-warp), seven
features (the glow, a colour table, Phong shading, gradient opacity, maximum- and
average-intensity projection, shaded tissue labels with the box filter), orthographic and
perspective views: 70 cells. A volume of six Gaussian blobs, 48^3 into 96^2, trilinear (the
box filter for the labels). A cell that renders gives the rmse of its premultiplied RGBA
against the ray caster's image of the same cell (step 1/4 voxel); one that is refused keeps
the message the user sees. A cell that splatting's default sheet buffers refuse but its
direct mode renders is rendered again with ``mode="direct"`` and says so. Writes
``build/results/ch09_gallery/matrix.json``.
"""

import numpy as np

import data_gen
import vrlib
from chapters.common import progress, result_path, write_json

METHODS = ("raycast", "splat", "shear3", "shear2", "shearwarp")
PROJECTIONS = ("orthographic", "perspective")
SIZE = 96
#: The ray caster's step for the image each cell is compared with (voxels).
REFERENCE_STEP = 0.25


def scene():
    """The blobs and their box-filter labels (0 outside, 1 and 2 inside by brightness)."""
    volume = data_gen.make_field("random-blobs", count=6, seed=7).sample(48)
    low, high = volume.value_range
    cut = low + np.array([0.2, 0.5]) * (high - low)
    labels = vrlib.Volume(np.digitize(volume.data, cut).astype(float), volume.extent)
    return volume, labels


def features(volume, labels):
    """``{name: (volume, filter, transfer, render options)}``."""
    lit = vrlib.Phong(specular=0.3)
    table = vrlib.colormap("viridis", [(0, 0), (0.2, 0), (1, 0.6)], volume=volume)
    ramp = vrlib.GradientOpacity([0.0, 2.0], [0.0, 1.0])
    return {
        "glow": (volume, "trilinear", vrlib.Glow(4.0), {}),
        "colour table": (volume, "trilinear", table, {}),
        "Phong shading": (volume, "trilinear",
                          vrlib.colormap("viridis", [(0, 0), (0.2, 0), (1, 0.6)],
                                         volume=volume, shading=lit), {}),
        "gradient opacity": (volume, "trilinear",
                             vrlib.colormap("viridis", [(0, 0), (0.2, 0), (1, 0.6)],
                                            volume=volume, gradient_opacity=ramp), {}),
        "maximum intensity": (volume, "trilinear", table, {"blend": "maximum"}),
        "average intensity": (volume, "trilinear", table, {"blend": "average"}),
        "shaded labels (box)": (labels, "box",
                                vrlib.label_transfer(labels, opacity=0.3, shading=lit), {}),
    }


def cell(volume, view, method, filt, transfer, options):
    """``{"rendered": True, "rmse": ..., "option": ...}`` against the ray caster, or the
    refusal (splatting tried again in its direct mode)."""
    option = None
    try:
        image = vrlib.render(volume, view, method=method, filter=filt, transfer=transfer,
                             **options)
    except ValueError as error:
        if method != "splat" or "mode='direct'" not in str(error):
            return {"rendered": False, "reason": str(error)}
        option = "mode='direct'"
        image = vrlib.render(volume, view, method=method, filter=filt, transfer=transfer,
                             mode="direct", **options)
    reference = vrlib.render(volume, view, filter=filt, transfer=transfer,
                             step=REFERENCE_STEP, **options)
    return {"rendered": True, "rmse": vrlib.metrics.rmse(image, reference), "option": option,
            "seconds": image.stats.seconds}


def main():
    volume, labels = scene()
    cells = []
    grid = [(p, m, f) for p in PROJECTIONS for m in METHODS for f in features(volume, labels)]
    chosen = features(volume, labels)
    for projection, method, feature in progress(grid, "matrix"):
        vol, filt, transfer, options = chosen[feature]
        view = vrlib.View.orbit(azimuth=35, elevation=25, size=SIZE, projection=projection)
        cells.append({"projection": projection, "method": method, "feature": feature,
                      **cell(vol, view, method, filt, transfer, options)})
    write_json(result_path(__file__, "matrix.json"),
               {"size": SIZE, "reference_step": REFERENCE_STEP, "methods": list(METHODS),
                "features": list(chosen), "projections": list(PROJECTIONS), "cells": cells})


if __name__ == "__main__":
    main()
