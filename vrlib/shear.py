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
runs all three passes and composites along ``Z``. ``method="shear2"`` drops the third pass:
pass 3 only slides samples along their own ray and re-spaces them evenly, so the slices that
pass 2 leaves on the image's rows and columns are composited in slice order directly, each a
segment of the same length ``|i| ds`` (one global opacity correction). Both are affine, so
orthographic only.
"""

from __future__ import annotations

import itertools
import math
import time

import numpy as np

from vrlib import _validate
from vrlib._kernels import shear as _kernel
from vrlib.image import Image, RenderStats
from vrlib.raycast import reconstructed_range, taps_per_axis

__all__ = ["render_shear3", "render_shear2", "render_shearwarp", "ShearPlan", "plan_shear",
           "transparent_bound"]


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
    start = view.center - view.radius * view.forward
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


def _check(view, filt, refusal=None, transfer=None):
    """Refuse filters wider than 4 voxels, shaded transfer functions, and perspective views
    with ``refusal`` when one is given; return the filter's taps per axis."""
    if transfer is not None and transfer.shading is not None:
        raise ValueError("volume shearing does not shade (it resamples no gradients); use "
                         "method='raycast' for shaded images")
    if refusal is not None and view.is_perspective:
        raise ValueError(refusal)
    ntaps = taps_per_axis(filt)
    if ntaps > 8:
        raise ValueError(f"filter radius {filt.radius:g} is out of range: shearing takes radii "
                         "up to 4 voxels")
    return ntaps


_AFFINE_ONLY = ("three- and two-pass shearing factor an affine view: orthographic only; use "
                "method='shearwarp' or 'raycast' for perspective")


def _filled(first, last, length):
    """For the next pass: each of its lines runs across the lines of this pass, and holds data
    where this pass computed it. ``first[s, r] .. last[s, r]`` are the outputs this pass
    computed on line ``(s, r)``; returns, for every ``(s, q)`` with ``q`` in ``[0, length)``,
    the first and last ``r`` whose range covers ``q`` (``first > last`` where none does)."""
    q = np.arange(length)
    covered = (first[:, :, None] <= q) & (q <= last[:, :, None])  # [s, r, q]
    any_r = covered.any(axis=1)
    n_r = first.shape[1]
    lo = np.where(any_r, covered.argmax(axis=1), n_r)
    hi = np.where(any_r, n_r - 1 - covered[:, ::-1, :].argmax(axis=1), -1)
    return lo.astype(np.int64), hi.astype(np.int64)


def _run_pass(src, out, c0, c1, c2, offset, lo, hi, filt, ntaps):
    counts = np.zeros(out.shape[0], np.int64)
    first = np.empty(out.shape[:2], np.int64)
    last = np.empty(out.shape[:2], np.int64)
    _kernel.shear_pass(src, out, c0, c1, c2, offset, lo, hi, *filt.code, filt.radius, ntaps,
                       counts, first, last)
    return int(counts.sum()), first, last


#: Storage types of the shear methods' intermediate volumes.
INTERMEDIATES = {"float32": np.float32, "float64": np.float64}


def _passes(volume, view, plan, filt, ntaps, count, dtype):
    """Passes 1 and 2; returns ``V2[w, Y, X]`` and the computed output ranges of pass 2.

    Each pass computes only outputs the volume reaches: a line of pass 2 holds data where pass 1
    computed it, and so on.
    """
    u, v, w = plan.order
    data = np.transpose(volume.data, (2 - w, 2 - v, 2 - u))  # [w, v, u], a view
    nw, nv, nu = data.shape
    v1 = np.zeros((nw, nv, view.width), dtype)
    count["pass1"], first1, last1 = _run_pass(
        data, v1, plan.a, plan.b, plan.c, plan.t0, np.zeros((nw, nv), np.int64),
        np.full((nw, nv), nu - 1, np.int64), filt, ntaps)
    lo, hi = _filled(first1, last1, view.width)  # pass 2 lines (w, X) run along v
    v2 = np.zeros((nw, view.height, view.width), dtype)
    count["pass2"], first2, last2 = _run_pass(
        v1.transpose(0, 2, 1), v2.transpose(0, 2, 1), plan.e, plan.d, plan.f, plan.t1, lo, hi,
        filt, ntaps)
    count["buffers"] = v1.nbytes + v2.nbytes
    del v1
    return v2, first2, last2


def _stats(volume, taps, count, composited, seconds, largest):
    resampled = count["pass1"] + count["pass2"] + count.get("pass3", 0)
    return RenderStats(samples=resampled + composited,
                       operations=resampled * 12 * taps + composited * 12,
                       bytes=int(largest), seconds=seconds, voxels=resampled, passes=count)


