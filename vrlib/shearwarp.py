"""Shear-warp (Lacroute and Levoy 1994): slices sheared into an intermediate image, then warped.

Slices perpendicular to the volume axis most parallel to the view
(:func:`vrlib.view.principal_axis`) are translated (perspective: translated and scaled) so that
the view becomes a projection along that axis, each resampled in 2-D with the chosen filter and
composited front to back into an intermediate image at the front slice's resolution; the
intermediate image is then warped to the final one with bilinear interpolation. Runs of
transparent voxels are skipped (:func:`vrlib.skipping.transparent_runs`), Lacroute's
run-length encoding. With ``planes_per_slice`` above 1, sample planes between the slices
interpolate them linearly, for a smaller error along rays at a proportional cost (the method's
only knob of time against error: its in-slice resampling is the filter's own). Transfer
functions that need gradients (shading, gradient opacity) take the
samples' central differences resampled with the same weights (:mod:`vrlib.gradients`); a
perspective view shades each intermediate pixel's samples along its own ray.
:func:`vrlib.classify` is VolPack's form of the method, with classification and shading before
resampling.
"""

from __future__ import annotations

import math
import time

import numpy as np

from vrlib import validate
from vrlib._kernels import shear as _kernel
from vrlib._kernels._jit import readonly
from vrlib._kernels.shear import SLAB_EDGE
from vrlib._scheduling import on_threads, thread_number
from vrlib.compositing import SEGMENT_ENDS
from vrlib.gradients import kernel_lighting, no_gradients
from vrlib.image import Image, RenderStats
from vrlib.prefilter import Tally, prepared, prepared_gradients
from vrlib.projection import classify_projected
from vrlib.skipping import transparent_runs
from vrlib.value_bounds import lattice_sums, reconstructed_range
from vrlib.view import principal_axis

__all__ = ["render_shearwarp", "project_shearwarp", "transparent_bound", "intermediate_plane",
           "sample_planes", "ray_stretches", "whole_planes", "warp_homography", "warp",
           "MAX_PLANES_PER_SLICE"]

#: Final-image rows per unit of the warp's parallel work.
WARP_BAND = 16
#: The most sample planes per slice spacing shear-warp takes (``planes_per_slice``).
MAX_PLANES_PER_SLICE = 64


def ray_stretches(ends, shape, slice_shape):
    """Where each intermediate pixel's ray lies inside the volume, in slice coordinates:
    ``inside[J, I] = (k_lo, k_hi)`` within ``[0, n_k - 1]``, empty (``k_lo > k_hi``) where
    the ray misses it. ``ends`` holds ``(scale, di, dj)`` (rows) on the first and last
    slice (columns); the ray meets slice coordinate ``k`` at ``(i, j) = s (I, J) + (di, dj)``
    with all three linear in ``k`` (:func:`intermediate_plane`), ``slice_shape`` is ``(n_k,
    n_j, n_i)``.

    Examples
    --------
    >>> ends = np.array([[1.0, 1.0], [-2.0, 2.0], [0.0, 0.0]])  # i = I - 2 + k
    >>> ray_stretches(ends, (1, 3), (5, 1, 3))[0].tolist()   # inside for 0 <= i <= 2
    [[2.0, 4.0], [1.0, 3.0], [0.0, 2.0]]
    """
    n_k, n_j, n_i = slice_shape
    height, width = shape
    columns, rows = np.meshgrid(np.arange(width, dtype=float), np.arange(height, dtype=float))
    t_lo, t_hi = np.zeros(shape), np.ones(shape)
    for grid, d, limit in ((columns, ends[1], n_i - 1.0), (rows, ends[2], n_j - 1.0)):
        at_first, at_last = ends[0, 0] * grid + d[0], ends[0, 1] * grid + d[1]
        change = at_last - at_first
        moving = change != 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            a = np.where(moving, (0.0 - at_first) / change, -np.inf)
            b = np.where(moving, (limit - at_first) / change, np.inf)
        still_outside = ~moving & ((at_first < 0.0) | (at_first > limit))
        t_lo = np.maximum(t_lo, np.where(still_outside, np.inf, np.minimum(a, b)))
        t_hi = np.minimum(t_hi, np.where(still_outside, -np.inf, np.maximum(a, b)))
    return np.stack([t_lo * (n_k - 1.0), t_hi * (n_k - 1.0)], axis=-1)


