"""Volume shearing: Hanrahan's three-pass resampling and the two-pass variant without the z pass.

The affine map from volume index space to the image lattice (pixel columns ``X``, rows ``Y``
and ray samples ``Z``, the same lattice the ray caster samples) is factored into three scaled
shears, each a 1-D resampling along one axis (thesis section 1.2; Hanrahan 1990):

* pass 1 along the volume's ``u`` axis: ``X = a u + b v + c w + t0``;
* pass 2 along ``v``: ``Y = d X + e v + f w + t1``;
* pass 3 along ``w``: ``Z = g X + h Y + i w + t2``.

The axis order avoids bottlenecks (a small scale factor squeezes the data through a narrow
intermediate lattice and loses detail): ``w`` is the volume axis most parallel to the view,
and of the two orders of the others the renderer takes the one whose smaller scale factor
``|a|`` or ``|e|`` is larger. ``method="shear3"``
runs all three passes and composites along ``Z``; its third pass runs along the rays, so it is
fused with the compositing and no third volume is stored. ``method="shear2"`` drops the third pass:
pass 3 only slides samples along their own ray and re-spaces them evenly, so the slices that
pass 2 leaves on the image's rows and columns are composited in slice order directly, each a
segment of the same length ``|i| ds`` (one global opacity correction). Both are affine, so
orthographic only. Transfer functions that need gradients (shading, gradient opacity) send the
samples' central differences through the same passes (:mod:`vrlib.gradients`: four channels
instead of one) and classify each sample by its resampled gradient.
"""

from __future__ import annotations

import itertools
import math
import time

import numpy as np

from vrlib import validate
from vrlib._kernels import shear as _kernel
from vrlib._kernels._jit import readonly
from vrlib.compositing import SEGMENT_ENDS
from vrlib.gradients import kernel_lighting, no_gradients
from vrlib.image import Image, RenderStats
from vrlib.prefilter import Tally, filter_lines, prepared, prepared_gradients
from vrlib.value_bounds import reconstructed_range

__all__ = ["render_shear3", "render_shear2", "ShearPlan", "plan_shear", "INTERMEDIATES"]


class ShearPlan:
    """The factored view: axis order, shear coefficients and pass sizes.

    Attributes
    ----------
    order : tuple of int
        Volume axes (0, 1, 2 for x, y, z) taken as ``u, v, w``.
    a, b, c, d, e, f, g, h, i : float
        Shear coefficients (module docstring).
    t0, t1, t2 : float
        Offsets of the three passes (``t2`` relative to the first depth sample kept).
    depth_samples : int
        Samples along ``Z`` that the third pass produces.
    matrix, shift : ndarray
        The full map ``(X, Y, Z) = matrix @ (u, v, w) + shift``.
    """

    def __init__(self, order, coefficients, offsets, depth_samples, matrix, shift):
        self.order = order
        (self.a, self.b, self.c, self.d, self.e, self.f, self.g, self.h, self.i) = coefficients
        self.t0, self.t1, self.t2 = offsets
        self.depth_samples = depth_samples
        self.matrix, self.shift = matrix, shift


def _image_map(volume, view, ds):
    """Affine map from volume index ``(x, y, z)`` to the image lattice ``(X, Y, Z)``."""
    start = view.start
    px = view.pixel_size
    scale = np.diag([1.0 / px, -1.0 / px, 1.0 / ds])
    matrix = scale @ view.basis @ np.diag(volume.spacing)
    shift = scale @ view.basis @ (volume.origin - start) + [0.5 * view.width - 0.5,
                                                            0.5 * view.height - 0.5, -0.5]
    return matrix, shift


def _factor(m):
    """Shear coefficients of ``m`` (columns u, v, w), or None where a pivot vanishes."""
    a, b, c = m[0]
    if abs(a) < 1e-9:
        return None
    d = m[1, 0] / a
    e, f = m[1, 1] - d * b, m[1, 2] - d * c
    pivots = np.array([[m[0, 0], m[1, 0]], [m[0, 1], m[1, 1]]])
    if abs(e) < 1e-9 or abs(np.linalg.det(pivots)) < 1e-12:
        return None
    g, h = np.linalg.solve(pivots, m[2, :2])
    i = m[2, 2] - g * m[0, 2] - h * m[1, 2]
    if abs(i) < 1e-9:
        return None
    return a, b, c, d, e, f, g, h, i


