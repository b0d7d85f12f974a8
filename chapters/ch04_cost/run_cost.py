"""Measured cost per reconstructed point on this machine, for every method and three filters,
on a dense and a sparse scene, with numba on 1 thread, on all threads, and with the NumPy twins
of the kernels (``tests/naive.py``, a much slower "workstation", on a small volume).

Writes ``build/results/ch04_cost/machines/<machine id>.json``; the tables merge every machine's
file found there or committed under ``chapters/ch04_cost/machines/``.
"""

import sys
from functools import partial

import numba

import vrlib
from chapters.ch04_cost import _scenes
from chapters.common import ROOT, by_profile, progress, result_path, write_json
from vrlib.cost import machine, measure, points

METHODS = list(vrlib.METHODS)
FILTERS = ["pyramid", "gaussian", "catmull-rom"]
N, SIZE = by_profile(64, 128), by_profile(128, 256)
TWIN_N, TWIN_SIZE = 10, 12


def twins():
    """The naive NumPy twins of the renderers (``tests/naive.py``), by method."""
    sys.path.insert(0, str(ROOT / "tests"))
    import naive

    return naive.TWINS


def main():
    record = {"machine": machine(), "n": N, "size": SIZE, "twin_n": TWIN_N,
              "twin_size": TWIN_SIZE, "rows": []}
    all_threads = numba.config.NUMBA_NUM_THREADS
    backends = [("numba 1 thread", 1), (f"numba {all_threads} threads", all_threads)]
    scenes = {"dense": _scenes.dense(), "sparse": _scenes.sparse()}
    jobs = [(s, m, f) for s in scenes for m in METHODS for f in FILTERS]
    twin = twins()
    for scene, method, filt in progress(jobs, "cost"):
        field, transfer = scenes[scene]
        for n, size, backends_here in [(N, SIZE, backends), (TWIN_N, TWIN_SIZE, None)]:
            volume = field.sample(n)
            view = vrlib.View.orbit(azimuth=30, elevation=20, size=size)

            draw = partial(_draw, volume, view, method, filt, transfer)

            if backends_here is None:  # the NumPy twin, counted by the kernel's statistics
                stats = draw(1).stats
                filt_obj = vrlib.make_filter(filt)
                seconds, _ = measure(partial(twin[method], volume, view, filt_obj, transfer),
                                     repeats=1)
                runs = [("numpy twins", seconds, stats)]
            else:
                runs = []
                for label, threads in backends_here:
                    seconds, image = measure(partial(draw, threads))
                    runs.append((label, seconds, image.stats))
            for label, seconds, stats in runs:
                count = points(stats)
                record["rows"].append({
                    "scene": scene, "method": method, "filter": filt, "backend": label,
                    "n": n, "size": size, "seconds": seconds, "points": count,
                    "operations": int(stats.operations),
                    "ns_per_point": 1e9 * seconds / max(count, 1),
                    "visible_fraction": _scenes.visible_fraction(volume, transfer)})
    write_json(result_path(__file__, f"machines/{record['machine']['id']}.json"), record)


def _draw(volume, view, method, filt, transfer, threads):
    return vrlib.render(volume, view, method=method, filter=filt, transfer=transfer, step=0.5,
                        threads=threads)


if __name__ == "__main__":
    main()