def whole_planes(inside, n_k, planes):
    """The first and last plane (on the planes' lattice from slice 0, ``1 / planes`` apart)
    whose whole segment, ``[q h - h/2, q h + h/2]`` cut to ``[0, n_k - 1]``, lies in each
    pixel's stretch ``inside`` (:func:`ray_stretches`); first > last where none does.

    Examples
    --------
    >>> inside = np.array([[[0.0, 4.0], [0.3, 2.6], [1.2, 1.4]]])
    >>> [a.tolist() for a in whole_planes(inside, 5, 1)]
    [[[0, 1, 2]], [[4, 2, 0]]]
    """
    k_lo, k_hi = inside[..., 0], inside[..., 1]
    last = (n_k - 1) * planes
    # A ray that meets an end slice within rounding of its edge takes that slice's half
    # segment, sampled on the slice, as every ray through the end slices does (the middle
    # of a cut part would lie a quarter segment in: not a rounding's worth).
    first = np.where(k_lo <= SLAB_EDGE, 0, np.ceil(k_lo * planes + 0.5))
    final = np.where(k_hi >= n_k - 1.0 - SLAB_EDGE, last, np.floor(k_hi * planes - 0.5))
    missed = ~(k_lo <= k_hi)
    first = np.where(missed, 1, first).astype(np.int64)
    final = np.where(missed, 0, final).astype(np.int64)
    return first, final


def sample_planes(n_k, ascending, planes):
    """Shear-warp's sample planes, front to back, for ``n_k`` slices and ``planes`` planes
    per slice spacing: ``(order, other, between)``, plane ``p`` lying ``between[p]`` of the
    way from slice ``order[p]`` to slice ``other[p]`` (0: the slice itself).

    Examples
    --------
    >>> order, other, between = sample_planes(3, False, 2)
    >>> order.tolist(), other.tolist(), between.tolist()
    ([2, 2, 1, 1, 0], [2, 1, 1, 0, 0], [0.0, 0.5, 0.0, 0.5, 0.0])
    """
    slices = np.arange(n_k) if ascending else np.arange(n_k)[::-1].copy()
    if planes == 1:
        return slices, slices, np.zeros(n_k)
    order = np.repeat(slices, planes)[: (n_k - 1) * planes + 1]
    other = np.append(np.repeat(slices[1:], planes), slices[-1])
    other[::planes] = slices  # the slices themselves
    between = np.tile(np.arange(planes) / planes, n_k)[: (n_k - 1) * planes + 1]
    return order, other, between


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


def intermediate_plane(volume, view, axis, ascending, positions=None):
    """Shear-warp's factorisation: the plane of the front slice and, per slice (or per
    sample plane at ``positions``, slice indices that may lie between slices), the map from
    intermediate pixels to slice samples (:func:`vrlib._kernels.shear.shear_slices`).

    Returns ``scale, di, dj`` (per slice or position), the offsets ``oi, oj`` and size
    ``(height, width)`` of the intermediate image, the front slice ``kf``, and
    ``rays(points)``: the direction in index units of the ray through plane points (index
    units, ``[..., (i, j)]``)."""
    q_axis, p_axis = [a for a in range(3) if a != axis]  # columns i, rows j (Volume.slices)
    axes = [q_axis, p_axis, axis]
    n = [volume.shape[2 - a] for a in axes]  # (n_i, n_j, n_k)
    kf = 0 if ascending else n[2] - 1
    if positions is None:
        positions = np.arange(n[2], dtype=float)
    if not view.is_perspective:
        # In plain floats (a frame of VolPack's example: numpy's calls on vectors this short
        # cost more than their arithmetic), the same operations as on arrays.
        forward, spacing = view.forward.tolist(), volume.spacing.tolist()
        direction = [forward[a] / spacing[a] for a in axes]
        slope = [direction[0] / direction[2], direction[1] / direction[2]]
        # sample = plane point + slope (k - kf): where the end slices land.
        low, size = _covering([(t * (0.0 - kf), t * (n[2] - 1.0 - kf)) for t in slope],
                              1.0, 1.0, n)
        scale = np.ones(len(positions))
        offsets = positions - kf
        di, dj = (t * offsets + start for t, start in zip(slope, low, strict=True))

        def rays(points):
            return np.broadcast_to(np.array(direction), points.shape[:-1] + (3,))
    else:
        eye = ((view.eye - volume.origin) / volume.spacing)[axes]
        if (eye[2] >= 0.0) if ascending else (eye[2] <= n[2] - 1):
            name = "xyz"[axis]
            raise ValueError(
                f"perspective shear-warp needs the eye outside the volume's slab along its "
                f"principal axis {name}: the eye is at {name} index {eye[2]:.3g}, the slab spans "
                f"[0, {n[2] - 1}]; move the eye out or use method='raycast'")
        ends = (np.array([0.0, n[2] - 1.0]) - eye[2]) / (kf - eye[2])
        scale = (positions - eye[2]) / (kf - eye[2])  # >= 1: slices behind the front shrink
        shift = eye[:2, None] * (1.0 - scale)  # sample = scale * plane point + shift
        end_shift = eye[:2, None] * (1.0 - ends)  # the end slices' (the image covers both)
        low, size = _covering(
            zip(end_shift[:, 0].tolist(), end_shift[:, -1].tolist(), strict=True),
            float(ends[0]), float(ends[-1]), n)
        di, dj = shift + scale * np.array(low)[:, None]  # sample = scale * I + d

        def rays(points):
            return np.concatenate([points, np.full(points.shape[:-1] + (1,), float(kf))],
                                  -1) - eye
    return scale, di, dj, -np.array(low), (size[1], size[0]), kf, rays