def plan_shear(volume, view, ds):
    """Choose the axis order that avoids bottlenecks and factor the view.

    Examples
    --------
    >>> from vrlib import Volume, View
    >>> plan = plan_shear(Volume(np.zeros((4, 4, 4))), View.orbit(azimuth=20, elevation=10,
    ...                   size=16), 0.1)
    >>> plan.order                  # w = x: the view runs mostly along x
    (1, 2, 0)
    """
    matrix, shift = _image_map(volume, view, ds)
    sizes = np.array(volume.shape[::-1])  # x, y, z
    corners = np.array(list(itertools.product(*[(0, n - 1) for n in sizes])), float)
    image = corners @ matrix.T + shift
    # The principal axis: the largest depth change per sample (ties to the lower axis).
    strength = np.abs(matrix[2])
    w = int(np.flatnonzero(strength >= strength.max() * (1 - 1e-12))[0])
    best = None
    for u, v in itertools.permutations([a for a in range(3) if a != w]):
        coefficients = _factor(matrix[:, (u, v, w)])
        if coefficients is None:
            continue
        score = min(abs(coefficients[0]), abs(coefficients[4]))
        if best is None or score > best[0]:
            best = (score, (u, v, w), coefficients)
    if best is None:
        raise ValueError("the view cannot be factored into shears (degenerate view matrix)")
    _, order, coefficients = best
    a, b, c, d, e, f, g, h, i = coefficients
    t0, ty, tz = shift
    z_first = math.floor(image[:, 2].min()) - 1
    depth = math.ceil(image[:, 2].max()) + 2 - z_first
    offsets = (t0, ty - d * t0, tz - g * t0 - h * ty - z_first)
    return ShearPlan(order, coefficients, offsets, depth, matrix[:, order],
                     np.array([t0, ty, tz - z_first]))


def _check(view):
    """Refuse what three- and two-pass shearing cannot render."""
    if view.is_perspective:
        raise ValueError("three- and two-pass shearing factor an affine view: orthographic "
                         "only; use method='shearwarp' or method='raycast' for perspective")


def _filled(first, last, length):
    """Where the next pass's lines hold data (:func:`vrlib._kernels.shear.filled`)."""
    lo = np.empty((first.shape[0], length), np.int64)
    hi = np.empty_like(lo)
    _kernel.filled(first, last, length, lo, hi)
    return lo, hi


def _run_pass(src, out, c0, c1, c2, offset, lo, hi, filt):
    """Run one pass in the loop order that suits the arrays' memory layout: a pass is the same
    with its outer axes ``s`` and ``r`` swapped (and ``c1``, ``c2`` with them), and its lines
    advance together when ``r`` is the axis that lies contiguous in memory. The outputs do not
    depend on the order."""
    swap = src.strides[0] < src.strides[1]
    if swap:
        src, out, c1, c2 = src.transpose(1, 0, 2), out.transpose(1, 0, 2), c2, c1
        lo, hi = lo.T, hi.T
    across = src.strides[1] < src.strides[2] and out.strides[1] < out.strides[2]
    counts = np.zeros(out.shape[0], np.int64)
    first = np.empty(out.shape[:2], np.int64)
    last = np.empty(out.shape[:2], np.int64)
    _kernel.shear_pass(readonly(src), out, c0, c1, c2, offset, np.ascontiguousarray(lo),
                       np.ascontiguousarray(hi), *filt.code, filt.radius, filt.taps, across,
                       counts, first, last)
    if swap:
        first, last = first.T, last.T
    return int(counts.sum()), first, last


#: Storage types of the shear methods' intermediate volumes.
INTERMEDIATES = {"float32": np.float32, "float64": np.float64}


