"""Run time against error: every method, filter and step on one scene, timed on this machine
(all threads) and compared with the reference renderer; VTK's CPU ray caster and VolPack (when
installed) beside them.

Writes ``build/results/ch04_cost/pareto.json``.
"""

from functools import partial

import numba
import numpy as np

import vrlib
from chapters.ch04_cost import _peers, _scenes
from chapters.common import by_profile, progress, result_path, write_json
from vrlib.cost import machine, measure

N, SIZE = by_profile(64, 128), by_profile(256, 512)
FILTERS = list(vrlib.filters.STANDARD)
# Steps tried per method; a method not named here (one whose samples along a ray are not set
# by ``step``, or a new one) renders at its default.
STEPS = {"raycast": (0.25, 0.5, 1.0), "shear3": (0.5, 1.0), "shear2": (0.5, 1.0)}
CONFIGS = [(method, step) for method in vrlib.METHODS for step in STEPS.get(method, (None,))]


def pareto(points):
    """Indices of the points no other point beats in both time and error."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], np.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def main():
    field, transfer = _scenes.dense()
    volume = field.sample(N)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE)
    ref = vrlib.render_reference(field, view, transfer=transfer, tol=1e-6).alpha
    rows = []
    jobs = [(m, s, f) for m, s in CONFIGS for f in FILTERS]
    for method, step, filt in progress(jobs, "pareto"):
        options = {} if step is None else {"step": step}
        seconds, image = measure(lambda method=method, filt=filt, options=options: vrlib.render(
            volume, view, method=method, filter=filt, transfer=transfer, **options))
        rows.append({"renderer": "vrlib", "method": method, "filter": filt, "step": step,
                     "seconds": seconds, "rmse": vrlib.metrics.rmse(image.alpha, ref)})
    peers = []
    vtk_caster, (load_volpack, volpack) = _peers.peers()
    if vtk_caster is not None:
        for step in (0.5, 1.0):
            caster = vtk_caster(volume, view, transfer, step * float(volume.spacing.min()))
            best, _ = measure(partial(caster.render, numba.config.NUMBA_NUM_THREADS))
            peers.append({"renderer": "VTK fixed-point ray caster", "step": step,
                          "seconds": best, "rmse": vrlib.metrics.rmse(caster.image(), ref)})
            caster.close()
    lib = load_volpack()
    if lib is not None:
        vp = volpack(lib, volume, view, transfer, min_opacity=0.0, max_opacity=1.0)
        seconds, _ = measure(vp.render)
        peers.append({"renderer": "VolPack (1 thread, thresholds off)", "step": None,
                      "seconds": seconds, "rmse": vrlib.metrics.rmse(vp.alpha(), ref)})
        vp.close()
    front = pareto([(r["seconds"], r["rmse"]) for r in rows])
    write_json(result_path(__file__, "pareto.json"), {
        "machine": machine(), "n": N, "size": SIZE, "rows": rows, "peers": peers,
        "front": [rows[i] for i in front],
        "volpack_installed": lib is not None, "vtk_installed": vtk_caster is not None})


if __name__ == "__main__":
    main()
