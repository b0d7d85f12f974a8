"""Ray casting (Levoy 1988; the first of the thesis's three methods).

For every pixel a ray is resampled at a constant step, each sample reconstructed with the
chosen filter (eq 1.1), classified by the transfer function and composited front to back
(eqs 1.7-1.8). Two skips leave out work a scene does not need: empty-space skipping jumps over
blocks of the volume that cannot be visible (the image is unchanged, bit for bit), and early
ray termination stops a ray once its opacity reaches a threshold (the image changes by at most
``1 - threshold`` times the brightest emission).
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import os
import time
from typing import NamedTuple

import numba
import numpy as np

from vrlib import validate
from vrlib._kernels import raycast as _kernel
from vrlib._kernels._jit import compiled_or_cached, readonly
from vrlib._kernels.filters import MAX_TAPS, TENT
from vrlib._scheduling import on_threads
from vrlib.adaptive import step_multipliers
from vrlib.compositing import SEGMENT_ENDS
from vrlib.image import Image, RenderStats
from vrlib.prefilter import Tally, prepared
from vrlib.skipping import BLOCK, footprint_mask, footprint_ready, skip_grid, visible_box
from vrlib.value_bounds import reconstructed_range
from vrlib.volume import lattice_extent

__all__ = ["render_raycast", "cast_rays", "quick_starts", "segment_options",
           "operations_per_sample", "skip_bounds", "brightest"]

#: Pixels (rows, columns) of the image tiles that the threads take from the queue. Packets
#: go along a tile's rows: wide tiles keep the next packets on the lines the last ones
#: fetched (256^3 -> 512^2, 2 threads: 8 x 128 took 72 ms where 32 x 32 took 75).
TILE = (8, 128)

#: A quick start (the command line's render, :func:`quick_starts`): a one-off render of
#: fewer samples than this (bounded by the rays that can meet something times the box's
#: diagonal over the step) takes a kernel of its own,
#: :func:`vrlib._kernels.raycast.raycast_quick` (the tent filter unlit, rays one at a time,
#: nothing skipped), while the kernel with packets is neither compiled nor in numba's
#: cache, and renders without skipping while that kernel is not. It gives the same image
#: bit for bit and compiles in about two thirds of the time that the packets' kernel took
#: compiled without its packets: a first `vrlib render gaussian-blob:32` on a 2-core Intel
#: Xeon took 3.8 to 4.6 s against 5.7 to 6.2 (docs/kernel.md), and 8.3 to 10.4 s with the
#: kernel with packets and skipping. What the slower loop costs stays below what it saves:
#: dense Marschner-Lobb 256^3 -> 256^2 at half a voxel (58 M by the bound, 11 M samples
#: taken) 121 ms against 49 ms with packets, six sparse blobs 40 ms against 5 ms, where the
#: compile saved is 0.9 to 2.7 s. The command line's default image, 256^2, of a volume up
#: to about 290 samples a side at its default step (half a voxel) lies below the bound.
QUICK_START_SAMPLES = 1 << 26
#: A render with the tent filter, unlit, whose work by :func:`_work` (samples by the same
#: bound, and :data:`RAY_SAMPLES` a ray) comes to less than this runs on one thread,
#: whatever the thread count: a second thread costs a second call of the kernel (its 60
#: arguments unboxed under the GIL) and a wake-up, more than it saves on so little. On a
#: 2-core Intel Xeon, one-off 32^2 renders at two voxels of chapter 11's six unlit scenes (a
#: render to a tolerance's pilots): medians 0.53 to 0.86 ms on two threads, 0.38 to 0.60 on
#: one; 96^2 at two voxels, 338 thousand samples by the bound, 2.4 ms on two against 3.0.
#: Shading and the other filters cost enough a sample that two threads gain already at 32^2.
#: The image is the same.
ONE_THREAD_SAMPLES = 1 << 18
#: What a ray costs before its samples, counted in samples, in the work that picks one thread
#: or two: its set-up and its first reads, which miss the cache where the volume is larger
#: than it and the rays lie far apart. Measured (2026-11-29): a render to a tolerance's
#: 64^2 pilots of Marschner-Lobb 256^3 at 16 voxels, six samples a ray, took 640 ns a ray on
#: one thread, and 13 ns a sample at one voxel; chapter 11's pilots at 32^2 to 64^2 on 41^3
#: to 64^3 volumes (steps 2 to 1/4 voxel, one thread against two alternated) were as fast
#: with it as without, within the noise, and the front's renders to a tolerance at 512^2
#: 0.92 to 0.96 times the time (``benchmarks/bench_time_error_front.py``'s scenes).
RAY_SAMPLES = 64

#: Where quick starts are on (:func:`quick_starts`), and the kinds of render whose kernel
#: with packets is known to be ready.
_quick_start = {"on": 0, "ready": set()}


@contextlib.contextmanager
def quick_starts():
    """Quick starts for the renders inside: ``vrlib render``'s one render, where a first
    use's wait is all of a user's wait. A Python session keeps its renders on the kernel
    with packets from the first (it compiles it on first use, a second longer): its later
    renders, and any timing of them, are then the fastest. ``VRLIB_QUICK_START=0`` in the
    environment turns quick starts off everywhere (the test suite's setting: a kernel
    compiled once, not twice)."""
    _quick_start["on"] += 1
    try:
        yield
    finally:
        _quick_start["on"] -= 1


def operations_per_sample(filt, *, shading=False):
    """Arithmetic operations for one ray sample, by this renderer's count.

    Position (6), reconstruction (trilinear: 7 lerps of 3 operations plus 9 for the fractions;
    other filters: 3n weight evaluations of about 10 operations and n^3 + n^2 multiply-adds),
    classification and compositing (about 20), and with shading the gradient (3 more sums of
    n^3 terms, 3n derivative evaluations) and lighting (about 30).

    Examples
    --------
    >>> from vrlib import make_filter
    >>> operations_per_sample(make_filter("trilinear"))
    56
    """
    n = filt.taps
    recon = 30 if filt.code[0] == TENT else 30 * n + 2 * (n**3 + n**2)
    ops = 6 + recon + 20
    if shading:
        ops += 30 * n + 6 * n**3 + 30
    return ops


#: How a segment is classified (``classification``).
CLASSIFICATIONS = ("point", "preintegrated")


def render_raycast(volume, view, *, filt, transfer, step, early_termination,
                   empty_space_skipping, segment_ends=None, classification="point",
                   skip_budget=0.0, step_budget=0.0, memo=None):
    """Ray-cast ``volume`` (arguments already validated by :func:`vrlib.render`).

    ``segment_ends="lattice"`` lets every sample stand for a whole step, also where the
    volume's faces cut its segment (an error of first order in the step wherever the field is
    not zero at the faces); ``"exact"`` counts only the part of those segments inside the
    volume, sampled at its middle (second order; :mod:`vrlib._kernels.raycast`). The default
    is ``"lattice"`` with point classification and ``"exact"`` (the only choice) with
    pre-integration.

    ``classification="point"`` classifies each segment by the value at its middle;
    ``"preintegrated"`` by the values at its two ends, through a table that integrates the
    transfer function between them (:meth:`vrlib.TransferFunction.preintegrated_table`):
    steep transfer functions are then not aliased. It takes the field as linear along a
    segment (a step at its middle with the box filter); gradient opacity and shading use the
    gradient at the segment's middle (docs/kernel.md).

    Shading and gradient opacity differentiate the filter; the box filter, whose derivative
    is zero, takes the samples' gradient (central differences, :func:`numpy.gradient`) at the
    sample it reconstructs, as the methods that resample in passes do.

    ``skip_budget`` (>= 0, premultiplied colour units) lets each ray leave out blocks that
    are not empty, while the most those blocks could change any channel of its pixel
    (:func:`skip_bounds`) adds up to at most the budget; 0 skips only empty blocks.

    ``step_budget`` (>= 0, the same units) lets one sample stand for 2, 4 or 8 steps in
    blocks where the classified field changes slowly enough that no pixel moves by more than
    the budget from the image at ``step`` (adaptive steps, :mod:`vrlib.adaptive`); 0 takes
    every step. Point classification without shading or gradient opacity only.

    The skip grid (the blocks' densities, which are empty, how far each is from a block of
    the other kind) is kept with the volume (:func:`vrlib.skipping.skip_grid`). ``memo`` (a
    dict, empty at first) keeps what does not depend on the step (the pixels whose rays can
    meet a block, the tiles' order, the kernel's arguments: :class:`RayPlan`) between
    renders of one volume, filter and transfer function, unchanged, at several steps: a
    render to a tolerance's pilot images, and its phase check's, of the view moved back
    (the same ray lines, :attr:`vrlib.View.lines`). The images are the same with it or
    without.
    """
    skip_budget = validate.finite_number("skip_budget", skip_budget, low=0.0)
    step_budget = validate.finite_number("step_budget", step_budget, low=0.0)
    exact, preint = segment_options(segment_ends, classification,
                                    holes=volume.holes is not None)
    if step_budget > 0.0:
        if preint:
            raise ValueError("step_budget > 0 (adaptive steps) is built for "
                             "classification='point' only; pre-integration takes every step")
        if transfer.needs_gradient:
            raise ValueError("step_budget > 0 (adaptive steps) bounds the change of an "
                             "unshaded field: leave out shading and gradient opacity, or use "
                             "step_budget=0")
        if not empty_space_skipping:
            raise ValueError("step_budget > 0 keeps a step per block: it needs "
                             "empty_space_skipping=True")
    start = time.perf_counter()
    tally = Tally()
    volume = prepared(volume, filt, tally)  # prefiltered filters: the 3-D coefficients
    one_off, memo = memo is None, {} if memo is None else memo
    kept = functools.partial(_kept, memo)
    extent = volume.extent
    box_lo, box_hi = kept("box", (volume,), lambda: (extent[:, 0].copy(), extent[:, 1].copy()))
    ds = step * float(volume.spacing.min())
    value_range = kept("range", (volume, filt), lambda: reconstructed_range(volume, filt))
    skip = bound = multiplier = None
    if skip_budget > 0.0 and not empty_space_skipping:
        raise ValueError("skip_budget > 0 skips blocks: it needs empty_space_skipping=True")
    if empty_space_skipping:
        grid = kept("grid", (volume, filt, transfer),
                    lambda: skip_grid(volume, filt, transfer, block=BLOCK))
        densities, empty = grid.densities, grid.empty
        if skip_budget > 0.0:
            bound = skip_bounds(densities, volume, transfer, ds, value_range)
        if step_budget > 0.0:
            multiplier = step_multipliers(volume, filt, transfer, ds, step_budget,
                                          value_range=value_range,
                                          brightest=brightest(transfer, value_range),
                                          block=BLOCK)
            if not np.any(multiplier > 1):
                multiplier = None
        # With nothing to skip or stretch, checking would only cost time.
        skipping = (empty.any() or (bound is not None and np.any(bound <= skip_budget))
                    or multiplier is not None)
        if skipping:
            box_lo, box_hi = kept("visible box", (grid, box_lo, box_hi),
                                  lambda: visible_box(volume, empty, BLOCK, box_lo, box_hi))
            if preint:  # a segment owned outside the box reaches half a step into it
                box_lo = np.maximum(box_lo - 0.5 * ds, extent[:, 0])
                box_hi = np.minimum(box_hi + 0.5 * ds, extent[:, 1])
            if (one_off and not preint and skip_budget == step_budget == 0.0
                    and _quick(view.height * view.width, np.linalg.norm(box_hi - box_lo), ds)
                    and not _skipping_ready(volume, view, (box_lo, box_hi), filt, transfer,
                                            ds, value_range, exact)):
                # A quick start: the rays sample the visible box through, as the same
                # image bit for bit (skipping only leaves out samples that add nothing);
                # on so few samples skipping saves less than its kernel's compile (1.1 s of
                # a first render of a volume with empty space).
                skipping = False
        if skipping:
            skip = (empty, grid.clearance, BLOCK,
                    kept("mask", (view.lines, grid), lambda: _footprint(view, volume, empty, (
                        box_lo, box_hi), ds, one_off)))
    rgba, taken = cast_rays(
        volume.data, offset=(0, 0, 0), global_shape=volume.shape, origin=volume.origin,
        spacing=volume.spacing, box=(box_lo, box_hi), view=view, filt=filt, transfer=transfer,
        ds=ds, value_range=value_range,
        early_termination=early_termination, skip=skip, exact_ends=exact,
        preintegrated=preint, bound=bound, budget=skip_budget, multiplier=multiplier,
        memo=memo, quick_start=one_off)
    stats = RenderStats(
        samples=taken,
        operations=taken * operations_per_sample(filt, shading=transfer.needs_gradient),
        bytes=int(volume.data.nbytes + rgba.nbytes),
        seconds=time.perf_counter() - start,
    )
    return Image(rgba, tally.finish(stats, filt), checked=False)  # cast_rays clipped it


def segment_options(segment_ends, classification, *, holes=False):
    """Check how segments end and are classified (:func:`render_raycast`'s arguments, also
    taken by the MPI renderers); returns ``(exact_ends, preintegrated)``.

    Examples
    --------
    >>> segment_options(None, "preintegrated")
    (True, True)
    >>> segment_options(None, "point")
    (False, False)
    """
    validate.choice("classification", classification, CLASSIFICATIONS)
    preint = classification == "preintegrated"
    if segment_ends is None:
        segment_ends = "exact" if preint else "lattice"
    validate.choice("segment_ends", segment_ends, SEGMENT_ENDS)
    if preint and segment_ends != "exact":
        raise ValueError("classification='preintegrated' takes its segments' values at their "
                         "ends, which must lie inside the volume: use segment_ends='exact' "
                         "(or leave it out)")
    if preint and holes:
        raise ValueError("classification='preintegrated' cannot take holes "
                         "(nan='transparent'): no value runs linearly into a hole; use "
                         "classification='point'")
    return segment_ends == "exact", preint


def skip_bounds(densities, volume, transfer, ds, value_range):
    """The most leaving one block out can change any channel of a pixel, per block.

    A block of largest density ``Omega`` (:func:`vrlib.skipping.block_densities`) gives the
    samples a ray takes in it at most opacity ``a = 1 - exp(-Omega l)``, with ``l`` the
    block's diagonal plus one step ``ds`` (the segments whose samples lie in it). Leaving them
    out changes the pixel by their own light, at most ``E a``, less the light they hid, at
    most ``E a`` again, two non-negative amounts: by at most ``E a``, with ``E`` the
    brightest channel any sample can send (the emission's largest value, lit and
    highlighted; 1 for opacity). Bounds of several blocks add.

    Examples
    --------
    >>> from vrlib import Glow, Volume
    >>> vol = Volume(np.zeros((9, 9, 9)))
    >>> b = skip_bounds(np.array([[[0.0, 1.0]]]), vol, Glow(1.0), 0.1, (0.0, 1.0))
    >>> b.round(4).tolist()          # diagonal of 8 cells of 0.25: 3.4641, plus the step
    [[[0.0, 0.9716]]]
    """
    diagonal = float(np.linalg.norm(BLOCK * volume.spacing)) + ds
    return brightest(transfer, value_range) * -np.expm1(-densities * diagonal)


def brightest(transfer, value_range):
    """The most light a segment can send in any channel per unit of its opacity: the
    emission's largest value over ``value_range``, lit and highlighted at most as brightly as
    the shading allows, and at least 1 (the alpha channel's).

    Examples
    --------
    >>> from vrlib import Glow, Phong
    >>> brightest(Glow(1.0, shading=Phong(ambient=0.3, diffuse=0.7, specular=0.5)), (0, 1))
    1.5
    """
    most = transfer.brightest_emission(*value_range)
    shading = transfer.shading
    if shading is not None:
        most = most * (shading.ambient + shading.diffuse) + shading.specular
    return max(1.0, most)


def cast_rays(data, *, offset, global_shape, origin, spacing, box, view, filt, transfer, ds,
              value_range, early_termination, skip=None, exact_ends=False,
              preintegrated=False, bound=None, budget=0.0, multiplier=None, memo=None,
              quick_start=False):
    """Ray-cast samples ``data`` (all of a volume, or a brick of it with ghost samples): the
    ray caster's core, which the MPI renderers run on each brick or tile.

    Parameters
    ----------
    data : ndarray (nz, ny, nx)
        Samples from global index ``offset`` (z, y, x) on, of a volume of ``global_shape``
        whose first sample lies at world ``origin`` with ``spacing`` (x, y, z).
    box : (ndarray, ndarray)
        World box whose samples these rays take (a brick's own region, without ghosts).
    ds : float
        Sample spacing along rays, world units.
    value_range : (float, float)
        Bounds on reconstructed values (for the classification table).
    skip : (empty, clearance, block, mask) or None
        Empty-space skipping grids (global blocks of ``block`` cells a side, a power of
        two), each block's clearance (:func:`vrlib.skipping.clearance`) and the pixels whose
        rays can meet a non-empty block, or None to sample everywhere.
    exact_ends : bool
        Cut the segments at the whole volume's faces to their part inside it (never at a
        brick's own faces, so that bricks take exactly the serial samples).
    preintegrated : bool
        Classify each segment from its values at its two ends (needs ``exact_ends``; the
        box filter takes the value as a step at the segment's middle). A brick then needs
        ghost samples half a step beyond its box as well.
    bound : ndarray or None
        Per block of the skip grid, the most leaving it out can change a pixel
        (:func:`skip_bounds`); with ``budget > 0`` a ray leaves blocks out while their
        bounds add up to at most ``budget``.
    multiplier : ndarray of int or None
        Per block of the skip grid, how many steps one sample may stand for (adaptive steps,
        :func:`vrlib.adaptive.step_multipliers`; point classification only), or None.
    memo : dict or None
        Keeps what does not depend on the step (:class:`RayPlan`) between calls that give
        the same objects for all else: renders of one scene at several steps.
    quick_start : bool
        A one-off render, which inside :func:`quick_starts` takes the quick start's kernel
        (:func:`vrlib._kernels.raycast.raycast_quick`: compiled sooner, the same image) if
        it is of the tent filter, unlit, skips nothing, has fewer than
        :data:`QUICK_START_SAMPLES` samples, and the kernel with packets is neither compiled
        nor in numba's cache.

    Returns
    -------
    rgba : ndarray (height, width, 4)
    samples : int
        Samples reconstructed.
    """
    plan = _ray_plan(data, offset, global_shape, origin, spacing, box, view, filt, transfer,
                     skip, memo)
    vector = np.ascontiguousarray
    out = np.empty(view.shape + (4,))  # each tile cleared by the thread that takes it
    samples = np.zeros(plan.tiles, dtype=np.int64)
    skips = (early_termination, *plan.grids,
             readonly(vector(_NO_BOUND if bound is None else bound, np.float64)), float(budget))
    # The tiles, heaviest first, behind a queue that every thread takes the next one from.
    tiles = (*TILE, plan.order, np.zeros(1, np.int64), out, samples)
    filtering, lit, skipping, packets = plan.kind
    if preintegrated:
        profile = "step" if filt.radius <= 0.5 else "linear"  # the box filter jumps
        arguments = (*plan.layout, view.packed(), view.height, view.width, ds, *filt.code,
                     filt.radius, filt.taps,
                     *transfer.preintegrated_table(ds, *value_range, profile=profile),
                     *plan.lighting, *plan.by_gradient, *skips, *tiles, filtering)
        on_threads(lambda i: _kernel.raycast_preintegrated(*arguments, plan.scratch[i]),
                   plan.threads)
    else:
        arguments = _point_arguments(plan, view, ds, filt, transfer, value_range, exact_ends,
                                     skips, multiplier, tiles)
        if (quick_start and packets and skipping is None
                and _quick(plan.rays, plan.diagonal, ds) and not _ready(arguments, plan)):
            arguments = _quick_arguments(arguments)  # a quick start
            on_threads(lambda i: _kernel.raycast_quick(*arguments), _threads_for(plan, ds))
        else:
            on_threads(lambda i: _kernel.raycast(*arguments, packets, plan.scratch[i],
                                                 *(a[i] for a in plan.lanes)),
                       _threads_for(plan, ds))
    return out, int(samples.sum())  # the kernels clip each pixel's opacity


def _footprint(view, volume, empty, box, ds, one_off):
    """The pixels whose rays can meet a block that is not empty
    (:func:`vrlib.skipping.footprint_mask`), or on a quick start all of them, while that
    mask's kernel is neither compiled nor in numba's cache: the same image (a ray outside
    the mask crosses only empty blocks, whose samples add exactly nothing) without its
    compile (0.7 s of a first render of a volume with empty space)."""
    if (one_off and _quick(view.height * view.width, np.linalg.norm(box[1] - box[0]), ds)
            and not footprint_ready(view, volume, empty, BLOCK)):
        return np.ones(view.shape, dtype=bool)
    return footprint_mask(view, volume, empty, BLOCK)


def _point_arguments(plan, view, ds, filt, transfer, value_range, exact_ends, skips,
                     multiplier, tiles):
    """The point-classifying kernel's arguments (:func:`vrlib._kernels.raycast.raycast`) up
    to its kind's flags, all but ``packets`` and a thread's scratch and lanes."""
    tables = transfer.segment_table(ds, *value_range)
    # Colour equals opacity: white emission, no shading.
    grey = transfer.shading is None and bool(np.all(tables[4] == 1.0))
    filtering, lit, skipping, _ = plan.kind
    # The tent filter unlit (a first render's kernel) is compiled without the colour of a
    # grey table (None); the other kernels take it as a flag (False), one kernel for both.
    # The exact ends are a flag here (None drops their code, 0.2 s of a first compile, but
    # would double the kernels `make test` compiles): only a quick start's kernel takes None
    # (_quick_arguments).
    colour = (None if grey else True) if filtering is None and lit is None else not grey
    vector = np.ascontiguousarray
    return (*plan.layout, bool(exact_ends), view.packed(), view.height, view.width, ds,
            *filt.code, filt.radius, filt.taps, *tables, *plan.lighting, *plan.by_gradient,
            *skips,
            readonly(vector(_NO_MULTIPLIER if multiplier is None else multiplier, np.int64)),
            *tiles, colour, filtering, lit, skipping)


def _threads_for(plan, ds):
    """The threads a point-classifying render of ``plan`` at step ``ds`` (world units) runs
    on: one for a small render with the tent filter unlit (:data:`ONE_THREAD_SAMPLES`), else
    the plan's."""
    filtering, lit, _, _ = plan.kind
    if (filtering is None and lit is None
            and _work(plan.rays, plan.diagonal, ds) < ONE_THREAD_SAMPLES):
        return 1
    return plan.threads


def _work(rays, diagonal, ds):
    """A render's work in samples, for the choice of threads: the bound on its samples
    (:func:`_most_samples`) and :data:`RAY_SAMPLES` for each ray."""
    return _most_samples(rays, diagonal, ds) + RAY_SAMPLES * rays


def _most_samples(rays, diagonal, ds):
    """A bound on the samples ``rays`` rays take at step ``ds`` (world units) in a box of
    ``diagonal``: each ray the whole diagonal, and two samples more for its ends."""
    return rays * (diagonal / ds + 2.0)


def _quick(rays, diagonal, ds):
    """Whether a one-off render of ``rays`` rays across a box of ``diagonal`` at step ``ds``
    (world units) may take a quick start (:data:`QUICK_START_SAMPLES`)."""
    return bool(_quick_start["on"] and os.environ.get("VRLIB_QUICK_START") != "0"
                and _most_samples(rays, diagonal, ds) < QUICK_START_SAMPLES)


def _skipping_ready(volume, view, box, filt, transfer, ds, value_range, exact_ends):
    """Whether the point-classifying kernel that skips empty blocks is ready, for this
    render, without compiling: asked with stand-in skip grids of the real ones' types."""
    stand_in = (np.zeros((1, 1, 1), dtype=bool), np.zeros((1, 1, 1), np.int64), BLOCK,
                np.ones(view.shape, dtype=bool))
    plan = _build_plan(volume.data, (0, 0, 0), volume.shape, volume.origin, volume.spacing,
                       box, view, filt, transfer, stand_in, numba.get_num_threads())
    skips = (1.0, *plan.grids, readonly(_NO_BOUND), 0.0)
    tiles = (*TILE, plan.order, np.zeros(1, np.int64), np.zeros(view.shape + (4,)),
             np.zeros(plan.tiles, dtype=np.int64))
    arguments = _point_arguments(plan, view, ds, filt, transfer, value_range, exact_ends,
                                 skips, None, tiles)
    return _ready(arguments, plan)


def _quick_arguments(arguments):
    """Of :func:`_point_arguments`'s ``arguments``, those a quick start's kernel
    (:func:`vrlib._kernels.raycast.raycast_quick`, :data:`QUICK_START_SAMPLES`) takes, by
    name; lattice ends come as None, not False, so that it compiles without the cut
    segments' code (0.2 s less of a first render's wait; only the quick start's kernel takes
    them so, as the ``make test`` suite, which renders with exact ends and without, compiles
    the other kernels once for both)."""
    named = dict(zip(_parameters(_kernel.raycast), arguments, strict=False))  # no lanes
    named["exact"] = True if named["exact"] else None
    return tuple(named[name] for name in _parameters(_kernel.raycast_quick))


@functools.cache
def _parameters(kernel):
    """The names of ``kernel``'s parameters (a numba dispatcher's, or the plain function's
    with numba's JIT off)."""
    return tuple(inspect.signature(getattr(kernel, "py_func", kernel)).parameters)


def _ready(arguments, plan):
    """Whether the ray caster's kernel for ``arguments`` (all but ``packets`` and a
    thread's scratch and lanes, from ``plan``) is ready without compiling: compiled in this
    process or in numba's cache (:func:`vrlib._kernels._jit.compiled_or_cached`, which loads
    it then). A yes is kept per kind of arguments (their types, told apart cheaply)."""
    packets = plan.kind[3]
    kind = tuple(a.dtype.str + a.flags.c_contiguous * "C" + a.flags.writeable * "W"
                 if isinstance(a, np.ndarray) else type(a) for a in arguments) + (packets,)
    ready = _quick_start["ready"]
    if kind not in ready and compiled_or_cached(_kernel.raycast, (
            *arguments, packets, plan.scratch[0], *(a[0] for a in plan.lanes))):
        ready.add(kind)
    return kind in ready


#: Stand-ins for the kernels' arrays a render does not use (read-only: shared by every render).
_NO_BOUND = readonly(np.zeros((1, 1, 1)))
_NO_MULTIPLIER = readonly(np.ones((1, 1, 1), np.int64))


class RayPlan(NamedTuple):
    """What :func:`cast_rays` hands its kernel that does not depend on the step."""

    #: The samples and the lattice: data, offset, global shape, origin, spacing, the box's
    #: corners and the whole volume's.
    layout: tuple
    lighting: tuple
    by_gradient: tuple
    #: The skip grids (empty, clearance, block, pixel mask), as the kernel takes them.
    grids: tuple
    #: The tiles whose pixels' rays can meet something, heaviest first, then the others as
    #: ``-1 - tile`` (only cleared); how many tiles the image has.
    order: np.ndarray
    tiles: int
    threads: int
    #: Each thread's scratch for the filter's weights, and its lanes
    #: (:func:`vrlib._kernels.raycast.lanes`).
    scratch: np.ndarray
    lanes: tuple
    #: The kernel compiled for this kind of render (``filtering, lit, skipping, packets``):
    #: the tent filter, no shading or gradient opacity, a volume with nothing to skip, make a
    #: smaller kernel, a shorter first wait.
    kind: tuple
    #: The rays that can meet something, and the length of the box's diagonal (world
    #: units): how many samples a render can take at most, with the step.
    rays: int
    diagonal: float


def _ray_plan(data, offset, global_shape, origin, spacing, box, view, filt, transfer, skip,
              memo):
    """:func:`cast_rays`'s :class:`RayPlan`, kept in ``memo`` (a dict, or None) while the
    samples, box, filter, transfer function and skip grids are the same objects, the image
    the same size and the thread count the same (a render to a tolerance's pilot images at
    several steps and its phase check's, of the view moved back: 0.1 ms each at 32^2). The
    plan depends on the view through its size and the pixel mask (a skip grid) alone."""
    threads = numba.get_num_threads()
    key = (data, tuple(offset), tuple(global_shape), tuple(np.asarray(origin).tolist()),
           tuple(np.asarray(spacing).tolist()), view.shape, box[0], box[1], filt, transfer,
           threads) + (() if skip is None else tuple(skip))
    return _kept({} if memo is None else memo, "ray plan", key, lambda: _build_plan(
        data, offset, global_shape, origin, spacing, box, view, filt, transfer, skip, threads))


def _build_plan(data, offset, global_shape, origin, spacing, box, view, filt, transfer, skip,
                threads):
    """:func:`_ray_plan`'s plan, built."""
    shading = transfer.shading
    if shading is None:
        lighting = (False, 0.0, 0.0, 0.0, 1.0, np.zeros(3), True)
    else:
        light = np.zeros(3) if shading.light is None else np.asarray(shading.light, float)
        lighting = (True, shading.ambient, shading.diffuse, shading.specular,
                    shading.shininess, light, shading.light is None)
    if skip is None:
        skip = (np.zeros((1, 1, 1), dtype=bool), np.zeros((1, 1, 1), np.int64), 0,
                np.ones(view.shape, dtype=bool))
    elif skip[2] <= 0 or skip[2] & (skip[2] - 1):
        raise ValueError(f"skip's block must be a power of two (cells per block), got "
                         f"{skip[2]}")
    empty, clearance, block, mask = skip
    ramp = transfer.gradient_opacity
    by_gradient = (np.zeros(2), np.zeros(2), False) if ramp is None else (
        ramp.magnitudes, ramp.factors, True)
    rows, cols = -(-view.height // TILE[0]), -(-view.width // TILE[1])
    # Cost of a tile: the pixels whose rays can meet something visible; the threads take the
    # heaviest tiles first, then clear the tiles without such a pixel (as -1 - tile).
    padded = np.zeros((rows * TILE[0], cols * TILE[1]), np.uint8)
    padded[: view.height, : view.width] = mask
    costs = np.add.reduce(padded.reshape(rows, TILE[0], cols * TILE[1]), axis=1,
                          dtype=np.int32)  # a tile's rows, then its columns
    costs = np.add.reduce(costs.reshape(rows, cols, TILE[1]), axis=2).ravel()
    order = np.argsort(-costs, kind="stable")  # the tiles without cost last, in index order
    live = np.count_nonzero(costs)
    order[live:] = -1 - order[live:]
    # One array type per argument (read-only samples and grids, contiguous vectors): every
    # other combination would compile the kernel once more.
    vector = np.ascontiguousarray
    layout = (readonly(data), vector(offset, np.int64), vector(global_shape, np.int64),
              vector(origin, np.float64), vector(spacing, np.float64),
              vector(box[0], np.float64), vector(box[1], np.float64),
              *lattice_extent(global_shape, spacing, origin).T.copy())
    grids = (readonly(vector(empty, bool)), readonly(vector(clearance, np.int64)), block,
             readonly(vector(mask, bool)))
    filtering = None if filt.code[0] == TENT else True
    lit = None if shading is None and ramp is None else True
    return RayPlan(layout, lighting, by_gradient, grids, order, rows * cols, threads,
                   # Rows of MAX_TAPS = 8 floats, a cache line; an unused row between two
                   # threads' keeps them off each other's lines.
                   np.zeros((threads, 7, MAX_TAPS))[:, :6], _kernel.lanes(threads),
                   (filtering, lit, None if block == 0 else True,
                    True if filtering is None and lit is None else None),
                   int(costs.sum()), float(np.linalg.norm(np.subtract(box[1], box[0]))))


def _kept(memo, name, key, build):
    """``build()``, kept in ``memo`` under ``name`` while ``key`` names the same objects
    (:func:`_same`)."""
    held = memo.get(name)
    if held is not None and _same(held[0], key):
        return held[1]
    value = build()
    memo[name] = (key, value)
    return value


def _same(held, key):
    """Whether the key ``held`` names the same objects as ``key`` (numbers and tuples of
    them: equal ones)."""
    return len(held) == len(key) and all(
        a is b or (type(a) is type(b) and isinstance(a, (int, tuple)) and a == b)
        for a, b in zip(held, key, strict=True))