def _passes(volume, view, plan, filt, count, dtype, transfer, tally, third_pass):
    """Passes 1 and 2; returns ``V2[w, Y, X]``, the gradient's components after the same passes
    (``[3, w, Y, X]``, when ``transfer`` needs them: :mod:`vrlib.gradients`; else a
    placeholder, :func:`vrlib.gradients.no_gradients`) and, when ``third_pass``, where pass 3's
    lines (along ``w``, one per pixel) hold data: ``(lo, hi)``, each ``[Y, X]``.

    Each pass computes only outputs the volume reaches: a line of pass 2 holds data where pass 1
    computed it, and so on. A prefiltered filter prefilters each pass's lines along the pass's
    axis first (:mod:`vrlib.prefilter`): pass 1's input along ``u`` (the volume's, cached),
    pass 2's along ``v`` and, when ``third_pass``, pass 3's along ``w`` (counted in ``tally``).
    """
    u, v, w = plan.order
    order = (2 - w, 2 - v, 2 - u)  # [w, v, u]
    channels = [prepared(volume, filt, tally, axes=(u,)).data]
    if transfer.needs_gradient:
        channels += list(prepared_gradients(volume, filt, tally, axes=(u,)))
    nw, nv, nu = np.transpose(volume.data, order).shape
    # V2[w, Y, X] is stored as [Y, w, X]: the samples one image row needs lie together, for
    # the last pass (shear3) or the compositing (shear2), which take an image row at a time.
    stored = np.zeros((len(channels), view.height, nw, view.width), dtype)
    v2 = stored.transpose(0, 2, 1, 3)
    v1 = np.empty((nw, nv, view.width), dtype)
    count["pass1"] = count["pass2"] = 0
    for channel, data in enumerate(channels):
        v1[...] = 0.0
        done, first1, last1 = _run_pass(
            np.transpose(data, order), v1, plan.a, plan.b, plan.c, plan.t0,
            np.zeros((nw, nv), np.int64), np.full((nw, nv), nu - 1, np.int64), filt)
        count["pass1"] += done
        if channel == 0:  # where data lies depends on the geometry only: the same for all
            lo, hi = _filled(first1, last1, view.width)  # pass 2 lines (w, X) run along v
        _prefilter_lines(v1, lo, hi, filt, tally)  # V1[w, v, X]: lines along v
        done, first2, last2 = _run_pass(
            v1.transpose(0, 2, 1), v2[channel].transpose(0, 2, 1), plan.e, plan.d, plan.f,
            plan.t1, lo, hi, filt)
        count["pass2"] += done
        if third_pass and channel == 0:  # like pass 2's, the same for every channel
            lo3, hi3 = (np.ascontiguousarray(a.T) for a in _filled(
                first2.transpose(1, 0), last2.transpose(1, 0), view.height))
        if third_pass:  # V2 stored [Y, w, X]: pass 3's lines along w
            _prefilter_lines(stored[channel], lo3, hi3, filt, tally)
    count["buffers"] = v1.nbytes + stored.nbytes
    grads = no_gradients(dtype)
    if len(channels) > 1:
        grads = v2[1:]
        grads.flags.writeable = False  # the placeholder's type: one compiled kernel
    return v2[0], grads, (lo3, hi3) if third_pass else None


def _prefilter_lines(lines, lo, hi, filt, tally):
    """Prefilter an intermediate volume's lines ``lines[s, k, r]`` along ``k`` on their data
    ranges, in place, for a prefiltered filter (subnormal results flushed to zero)."""
    if not filt.prefiltered:
        return
    start = time.perf_counter()
    filter_lines(lines, lo, hi, filt.poles, tiny=float(np.finfo(lines.dtype).tiny))
    tally.add(time.perf_counter() - start, np.maximum(hi - lo + 1, 0).sum(), len(filt.poles))


def _first_passes(volume, view, filt, step, dtype, transfer, tally, third_pass):
    """What both methods do first: the ray step in world units, the plan, and passes 1 and 2
    (:func:`_passes`) with their counts."""
    ds = step * float(volume.spacing.min())
    plan = plan_shear(volume, view, ds)
    count = {}
    return ds, plan, count, _passes(volume, view, plan, filt, count, dtype, transfer, tally,
                                    third_pass)


def _stats(volume, taps, count, composited, seconds, largest):
    resampled = count["pass1"] + count["pass2"] + count.get("pass3", 0)
    return RenderStats(samples=resampled + composited,
                       operations=resampled * 12 * taps + composited * 12,
                       bytes=int(largest), seconds=seconds, voxels=resampled, passes=count,
                       points=composited)


#: Magnitudes float32 intermediates hold with room to spare (its normal range is 1.2e-38 to
#: 3.4e38, and the filter weights scale values by a few).
_FLOAT32_SAFE = (1e-30, 1e30)


def _intermediate(intermediate, volume):
    """Storage type of the intermediate volumes: ``"auto"`` takes float32 unless the
    volume's non-zero magnitudes fall outside what float32 holds safely."""
    validate.choice("intermediate", intermediate, ("auto", *INTERMEDIATES))
    if intermediate != "auto":
        return INTERMEDIATES[intermediate]

    def float32_safe():  # read once per volume (its samples are read-only)
        lo, hi = volume.value_range
        largest = max(abs(lo), abs(hi))
        data = np.abs(volume.data)
        smallest = float(data[data > 0].min()) if largest > 0 else 1.0
        return _FLOAT32_SAFE[0] <= smallest and largest <= _FLOAT32_SAFE[1]

    return np.float32 if volume.cached(("float32_safe",), float32_safe) else np.float64


