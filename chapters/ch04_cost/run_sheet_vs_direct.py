"""Splatting's three compositing modes, for a transfer function with a sharp edge, and what a
reconstructed point costs in each.

Renders a smooth sphere whose values cross a step in opacity with the splatter in every mode
(axis-aligned sheets, image-aligned sheets, direct), the ray caster and the reference renderer,
and writes the images and their errors to ``build/results/ch04_cost/``. Under the glow transfer
function the modes agree; a sharp transfer function separates them: direct splatting
classifies each voxel before reconstruction, so the step is blurred by the kernel, while sheet
buffers classify the reconstructed slab. Then times each mode (best of three, all threads) on
the chapter's dense and sparse scenes: seconds per frame, reconstructed points (footprint
pixels) and nanoseconds per point.
"""

import numpy as np

import data_gen
import vrlib
from chapters.ch04_cost import _scenes
from chapters.common import atomic_path, by_profile, progress, result_path, write_json
from vrlib.cost import measure, points

MODES = list(vrlib.splat.MODES)


def costs():
    """Each mode's frame time and cost per point on the dense and sparse scenes."""
    rows = []
    n = by_profile(64, 128)
    jobs = [(scene, filt, mode) for scene in ("dense", "sparse")
            for filt in ("trilinear", "catmull-rom") for mode in MODES]
    volumes = {}
    for scene, filt, mode in progress(jobs, "splatting modes"):
        field, transfer = getattr(_scenes, scene)()
        volume = volumes.setdefault(scene, field.sample(n))
        view = vrlib.View.orbit(azimuth=30, elevation=20, size=2 * n)
        seconds, image = measure(lambda volume=volume, view=view, transfer=transfer, filt=filt,
                                 mode=mode: vrlib.render(volume, view, method="splat",
                                                         filter=filt, mode=mode,
                                                         transfer=transfer))
        count = points(image.stats)
        rows.append({"scene": scene, "filter": filt, "mode": mode, "seconds": seconds,
                     "points": count, "footprints": int(image.stats.voxels),
                     "ns_per_point": 1e9 * seconds / max(count, 1)})
    return {"n": n, "rows": rows}


def main():
    field = data_gen.make_field("smooth-sphere", radius=0.6, width=0.15)
    volume = field.sample(by_profile(32, 64))
    step_tf = vrlib.LookupTransfer(np.r_[np.zeros(50), np.full(51, 8.0)],
                                   value_range=(0.0, 1.0))
    view = vrlib.View.orbit(azimuth=20, elevation=10, size=by_profile(128, 256))
    images = {"reference": vrlib.render_reference(field, view, transfer=step_tf, tol=1e-5)}
    for mode in MODES:
        images[mode] = vrlib.render(volume, view, method="splat", transfer=step_tf, mode=mode)
    images["raycast"] = vrlib.render(volume, view, transfer=step_tf, step=0.25)
    ref = images["reference"]
    summary = {name: {"rmse": vrlib.metrics.rmse(img, ref),
                      "max": vrlib.metrics.max_abs_error(img, ref)}
               for name, img in images.items() if name != "reference"}
    summary["sheet_vs_direct_rmse"] = vrlib.metrics.rmse(images["sheet"], images["direct"])
    glow = {mode: vrlib.render(volume, view, method="splat", mode=mode) for mode in MODES}
    summary["glow_sheet_vs_direct_max"] = vrlib.metrics.max_abs_error(glow["sheet"],
                                                                      glow["direct"])
    summary["glow_image_aligned_vs_direct_max"] = vrlib.metrics.max_abs_error(
        glow["image-aligned"], glow["direct"])
    summary["modes"] = MODES
    summary["cost"] = costs()
    with atomic_path(result_path(__file__, "sheet_vs_direct.npz")) as tmp:
        np.savez(tmp, **{name: img.alpha for name, img in images.items()})
    write_json(result_path(__file__, "sheet_vs_direct.json"), summary)


if __name__ == "__main__":
    main()