#: Magnitudes float32 intermediates hold with room to spare (its normal range is 1.2e-38 to
#: 3.4e38, and the filter weights scale values by a few).
_FLOAT32_SAFE = (1e-30, 1e30)


def _intermediate(intermediate, volume):
    """Storage type of the intermediate volumes: ``"auto"`` takes float32 unless the
    volume's non-zero magnitudes fall outside what float32 holds safely."""
    _validate.choice("intermediate", intermediate, ("auto", *INTERMEDIATES))
    if intermediate != "auto":
        return INTERMEDIATES[intermediate]
    derived = volume._derived  # read once per volume (its samples are read-only)
    if "float32_safe" not in derived:
        lo, hi = volume.value_range
        largest = max(abs(lo), abs(hi))
        data = np.abs(volume.data)
        smallest = float(data[data > 0].min()) if largest > 0 else 1.0
        derived["float32_safe"] = _FLOAT32_SAFE[0] <= smallest and largest <= _FLOAT32_SAFE[1]
    return np.float32 if derived["float32_safe"] else np.float64


def render_shear3(volume, view, *, filt, transfer, step, early_termination,
                  empty_space_skipping, intermediate="auto"):
    """Three-pass shear rendering (arguments validated by :func:`vrlib.render`).
    ``intermediate`` stores the resampled volumes as float32 (half the memory) or float64;
    ``"auto"`` takes float32 unless the volume's magnitudes need float64 (chapter ch08
    measures the difference: about 1e-8 in the image)."""
    ntaps = _check(view, filt, _AFFINE_ONLY, transfer)
    dtype = _intermediate(intermediate, volume)
    start = time.perf_counter()
    ds = step * float(volume.spacing.min())
    plan = plan_shear(volume, view, ds)
    count = {}
    v2, first2, last2 = _passes(volume, view, plan, filt, ntaps, count, dtype)
    v3 = np.zeros((plan.depth_samples, view.height, view.width), dtype)
    # Pass 3 lines (Y, X) run along w: first2/last2 are indexed [w, X] over Y.
    lo, hi = _filled(first2.transpose(1, 0), last2.transpose(1, 0), view.height)  # [X, Y]
    count["pass3"], _, _ = _run_pass(
        v2.transpose(1, 2, 0), v3.transpose(1, 2, 0), plan.i, plan.g, plan.h, plan.t2,
        np.ascontiguousarray(lo.T), np.ascontiguousarray(hi.T), filt, ntaps)
    largest = max(count["buffers"], v2.nbytes + v3.nbytes)
    del v2
    tables = transfer.segment_table(ds, *reconstructed_range(volume, filt))
    out = np.zeros(view.shape + (4,))
    counts = np.zeros(view.height, np.int64)
    limits = np.array(volume.shape[::-1], float)[list(plan.order)] - 1.0
    _kernel.composite_lattice(v3, np.linalg.inv(plan.matrix), plan.shift, limits, tables[0],
                              tables[1], tables[2], tables[3], early_termination, out, counts)
    stats = _stats(volume, ntaps, count, int(counts.sum()), time.perf_counter() - start,
                   largest)
    return Image(np.clip(out, 0.0, 1.0), stats)


def render_shear2(volume, view, *, filt, transfer, step, early_termination,
                  empty_space_skipping, intermediate="auto"):
    """Two-pass shear rendering (arguments validated by :func:`vrlib.render`). ``step`` sets
    the lattice of the image plane only: samples along a ray are the volume's slices.
    ``intermediate`` as for :func:`render_shear3`."""
    ntaps = _check(view, filt, _AFFINE_ONLY, transfer)
    dtype = _intermediate(intermediate, volume)
    start = time.perf_counter()
    ds = step * float(volume.spacing.min())
    plan = plan_shear(volume, view, ds)
    count = {}
    v2, _, _ = _passes(volume, view, plan, filt, ntaps, count, dtype)
    length = abs(plan.i) * ds  # world distance between slices along a ray
    tables = transfer.segment_table(length, *reconstructed_range(volume, filt))
    m = plan.matrix
    inverse2 = np.linalg.inv(np.array([[m[0, 0], m[0, 1]], [m[1, 0], m[1, 1]]]))
    shift = np.array([plan.shift[0], plan.shift[1], m[0, 2], m[1, 2]])
    limits = np.array(volume.shape[::-1], float)[list(plan.order)][:2] - 1.0
    out = np.zeros(view.shape + (4,))
    counts = np.zeros(view.height, np.int64)
    _kernel.composite_slices(v2, plan.i > 0, inverse2, shift, limits, tables[0], tables[1],
                             tables[2], tables[3], early_termination, out, counts)
    stats = _stats(volume, ntaps, count, int(counts.sum()), time.perf_counter() - start,
                   count["buffers"])
    return Image(np.clip(out, 0.0, 1.0), stats)