def render_shear3(volume, view, *, filt, transfer, step, early_termination,
                  empty_space_skipping, intermediate="auto", segment_ends="lattice"):
    """Three-pass shear rendering (arguments validated by :func:`vrlib.render`).
    ``intermediate`` stores the resampled volumes as float32 (half the memory) or float64;
    ``"auto"`` takes float32 unless the volume's magnitudes need float64 (chapter ch08
    measures the difference: about 1e-8 in the image). ``segment_ends`` as the ray
    caster's: ``"lattice"`` lets each sample inside the volume stand for its whole segment
    of the ray, ``"exact"`` counts only the part inside of the segments that the volume's
    faces cut, each sampled at its middle (pass 3 resamples the ray there)."""
    exact = validate.choice("segment_ends", segment_ends, SEGMENT_ENDS) == "exact"
    _check(view)
    dtype = _intermediate(intermediate, volume)
    start = time.perf_counter()
    tally = Tally()
    ds, plan, count, (v2, grads, (lo, hi)) = _first_passes(volume, view, filt, step, dtype,
                                                           transfer, tally, True)
    # Pass 3 runs along the rays: fused with compositing, no third volume is stored.
    tables = transfer.segment_table(ds, *reconstructed_range(volume, filt, cardinal=True))
    out = np.zeros(view.shape + (4,))
    resampled = np.zeros(view.height, np.int64)
    counts = np.zeros(view.height, np.int64)
    limits = np.array(volume.shape[::-1], float)[list(plan.order)] - 1.0
    _kernel.resample_composite(
        v2.transpose(1, 2, 0), plan.i, plan.g, plan.h, plan.t2, lo, hi, *filt.code,
        filt.radius, filt.taps, plan.depth_samples,
        np.linalg.inv(plan.matrix), plan.shift, limits, *tables,
        grads.transpose(0, 2, 3, 1), *kernel_lighting(transfer, view.forward), early_termination,
        out, resampled, counts, exact)
    count["pass3"] = int(resampled.sum())
    largest = max(count["buffers"], v2.nbytes)
    del v2
    stats = _stats(volume, filt.taps, count, int(counts.sum()), time.perf_counter() - start,
                   largest)
    return Image(np.clip(out, 0.0, 1.0), tally.finish(stats, filt))


def render_shear2(volume, view, *, filt, transfer, step, early_termination,
                  empty_space_skipping, intermediate="auto", segment_ends="lattice"):
    """Two-pass shear rendering (arguments validated by :func:`vrlib.render`). ``step`` sets
    the lattice of the image plane only: samples along a ray are the volume's slices.
    ``intermediate`` as for :func:`render_shear3`. ``segment_ends="exact"`` counts only the
    part inside of the segments that the volume's side faces cut, each by the nearest slice
    sample inside on the pixel's ray (the end slices keep their half segments):
    :func:`vrlib._kernels.shear.composite_slices`."""
    exact = validate.choice("segment_ends", segment_ends, SEGMENT_ENDS) == "exact"
    _check(view)
    dtype = _intermediate(intermediate, volume)
    start = time.perf_counter()
    tally = Tally()
    ds, plan, count, (v2, grads, _) = _first_passes(volume, view, filt, step, dtype, transfer,
                                                    tally, False)
    length = abs(plan.i) * ds  # world distance between slices along a ray
    tables = transfer.segment_table(length, *reconstructed_range(volume, filt, cardinal=True))
    m = plan.matrix
    inverse2 = np.linalg.inv(np.array([[m[0, 0], m[0, 1]], [m[1, 0], m[1, 1]]]))
    shift = np.array([plan.shift[0], plan.shift[1], m[0, 2], m[1, 2]])
    limits = np.array(volume.shape[::-1], float)[list(plan.order)][:2] - 1.0
    out = np.zeros(view.shape + (4,))
    counts = np.zeros(view.height, np.int64)
    _kernel.composite_slices(v2, plan.i > 0, inverse2, shift, limits, *tables, grads,
                             *kernel_lighting(transfer, view.forward), early_termination, out,
                             counts, exact)
    stats = _stats(volume, filt.taps, count, int(counts.sum()), time.perf_counter() - start,
                   count["buffers"])
    return Image(np.clip(out, 0.0, 1.0), tally.finish(stats, filt))
