"""Which method is cheapest, per reconstructed point and per frame, across pixels per voxel
(m = image size / volume size) and the share of visible voxels: ray casting, splatting and
shear-warp with the pyramid filter, all threads, measured on this machine.

Writes ``build/results/ch04_cost/regimes.json``.
"""

import numpy as np

import vrlib
from chapters.ch04_cost import _scenes
from chapters.common import by_profile, progress, result_path, write_json
from vrlib.cost import machine, measure, points

METHODS = ["raycast", "splat", "shearwarp"]
N = by_profile(64, 128)
PIXELS_PER_VOXEL = [0.5, 1.0, 2.0, 4.0]


def scenes():
    return {"sparse": _scenes.sparse(),
            "medium": _scenes.sparse(count=40, sigma=(0.12, 0.2), threshold=0.5),
            "dense": _scenes.dense()}


def main():
    rows = []
    jobs = [(s, m) for s in scenes() for m in PIXELS_PER_VOXEL]
    built = scenes()
    for scene, m in progress(jobs, "regimes"):
        field, transfer = built[scene]
        volume = field.sample(N)
        view = vrlib.View.orbit(azimuth=30, elevation=20, size=int(round(m * N)))
        for method in METHODS:
            seconds, image = measure(lambda volume=volume, view=view, transfer=transfer,
                                     method=method: vrlib.render(
                                         volume, view, method=method, filter="pyramid",
                                         transfer=transfer, step=1.0))
            count = points(image.stats)
            rows.append({"scene": scene, "m": m, "method": method, "seconds": seconds,
                         "points": count, "ns_per_point": 1e9 * seconds / max(count, 1),
                         "visible_fraction": _scenes.visible_fraction(volume, transfer)})
    cells = {}
    for scene, m in jobs:
        here = [r for r in rows if r["scene"] == scene and r["m"] == m]
        cells[f"{scene}|{m:g}"] = {
            "cheapest_per_point": min(here, key=lambda r: r["ns_per_point"])["method"],
            "fastest_frame": min(here, key=lambda r: r["seconds"])["method"],
            "visible_fraction": here[0]["visible_fraction"]}
    write_json(result_path(__file__, "regimes.json"), {
        "machine": machine(), "n": N, "pixels_per_voxel": PIXELS_PER_VOXEL,
        "scenes": list(built), "methods": METHODS, "rows": rows, "cells": cells,
        "splat_cheapest_per_point_cells": int(sum(c["cheapest_per_point"] == "splat"
                                                  for c in cells.values())),
        "splat_fastest_frame_cells": int(sum(c["fastest_frame"] == "splat"
                                             for c in cells.values())),
        "cell_count": len(cells),
        "median_splat_over_raycast_per_point": float(np.median([
            r["ns_per_point"] / next(q["ns_per_point"] for q in rows if q["method"] == "raycast"
                                     and q["scene"] == r["scene"] and q["m"] == r["m"])
            for r in rows if r["method"] == "splat"]))})


if __name__ == "__main__":
    main()
