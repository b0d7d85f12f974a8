"""This machine's ceilings and each renderer's fraction of them (``make bench``).

The ceilings come from :func:`vrlib.roofline.measure`: STREAM-triad bandwidth, and the peak
rate of trilinear and Catmull-Rom samples along rays inside a cache-resident brick. Every
method then renders three scenes (dense Marschner-Lobb under Glow, a dense Gaussian blob, six
sparse blobs under a thresholded ramp) at 256^3 -> 512^2, step 1; its rate is reconstructed
points per second (:func:`vrlib.cost.points`). For ray casting, whose point is one 3-D
reconstruction, the table gives the rate as a fraction of the sampling ceiling of its filter on
the same number of threads. The other methods' points are other work (a footprint-table pixel
for splatting, a composited sample after 1-D resampling passes for shearing), so the 3-D
ceiling does not bound them and no fraction is given: their own ceilings are still to be
measured. Sparse scenes skip most of the volume, so their rate counts only the points taken.

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


def main():
    threads = numba.config.NUMBA_NUM_THREADS
    limits = {t: roofline.measure(threads=t) for t in sorted({1, threads})}
    rows = [[f"{t}", f"{lim['bandwidth'] / 1e9:.1f}", f"{lim['trilinear_float32'] / 1e6:.0f}",
             f"{lim['trilinear_float64'] / 1e6:.0f}", f"{lim['tricubic_float32'] / 1e6:.0f}"]
            for t, lim in limits.items()]
    print("## This machine's ceilings\n")
    print(markdown(["threads", "triad GB/s", "trilinear f32 M/s", "trilinear f64 M/s",
                    "tricubic f32 M/s"], rows))
    ceiling = limits[threads]
    results = []
    for scene, (field, transfer) in scenes().items():
        volume = field.sample(N)
        view = vrlib.View.orbit(azimuth=30.0, elevation=20.0, size=SIZE)
        for method in vrlib.METHODS:
            for filt, limit in (("trilinear", "trilinear_float32"),
                                ("catmull-rom", "tricubic_float32")):
                try:
                    seconds, image = measure(partial(
                        vrlib.render, volume, view, method=method, filter=filt,
                        transfer=transfer, step=STEP))
                except ValueError:
                    continue
                rate = points(image.stats) / seconds
                fraction = rate / ceiling[limit] if method == "raycast" else None
                results.append({"scene": scene, "method": method, "filter": filt,
                                "seconds": seconds, "points": points(image.stats),
                                "rate": rate, "fraction": fraction})
    print(f"\n## Renderers at {N}^3 -> {SIZE}^2, step {STEP:g}, {threads} threads: points "
          "per second, and for ray casting the fraction of its sampling ceiling\n")
    print(markdown(["scene", "method", "filter", "seconds", "M points/s", "of ceiling"],
                   [[r["scene"], r["method"], r["filter"], f"{r['seconds']:.3f}",
                     f"{r['rate'] / 1e6:.1f}",
                     "-" if r["fraction"] is None else f"{r['fraction']:.2f}"] for r in results]))
    write_record("roofline", {"machine": machine(), "n": N, "size": SIZE, "step": STEP,
                              "limits": {str(t): v for t, v in limits.items()},
                              "renderers": results})


if __name__ == "__main__":
    main()