def transparent_bound(transfer, low, high, length, min_opacity):
    """Largest value up to which every value is transparent: its segment opacity at ``length``
    stays at or below ``min_opacity`` (0: exactly transparent). ``-inf`` when none is.

    Examples
    --------
    >>> from vrlib import Glow
    >>> transparent_bound(Glow(1.0), -1.0, 1.0, 0.1, 0.0)
    0.0
    """
    start, inv, density, _ = transfer.value_table(low, high)
    alpha = -np.expm1(-density * length)
    visible = np.flatnonzero(alpha > min_opacity)
    if visible.size == 0:
        return math.inf
    if visible[0] == 0:
        return -math.inf
    return float(start + (visible[0] - 1) / inv)


def _intermediate_plane(volume, view, axis, ascending):
    """Shear-warp's factorisation: the plane of the front slice and, per slice, the map from
    intermediate pixels to slice samples (:func:`vrlib._kernels.shear.shear_slices`).

    Returns ``scale, di, dj`` (per slice), the offsets ``oi, oj`` and size ``(height, width)``
    of the intermediate image, the front slice ``kf``, and ``rays(points)``: the direction in
    index units of the ray through plane points (index units, ``[..., (i, j)]``)."""
    q_axis, p_axis = [a for a in range(3) if a != axis]  # columns i, rows j (Volume.slices)
    axes = [q_axis, p_axis, axis]
    n = np.array(volume.shape[::-1])[axes]  # (n_i, n_j, n_k)
    kf = 0 if ascending else n[2] - 1
    k = np.arange(n[2], dtype=float)
    if view.eye is None:
        direction = (view.forward / volume.spacing)[axes]
        slope = direction[:2] / direction[2]
        scale = np.ones(n[2])
        shift = slope[:, None] * (k - kf)  # sample = plane point + shift

        def rays(points):
            return np.broadcast_to(direction, points.shape[:-1] + (3,))
    else:
        eye = ((view.eye - volume.origin) / volume.spacing)[axes]
        if (eye[2] >= 0.0) if ascending else (eye[2] <= n[2] - 1):
            name = "xyz"[axis]
            raise ValueError(
                f"perspective shear-warp needs the eye outside the volume's slab along its "
                f"principal axis {name}: the eye is at {name} index {eye[2]:.3g}, the slab spans "
                f"[0, {n[2] - 1}]; move the eye out or use method='raycast'")
        scale = (k - eye[2]) / (kf - eye[2])  # >= 1: slices behind the front one shrink
        shift = eye[:2, None] * (1.0 - scale)  # sample = scale * plane point + shift

        def rays(points):
            return np.concatenate([points, np.full(points.shape[:-1] + (1,), float(kf))],
                                  -1) - eye
    # Where the end slices land on the plane: the intermediate image covers both.
    ends = [0, n[2] - 1]
    low = np.min([(0.0 - shift[:, e]) / scale[e] for e in ends], axis=0)
    high = np.max([(n[:2] - 1.0 - shift[:, e]) / scale[e] for e in ends], axis=0)
    width, height = (np.ceil(high - low - 1e-9).astype(int) + 1)
    di, dj = shift + scale * low[:, None]  # sample = scale * I + d
    return scale, di, dj, -low, (int(height), int(width)), kf, rays


def _warp_homography(view, volume, axis, plane, offsets):
    """``H`` with ``(A, B, D) = H @ (column, row, 1)``: the pixel's ray meets the plane
    ``x[axis] = plane`` at intermediate coordinates ``(A / D, B / D)`` (``D > 0`` where it meets
    it in front of the eye). Affine for orthographic views (``D = 1``), projective for
    perspective ones; built from three pixels, as every term is affine in the pixel."""
    q_axis, p_axis = [a for a in range(3) if a != axis]
    right, up, forward = view.basis
    pixel = view.packed()[12]
    h, origin = volume.spacing, volume.origin
    rows = []
    for col, row in [(0, 0), (1, 0), (0, 1)]:
        offset = ((col + 0.5 - 0.5 * view.width) * right
                  + (0.5 * view.height - row - 0.5) * up) * pixel
        if view.eye is None:
            start = view.center - view.radius * forward + offset
            point = start + (plane - start[axis]) / forward[axis] * forward
            d, scaled = 1.0, point
        else:  # eye + (plane - eye_axis) / d_axis * d, scaled by d_axis (> 0 toward the plane)
            direction = forward + offset
            sign = math.copysign(1.0, plane - view.eye[axis])
            d = sign * direction[axis]
            scaled = sign * ((plane - view.eye[axis]) * direction + direction[axis] * view.eye)
        rows.append([(scaled[q_axis] - d * origin[q_axis]) / h[q_axis] + d * offsets[0],
                     (scaled[p_axis] - d * origin[p_axis]) / h[p_axis] + d * offsets[1], d])
    g00, g10, g01 = np.array(rows)
    return np.stack([g10 - g00, g01 - g00, g00], axis=1)


