"""Frequency responses of every reconstruction filter (analytic, from vrlib.filters): for a
prefiltered filter, the effective response of the reconstruction from the samples (its kernel's
divided by the sampled kernel's, the prefilter's inverse).

Writes ``build/results/ch02_filters/responses.npz`` (the curves) and ``responses.json`` (the
values the table and the report quote). Omega is in radians per sample: Nyquist is pi, and a
filter that sums to one over the lattice has zeros at every non-zero multiple of 2 pi.
"""

import numpy as np

from chapters.common import atomic_path, result_path, write_json
from vrlib.filters import make_filter

FILTERS = {
    "box": "box",
    "pyramid": "pyramid",
    "catmull-rom": "catmull-rom",
    "mitchell": "mitchell",
    "bspline": "bspline",
    "cardinal-bspline": "cardinal-bspline",
    "omoms": "omoms",
    "gaussian s=0.5": ("gaussian", 0.5, 2.0),
    "gaussian s=0.6": ("gaussian", 0.6, 2.0),
    "gaussian s=0.8": ("gaussian", 0.8, 2.0),
}


def main():
    omega = np.linspace(0.0, 4 * np.pi, 1601)
    sidelobes = omega >= 1.5 * np.pi
    curves, summary = {}, {}
    for label, spec in FILTERS.items():
        f = make_filter(spec)
        k = f.effective_response(omega)
        curves[label] = k
        summary[label] = {
            "dc": float(f.effective_response(0.0)),
            "half_nyquist": float(f.effective_response(np.pi / 2)),
            "nyquist": float(f.effective_response(np.pi)),
            "sidelobe_peak": float(np.max(np.abs(k[sidelobes]))),
            "at_2pi": float(f.effective_response(2 * np.pi)),
            "partition_of_unity": bool(f.partition_of_unity),
            "interpolating": bool(f.interpolates_samples),
            "prefiltered": bool(f.prefiltered),
        }
    with atomic_path(result_path(__file__, "responses.npz")) as tmp:
        np.savez(tmp, omega=omega, labels=np.array(list(curves)),
                 curves=np.array(list(curves.values())))
    write_json(result_path(__file__, "responses.json"), summary)


if __name__ == "__main__":
    main()