def _covering(ends, s0, s1, n):
    """The intermediate image's low corner and size per axis (i, j): it covers both end
    slices, which land at ``(index - shift) / scale`` for their ``(shift, scale)``, ``ends``
    holding the two shifts per axis (in plain floats: numpy's minimum and maximum picked as
    numpy picks them, signed zeros too)."""
    low, size = [], []
    for (front, back), top in zip(ends, (n[0] - 1.0, n[1] - 1.0), strict=True):
        a, b = (0.0 - front) / s0, (0.0 - back) / s1
        lo = a if a < b else b
        a, b = (top - front) / s0, (top - back) / s1
        hi = a if a > b else b
        low.append(lo)
        size.append(math.ceil(hi - lo - 1e-9) + 1)
    return low, size


def warp_homography(view, volume, axis, plane, offsets):
    """``H`` with ``(A, B, D) = H @ (column, row, 1)``: the pixel's ray meets the plane
    ``x[axis] = plane`` at intermediate coordinates ``(A / D, B / D)`` (``D > 0`` where it meets
    it in front of the eye). Affine for orthographic views (``D = 1``), projective for
    perspective ones; built from three pixels, as every term is affine in the pixel."""
    q_axis, p_axis = [a for a in range(3) if a != axis]
    # Plain floats, component by component (the same arithmetic as on 3-vectors, a tenth of
    # numpy's time on vectors this short).
    right, up, forward = view.basis.tolist()
    pixel = view.plane_pixel
    h, origin = volume.spacing.tolist(), volume.origin.tolist()
    start = view.start.tolist()
    eye = start  # perspective: rays start at the eye
    rows = []
    for col, row in [(0, 0), (1, 0), (0, 1)]:
        along, down = col + 0.5 - 0.5 * view.width, 0.5 * view.height - row - 0.5
        if not view.is_perspective:  # from the pixel's start on the plane (D = 1)
            bq, bp, ba = [start[a] + (along * right[a] + down * up[a]) * pixel
                          for a in (q_axis, p_axis, axis)]
            reach = (plane - ba) / forward[axis]
            rows.append([(bq + reach * forward[q_axis] - origin[q_axis]) / h[q_axis]
                         + offsets[0],
                         (bp + reach * forward[p_axis] - origin[p_axis]) / h[p_axis]
                         + offsets[1], 1.0])
            continue
        # eye + (plane - eye_axis) / d_axis * d, scaled by d_axis (> 0 toward the plane)
        direction = [f + (along * r + down * u) * pixel
                     for f, r, u in zip(forward, right, up, strict=True)]
        sign = math.copysign(1.0, plane - eye[axis])
        d = sign * direction[axis]
        scaled = [sign * ((plane - eye[axis]) * t + direction[axis] * e)
                  for t, e in zip(direction, eye, strict=True)]
        rows.append([(scaled[q_axis] - d * origin[q_axis]) / h[q_axis] + d * offsets[0],
                     (scaled[p_axis] - d * origin[p_axis]) / h[p_axis] + d * offsets[1], d])
    g00, g10, g01 = rows
    return np.array([[b - a, c - a, a] for a, b, c in zip(g00, g10, g01, strict=True)])