def render_shearwarp(volume, view, *, filt, transfer, step, early_termination,
                     empty_space_skipping, min_opacity=0.0):
    """Shear-warp rendering (Lacroute and Levoy 1994; arguments validated by
    :func:`vrlib.render`).

    Slices perpendicular to the volume axis most parallel to the view are translated (sheared;
    perspective: translated and scaled) so that the view becomes a projection along that axis,
    resampled with the chosen filter (in 2-D), composited front to back into an intermediate
    image at the front slice's resolution, and the intermediate image is warped to the final
    one with bilinear interpolation. ``step`` is unused: the samples along a ray are the
    slices. Perspective views need the eye outside the volume's slab along that axis.

    Parameters
    ----------
    min_opacity : float, default 0
        Voxels whose segment opacity is at most this are transparent for run-length skipping;
        0 skips only voxels that add nothing (exact), larger values skip faint voxels too
        (lossy, as VolPack's threshold). Skipping is on with ``empty_space_skipping`` and for
        filters without negative lobes.
    """
    from vrlib.skipping import lattice_sums, transparent_runs
    from vrlib.splat import major_axis

    min_opacity = _validate.finite_number("min_opacity", min_opacity, low=0.0, high=1.0,
                                          high_open=True)
    ntaps = _check(view, filt, transfer=transfer)
    start = time.perf_counter()
    axis, ascending = major_axis(volume, view)
    scale, di, dj, (oi, oj), (height, width), kf, rays = _intermediate_plane(
        volume, view, axis, ascending)
    q_axis, p_axis = [a for a in range(3) if a != axis]
    slices = volume.slices(axis)  # [k, j, i]: j along p_axis, i along q_axis
    n_k = slices.shape[0]
    h = volume.spacing
    order = np.arange(n_k) if ascending else np.arange(n_k)[::-1].copy()

    def segment(direction):  # world distance between slices along rays of these directions
        world = direction * h[[q_axis, p_axis, axis]]
        return np.linalg.norm(world, axis=-1) / np.abs(direction[..., 2])

    centre = np.array([0.5 * (volume.shape[::-1][q_axis] - 1),
                       0.5 * (volume.shape[::-1][p_axis] - 1)])
    length = float(segment(rays(centre[None])[0]))
    if view.eye is None:
        fraction = np.ones((1, 1))
    else:
        grid = np.stack(np.meshgrid(np.arange(width) - oi, np.arange(height) - oj), -1)
        fraction = segment(rays(grid)) / length
    low, high = reconstructed_range(volume, filt)
    tables = transfer.segment_table(length, low, high)
    bound = -math.inf
    if empty_space_skipping and lattice_sums(filt)[2] <= 1.0 + 1e-6:
        bound = transparent_bound(transfer, low, high, length, min_opacity)
    first, last = transparent_runs(volume, axis, bound)
    inter = np.zeros((height, width, 4))
    counts = np.zeros(height, np.int64)
    _kernel.shear_slices(slices, order, scale, di, dj, fraction, *filt.code, filt.radius,
                         ntaps, tables[0], tables[1], tables[2], tables[3], early_termination,
                         first, last, inter, counts)
    # The warp: where each pixel's ray meets the front slice, in intermediate coordinates.
    plane = volume.origin[axis] + kf * h[axis]
    out = np.empty(view.shape + (4,))
    _kernel.warp(inter, _warp_homography(view, volume, axis, plane, (oi, oj)), out)
    resampled = int(counts.sum())
    stats = RenderStats(samples=resampled, operations=resampled * (2 * ntaps**2 + 12)
                        + out.size * 8, bytes=int(volume.data.nbytes + inter.nbytes + out.nbytes),
                        seconds=time.perf_counter() - start, voxels=resampled)
    return Image(np.clip(out, 0.0, 1.0), stats)
