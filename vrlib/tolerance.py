"""Rendering to a requested error: ``render(..., tolerance=t)``.

The promise: the image's rmse (premultiplied RGBA, :func:`vrlib.metrics.rmse`) against the
exact image of the field the chosen filter reconstructs (:class:`vrlib.ReconstructedField`
integrated by :func:`vrlib.render_reference`) is at most ``t``. The reconstruction's own
error, the filter against the true field, is not part of it: that is the filter's choice.

How it is kept (docs/kernel.md):

* The ray caster runs with exact segment ends, whose error along rays falls as the step
  squared once the step resolves the field, and point classification (:data:`CLASSIFICATION`):
  pre-integration kept the promise in the same cases but cost more at the steps the promise
  needs (the report's chapter on time against error measures both).
* Early termination takes :data:`TERM_SHARE` of ``t``: rays stop at opacity
  ``1 - TERM_SHARE t / E``, where ``E`` is the brightest channel a sample can send, which
  changes no pixel by more than that share.
* The step takes :data:`STEP_SHARE` of ``t``. A pilot renders the view at a quarter of its
  pixels per axis with steps of 2, 1, 1/2 ... voxels. The differences between successive
  pilot images give the order of convergence ``p`` (taken between 1 and 2) and the error of
  the finest, ``d / (2^p - 1)`` (Richardson). When the first two already differ by at most
  half the share, the coarsest step is taken at once: its error is at most ``2 d`` for any
  order of at least 1. The step is then the one whose extrapolated
  error is the share, but never coarser than the pilot's coarsest. The pilot goes on halving
  while the step it predicts lies below half its finest step, so the prediction never
  reaches far past what it measured.
* A tolerance that would need a step below :data:`MIN_STEP` voxel is refused, with the
  error that step reaches, never answered with a worse image.

``img.stats.choices`` records what was chosen and the estimated error.
"""

from __future__ import annotations

import math
import time

from vrlib import validate
from vrlib.metrics import rmse
from vrlib.raycast import brightest, render_raycast
from vrlib.value_bounds import reconstructed_range

__all__ = ["render_within", "TERM_SHARE", "STEP_SHARE", "MIN_STEP", "MAX_STEP"]

#: How a render to a tolerance classifies its segments. Measured on the chapter's matrix
#: (96^2): point sampling with exact ends kept every promise pre-integration kept, in 1.0 to
#: 2.1 times less time, because pre-integration costs 1.8 times as much per sample and, at the
#: steps a tolerance of 1e-2 or less needs, saves few samples.
CLASSIFICATION = "point"
#: Share of the tolerance given to early ray termination.
TERM_SHARE = 0.05
#: Share of the tolerance the estimated step error may take (the rest is a margin for the
#: estimate's own error).
STEP_SHARE = 0.8
#: Smallest step (voxels) a tolerance may ask for.
MIN_STEP = 1.0 / 256.0
#: Largest step (voxels) a tolerance may be given: the pilot's first.
MAX_STEP = 2.0
#: Pilot images have this many times fewer pixels per axis than the image (at least
#: :data:`PILOT_MIN` pixels a side).
PILOT_SHRINK = 4
PILOT_MIN = 32


