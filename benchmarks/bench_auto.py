"""The filter ``method="auto"`` chooses for a tolerance (``make bench``): this machine's cost
model is fitted by ``vrlib bench`` (into a temporary file, as a user's would be into their
cache), then each case is rendered to the tolerance with trilinear, with Catmull-Rom, and
with ``method="auto"`` (no filter given), timed in turn (``_report.best_of_each``). The
table gives each time, the filter auto chose, whether it is the faster of the two, and
auto's time over the faster one's: what the choice and its extra pilots cost or save.
"""

from __future__ import annotations

import contextlib
import io
import os
import statistics
import tempfile
from functools import partial
from pathlib import Path

import bench_raycast_vtk
import numpy as np
from _report import best_of_each, markdown, write_record

import vrlib
from vrlib import cli

N = 128
SIZES = (128, 512)
TOLERANCES = (1e-2, 1e-3, 1e-4)
VIEW = {"azimuth": 30, "elevation": 20}
FILTERS = ("trilinear", "catmull-rom")


def scenes():
    """``{label: (volume, transfer)}``: the ray-casting benchmark's dense, sparse and smooth
    scenes (:func:`bench_raycast_vtk.scenes`), sampled at :data:`N`."""
    return {label: (field.sample(N, dtype=np.float32), transfer)
            for label, (field, transfer) in bench_raycast_vtk.scenes().items()}


def main():
    rows, record = [], {"n": N, "rows": []}
    with tempfile.TemporaryDirectory() as folder:
        model = Path(folder) / "cost.json"
        with contextlib.redirect_stdout(io.StringIO()) as said:
            status = cli.main(["bench", "--model", str(model)])
        if status:
            raise SystemExit(f"vrlib bench failed ({status})")
        print(said.getvalue().split("\n\n", 1)[-1])  # the fitted model
        os.environ["VRLIB_COST_MODEL"] = str(model)
        record["model"] = vrlib.cost.load_model(model)["methods"]
        for label, (volume, transfer) in scenes().items():
            for size in SIZES:
                view = vrlib.View.orbit(size=size, **VIEW)
                for tolerance in TOLERANCES:
                    draw = partial(vrlib.render, volume, view, transfer=transfer,
                                   tolerance=tolerance)
                    fns = {name: partial(draw, filter=name) for name in FILTERS}
                    fns["auto"] = partial(draw, method="auto")
                    for fn in fns.values():
                        fn()  # warm
                    timed = best_of_each(fns)
                    times = {name: timed[name][0] for name in FILTERS}
                    auto, image = timed["auto"]
                    chosen = image.stats.choices["auto"]["filter"]
                    fastest = min(times, key=times.get)
                    ratio = auto / times[fastest]
                    record["rows"].append({"scene": label, "size": size,
                                           "tolerance": tolerance, "seconds": times,
                                           "auto_seconds": auto, "chosen": chosen,
                                           "fastest": fastest, "ratio": ratio,
                                           "candidates": image.stats.choices["auto"][
                                               "candidates"]})
                    rows.append((label, f"{size}^2", f"{tolerance:g}",
                                 f"{times['trilinear'] * 1e3:.1f}",
                                 f"{times['catmull-rom'] * 1e3:.1f}", f"{auto * 1e3:.1f}",
                                 chosen, "yes" if chosen == fastest else "no",
                                 f"{ratio:.2f}"))
    print(markdown(["scene", "image", "tolerance", "trilinear ms", "Catmull-Rom ms",
                    "auto ms", "auto chose", "the faster", "auto / faster"], rows))
    ratios = [r["ratio"] for r in record["rows"]]
    right = sum(r["chosen"] == r["fastest"] for r in record["rows"])
    record["summary"] = {"cases": len(ratios), "chose_the_faster": right,
                         "median_ratio": statistics.median(ratios), "max_ratio": max(ratios)}
    print(f"\n{N}^3 volumes, 2 threads: auto chose the faster filter in {right} of "
          f"{len(ratios)} cases; its time over the faster one's: median "
          f"{statistics.median(ratios):.2f}, largest {max(ratios):.2f}")
    write_record("auto", record)


if __name__ == "__main__":
    main()
