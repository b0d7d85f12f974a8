"""Speedups from each skip, on sparse, dense and opaque scenes, with the image change each causes:
empty-space skipping and early ray termination (ray casting), run-length skipping of
transparent voxels and early termination (shear-warp), zero-voxel culling (splatting).

Writes ``build/results/ch04_cost/skips.json``.
"""

from functools import partial

import numpy as np

import vrlib
from chapters.ch04_cost import _scenes
from chapters.common import by_profile, progress, result_path, write_json
from vrlib.cost import machine, measure

N, SIZE = by_profile(96, 192), by_profile(192, 384)
# (skip, method, options with the skip on, options with it off)
SKIPS = [
    ("empty space (min-max blocks)", "raycast", {"empty_space_skipping": True},
     {"empty_space_skipping": False}),
    ("early ray termination (0.999)", "raycast", {"early_termination": 0.999},
     {"early_termination": 1.0}),
    ("run-length skipping (transparent row ends)", "shearwarp",
     {"empty_space_skipping": True}, {"empty_space_skipping": False}),
    ("early ray termination (0.999)", "shearwarp", {"early_termination": 0.999},
     {"early_termination": 1.0}),
    ("zero-voxel culling", "splat", {"empty_space_skipping": True},
     {"empty_space_skipping": False}),
]


def main():
    scenes = {"sparse": _scenes.sparse(), "sparse, zeroed": _scenes.sparse(),
              "dense": _scenes.dense(),
              "opaque": (_scenes.dense()[0], vrlib.Glow(20.0))}
    rows = []
    jobs = [(scene, skip) for scene in scenes for skip in SKIPS]
    for scene, (label, method, on, off) in progress(jobs, "skips"):
        field, transfer = scenes[scene]
        volume = field.sample(N)
        if scene.endswith("zeroed"):
            volume = _scenes.zeroed(volume, transfer)
        view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE)
        common = {"method": method, "filter": "pyramid", "transfer": transfer, "step": 0.5}
        base = {"early_termination": 1.0, "empty_space_skipping": False}
        t_on, img_on = measure(partial(vrlib.render, volume, view, **common, **{**base, **on}))
        t_off, img_off = measure(partial(vrlib.render, volume, view, **common,
                                         **{**base, **off}))
        rows.append({"scene": scene, "skip": label, "method": method,
                     "seconds_on": t_on, "seconds_off": t_off, "speedup": t_off / t_on,
                     "max_change": float(np.abs(img_on.rgba - img_off.rgba).max()),
                     "visible_fraction": _scenes.visible_fraction(volume, transfer)})
    write_json(result_path(__file__, "skips.json"), {"machine": machine(), "n": N,
                                                     "size": SIZE, "rows": rows})


if __name__ == "__main__":
    main()
