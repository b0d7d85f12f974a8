"""Sheet buffers against direct splatting, for a transfer function with a sharp edge.

Renders a smooth sphere whose values cross a step in opacity with the splatter in both modes,
the ray caster and the reference renderer, and writes the images and their errors to
``build/results/ch04_splatting/``. Under the glow transfer function the two modes are
identical; a sharp transfer function separates them: direct splatting classifies each voxel
before reconstruction, so the step is blurred by the kernel, while sheet buffers classify the
reconstructed slab.
"""

import numpy as np

import data_gen
import vrlib
from chapters.common import atomic_path, by_profile, result_path, write_json


def main():
    field = data_gen.make_field("smooth-sphere", radius=0.6, width=0.15)
    volume = field.sample(by_profile(32, 64))
    step_tf = vrlib.LookupTransfer(np.r_[np.zeros(50), np.full(51, 8.0)],
                                   value_range=(0.0, 1.0))
    view = vrlib.View.orbit(azimuth=20, elevation=10, size=by_profile(128, 256))
    images = {
        "reference": vrlib.render_reference(field, view, transfer=step_tf, tol=1e-5),
        "sheet": vrlib.render(volume, view, method="splat", transfer=step_tf, mode="sheet"),
        "direct": vrlib.render(volume, view, method="splat", transfer=step_tf, mode="direct"),
        "raycast": vrlib.render(volume, view, transfer=step_tf, step=0.25),
    }
    ref = images["reference"]
    summary = {name: {"rmse": vrlib.metrics.rmse(img, ref),
                      "max": vrlib.metrics.max_abs_error(img, ref)}
               for name, img in images.items() if name != "reference"}
    summary["sheet_vs_direct_rmse"] = vrlib.metrics.rmse(images["sheet"], images["direct"])
    summary["glow_sheet_vs_direct_max"] = vrlib.metrics.max_abs_error(
        vrlib.render(volume, view, method="splat", mode="sheet"),
        vrlib.render(volume, view, method="splat", mode="direct"))
    with atomic_path(result_path(__file__, "sheet_vs_direct.npz")) as tmp:
        np.savez(tmp, **{name: img.alpha for name, img in images.items()})
    write_json(result_path(__file__, "sheet_vs_direct.json"), summary)


if __name__ == "__main__":
    main()
