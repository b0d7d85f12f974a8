"""The prefilter's cost per voxel (``make bench``): vrlib's recursion (:mod:`vrlib.prefilter`)
beside scipy's ``ndimage.spline_filter`` (order 3, mode ``"reflect"``: the same coefficients),
at 128^3 and 256^3, float32 and float64 volumes, 1 and 2 threads; and what a prefiltered
filter adds to a frame of each method (256^3 into 512^2, orthographic, Marschner-Lobb under
the glow): the first frame of a new volume (coefficients computed) and later frames (kept), beside
Catmull-Rom's (a first frame of a new volume builds its skip structures too). Each time is the
best of three.
"""

from __future__ import annotations

import numpy as np
from _report import best_of, markdown, write_record
from scipy import ndimage

import data_gen
import vrlib
from vrlib import prefilter

SIZES = (128, 256)


def main():
    field = data_gen.make_field("marschner-lobb")
    pole = vrlib.make_filter("cardinal-bspline").poles
    rows, record = [], {"rows": [], "frames": []}
    for n in SIZES:
        for dtype in (np.float32, np.float64):
            data = field.sample(n, dtype=dtype).data
            voxels = data.size
            prefilter.coefficients(data[:4, :4, :4], pole)  # compile
            ours = {t: best_of(lambda t=t, data=data: _threads(
                t, lambda: prefilter.coefficients(data, pole)))[0] for t in (1, 2)}
            theirs, c_scipy = best_of(lambda data=data: ndimage.spline_filter(
                data, order=3, mode="reflect", output=np.float64))
            agree = float(np.abs(prefilter.coefficients(data, pole) - c_scipy).max())
            row = {"n": n, "dtype": np.dtype(dtype).name, "vrlib_1t_ns": 1e9 * ours[1] / voxels,
                   "vrlib_2t_ns": 1e9 * ours[2] / voxels, "scipy_ns": 1e9 * theirs / voxels,
                   "speedup_2t": theirs / ours[2], "max_difference": agree}
            record["rows"].append(row)
            rows.append([f"{n}^3", row["dtype"], f"{row['vrlib_1t_ns']:.1f}",
                         f"{row['vrlib_2t_ns']:.1f}", f"{row['scipy_ns']:.1f}",
                         f"{row['speedup_2t']:.2f}x", f"{agree:.1e}"])
    print("## Prefilter (cubic B-spline, 3 axes): nanoseconds per voxel\n")
    print(markdown(["volume", "dtype", "vrlib 1 thread", "vrlib 2 threads",
                    "scipy spline_filter", "scipy / vrlib (2 threads)",
                    "largest difference"], rows))

    n, size = 256, 512
    volume = field.sample(n, dtype=np.float32)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=size)
    frames = []
    for method in vrlib.METHODS:
        options = {"step": 1.0} if method in ("raycast", "shear3", "shear2") else {}

        def frame(filt, vol=None, method=method, options=options):
            return vrlib.render(volume if vol is None else vol, view, method=method,
                                filter=filt, transfer=vrlib.Glow(1.0), **options)

        frame("catmull-rom")
        frame("omoms")  # compile, and keep the coefficients
        def new(filt):  # a first frame of a new volume: its skip structures, coefficients...
            return frame(filt, vrlib.Volume(volume.data, volume.extent, copy=False))

        cubic, _ = best_of(lambda: frame("catmull-rom"))
        cubic_new, _ = best_of(lambda: new("catmull-rom"))
        later, image = best_of(lambda: frame("omoms"))
        first, _ = best_of(lambda: new("omoms"))
        record["frames"].append({"method": method, "catmull_rom_s": cubic,
                                 "catmull_rom_new_volume_s": cubic_new,
                                 "omoms_new_volume_s": first, "omoms_s": later,
                                 "omoms_per_frame_prefilter_s": image.stats.prefilter["seconds"]})
        frames.append([method, f"{cubic_new:.3f}", f"{first:.3f}", f"{cubic:.3f}", f"{later:.3f}",
                       f"{image.stats.prefilter['seconds']:.3f}", f"{first / cubic_new:.2f}x",
                       f"{later / cubic:.2f}x"])
    print(f"\n## A frame with O-MOMS beside Catmull-Rom ({n}^3 -> {size}^2, seconds)\n")
    print(markdown(["method", "Catmull-Rom, new volume", "O-MOMS, new volume",
                    "Catmull-Rom, later frames", "O-MOMS, later frames",
                    "of which prefilter per frame", "O-MOMS / Catmull-Rom, new",
                    "O-MOMS / Catmull-Rom, later"], frames))
    write_record("prefilter", record)


def _threads(count, fn):
    import numba

    before = numba.get_num_threads()
    numba.set_num_threads(min(count, numba.config.NUMBA_NUM_THREADS))
    try:
        return fn()
    finally:
        numba.set_num_threads(before)


if __name__ == "__main__":
    main()