def render_within(volume, view, *, filt, transfer, tolerance, empty_space_skipping=True):
    """Ray-cast ``volume`` within rmse ``tolerance`` of the exact image of the field ``filt``
    reconstructs (arguments checked by :func:`vrlib.render`).

    Returns
    -------
    Image
        Its ``stats.choices`` holds the step, classification, segment ends, early
        termination and skip budget chosen, the pilot's steps, errors and time, and
        ``estimate``, the error it expects.

    Raises
    ------
    ValueError
        The tolerance needs a step below :data:`MIN_STEP` voxel.

    Examples
    --------
    >>> import data_gen, vrlib
    >>> vol = data_gen.make_field("marschner-lobb").sample(17)
    >>> img = vrlib.render(vol, vrlib.View.orbit(size=32), tolerance=1e-3)
    >>> sorted(img.stats.choices)[:4]
    ['classification', 'early_termination', 'estimate', 'filter']
    >>> bool(img.stats.choices["estimate"] <= 1e-3)
    True
    """
    tolerance = validate.finite_number("tolerance", tolerance, low=0.0, high=1.0,
                                       low_open=True, high_open=True)
    start = time.perf_counter()
    classification = "point" if volume.holes is not None else CLASSIFICATION
    light = brightest(transfer, reconstructed_range(volume, filt))
    early_termination = 1.0 - TERM_SHARE * tolerance / light
    options = dict(filt=filt, transfer=transfer, early_termination=early_termination,
                   empty_space_skipping=empty_space_skipping, segment_ends="exact",
                   classification=classification, memo={})  # the pilots' footprint masks

    pilot_view = view.resized(tuple(max(PILOT_MIN, n // PILOT_SHRINK) for n in view.shape))
    if pilot_view.height >= view.height and pilot_view.width >= view.width:
        pilot_view = view
    target = STEP_SHARE * tolerance
    steps, differences = [], []
    step = MAX_STEP
    previous = predicted = None
    while True:
        steps.append(step)
        pilot = render_raycast(volume, pilot_view, step=step, **options)
        if previous is not None:
            differences.append(rmse(previous, pilot))
        previous = pilot
        if len(differences) == 1 and 2.0 * differences[0] <= target:
            # The coarsest step already meets the share: with order >= 1 its error is at
            # most d / (1 - 2^-p) <= 2 d, coherent or not (a third pilot would only cost).
            predicted, error_at = MAX_STEP, _first_order_bound(differences[0])
            break
        if len(differences) >= 2:
            predicted, error_at = _predict(steps, differences, target)
            if predicted >= 0.5 * steps[-1] or step / 2.0 < MIN_STEP:
                break
        step /= 2.0
    if predicted < MIN_STEP:
        reach = error_at(MIN_STEP)
        raise ValueError(
            f"tolerance={tolerance:g} is out of reach of ray casting with the {filt.name} "
            f"filter here: it would need a step below {MIN_STEP:g} voxel, where the error "
            f"along rays is still about {reach:.2g}; ask for a tolerance of at least "
            f"{reach / STEP_SHARE:.2g}")
    step = float(min(predicted, MAX_STEP))
    pilot_seconds = time.perf_counter() - start
    image = render_raycast(volume, view, step=step, **options)
    estimate = error_at(step) + TERM_SHARE * tolerance
    image.stats.seconds = time.perf_counter() - start
    image.stats.choices = {
        "tolerance": tolerance, "method": "raycast", "filter": filt.name, "step": step,
        "classification": classification, "segment_ends": "exact",
        "early_termination": early_termination, "skip_budget": 0.0, "estimate": estimate,
        "pilot": {"shape": list(pilot_view.shape), "steps": steps,
                  "differences": differences, "seconds": pilot_seconds},
    }
    return image


def _first_order_bound(difference):
    """The error model after two pilots whose images differ by ``difference``: at most twice
    that at the coarser step (order at least 1)."""
    return lambda h: 2.0 * difference * h / MAX_STEP


def _predict(steps, differences, target):
    """The step whose extrapolated error is ``target``, and the error model it uses.

    ``differences[i]`` is the rmse between the pilot images at ``steps[i]`` and
    ``steps[i + 1] = steps[i] / 2``. The order ``p`` comes from the last two differences
    (between 1 and 2); the error of the finest pilot is ``d / (2^p - 1)``, and the error at
    step ``h`` is taken as that times ``(h / finest)^p``.
    """
    d_prev, d_last = differences[-2], differences[-1]
    finest = steps[-1]
    if not d_last > 0.0:
        return MAX_STEP, lambda h: 0.0
    order = math.log2(d_prev / d_last) if d_prev > 0.0 else 2.0
    order = min(max(order, 1.0), 2.0)
    error = d_last / (2.0**order - 1.0)

    def error_at(h):
        return error * (h / finest) ** order

    return finest * (target / error) ** (1.0 / order), error_at