def warp(inter, homography, out, grey=False, *, threads=None):
    """The 2-D warp into ``out`` (``(height, width, 4)``): each pixel ``(c, r)`` samples
    ``inter`` (RGBA, or for a ``grey`` image red and opacity alone: ``(.., .., 2)``)
    bilinearly at ``(A / D, B / D)`` with ``(A, B, D) = homography @ (c, r, 1)``
    (:func:`warp_homography`), on ``threads`` threads (None: numba's thread count)
    (:func:`vrlib._kernels.shear.warp_rows`, which says what it skips).

    Python threads run it (:func:`vrlib._scheduling.on_threads`), not a ``prange``: on one
    thread the call runs in the caller's own thread, and the kernel compiles without numba's
    parallel passes. On VolPack's example (256^2 pixels, ``bench_volpack_example.py``) the
    warp took 0.33 ms a frame in a ``prange``, 0.23 ms on Python threads, and 0.16 ms with
    eight pixels at once in vector form (:func:`vrlib._kernels.shear.warp_octet`); on the
    Zen 4 machine of later sessions 0.27 ms with the eight pixels' neighbours gathered
    value by value, 0.19 ms with each pixel's loaded a row at a time.

    Raises
    ------
    ValueError
        If ``out`` is not C-contiguous, or ``inter`` has fewer than 2 rows or columns or a
        number of channels other than 4 (or 2 for a ``grey`` image).

    Examples
    --------
    >>> import numpy as np
    >>> inter = np.zeros((2, 2, 4))
    >>> inter[:, 1] = 0.5                        # the right column half opaque
    >>> halfway = np.array([[0.5, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    >>> out = np.empty((2, 3, 4))
    >>> warp(inter, halfway, out)                # column c samples I = c / 2
    >>> out[0, :, 3].tolist()
    [0.0, 0.25, 0.5]
    """
    if not out.flags.c_contiguous:
        raise ValueError("out must be a C-contiguous (height, width, 4) array")
    if (inter.ndim != 3 or min(inter.shape[:2]) < 2
            or inter.shape[2] not in ((2, 4) if grey else (4,))):
        raise ValueError(f"inter must be a (rows, columns, {'2 or 4' if grey else 4}) array "
                         f"of at least 2 rows and columns, got shape {inter.shape}")
    inter = np.ascontiguousarray(inter)  # the vector warp reads pixels at flat offsets
    affine = homography[2, 0] == 0.0 and homography[2, 1] == 0.0 and homography[2, 2] == 1.0
    seen = _kernel.seen_box(inter) if affine else np.zeros(4)
    counter = np.zeros(1, np.int64)
    on_threads(lambda i: _kernel.warp_rows(inter, homography, out, grey, seen, WARP_BAND,
                                           counter),
               thread_number(threads))


