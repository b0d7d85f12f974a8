"""Shear-warp beside the ray caster and the two shear methods (``make bench``).

256^3 volume into a 512^2 image, orthographic, on a dense volume (Marschner-Lobb, Glow) and a
sparse one (six blobs under a ramp from 0.1). Shear-warp runs with exact skipping (opacity
threshold 0, termination at 0.999) and with VolPack's lossy defaults (0.05 / 0.95), both as
post-classified shear-warp (``method="shearwarp"``: values resampled, then classified) and as
the classified shear-warp (:func:`vrlib.classify`: voxels classified once, VolPack's way; its
classification is timed apart and printed). Each time is the best of three, at 1 and 2
threads; errors are against the reference renderer.

VolPack's thresholds act on each voxel's opacity per slice; under the glow function at this
resolution every voxel of the dense scene is fainter than 0.05 (one slice is 1/256 of the
volume), so the lossy setting drops them all: the row shows what such a threshold can cost.

VolPack itself (Debian's ``libvolpack1``, through ctypes: ``_volpack.py``) renders the same
volume, view and glow table beside them, with the thresholds off and at 0.05 / 0.95, when the
library is installed (``make bench`` installs it when it can); otherwise its rows are skipped
with a message. VolPack is single-threaded; its classification (run once per volume and
transfer function) is timed apart from the render.
"""

from __future__ import annotations

import time
import tracemalloc

import numpy as np
from _report import best_of, markdown, write_record
from _volpack import VolPack, load

import data_gen
import vrlib

N, SIZE = 256, 512


def scenes():
    ramp = np.linspace(0.0, 1.0, 11)
    sparse_tf = vrlib.LookupTransfer(6.0 * np.clip((ramp - 0.1) / 0.9, 0.0, None))
    blobs = data_gen.make_field("random-blobs", count=6, seed=4, sigma=(0.06, 0.1))
    return {"dense": (data_gen.make_field("marschner-lobb"), vrlib.Glow(1.0)),
            "sparse": (blobs, sparse_tf)}




#: The classified shear-warp (:func:`vrlib.classify`, VolPack's way), per frame; its
#: classification is timed apart, as VolPack's.
CLASSIFIED = [("classified exact", {"classified": 0.0}),
              ("classified 0.05/0.95", {"classified": 0.05, "early_termination": 0.95})]


def main():
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE)
    configs = [
        ("raycast", {"method": "raycast", "step": 1.0}),
        ("shear3", {"method": "shear3", "step": 1.0, "filter": "trilinear"}),
        ("shear2", {"method": "shear2", "step": 1.0, "filter": "trilinear"}),
        ("shearwarp exact", {"method": "shearwarp"}),
        ("shearwarp 0.05/0.95", {"method": "shearwarp", "min_opacity": 0.05,
                                 "early_termination": 0.95}),
    ]
    rows, record = [], {"N": N, "size": SIZE, "rows": []}
    for scene, (field, transfer) in scenes().items():
        volume = field.sample(N, dtype=np.float32)
        ref = vrlib.render_reference(field, view, transfer=transfer, tol=1e-5).alpha
        classified = {}
        for low in (0.0, 0.05):
            start = time.perf_counter()
            classified[low] = vrlib.classify(volume, transfer, min_opacity=low)
            classified[low].render(view)  # encodes the view's axis
            record[f"classify_s {scene} {low}"] = time.perf_counter() - start
        for label, options in configs + CLASSIFIED:
            def go(threads, options=options, volume=volume, transfer=transfer,
                   classified=classified):
                if "classified" in options:
                    options = dict(options)
                    return classified[options.pop("classified")].render(view, threads=threads,
                                                                        **options)
                return vrlib.render(volume, view, transfer=transfer, threads=threads, **options)

            go(2)
            t1, _ = best_of(lambda go=go: go(1))
            t2, img = best_of(lambda go=go: go(2))
            tracemalloc.start()
            go(2)
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
            error = vrlib.metrics.rmse(img.alpha, ref)
            record["rows"].append({"scene": scene, "config": label, "t1": t1, "t2": t2,
                                   "rmse": error, "peak_bytes": peak})
            rows.append([scene, label, f"{t2:.3f}", f"{t1 / t2:.2f}", f"{error:.2e}",
                         f"{peak / 2**20:.0f}"])
            print("| " + " | ".join(rows[-1]) + " |", flush=True)
        lib = load()
        if lib is None:
            print("VolPack (libvolpack1) is not installed: its comparison is skipped")
            continue
        for label, low, high in [("VolPack 0/1", 0.0, 1.0), ("VolPack 0.05/0.95", 0.05, 0.95)]:
            vp = VolPack(lib, volume, view, transfer, min_opacity=low, max_opacity=high)
            if vp.table.max() <= low:
                # Every voxel is below the threshold: VolPack's classified volume is empty, and
                # rendering an empty classified volume does not return (seen with 1.0b3-9).
                error = vrlib.metrics.rmse(np.zeros_like(ref), ref)
                rows.append([scene, label, "(every voxel below threshold)", "-",
                             f"{error:.2e}", "-"])
                print("| " + " | ".join(rows[-1]) + " |", flush=True)
                vp.close()
                continue
            vp.render()
            t, _ = best_of(vp.render)
            error = vrlib.metrics.rmse(vp.alpha(), ref)
            record["rows"].append({"scene": scene, "config": label, "t1": t, "t2": None,
                                   "rmse": error, "classify_s": vp.classify_seconds})
            rows.append([scene, label, f"{t:.3f} (1 thread)", "-", f"{error:.2e}",
                         f"classify {vp.classify_seconds:.2f} s"])
            print("| " + " | ".join(rows[-1]) + " |", flush=True)
            vp.close()
    print(f"\n{N}^3 -> {SIZE}^2, orthographic, trilinear (tent) filters\n")
    print(markdown(["scene", "method", "2 threads (s)", "1t / 2t", "rmse", "peak MiB"], rows))
    print("\nclassification (once per volume and transfer function): " + ", ".join(
        f"{key.split(' ', 1)[1]}: {seconds:.2f} s" for key, seconds in record.items()
        if key.startswith("classify_s")))
    write_record("shear", record)


if __name__ == "__main__":
    main()
