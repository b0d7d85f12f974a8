"""The filter chosen for a render to a tolerance: ``render(..., method="auto", tolerance=t)``
with no filter given.

Each filter keeps the promise with its own pilots (:mod:`vrlib.tolerance`), against the exact
image of the field *it* reconstructs; which of them keeps it soonest is a question of time,
which this machine's cost model answers (:mod:`vrlib.cost`: ``t = c_op * operations + c_pt *
points + c_0``, fitted per method by ``vrlib bench``).

* The candidates (:data:`CANDIDATES`) are the interpolating filters that need no prefilter,
  cheapest per sample first. Each passes through the samples, so the image shows the
  volume's own values wherever it has them: an approximating filter (B-spline, Gaussian)
  would reach a tolerance sooner only by blurring the volume, which a tolerance measured
  against that filter's own field does not see.
* The first candidate is planned (its pilots choose its step) and the model predicts its
  image's time from the samples its first pilot took, scaled to the image's pixels and the
  step (:meth:`vrlib.tolerance.Plan.samples`). A later candidate's plan is dropped as soon
  as the model's time for what it still costs is no less than the best prediction so far:
  before its first pilot, its image at the longest step any plan may take
  (:attr:`Plan.longest`) and its first two pilots (at 2 and 1 voxels, the first
  candidate's pilot's samples: one dearer per sample cannot win where the first took that
  step already, so then it costs nothing), and after its first two, where they show that
  its first step, :data:`vrlib.tolerance.MAX_STEP`, is too long, its image at that step
  (longer ones are tried only from one that meets the tolerance; see
  :func:`vrlib.tolerance.plan_within`). With the pilots counted (2026-11-29),
  ``benchmarks/bench_auto.py``'s sparse blobs at 512^2 and 1e-3 no longer ran
  Catmull-Rom's pilots: 0.88 and 1.11 times the faster filter's time in two runs, instead
  of 1.54.
* The candidate with the least predicted time is rendered. Without a cost model on this
  machine the first candidate is, and ``img.stats.choices["auto"]`` says so (``vrlib bench``
  fits one).

Only ray casting renders to a tolerance, so the method chosen is ray casting. The choice
depends on this machine's model, never on the thread count: the same model gives the same
image.
"""

from __future__ import annotations

import time

from vrlib.cost import load_model, predict
from vrlib.filters import make_filter
from vrlib.holes import with_holes
from vrlib.raycast import operations_per_sample
from vrlib.tolerance import plan_within, render_plan

__all__ = ["render_auto", "CANDIDATES"]

#: The filters a render to a tolerance chooses between, cheapest per sample first.
CANDIDATES = ("trilinear", "catmull-rom")


def render_auto(volume, view, *, transfer, tolerance, empty_space_skipping=True):
    """Ray-cast ``volume`` within ``tolerance`` with the candidate filter this machine's cost
    model predicts to be fastest (the module's docstring; arguments checked by
    :func:`vrlib.render`, ``transfer`` not yet wrapped for the volume's holes: each filter
    wraps it for the range it reconstructs).

    Returns
    -------
    Image
        Its ``stats.choices`` are the chosen filter's (:func:`vrlib.tolerance.render_within`),
        with ``auto``: the filter chosen (by its name in :data:`CANDIDATES`), the cost
        model's file (None where there is none), per candidate its step and predicted
        seconds or why it was not planned, and the seconds the choice took.

    Raises
    ------
    ValueError
        The cost model's file is not one ``vrlib bench`` wrote, or the tolerance is out of
        the first candidate's reach.

    Examples
    --------
    >>> import os, tempfile, data_gen, vrlib
    >>> from unittest import mock
    >>> from vrlib.cost import save_model
    >>> path = os.path.join(tempfile.mkdtemp(), "cost.json")
    >>> _ = save_model({"raycast": {"c_op": 1e-10, "c_pt": 1e-8, "c_0": 1e-4}}, path)
    >>> vol = data_gen.make_field("marschner-lobb").sample(17)
    >>> with mock.patch.dict(os.environ, VRLIB_COST_MODEL=path):
    ...     img = vrlib.render(vol, vrlib.View.orbit(size=32), method="auto", tolerance=1e-3)
    >>> img.stats.choices["auto"]["filter"], img.stats.choices["step"]
    ('trilinear', 1.0)
    >>> [c.get("skipped", "planned")[:41] for c in img.stats.choices["auto"]["candidates"]]
    ['planned', 'at 2 voxels, the longest step left to it,']
    """
    start = time.perf_counter()
    model = load_model()
    constants = None if model is None else model["methods"].get("raycast")
    why_not = ("no cost model on this machine: `vrlib bench` fits one" if model is None else
               "the cost model has no ray casting: `vrlib bench` fits it")
    pixels = view.height * view.width
    shading = transfer.needs_gradient

    def seconds(filt, samples):
        ops = operations_per_sample(filt, shading=shading)
        return predict(constants, samples * ops, samples)

    plans, predicted, rows, refusal = [], [], [], None
    for name in CANDIDATES:
        filt = make_filter(name)
        if plans and constants is None:
            rows.append({"filter": name, "skipped": why_not})
            continue
        bounds = []

        def no_faster(longest, filt=filt, bounds=bounds):
            """Whether the model's time for what this filter still costs (a lower bound:
            its image at the longest step still open, and before its first pilot, its
            first two pilots, at 2 and 1 voxels) is no less than the best image's so far."""
            pilots = 0.0 if bounds else seconds(filt, 3 * plans[0].pilot_samples)
            image = seconds(filt, plans[0].samples(pixels, longest))
            bounds.append((longest, image + pilots))
            return bounds[-1][1] >= min(predicted)

        try:
            plan = plan_within(volume, view, filt=filt,
                               transfer=with_holes(volume, transfer, filt, "raycast"),
                               tolerance=tolerance, empty_space_skipping=empty_space_skipping,
                               abandon=no_faster if plans else None)
        except ValueError as error:  # out of this filter's reach: the next may reach it
            refusal = refusal or error
            rows.append({"filter": name, "skipped": str(error)})
            continue
        if plan is None:
            longest, bound = bounds[-1]
            rows.append({"filter": name, "bound_seconds": bound, "skipped": (
                f"at {longest:g} voxels, the longest step left to it, the model predicts "
                f"{'with its first pilots ' if len(bounds) == 1 else ''}"
                f"{bound:.3g} s, no less than {min(predicted):.3g} s")})
            continue
        plans.append(plan)
        predicted.append(None if constants is None else seconds(filt, plan.samples(pixels)))
        rows.append({"filter": name, "step": plan.step, "predicted_seconds": predicted[-1]})
    if not plans:
        raise refusal
    best = 0 if constants is None else predicted.index(min(predicted))
    chosen = plans[best]
    chosen.choices["auto"] = {
        "filter": [row["filter"] for row in rows if "step" in row][best],
        "cost_model": None if model is None else model["path"],
        "candidates": rows, "seconds": time.perf_counter() - start}
    return render_plan(volume, view, chosen, start)
