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
  pixels per axis (32 to 64 a side) with steps of 2, 1, 1/2 ... voxels. The differences
  between successive pilot images give the order of convergence ``p`` (taken between 1 and
  2) and the error of the finest, Richardson's ``d / (2^p - 1)``. That takes successive
  differences as pointing the same way (a truncation error that keeps its pattern); where
  they do not (aliasing, whose pattern changes with the step), the error is smaller
  (:func:`finest_error`), and the longer step that allows is taken when one more pilot at
  it, compared with the finest, confirms it. When the first two already differ by at most
  half the share, the coarsest step is taken at once: its error is at most ``2 d`` for any
  order of at least 1. The step is then the one whose extrapolated error is the share, but
  never coarser than the pilot's coarsest. The pilot goes on halving while the step it
  predicts lies below half its finest step, so the prediction never reaches far past what it
  measured.
* Where a coarser pilot measured more error than the model gives at its step (by the
  triangle inequality its error is at least its difference from the next pilot less that
  one's error), the model does not hold up to that step, and only a pilot's own step is
  taken there: the coarser one if the difference plus the finer one's error meets the
  share, else the finer, unless a pilot at the step itself bore it out (below).
* On an orthographic view the sampling's phase is checked at the step chosen: the same view
  moved half a step back along its direction samples the lattice at the other phase, and
  the step is halved while the estimate plus what that changes exceeds the share (views along
  the lattice, where every ray samples it at the same phase, had let the pilots agree while
  all missed a narrow peak: up to 14 times the tolerance).
* On a large image (:data:`LONGER_PIXELS` times the pilot's pixels) whose step reached the
  pilot's first, longer steps are tried up to :data:`LONGEST_STEP` (:func:`_longest_step`):
  each try is one more pilot, and a step is taken where the error at the pilot's first step
  plus the difference between the two pilots (a bound by the triangle inequality, with no
  order of convergence assumed) stays within the share.
* A tolerance that would need a step below :data:`MIN_STEP` voxel is refused, with the
  error that step reaches, never answered with a worse image.

``img.stats.choices`` records what was chosen and the estimated error.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from vrlib import validate
from vrlib.raycast import brightest, render_raycast
from vrlib.value_bounds import reconstructed_range

__all__ = ["render_within", "plan_within", "render_plan", "Plan", "finest_error", "TERM_SHARE",
           "STEP_SHARE", "MIN_STEP", "MAX_STEP", "LONGEST_STEP", "LONGER_PIXELS"]

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
#: The pilot's first step (voxels), and the largest a tolerance may be given unless the
#: image is large (:data:`LONGEST_STEP`).
MAX_STEP = 2.0
#: Pilot images have this many times fewer pixels per axis than the image, at least
#: :data:`PILOT_MIN` and at most :data:`PILOT_MAX` a side: their rays sample the image's
#: rays, and 64^2 of them estimate its rmse well enough (at 512^2 the front's scenes kept
#: their promises with them in 4 to 23% less time; a pilot's rays far apart read the
#: volume with few cache hits, so 128^2 of them cost a good part of the image).
PILOT_SHRINK = 4
PILOT_MIN = 32
PILOT_MAX = 64
#: Steps longer than :data:`MAX_STEP`, up to this (voxels), are tried where the image has at
#: least :data:`LONGER_PIXELS` times the pilot's pixels: there one more pilot costs less
#: than the samples a doubled step saves (a rule on sizes, not timings, so that the image
#: never depends on the machine). 32 voxels were tried (2026-11-29): the front's smooth
#: field with long low tails (256^3 -> 512^2) took them, in 0.89 to 0.92 times the time of
#: 16, but ``method="auto"`` bounds a second filter's time by its samples at this step
#: (:mod:`vrlib.auto`), and at 32 that bound let Catmull-Rom's pilots run where at 16 it
#: had spared them: the auto benchmark's dense scene at 512^2 took 1.96 and 1.70 times the
#: faster filter's time at 1e-2 and 1e-3, against 0.94 and 1.51 at 16. Not kept.
LONGEST_STEP = 16.0
LONGER_PIXELS = 32


@dataclasses.dataclass
class Plan:
    """What a render to a tolerance chose for one filter, before the image is rendered
    (:func:`plan_within`).

    Attributes
    ----------
    step : float
        The step chosen (voxels).
    options : dict
        The ray caster's arguments besides the step (filter, transfer function, early
        termination, classification, segment ends, the pilots' memo).
    choices : dict
        What ``img.stats.choices`` reports (the step, the pilot's steps, errors and time).
    pilot_samples : int
        Samples the pilot at its first step (:data:`MAX_STEP`) took, and ``pilot_pixels``, its
        pixels: the image's samples at ``step`` are about ``pilot_samples * (pixels /
        pilot_pixels) * (MAX_STEP / step)``.
    longest : float
        The longest step this image could be given: :data:`LONGEST_STEP` on a large image,
        else :data:`MAX_STEP`.
    """

    step: float
    options: dict
    choices: dict
    pilot_samples: int
    pilot_pixels: int
    longest: float

    def samples(self, pixels, step=None):
        """The image's samples at ``step`` (default the chosen one), scaled from the pilot's."""
        step = self.step if step is None else step
        return self.pilot_samples * (pixels / self.pilot_pixels) * (MAX_STEP / step)


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
    start = time.perf_counter()
    plan = plan_within(volume, view, filt=filt, transfer=transfer, tolerance=tolerance,
                       empty_space_skipping=empty_space_skipping)
    return render_plan(volume, view, plan, start)


def render_plan(volume, view, plan, start):
    """The image of a :class:`Plan`, its statistics' ``seconds`` counted from ``start`` (a
    ``time.perf_counter()`` reading) and their ``choices`` the plan's."""
    image = render_raycast(volume, view, step=plan.step, **plan.options)
    image.stats.seconds = time.perf_counter() - start
    image.stats.choices = plan.choices
    return image


def plan_within(volume, view, *, filt, transfer, tolerance, empty_space_skipping=True,
                abandon=None):
    """The step and settings that keep ``tolerance`` with ``filt``, chosen by pilots (the
    module's docstring), as a :class:`Plan`.

    ``abandon``, if given, is called with the longest step the plan can still choose: before
    the first pilot (:data:`LONGEST_STEP` on a large image, else :data:`MAX_STEP`), and
    again with :data:`MAX_STEP` once the first two pilots show that the first step does not
    meet the share (longer steps are tried only from one that does). Where it returns True
    the plan stops there and None is returned (:mod:`vrlib.auto` drops a candidate so).

    Raises
    ------
    ValueError
        The tolerance needs a step below :data:`MIN_STEP` voxel.
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

    pilot_view = view.resized(tuple(min(max(PILOT_MIN, n // PILOT_SHRINK), PILOT_MAX)
                                     for n in view.shape))
    if pilot_view.height >= view.height and pilot_view.width >= view.width:
        pilot_view = view
    large = view.height * view.width >= LONGER_PIXELS * pilot_view.height * pilot_view.width
    longest = LONGEST_STEP if large else MAX_STEP
    if abandon is not None and abandon(longest):
        return None
    target = STEP_SHARE * tolerance
    steps, differences, alignments, images = [], [], [], {}
    step = MAX_STEP
    previous = change = predicted = coarsest = pilot_samples = None
    while True:
        steps.append(step)
        pilot = render_raycast(volume, pilot_view, step=step, **options)
        if coarsest is None:
            coarsest, pilot_samples = pilot.rgba, pilot.stats.points
        pilot = images[step] = pilot.rgba
        if previous is not None:
            last_change, change = change, previous - pilot
            differences.append(_rms(change))
            if last_change is not None:
                alignments.append(float(np.mean(last_change * change)))
        previous = pilot
        if len(differences) == 1 and 2.0 * differences[0] <= target:
            # The coarsest step already meets the share: with order >= 1 its error is at
            # most d / (1 - 2^-p) <= 2 d, coherent or not (a third pilot would only cost).
            predicted, error_at = MAX_STEP, _first_order_bound(differences[0])
            break
        if len(differences) == 1 and abandon is not None and longest > MAX_STEP and abandon(
                MAX_STEP):
            return None
        if len(differences) >= 2:
            predicted, error_at, _ = _predict(steps, differences, target)
            if predicted >= 0.5 * steps[-1] or step / 2.0 < MIN_STEP:
                break
        step /= 2.0
    checked = confirmed = None
    if alignments:
        # Richardson's error takes the differences as aligned; where they are not, the
        # finest pilot's error is smaller and a longer step may do. One more pilot at that
        # step measures its error against the finest, m: with e = k s + n (k the part that
        # keeps its pattern, n the rest, uncorrelated) at both steps, e^2 <= m^2 + 2 k k_f
        # - k_f^2 = e^2 + |n_f|^2 by the model. So the longer step aims at e^2 = share^2 -
        # |n_f|^2, and is taken only when the pilot bears that out.
        _, finest_at, kept_at = _predict(steps, differences, target, alignments[-1])
        finest, kept_finest = finest_at(steps[-1]), kept_at(steps[-1])
        aim = math.sqrt(max(target**2 - (finest**2 - kept_finest**2), 0.0))
        longer, longer_error_at, _ = _predict(steps, differences, aim, alignments[-1])
        if aim > 0.0 and min(longer, MAX_STEP) > min(predicted, MAX_STEP):
            checked = float(min(longer, MAX_STEP))
            # Kept: where the step is this one, the phase check takes it as its first image.
            images[checked] = render_raycast(volume, pilot_view, step=checked, **options).rgba
            miss = images[checked] - previous
            kept = kept_at(checked)
            bound = np.mean(miss * miss) + 2.0 * kept * kept_finest - kept_finest**2
            if bound <= target**2:
                predicted, error_at, confirmed = longer, longer_error_at, checked
    if predicted < MIN_STEP:
        reach = error_at(MIN_STEP)
        raise ValueError(
            f"tolerance={tolerance:g} is out of reach of ray casting with the {filt.name} "
            f"filter here: it would need a step below {MIN_STEP:g} voxel, where the error "
            f"along rays is still about {reach:.2g}; ask for a tolerance of at least "
            f"{reach / STEP_SHARE:.2g}")
    step = float(min(predicted, MAX_STEP))
    error = error_at(step)
    if step != confirmed:  # a step no pilot bore out directly
        step, error = _within_measured(steps, differences, step, error_at, target)
    longer = []
    if step == MAX_STEP and large:
        step, error = _longest_step(volume, pilot_view, error, coarsest, target, options,
                                    images, longer)
    phase = []
    if not view.is_perspective:
        step, error, phase = _phase_checked(volume, pilot_view, step, error, error_at, target,
                                            options, images, tolerance, filt)
    pilot_seconds = time.perf_counter() - start
    choices = {
        "tolerance": tolerance, "method": "raycast", "filter": filt.name, "step": step,
        "classification": classification, "segment_ends": "exact",
        "early_termination": early_termination, "skip_budget": 0.0,
        "estimate": error + TERM_SHARE * tolerance,
        "pilot": {"shape": list(pilot_view.shape), "steps": steps,
                  "differences": differences, "alignments": alignments,
                  "checked": checked, "longer": longer, "phase": phase,
                  "seconds": pilot_seconds},
    }
    return Plan(step=step, options=options, choices=choices,
                pilot_samples=int(pilot_samples),
                pilot_pixels=pilot_view.height * pilot_view.width, longest=longest)


def _longest_step(volume, view, error, anchor, target, options, images, tried):
    """A step of ``2 MAX_STEP, 4 MAX_STEP ... LONGEST_STEP`` that keeps ``target``, the
    longest the search below finds, and its error bound; ``(MAX_STEP, error)`` where none
    does.

    The error at a longer step is at most the error at :data:`MAX_STEP` (``error``, from the
    first pilots) plus the difference between the pilot images at the two steps (``anchor``
    is the one at :data:`MAX_STEP`): the triangle inequality, with no order of convergence
    assumed where a long step may not resolve the field. The steps are searched by halves
    (each try one pilot at ``view``, its image kept in ``images``, ``[step, difference]``
    appended to ``tried``), taking a step's passing as meaning that the shorter ones pass:
    from 2 to 16 voxels, two pilots (8 first), where trying each doubling in turn took one to
    three, three wherever 8 voxels passed. At 512^2 on a 256^3 volume a 64^2 pilot's rays
    miss the cache, so a pilot costs about as much at any long step (1.9 ms at 16 voxels
    against 2.5 at 8 and 3.2 at 4 on Marschner-Lobb). Whatever the order, a step is taken
    only where its own pilot bears it out.
    """
    candidates = []
    while MAX_STEP * 2.0 ** (len(candidates) + 1) <= LONGEST_STEP:
        candidates.append(MAX_STEP * 2.0 ** (len(candidates) + 1))
    best, low, high = (MAX_STEP, error), 0, len(candidates)
    while low < high:
        middle = (low + high) // 2
        step = candidates[middle]
        images[step] = render_raycast(volume, view, step=step, **options).rgba
        difference = _rms(images[step] - anchor)
        tried.append([step, difference])
        if error + difference <= target:
            best, low = (step, error + difference), middle + 1
        else:
            high = middle
    return best


def _rms(difference):
    """The rmse of two pilot images from their difference (:func:`vrlib.metrics.rmse`'s
    number; the difference itself is kept, for the next one's alignment)."""
    return float(np.sqrt(np.mean(difference * difference)))


def _within_measured(steps, differences, step, error_at, target):
    """The step and its error where the error model contradicts what a coarser pilot
    measured: ``(step, error_at(step))`` unless ``step`` lies between two pilots' steps, or
    at the coarser one, and the model's error at the coarser is below what that pilot
    measured.

    The model extrapolates from the finest pilots with an order of at most 2; a field whose
    error grows faster between the pilots' steps would be given a step up to the coarser one
    whose error is several times the model's (Catmull-Rom's on Marschner-Lobb at 17^3 ->
    24^2 within 1e-3: 2.5e-3 at the 1.64 voxels the model gave, 2.8e-4 at 1 and 4.5e-3 at 2;
    a power law through those two would give 1.3, and at 25^3 its 1.64 for 3e-3 missed by
    1.6 times: the steps of 1 and 2 voxels, whole multiples of the voxel, can err much less
    than those between). By the triangle inequality the coarser pilot's error is at least its
    difference ``d`` from the finer one less the finer one's error ``e``, and at most ``d +
    e``. Where the model's error there is below ``d - e`` it does not hold between the two
    steps, and only the pilots' own steps are taken: the coarser if ``d + e`` meets
    ``target``, else the finer.
    """
    for coarse, fine, difference in zip(steps, steps[1:], differences, strict=False):
        if fine < step <= coarse:
            error = error_at(fine)
            if error_at(coarse) >= difference - error:
                break
            upper = difference + error
            return (coarse, upper) if upper <= target else (fine, error)
    return step, error_at(step)


def _phase_checked(volume, view, step, error, error_at, target, options, images, tolerance,
                   filt):
    """The step, its error and the checks made, once the sampling's phase is checked at
    ``step`` (orthographic views).

    A ray's samples lie a whole number of steps (and a half) from where it starts. Where the
    rays run along the lattice (a view along an axis or a diagonal of the volume), every ray
    samples the lattice at the same phase, and the pilots at steps 2, 1, 1/2 ... can agree
    while all miss what lies between their samples (a narrow opacity peak seen along z:
    their differences gave an error 14 times too small). The same image with the camera
    moved half a step back along its direction (:meth:`vrlib.View.moved_back`) is exactly
    the same image and samples at the other phase: its rms difference ``d`` from the first is
    what the phase changes, ``d / sqrt 2`` for each if the two phases' own errors are
    uncorrelated. The pilots' estimate plus that bounds the image's error; while it exceeds
    ``target`` the step is halved (each halving two more pilots), down to :data:`MIN_STEP`.
    Measured on 84 cases (chapter 11's seven analytic scenes at 64^2, views along x, y and
    z, along a diagonal, oblique and in perspective, 1e-2 and 1e-3): 13 promises broken
    without the check (up to 14 times), none with it (worst 0.69). Views near the lattice
    need it too (the narrow peak 8 degrees off x: 2.98 times without it), so no test of the
    view's direction replaces it. Not cheaper: the root of the sum of squares missed a
    narrow peak seen along x by 1.1 times; trusting the pilots wherever ``d / sqrt 2`` lay
    within their estimate missed it by 6.5 times; jittered rays (a phase per pixel) with the
    pilots alone, 4.1 times a degree off x; shrinking the step in proportion to the sum
    instead of halving it took that peak along x to 0.98 of its tolerance (docs/kernel.md).
    Its price is on views across the lattice, where the pilots had seen the phases already:
    chapter 11's orthographic cases take steps up to half as long (19 instead of 26 to 32 of
    its 44 timed cases within 1.5 times the fastest fixed setting), and its shaded field at
    1e-4 is refused.
    """
    checks = []
    while True:
        here = images.get(step)
        if here is None:
            here = images[step] = render_raycast(volume, view, step=step, **options).rgba
        shift = 0.5 * step * float(np.min(volume.spacing))
        there = render_raycast(volume, view.moved_back(shift), step=step, **options).rgba
        difference = _rms(here - there)
        checks.append([step, difference])
        total = error + difference / math.sqrt(2.0)
        if total <= target:
            return step, total, checks
        if step / 2.0 < MIN_STEP:
            raise ValueError(
                f"tolerance={tolerance:g} is out of reach of ray casting with the {filt.name} "
                f"filter here: at a step of {step:g} voxel the image still changes by "
                f"{difference:.2g} with the samples' phase; ask for a tolerance of at least "
                f"{total / STEP_SHARE:.2g}")
        step /= 2.0
        if step <= MAX_STEP:
            error = error_at(step)


def _first_order_bound(difference):
    """The error model after two pilots whose images differ by ``difference``: at most twice
    that at the coarser step (order at least 1)."""
    return lambda h: 2.0 * difference * h / MAX_STEP


def _predict(steps, differences, target, alignment=None):
    """The step whose extrapolated error is ``target``, the error model it uses, and the
    part of that error that keeps its pattern (all of it for Richardson's), at step ``h``.

    ``differences[i]`` is the rmse between the pilot images at ``steps[i]`` and
    ``steps[i + 1] = steps[i] / 2``. The order ``p`` comes from the last two differences
    (between 1 and 2); the error at step ``h`` is taken as the finest pilot's times
    ``(h / finest)^p``. The finest pilot's error is Richardson's ``d / (2^p - 1)``, or with
    ``alignment``, the mean product of the last two differences pixel by pixel,
    :func:`finest_error`'s.
    """
    d_prev, d_last = differences[-2], differences[-1]
    finest = steps[-1]
    if not d_last > 0.0:
        return MAX_STEP, lambda h: 0.0, lambda h: 0.0
    order = math.log2(d_prev / d_last) if d_prev > 0.0 else 2.0
    order = min(max(order, 1.0), 2.0)
    if alignment is None:
        error = kept = d_last / (2.0**order - 1.0)
    else:
        error, kept = finest_error(d_prev, d_last, alignment, order)

    def error_at(h):
        return error * (h / finest) ** order

    def kept_at(h):
        return kept * (h / finest) ** order

    return finest * (target / error) ** (1.0 / order), error_at, kept_at


def finest_error(d_prev, d_last, alignment, order):
    """The error of the finest of three pilot images ``I0, I1, I2`` (steps ``h, h/2, h/4``)
    from their differences ``D0 = I0 - I1`` and ``D1 = I1 - I2``: their rms ``d_prev`` and
    ``d_last`` and their mean product ``alignment``.

    Each image's error is taken as a part that keeps its pattern from step to step and
    shrinks by ``r = 2^-order`` a halving (``a r^k s``: the truncation error of a resolved
    field, which Richardson's ``d / (2^p - 1)`` assumes alone), plus a part that changes its
    pattern (``sigma r^k`` rms, uncorrelated between steps: aliasing of a steep transfer
    function, shading's highlights). The first makes the differences point the same way,
    the second opposite ways, so ``alignment`` tells the two apart. With ``A = a (1 - r)``,
    ``d_last^2 = r^2 S`` where ``S = A^2 + sigma^2 (1 + r^2)``, and ``alignment = A^2 r -
    sigma^2 r^2``, so that

        sigma^2 = (S - alignment / r) / (1 + r + r^2),

    and the finest error is ``sqrt((A r^2 / (1 - r))^2 + sigma^2 r^4)``: Richardson's when
    the differences are aligned, ``d_last r / sqrt(1 + r^2)`` when they are not correlated.
    It is never taken below the uncorrelated error at the measured ratio ``d_last /
    d_prev`` (between 1/4 and 1): an error that stopped shrinking is not extrapolated away.

    Returns ``(error, kept)``: the rms error and the rms of its part that keeps its pattern.

    Examples
    --------
    >>> [round(e, 6) for e in finest_error(0.4, 0.1, 0.4 * 0.1, 2.0)]   # d / (2^p - 1)
    [0.033333, 0.033333]
    >>> [round(e, 6) for e in finest_error(0.4, 0.1, -0.1**2 / (1 + 0.25**2), 2.0)]
    [0.024254, 0.0]
    """
    r = 2.0 ** -order
    total = (d_last / r) ** 2  # A^2 + sigma^2 (1 + r^2)
    sigma2 = (total - alignment / r) / (1.0 + r + r * r)
    sigma2 = min(max(sigma2, 0.0), total / (1.0 + r * r))  # both parts at least 0
    coherent = math.sqrt(max(total - sigma2 * (1.0 + r * r), 0.0)) * r * r / (1.0 - r)
    error = math.sqrt(coherent**2 + sigma2 * r**4)
    measured = min(max(d_last / d_prev, 0.25), 1.0) if d_prev > 0.0 else 0.25
    return max(error, d_last * measured / math.sqrt(1.0 + measured**2)), coherent
