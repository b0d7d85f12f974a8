"""This machine's ceilings and each renderer's fraction of them (``make bench``).

The ceilings come from :func:`vrlib.roofline.measure`: STREAM-triad bandwidth, and the peak rate
of each method's inner loop on cache-resident data: trilinear and Catmull-Rom samples along
rays (ray casting; trilinear also in packets of 8 rays in vector form, the packet ceiling
beside the scalar one), footprint-table pixels (splatting), 1-D resampled samples with per-output
weights (the shear passes) and 2-D slice samples at one translation (shear-warp). Every method
then renders three scenes (dense Marschner-Lobb under Glow, a dense Gaussian blob, six sparse
blobs under a thresholded ramp) at 256^3 -> 512^2, step 1, and its rate is divided by the
ceiling of its own inner loop and filter, on the same number of threads:

* ray casting: reconstructed points (ray samples) per second / the 3-D sampling ceiling;
* splatting: footprint pixels drawn per second / the footprint ceiling;
* shear3, shear2: samples resampled by the passes per second / the 1-D resampling ceiling
  (the compositing is extra work the ceiling does not include, so this fraction is the share
  of the run time that the resampling alone would need at the ceiling);
* shear-warp: composited 2-D samples per second / the slice ceiling.

Sparse scenes skip most of the volume, so their rates count only the work taken. A last table
follows the ray caster from its ceiling to a render (:func:`vrlib.roofline.ray_caster_ladder`):
the renderer's own sampling, then its classification and compositing, on a brick in cache, then
the renders themselves.

Prints Markdown tables and writes ``build/results/benchmarks/roofline.json``.
"""

from __future__ import annotations

import os
from functools import partial

import numba
import numpy as np
from _report import markdown, write_record

import data_gen
import vrlib
from vrlib import roofline
from vrlib.cost import machine, measure, points

N = int(os.environ.get("VRLIB_BENCH_N", 256))
SIZE = 512
STEP = 1.0


def scenes():
    ramp = np.linspace(0.0, 1.0, 11)
    sparse = vrlib.LookupTransfer(6.0 * np.clip((ramp - 0.1) / 0.9, 0.0, None),
                                  value_range=(0.0, 1.0))
    return {
        "dense Marschner-Lobb": (data_gen.make_field("marschner-lobb"), vrlib.Glow(1.0)),
        "dense Gaussian blob": (data_gen.make_field("gaussian-blob", sigma=0.5), vrlib.Glow(1.0)),
        "sparse six blobs": (data_gen.make_field("random-blobs", count=6, seed=4,
                                                 sigma=(0.06, 0.1)), sparse),
    }


#: The ceiling of each method's inner loop, per filter (module docstring).
CEILINGS = {
    "raycast": {"trilinear": "trilinear_float32", "catmull-rom": "tricubic_float32"},
    "splat": {"trilinear": "footprint_trilinear", "catmull-rom": "footprint_catmull-rom"},
    "shear3": {"trilinear": "resample_trilinear", "catmull-rom": "resample_catmull-rom"},
    "shear2": {"trilinear": "resample_trilinear", "catmull-rom": "resample_catmull-rom"},
    "shearwarp": {"trilinear": "slice_trilinear", "catmull-rom": "slice_catmull-rom"},
}


def inner_loop(method, filt, stats):
    """The work a method's inner loop did (module docstring) and the name of its ceiling
    (``None`` for a method without one)."""
    limit = CEILINGS.get(method, {}).get(filt)
    work = stats.voxels if method in ("shear3", "shear2") else points(stats)
    return work, limit


def main():
    threads = numba.config.NUMBA_NUM_THREADS
    limits = {t: roofline.measure(threads=t) for t in sorted({1, threads})}
    columns = {"trilinear_float32": "trilinear f32", "trilinear_float64": "trilinear f64",
               "packet_trilinear_float32": "packets f32",
               "packet_trilinear_float64": "packets f64",
               "tricubic_float32": "tricubic f32", "footprint_trilinear": "footprint tent",
               "footprint_catmull-rom": "footprint C-R",
               "resample_trilinear": "1-D resample 2 taps",
               "resample_catmull-rom": "1-D resample C-R", "slice_trilinear": "slice 2x2",
               "slice_catmull-rom": "slice 4x4"}
    rows = [[f"{t}", f"{lim['bandwidth'] / 1e9:.1f}"]
            + [f"{lim[key] / 1e6:.0f}" for key in columns] for t, lim in limits.items()]
    print("## This machine's ceilings (M per second)\n")
    print(markdown(["threads", "triad GB/s", *columns.values()], rows))
    ceiling = limits[threads]
    print("\nPackets of 8 rays sampled in vector form against the scalar loop, "
          f"{threads} threads: float32 "
          f"{ceiling['packet_trilinear_float32'] / ceiling['trilinear_float32']:.2f}x, "
          f"float64 {ceiling['packet_trilinear_float64'] / ceiling['trilinear_float64']:.2f}x")
    results = []
    for scene, (field, transfer) in scenes().items():
        volume = field.sample(N)
        view = vrlib.View.orbit(azimuth=30.0, elevation=20.0, size=SIZE)
        for method in vrlib.METHODS:
            for filt in ("trilinear", "catmull-rom"):
                try:
                    seconds, image = measure(partial(
                        vrlib.render, volume, view, method=method, filter=filt,
                        transfer=transfer, step=STEP))
                except ValueError:
                    continue
                rate = points(image.stats) / seconds
                work, limit = inner_loop(method, filt, image.stats)
                fraction = work / seconds / ceiling[limit] if limit else None
                results.append({"scene": scene, "method": method, "filter": filt,
                                "seconds": seconds, "points": points(image.stats),
                                "rate": rate, "work": work, "ceiling": limit,
                                "fraction": fraction})
    print(f"\n## Renderers at {N}^3 -> {SIZE}^2, step {STEP:g}, {threads} threads: points "
          "per second, and the inner loop's rate as a fraction of its ceiling\n")
    print(markdown(["scene", "method", "filter", "seconds", "M points/s", "ceiling",
                    "M inner/s", "of ceiling"],
                   [[r["scene"], r["method"], r["filter"], f"{r['seconds']:.3f}",
                     f"{r['rate'] / 1e6:.1f}", r["ceiling"] or "-",
                     f"{r['work'] / r['seconds'] / 1e6:.1f}",
                     "-" if r["fraction"] is None else f"{r['fraction']:.2f}"] for r in results]))
    ladder = roofline.ray_caster_ladder(threads=threads)
    for r in results:
        if r["method"] == "raycast" and r["filter"] == "trilinear":
            ladder[f"render: {r['scene']}"] = r["rate"]
    top = ladder["ceiling"]
    print(f"\n## Where the ray caster's time goes (trilinear, float64, {threads} threads)\n")
    print(markdown(["step", "M samples/s", "of ceiling"],
                   [[name, f"{rate / 1e6:.0f}", f"{rate / top:.2f}"]
                    for name, rate in ladder.items()]))
    write_record("roofline", {"machine": machine(), "n": N, "size": SIZE, "step": STEP,
                              "limits": {str(t): v for t, v in limits.items()},
                              "renderers": results, "ray_caster_ladder": ladder})


if __name__ == "__main__":
    main()
