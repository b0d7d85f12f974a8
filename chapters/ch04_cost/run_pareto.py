"""Run time against error: every method, filter and step on one scene, timed on this machine
(all threads) and compared with the reference renderer, with the classified shear-warp
(:func:`vrlib.classify`, its classification timed apart); VTK's CPU ray caster at sample
distances of 0.5, 1 and 2 voxels and VolPack with its thresholds off and at 0.05/0.95 (when
installed) beside them. For every peer point: the fastest vrlib configuration that is both
faster and more accurate, or, when none is, how much slower vrlib's fastest configuration of at
least the same accuracy is.

A prefiltered filter's time includes computing the volume's coefficients once
(``prefilter_seconds``, :mod:`vrlib.prefilter`): the time of a first frame of a new volume;
later frames of the same volume take ``frame_seconds``.

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


#: The classified shear-warp's settings: (label, min_opacity, early_termination).
CLASSIFIED = [("exact", 0.0, 0.999), ("0.05/0.95", 0.05, 0.95)]


def dominance(rows, peer):
    """How vrlib's configurations ``rows`` stand against one ``peer`` point: the fastest row
    both faster and more accurate (``dominated_by``), else the fastest row at least as accurate
    and its time over the peer's (``slower_by``; None when no row is as accurate)."""
    beats = [r for r in rows if r["seconds"] < peer["seconds"] and r["rmse"] < peer["rmse"]]
    if beats:
        best = min(beats, key=lambda r: r["seconds"])
        return {"dominated_by": best, "closest": None, "slower_by": None}
    accurate = [r for r in rows if r["rmse"] <= peer["rmse"]]
    if not accurate:
        return {"dominated_by": None, "closest": None, "slower_by": None}
    best = min(accurate, key=lambda r: r["seconds"])
    return {"dominated_by": None, "closest": best, "slower_by": best["seconds"] / peer["seconds"]}


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
        once = 0.0
        if vrlib.make_filter(filt).prefiltered:  # the first frame of a new volume: its
            fresh = vrlib.Volume(volume.data, volume.extent, copy=False)  # coefficients
            first = vrlib.render(fresh, view, method=method, filter=filt, transfer=transfer,
                                 **options)
            once = first.stats.prefilter["kept_seconds"]
        rows.append({"renderer": "vrlib", "method": method, "filter": filt, "step": step,
                     "seconds": seconds + once, "frame_seconds": seconds,
                     "prefilter_seconds": once, "rmse": vrlib.metrics.rmse(image.alpha, ref)})
    for label, low, termination in CLASSIFIED:
        scene = vrlib.classify(volume, transfer, min_opacity=low)
        seconds, image = measure(lambda scene=scene, termination=termination: scene.render(
            view, early_termination=termination))
        rows.append({"renderer": "vrlib", "method": f"classified {label}", "filter": "trilinear",
                     "step": None, "seconds": seconds, "classify_seconds": scene.seconds,
                     "rmse": vrlib.metrics.rmse(image.alpha, ref)})
    peers = []
    vtk_caster, (load_volpack, volpack) = _peers.peers()
    if vtk_caster is not None:
        for step in (0.5, 1.0, 2.0):
            caster = vtk_caster(volume, view, transfer, step * float(volume.spacing.min()))
            best, _ = measure(partial(caster.render, numba.config.NUMBA_NUM_THREADS))
            peers.append({"renderer": "VTK fixed-point ray caster", "step": step,
                          "seconds": best, "rmse": vrlib.metrics.rmse(caster.image(), ref)})
            caster.close()
    lib = load_volpack()
    if lib is not None:
        for label, low, high in [("thresholds off", 0.0, 1.0), ("0.05/0.95", 0.05, 0.95)]:
            vp = volpack(lib, volume, view, transfer, min_opacity=low, max_opacity=high)
            name = f"VolPack (1 thread, {label})"
            if vp.table.max() <= low:
                # Every voxel is below the threshold: the classified volume is empty, and
                # VolPack 1.0b3 does not return from rendering it. The image would be blank.
                peers.append({"renderer": name, "step": None, "seconds": None,
                              "rmse": vrlib.metrics.rmse(np.zeros_like(ref), ref),
                              "note": "every voxel below the threshold: blank image"})
                vp.close()
                continue
            seconds, _ = measure(vp.render)
            peers.append({"renderer": name, "step": None, "seconds": seconds,
                          "rmse": vrlib.metrics.rmse(vp.alpha(), ref)})
            vp.close()
    for peer in peers:  # every peer has the keys (None where untimed): the report reads them
        peer.update({"dominated_by": None, "closest": None, "slower_by": None})
        if peer["seconds"] is not None:
            peer.update(dominance(rows, peer))
    timed = rows + [p for p in peers if p["seconds"] is not None]
    front = pareto([(r["seconds"], r["rmse"]) for r in rows])
    front_all = pareto([(r["seconds"], r["rmse"]) for r in timed])
    write_json(result_path(__file__, "pareto.json"), {
        "machine": machine(), "n": N, "size": SIZE, "rows": rows, "peers": peers,
        "front": [rows[i] for i in front], "front_all": [timed[i] for i in front_all],
        "volpack_installed": lib is not None, "vtk_installed": vtk_caster is not None})


if __name__ == "__main__":
    main()
