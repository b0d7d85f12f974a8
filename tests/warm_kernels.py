"""Compile the renderers' kernels into numba's on-disk cache, in a process of their own.

``tests/conftest.py`` starts this beside a full test session: on a cold start (a fresh
clone's first ``make test``) the kernels that later tests need are compiled here meanwhile,
while the session's first tests compile their own, and the tests then load them from the
cache; a test that needs one first compiles it itself, as without this. Only what the tests
load belongs here: anything else takes time from the tests' two cores. With a warm cache
this takes seconds. Nothing here is checked: every call below is repeated, and checked, by
the tests.
"""

import data_gen
import vrlib


def main():
    field = data_gen.make_field("gaussian-blob", sigma=0.3)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=8)
    lit = vrlib.Glow(1.0, shading=vrlib.Phong())
    # In the order the workers come to need them (`make test` hands out whole files, the
    # largest first: the shear and ray-casting tests, which compile their own first kernels,
    # then shear-warp's naive twins, the shear methods' threads, splatting, classified).
    calls = [(m, f, t) for m in ("shearwarp", "shear3", "shear2") for f, t in
             [("catmull-rom", None), ("catmull-rom", lit), ("omoms", None)]]
    calls += [("splat", "trilinear", None), ("splat-perspective", "trilinear", None)]
    calls += [("classified", "trilinear", lit), ("classified", "trilinear", None)]
    calls += [(m, f, t) for m in ("splat", "raycast") for f, t in
              [("omoms", None), ("catmull-rom", lit)]]
    # float64 only: the suite renders float32 volumes with other kernels' variants than these
    # (ray casting with the tent filter: files, real volumes), so float32 ones compiled here
    # were never loaded, and took a third of this process's time from the tests' two cores.
    volume = field.sample(9)
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
