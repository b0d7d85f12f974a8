"""Convergence: each method's error against a closed-form image as the ray step shrinks (ray
casting, steps from 4 voxels down to 1/16) and as the volume's resolution grows (every
method), with the fitted order of convergence (the error may only fall, to within 2%, as the
step shrinks). Steps larger than a voxel must still give
finite images in range. Scene: a Gaussian blob (sigma 0.3) under Glow(2), whose image is
``1 - exp(-2 x line integral)`` exactly. Writes ``build/results/ch08_stability/convergence.json``.
"""

import numpy as np

import data_gen
import vrlib
from chapters.ch08_stability._exact import glow_image
from chapters.common import by_profile, progress, result_path, write_json

STEPS = [4.0, 2.0, 1.0, 0.5, 0.25, 0.125, 0.0625]
RESOLUTIONS = by_profile([12, 16, 24, 32, 48, 64], [16, 24, 32, 48, 64, 96, 128])
METHODS = list(vrlib.METHODS)
FILTERS = ["trilinear", "catmull-rom", "bspline"]
SCALE = 2.0


def order(x, errors):
    """Slope of log(error) against log(x) (the order of convergence)."""
    return float(np.polyfit(np.log(x), np.log(errors), 1)[0])


def main():
    field = data_gen.make_field("gaussian-blob", sigma=0.3, center=(0.05, -0.1, 0.08))
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=64)
    exact = glow_image(field, view, SCALE)
    vol = field.sample(48)
    steps = {}
    for filt in progress(FILTERS, "steps"):
        rows = []
        for step in STEPS:
            img = vrlib.render(vol, view, filter=filt, transfer=vrlib.Glow(SCALE), step=step,
                               early_termination=1.0)
            rows.append({"step": step, "finite": bool(np.all(np.isfinite(img.rgba))),
                         "in_range": bool(0.0 <= img.alpha.min() and img.alpha.max() <= 1.0),
                         "max_error": float(np.abs(img.alpha - exact).max()),
                         "rmse": float(np.sqrt(np.mean((img.alpha - exact) ** 2)))})
        errors = [r["max_error"] for r in rows]
        steps[filt] = {"rows": rows,
                       "order_large_steps": order(STEPS[:4], errors[:4]),
                       "monotone": bool(all(b <= a * 1.02 for a, b in zip(errors, errors[1:],
                                                                          strict=False)))}
    resolution = {}
    for method in progress(METHODS, "resolution"):
        rows = []
        for n in RESOLUTIONS:
            img = vrlib.render(field.sample(n), view, method=method, filter="catmull-rom",
                               transfer=vrlib.Glow(SCALE), step=0.25, early_termination=1.0)
            rows.append({"N": n, "max_error": float(np.abs(img.alpha - exact).max()),
                         "rmse": float(np.sqrt(np.mean((img.alpha - exact) ** 2)))})
        resolution[method] = {"rows": rows,
                              "order": -order(RESOLUTIONS, [r["rmse"] for r in rows])}
    write_json(result_path(__file__, "convergence.json"),
               {"steps": steps, "resolution": resolution, "scale": SCALE, "volume": 48,
                "image": 64})


if __name__ == "__main__":
    main()
