"""The two-pass shear saving, measured over random rotations.

For each of many random rotations (seeded), the same volume is rendered by the three-pass
(``shear3``) and the two-pass (``shear2``) shear methods at one image pixel and one ray sample
per voxel (the output lattice at the volume's resolution, as the thesis's comparison assumes),
with Catmull-Rom. Recorded per rotation: samples resampled by each pass (in units of N^3), the
arithmetic operations by the renderers' own count, wall time (best of two) and the peak of
NumPy memory during the render (tracemalloc). Writes ``build/results/ch05_shear/saving.json``.
"""

import tracemalloc
from functools import partial

import numpy as np
from tqdm import tqdm

import data_gen
import vrlib
from chapters.common import by_profile, result_path, write_json
from vrlib.cost import measure

N = by_profile(128, 256)
ROTATIONS = by_profile(50, 200)


def measure_pass(volume, view, method):
    best, img = measure(partial(vrlib.render, volume, view, method=method,
                                filter="catmull-rom", step=1.0), repeats=2, warmup=False)
    tracemalloc.start()
    vrlib.render(volume, view, method=method, filter="catmull-rom", step=1.0)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    passes = img.stats.passes
    return {"pass1": passes["pass1"], "pass2": passes["pass2"], "pass3": passes.get("pass3", 0),
            "resampled": img.stats.voxels, "operations": img.stats.operations,
            "seconds": best, "peak_bytes": peak, "buffer_bytes": img.stats.bytes}


def main():
    volume = data_gen.make_field("marschner-lobb").sample(N, dtype=np.float32)
    size = int(round(np.sqrt(3) * (N - 1)))  # one pixel per voxel at zoom 1
    rng = np.random.default_rng(1993)
    # Uniform random directions: azimuth uniform, sin(elevation) uniform.
    azimuths = rng.uniform(-180.0, 180.0, ROTATIONS)
    elevations = np.degrees(np.arcsin(rng.uniform(-1.0, 1.0, ROTATIONS)))
    vrlib.render(volume, vrlib.View.orbit(size=16), method="shear3")  # compile first
    rows = []
    for azimuth, elevation in tqdm(list(zip(azimuths, elevations, strict=True)),
                                   desc="rotations", disable=None):
        view = vrlib.View.orbit(azimuth=azimuth, elevation=elevation, size=size)
        rows.append({"azimuth": float(azimuth), "elevation": float(elevation),
                     "shear3": measure_pass(volume, view, "shear3"),
                     "shear2": measure_pass(volume, view, "shear2")})
    write_json(result_path(__file__, "saving.json"),
               {"N": N, "image": size, "rotations": rows, "volume_bytes": int(volume.data.nbytes)})


if __name__ == "__main__":
    main()
