"""Segment ends: the ray caster's error against the exact image of the field its filter
reconstructs (:class:`vrlib.ReconstructedField` integrated by :func:`vrlib.render_reference`,
so that the sampling error is left out and only the error along rays remains), as the step
shrinks, with the faces' cut segments counted as whole steps (``segment_ends="lattice"``) or
by their part inside the volume (``"exact"``). Fields live at the volume's faces
(Marschner-Lobb, and a blob on a constant floor) and one that vanishes there (a narrow blob).
Writes ``build/results/ch08_stability/segment_ends.json``.
"""

import numpy as np

import data_gen
import vrlib
from chapters.common import by_profile, progress, result_path, write_json

STEPS = [1.0, 0.5, 0.25, 0.125, 0.0625]
SIZE = by_profile(96, 192)
SAMPLES = 37
FILTERS = ["trilinear", "catmull-rom"]
ENDS = ["lattice", "exact"]


def scenes():
    """(key, label, live at the faces?, volume, transfer function)."""
    ml = data_gen.make_field("marschner-lobb").sample(SAMPLES)
    blob = data_gen.make_field("gaussian-blob", sigma=0.25, center=(0.05, -0.1, 0.08))
    narrow = blob.sample(SAMPLES)
    floor = vrlib.Volume(narrow.data + 0.3, narrow.extent)
    return [("ml", "Marschner-Lobb", True, ml, vrlib.Glow(1.0)),
            ("floor", "blob on a floor of 0.3", True, floor, vrlib.Glow(1.0)),
            ("narrow", "narrow blob (near zero at the faces)", False, narrow, vrlib.Glow(2.0))]


def order(steps, errors):
    """Slope of log(error) against log(step)."""
    return float(np.polyfit(np.log(steps), np.log(errors), 1)[0])


def main():
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE)
    rows, cases = [], {}
    for key, label, live, vol, transfer in progress(scenes(), "scenes"):
        for filt in FILTERS:
            exact = vrlib.render_reference(vrlib.ReconstructedField(vol, filt), view,
                                           transfer=transfer, tol=1e-8)
            for ends in ENDS:
                errors, samples = [], []
                for step in STEPS:
                    img = vrlib.render(vol, view, filter=filt, transfer=transfer, step=step,
                                       early_termination=1.0, segment_ends=ends)
                    errors.append(vrlib.metrics.rmse(img, exact))
                    samples.append(img.stats.samples)
                row = {"scene": label, "live_at_faces": live, "filter": filt, "ends": ends,
                       "steps": STEPS, "rmse": errors, "samples": samples,
                       "order": order(STEPS, errors)}
                rows.append(row)
                cases[f"{key}-{filt}-{ends}"] = row
            # The coarsest exact-ends step that is as accurate as lattice ends' finest step.
            finest = cases[f"{key}-{filt}-lattice"]["rmse"][-1]
            good = [s for s, e in zip(STEPS, cases[f"{key}-{filt}-exact"]["rmse"],
                                      strict=True) if e <= finest]
            cases[f"{key}-{filt}-exact"]["step_for_lattice_finest"] = max(good, default=None)
    write_json(result_path(__file__, "segment_ends.json"),
               {"rows": rows, "cases": cases, "steps": STEPS, "volume": SAMPLES, "image": SIZE})


if __name__ == "__main__":
    main()
