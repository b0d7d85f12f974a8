"""Compile the renderers' kernels into numba's on-disk cache, in a process of their own.

``tests/conftest.py`` starts this beside a full test session: numba compiles on one core, so
through most of a cold start (a fresh clone's first ``make test``) the second of the suite's
two cores is idle, and the kernels the later tests need are compiled there meanwhile; a test
that needs one first compiles it itself, as without this. With a warm cache this takes
seconds. Nothing here is checked: every call below is repeated, and checked, by the tests.
"""

import numpy as np

import data_gen
import vrlib


def main():
    field = data_gen.make_field("gaussian-blob", sigma=0.3)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=8)
    lit = vrlib.Glow(1.0, shading=vrlib.Phong())
    # The first tests need the ray caster and the splatter: the session compiles the first,
    # this process the second, then what later tests need.
    calls = [("splat", "trilinear", None), ("splat-perspective", "trilinear", None)]
    calls += [(m, f, t) for m in ("shear3", "shear2", "shearwarp") for f, t in
              [("catmull-rom", None), ("catmull-rom", lit), ("omoms", None)]]
    calls += [("classified", "trilinear", lit), ("classified", "trilinear", None)]
    calls += [(m, f, t) for m in ("splat", "raycast") for f, t in
              [("omoms", None), ("catmull-rom", lit)]]
    for dtype in (np.float64, np.float32):
        volume = field.sample(9, dtype=dtype)
        for method, filt, transfer in calls:
            try:
                if method == "classified":
                    vrlib.classify(volume, transfer).render(view)
                elif method == "splat-perspective":  # the slanted footprints' tables
                    vrlib.render(volume, vrlib.View.orbit(size=8, projection="perspective"),
                                 method="splat", filter=filt)
                else:
                    vrlib.render(volume, view, method=method, filter=filt, transfer=transfer)
            except ValueError:
                pass  # a refusal compiles nothing


if __name__ == "__main__":
    main()
