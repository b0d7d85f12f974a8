"""Splatting against ray casting: cost per reconstructed point (``make bench``).

The thesis claims splatting reconstructs a point more cheaply than ray casting. A point is a
ray sample for the ray caster (here one per voxel of depth) and a footprint pixel for the
splatter (one voxel's kernel integrated along one pixel's ray). Both run in this process on
the same volume, image and filter, at 1 and 2 threads, at m = 0.5, 1, 2 pixels per voxel, on a
dense volume (Marschner-Lobb, every voxel visible) and a sparse one (a few blobs, 97% of the
voxels exactly zero). The table gives each method's frame time, its points and its
nanoseconds per point, and the splatter's frame time over the ray caster's.

Writes ``build/results/benchmarks/splat_cost.json``.
"""

from __future__ import annotations

import os
import platform
import tracemalloc

import numpy as np
from _report import best_of, markdown, write_record

import data_gen
from vrlib import Glow, View, Volume, render

N = 128
FILTERS = ("trilinear", "gaussian", "catmull-rom")


def volumes():
    dense = data_gen.make_field("marschner-lobb").sample(N, dtype=np.float32)
    blobs = data_gen.make_field("random-blobs", count=6, seed=4, sigma=(0.05, 0.08))
    data = blobs.sample(N, dtype=np.float32).data.copy()
    data[data < 0.05] = 0.0
    return {"dense": dense, "sparse": Volume(data, copy=False)}




def footprint_errors():
    """Largest interpolation error of each footprint table against a 1025-entry one."""
    from vrlib.footprint import footprint

    view = View.orbit(azimuth=30, elevation=20)
    rows = []
    for filt in FILTERS:
        basis = None if filt == "gaussian" else view.basis
        fine = footprint(filt, (1.0, 1.0, 1.0), basis, resolution=1024)
        g = np.linspace(-fine.extent, fine.extent, 601)
        u, v = np.meshgrid(g, np.linspace(-(fine.extent_v or fine.extent),
                                          fine.extent_v or fine.extent, 601))
        truth = fine(u, v)
        errors = []
        for resolution in (33, 65, 129, 257):
            table = footprint(filt, (1.0, 1.0, 1.0), basis, resolution=resolution)
            errors.append(float(np.abs(table(u, v) - truth).max() / truth.max()))
        rows.append((filt, errors))
    return rows


def main():
    record = {"machine": {"cpu": platform.processor() or platform.machine(),
                          "cores": os.cpu_count(), "python": platform.python_version()},
              "N": N, "rows": []}
    header = ["volume", "m", "filter", "threads", "raycast (s)", "ns/sample",
              "sheet (s)", "direct (s)", "ns/footprint px", "voxels drawn", "Mvoxels/s",
              "Mpx/s", "peak MiB", "splat/raycast"]
    lines = []
    for name, volume in volumes().items():
        nonzero = float(np.count_nonzero(volume.data)) / volume.data.size
        for m in (0.5, 1.0, 2.0):
            size = round(np.sqrt(3) * m * (N - 1))
            view = View.orbit(azimuth=30, elevation=20, size=size)
            for filt in FILTERS:
                for threads in (1, 2):
                    def cast(filt=filt, threads=threads, view=view, volume=volume):
                        return render(volume, view, filter=filt, transfer=Glow(1.0), step=1.0,
                                      threads=threads)

                    def splat(mode, filt=filt, threads=threads, view=view, volume=volume):
                        return render(volume, view, method="splat", filter=filt, mode=mode,
                                      transfer=Glow(1.0), threads=threads)

                    cast()
                    splat("sheet")
                    splat("direct")  # compile and build the footprint tables first
                    t_cast, img_cast = best_of(cast)
                    t_sheet, img_sheet = best_of(lambda: splat("sheet"))
                    t_direct, _ = best_of(lambda: splat("direct"))
                    tracemalloc.start()
                    splat("sheet")
                    peak = tracemalloc.get_traced_memory()[1]
                    tracemalloc.stop()
                    row = {
                        "volume": name, "nonzero_voxels": nonzero, "m": m, "size": size,
                        "filter": filt, "threads": threads,
                        "raycast_s": t_cast, "raycast_samples": img_cast.stats.samples,
                        "sheet_s": t_sheet, "direct_s": t_direct,
                        "footprint_pixels": img_sheet.stats.samples,
                        "voxels_drawn": img_sheet.stats.voxels, "splat_peak_bytes": peak,
                        "difference_alpha_max": float(np.abs(img_sheet.alpha
                                                             - img_cast.alpha).max()),
                    }
                    record["rows"].append(row)
                    lines.append([
                        name, f"{m:g}", filt, str(threads), f"{t_cast:.3f}",
                        f"{1e9 * t_cast / max(img_cast.stats.samples, 1):.1f}",
                        f"{t_sheet:.3f}", f"{t_direct:.3f}",
                        f"{1e9 * t_sheet / max(img_sheet.stats.samples, 1):.1f}",
                        f"{img_sheet.stats.voxels}",
                        f"{img_sheet.stats.voxels / t_sheet / 1e6:.1f}",
                        f"{img_sheet.stats.samples / t_sheet / 1e6:.0f}",
                        f"{peak / 2**20:.1f}", f"{t_sheet / t_cast:.2f}",
                    ])
                    print("| " + " | ".join(lines[-1]) + " |", flush=True)
    print(f"\n{N}^3 volume; image {N - 1} sqrt(3) m pixels wide; Glow(1); ray step 1 voxel; "
          "ns per point at the given thread count\n")
    print(markdown(header, lines))
    record["footprint_errors"] = footprint_errors()
    print("\nfootprint table: largest error / peak, against 1025 entries per axis")
    print("| filter | 33 | 65 | 129 (default) | 257 |\n|---|---|---|---|---|")
    for filt, errors in record["footprint_errors"]:
        print(f"| {filt} | " + " | ".join(f"{e:.1e}" for e in errors) + " |")
    write_record("splat_cost", record)


if __name__ == "__main__":
    main()