def render_shearwarp(volume, view, *, filt, transfer, step, early_termination,
                     empty_space_skipping, min_opacity=0.0, planes_per_slice=1,
                     segment_ends="lattice"):
    """Shear-warp rendering (Lacroute and Levoy 1994; arguments validated by
    :func:`vrlib.render`).

    Slices perpendicular to the volume axis most parallel to the view are translated (sheared;
    perspective: translated and scaled) so that the view becomes a projection along that axis,
    resampled with the chosen filter (in 2-D), composited front to back into an intermediate
    image at the front slice's resolution, and the intermediate image is warped to the final
    one with bilinear interpolation. ``step`` is unused: the samples along a ray are the
    slices, and with ``planes_per_slice`` the planes between them. Perspective views need
    the eye outside the volume's slab along that axis.

    Parameters
    ----------
    min_opacity : float, default 0
        Voxels whose segment opacity is at most this are transparent for run-length skipping;
        0 skips only voxels that add nothing (exact), larger values skip faint voxels too
        (lossy, as VolPack's threshold). Skipping is on with ``empty_space_skipping`` and for
        filters without negative lobes.
    planes_per_slice : int, default 1
        Sample planes per slice spacing, from 1 to :data:`MAX_PLANES_PER_SLICE`: 1
        composites the slices themselves; ``m`` adds ``m - 1`` planes between each two
        slices, each interpolated linearly between them (the tent filter across slices,
        whatever the filter in them: with the trilinear filter the samples of its field
        exactly), each a segment of ``1/m`` of the path between slices. The error along
        rays falls as with a ray caster's step of ``1/m`` of the slice spacing, the cost
        grows about ``m`` times; the warp's bilinear interpolation of the intermediate image
        stays as it is.
    segment_ends : {"lattice", "exact"}, default "lattice"
        Where a ray enters or leaves the volume through a side face (one that does not lie
        in a slice's plane), ``"lattice"`` lets each plane inside stand for its whole
        segment, and one outside for none: an error of first order in the planes' spacing
        wherever the field is not zero at those faces. ``"exact"`` counts only the part of
        each segment inside the volume, sampled at its middle (the two slices about it
        interpolated linearly), as the ray caster's ``segment_ends="exact"`` does: second
        order. The end slices reach half a segment into the volume either way.

    Examples
    --------
    >>> import data_gen, vrlib
    >>> vol = data_gen.make_field("marschner-lobb").sample(17)
    >>> view = vrlib.View.orbit(size=24, azimuth=30, elevation=20)
    >>> exact = vrlib.render_reference(vrlib.ReconstructedField(vol), view,
    ...                                transfer=vrlib.Glow(1.0))  # the trilinear field's
    >>> [round(vrlib.metrics.rmse(vrlib.render(vol, view, method="shearwarp",
    ...                                        planes_per_slice=m), exact), 4) for m in (1, 4)]
    [0.0125, 0.0075]
    """
    min_opacity = validate.finite_number("min_opacity", min_opacity, low=0.0, high=1.0,
                                          high_open=True)
    exact = validate.choice("segment_ends", segment_ends, SEGMENT_ENDS) == "exact"
    planes = validate.positive_int("planes_per_slice", planes_per_slice)
    if planes > MAX_PLANES_PER_SLICE:
        raise ValueError(f"planes_per_slice must be an integer from 1 to "
                         f"{MAX_PLANES_PER_SLICE}, got {planes}")
    ntaps = filt.taps
    start = time.perf_counter()
    axis, ascending = principal_axis(view, volume)
    tally = Tally()
    # Prefiltered filters: coefficients in the slices' two axes (slices are not resampled
    # across, so their own samples are composited).
    in_slice = [a for a in range(3) if a != axis]
    samples, volume = volume, prepared(volume, filt, tally, axes=in_slice)
    q_axis, p_axis = [a for a in range(3) if a != axis]
    slices = volume.slices(axis)  # [k, j, i]: j along p_axis, i along q_axis
    n_k = slices.shape[0]
    h = volume.spacing
    order, other, between = sample_planes(n_k, ascending, planes)
    positions = order + between * (other - order)
    scale, di, dj, (oi, oj), (height, width), kf, rays = intermediate_plane(
        volume, view, axis, ascending, positions)

    def segment(direction):  # world distance between slices along rays of these directions
        world = direction * h[[q_axis, p_axis, axis]]
        return np.linalg.norm(world, axis=-1) / np.abs(direction[..., 2])

    centre = np.array([0.5 * (volume.shape[::-1][q_axis] - 1),
                       0.5 * (volume.shape[::-1][p_axis] - 1)])
    length = float(segment(rays(centre[None])[0]))
    if not view.is_perspective:
        fraction = np.ones((1, 1))
        directions = view.forward.reshape(1, 1, 3)
    else:
        grid = np.stack(np.meshgrid(np.arange(width) - oi, np.arange(height) - oj), -1)
        fraction = segment(rays(grid)) / length
        # Each intermediate pixel's ray, in world units (x, y, z), for shading.
        directions = np.empty((height, width, 3)) if transfer.shading is not None else \
            view.forward.reshape(1, 1, 3)
        if transfer.shading is not None:
            for column, a in enumerate((q_axis, p_axis, axis)):
                directions[..., a] = rays(grid)[..., column] * h[a]
            directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
    low, high = reconstructed_range(volume, filt)
    tables = transfer.segment_table(length / planes, low, high)
    bound = -math.inf
    if empty_space_skipping and lattice_sums(filt)[2] <= 1.0 + 1e-6:
        bound = transparent_bound(transfer, low, high, length, min_opacity)
    first, last = transparent_runs(volume, axis, bound)
    inter = np.zeros((height, width, 4))
    counts = np.zeros(height, np.int64)
    grads = no_gradients(np.float32)
    if transfer.needs_gradient:  # the gradient's components in slice order, like ``slices``
        grads = prepared_gradients(samples, filt, tally, in_slice).transpose(
            {2: (0, 1, 2, 3), 1: (0, 2, 1, 3), 0: (0, 3, 1, 2)}[axis])
    lattice = np.rint(positions * planes).astype(np.int64)  # each plane's, from slice 0
    full_first = full_last = np.zeros((1, 1), np.int64)  # lattice ends: every plane
    if exact:
        ends = np.array(intermediate_plane(volume, view, axis, ascending,
                                           np.array([0.0, n_k - 1.0]))[:3])
        inside = ray_stretches(ends, (height, width), slices.shape)
        full_first, full_last = whole_planes(inside, n_k, planes)
    lighting = kernel_lighting(transfer, view.forward)
    directions = readonly(np.ascontiguousarray(directions, np.float64))
    _kernel.shear_slices(slices, order, other, between, scale, di, dj, fraction, *filt.code,
                         filt.radius, ntaps, *tables, grads, *lighting, directions,
                         early_termination, readonly(first), readonly(last), inter, counts,
                         lattice, full_first, full_last)
    if exact:
        _kernel.shear_cut_ends(slices, planes, ascending, ends, fraction, *filt.code,
                               filt.radius, ntaps, *tables, grads, *lighting, directions,
                               inside, full_first, full_last, inter, counts)
    # The warp: where each pixel's ray meets the front slice, in intermediate coordinates.
    plane = volume.origin[axis] + kf * h[axis]
    out = np.empty(view.shape + (4,))
    grey = bool(np.all(tables[4] == 1.0))  # white emission: red, green and blue are equal
    warp(inter, warp_homography(view, volume, axis, plane, (oi, oj)), out, grey)
    resampled = int(counts.sum())
    # A plane between two slices resamples both (the others' share of the planes: 1 / m).
    sums = 2.0 - 1.0 / planes
    stats = RenderStats(samples=resampled, operations=int(resampled * (2 * ntaps**2 * sums + 12))
                        + out.size * 8, bytes=int(volume.data.nbytes + inter.nbytes + out.nbytes),
                        seconds=time.perf_counter() - start, voxels=resampled)
    return Image(out, tally.finish(stats, filt), checked=False)  # the warp clipped it


def project_shearwarp(volume, view, *, filt, transfer, blend):
    """Shear-warp's maximum- (``blend="maximum"``) or average-intensity projection
    (arguments checked by :func:`vrlib.render`): each intermediate pixel takes the largest, or
    the mean, of the values it samples in the sheared slices (the classic fast MIP: one
    resampling per slice, no ray set-up), classified as the ray caster's projections
    (:func:`vrlib.projection.classify_projected`), and the classified intermediate image is
    warped. No run is skipped.

    Examples
    --------
    >>> import data_gen, vrlib
    >>> vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(17)
    >>> gray = vrlib.colormap("gray", [(0, 1), (1, 1)], clim=(0, 1))
    >>> view = vrlib.View.orbit(size=9)
    >>> img = vrlib.render(vol, view, method="shearwarp", transfer=gray, blend="maximum")
    >>> bool(img.rgba[4, 4, 0] > 0.98)  # near the peak
    True
    """
    start = time.perf_counter()
    axis, ascending = principal_axis(view, volume)
    tally = Tally()
    in_slice = [a for a in range(3) if a != axis]
    volume = prepared(volume, filt, tally, axes=in_slice)
    scale, di, dj, (oi, oj), (height, width), kf, _ = intermediate_plane(
        volume, view, axis, ascending)
    n_k = volume.shape[::-1][axis]
    order = np.arange(n_k) if ascending else np.arange(n_k)[::-1].copy()
    value = np.zeros((height, width))
    count = np.zeros((height, width), np.int64)
    _kernel.project_slices(volume.slices(axis), order, scale, di, dj, *filt.code, filt.radius,
                           filt.taps, blend == "maximum", value, count)
    if blend == "average":
        value = value / np.maximum(count, 1)
    inter = classify_projected(transfer, value, count > 0, volume.spacing)
    out = np.empty(view.shape + (4,))
    plane = volume.origin[axis] + kf * volume.spacing[axis]
    warp(inter, warp_homography(view, volume, axis, plane, (oi, oj)), out)
    taken = int(count.sum())
    stats = RenderStats(samples=taken, operations=taken * (2 * filt.taps**2 + 4) + out.size * 8,
                        bytes=int(volume.data.nbytes + inter.nbytes + out.nbytes),
                        seconds=time.perf_counter() - start, voxels=taken)
    return Image(out, tally.finish(stats, filt), checked=False)  # the warp clipped it
