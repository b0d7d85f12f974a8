"""Naive NumPy twins of the numba kernels: slow, obvious, for small sizes.

Each twin follows the definition directly (per ray, per sample, per tap) so that a kernel's
optimisations (unrolled filters, skipping, tiling, threads) can be checked against it.
"""

import math

import numpy as np

import vrlib
from vrlib.reference import _clip_to_box


def random_orbits(count, *, seed, size):
    """``count`` orthographic views from random directions (reproducible)."""
    from vrlib import View

    rng = np.random.default_rng(seed)
    return [View.orbit(azimuth=a, elevation=e, size=size)
            for a, e in zip(rng.uniform(-180, 180, count), rng.uniform(-90, 90, count),
                            strict=True)]


def image_mass(image, view):
    """The rendering model (docs/model.md): sum over pixels of -ln(1 - alpha) times the pixel's
    area, which equals k times the integral of the field for a Glow(k) image that sees the
    whole volume."""
    return float(-np.log1p(-image.alpha).sum() * view.pixel_size**2)


def exact_blob_image(field, view, scale):
    """Closed-form Glow image of an analytic field with exact line integrals (docs/model.md):
    ``1 - exp(-k * line integral)``, each ray clipped to the field's box."""
    o, d = view.rays()
    t0, t1 = _clip_to_box(o, d, field.bounds[:, 0], field.bounds[:, 1])
    return 1.0 - np.exp(-scale * field.line_integral(o, d, t0, t1))


def interpolation_matrix(filt, n):
    """The n x n matrix taking a line's coefficients to its samples, ``f_m = sum_k c_k
    k(m - k)``, the coefficients extended half-sample symmetrically (``c_{-1-j} = c_j``): the
    prefilter's boundary rule written out as a linear system."""
    a = np.zeros((n, n))
    for m in range(n):
        for k in range(m - math.ceil(filt.radius), m + math.ceil(filt.radius) + 1):
            j = k
            while not 0 <= j < n:  # reflect until inside (short lines reflect twice)
                j = -1 - j if j < 0 else 2 * n - 1 - j
            a[m, j] += float(filt(float(m - k)))
    return a


def prefilter_naive(data, filt, axes):
    """Coefficients of ``data`` along array ``axes`` by solving each line's interpolation
    system (:func:`interpolation_matrix`); the data itself for filters without a prefilter."""
    data = np.asarray(data, dtype=np.float64)
    if not filt.prefiltered:
        return data
    for axis in axes:
        data = np.apply_along_axis(
            lambda f: np.linalg.solve(interpolation_matrix(filt, len(f)), f), axis, data)
    return data


def coefficient_volume_naive(volume, filt):
    """The volume a prefiltered filter's kernel reconstructs from: its 3-D coefficients."""
    if not filt.prefiltered:
        return volume
    return vrlib.Volume(prefilter_naive(volume.data, filt, (0, 1, 2)), volume.extent)


def reconstruct_naive(volume, filt, points_index, *, gradient=False):
    """Separable reconstruction at index positions ``(n, 3)`` (x, y, z), edge-clamped.

    With ``gradient`` also returns ``(n, 3)`` derivatives in index units (one axis's weights
    replaced by the kernel's derivative; for the box filter, whose derivative is zero,
    :func:`numpy.gradient` of the samples at the nearest sample).
    """
    data = np.asarray(volume.data, dtype=np.float64)
    nz, ny, nx = data.shape
    if gradient and filt.name == "box":
        sampled = [np.gradient(data, axis=a) if data.shape[a] > 1 else np.zeros_like(data)
                   for a in (2, 1, 0)]
        nearest = np.floor(np.asarray(points_index, dtype=np.float64) + 0.5).astype(int)
        nearest = np.clip(nearest, 0, [nx - 1, ny - 1, nz - 1])
        values = reconstruct_naive(volume, filt, points_index)
        ix, iy, iz = nearest.T
        return values, np.stack([g[iz, iy, ix] for g in sampled], axis=1)
    r = filt.radius
    out = np.zeros(len(points_index))
    grad = np.zeros((len(points_index), 3))
    for p, (ux, uy, uz) in enumerate(points_index):
        taps = []
        for u in (ux, uy, uz):
            first = math.floor(u - r) + 1
            idx = np.arange(first, first + max(1, math.ceil(2 * r)))
            taps.append((idx, filt(u - idx), filt.derivative(u - idx)))
        (ix, wx, dx), (iy, wy, dy), (iz, wz, dz) = taps
        iz, iy, ix = np.clip(iz, 0, nz - 1), np.clip(iy, 0, ny - 1), np.clip(ix, 0, nx - 1)
        cube = data[np.ix_(iz, iy, ix)]
        out[p] = np.einsum("k,j,i,kji->", wz, wy, wx, cube)
        grad[p] = [np.einsum("k,j,i,kji->", wz, wy, dx, cube),
                   np.einsum("k,j,i,kji->", wz, dy, wx, cube),
                   np.einsum("k,j,i,kji->", dz, wy, wx, cube)]
    return (out, grad) if gradient else out


def chord(o, d, lo, hi):
    """Where the ray ``o + t d`` (t >= 0) runs inside the box ``[lo, hi]``: ``(t_in, t_out)``,
    with ``t_out <= t_in`` when it misses."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (lo - o) / d, (hi - o) / d
    inside = d != 0
    if np.any(~inside & ((o < lo) | (o > hi))):
        return 0.0, 0.0
    return (max(0.0, np.max(np.minimum(ta, tb)[inside])),
            np.min(np.maximum(ta, tb)[inside]))


def raycast_naive(volume, view, filt, transfer, step, segment_ends="lattice", *,
                  multiplier=None, block=8):
    """Ray casting by the book: samples at t = (k + 1/2) ds inside the volume box, opacity
    1 - exp(-density ds) (eq 1.4), colour E alpha (eq 1.9), composited front to back.

    With ``segment_ends="exact"`` the ray's stretch inside the box is cut into the lattice's
    segments ``[k ds, (k + 1) ds)``, each sampled at its own middle with opacity
    ``1 - exp(-density length)``: the ends are the only cut segments.

    With ``multiplier`` (per block of ``block`` cells, a power of two), adaptive steps: the
    segments are merged into long ones (:func:`long_segments`)."""
    ds = step * float(volume.spacing.min())
    volume = coefficient_volume_naive(volume, filt)
    origins, directions = view.rays()
    lo, hi = volume.extent[:, 0], volume.extent[:, 1]
    image = np.zeros(view.shape + (4,))
    for r in range(view.height):
        for c in range(view.width):
            o, d = origins[r, c], directions[r, c]
            t_in, t_out = chord(o, d, lo, hi)
            if not t_out > t_in:
                continue
            if segment_ends == "exact":
                k = np.arange(math.floor(t_in / ds), math.ceil(t_out / ds))
                a, b = np.maximum(k * ds, t_in), np.minimum((k + 1) * ds, t_out)
                t, length = 0.5 * (a + b), b - a
            else:
                k = np.arange(math.ceil(t_in / ds - 0.5), math.ceil(t_out / ds - 0.5) + 1)
                t = (k + 0.5) * ds
                keep = (t >= t_in) & (t < t_out)
                k, t = k[keep], t[keep]
                length = np.full(t.shape, ds)
            if multiplier is not None:
                t, length = long_segments(volume, o, d, k, t, length, ds, multiplier, block,
                                          cut=segment_ends == "exact")
            length = length[:, None] if np.ndim(length) else length
            points = o + t[:, None] * d
            values, grad = reconstruct_naive(volume, filt, volume.world_to_index(points),
                                             gradient=True)
            alpha = -np.expm1(-transfer.opacity_density(values) * np.ravel(length))
            emit = transfer.emission(values)
            if transfer.shading is not None:
                world_grad = grad / volume.spacing
                emit = (emit * transfer.shading.factor(world_grad, -d)[:, None]
                        + transfer.shading.highlight(world_grad, -d)[:, None])
            rgba = np.concatenate([emit * alpha[:, None], alpha[:, None]], axis=1)
            acc = np.zeros(4)
            for segment in rgba:  # eqs 1.7-1.8
                acc = acc + (1.0 - acc[3]) * segment
            image[r, c] = acc
    return image


def long_segments(volume, o, d, k, t, length, ds, multiplier, block, *, cut):
    """Adaptive steps by the book: walking the ray's segments ``k`` (samples ``t``, lengths
    ``length``) front to back, segment ``k`` starts a long one of ``m`` segments when ``m``
    (a power of two, at most the multiplier of the block of ``block`` cells that holds
    sample ``k``) divides ``k`` and the long segment lies inside that block's stretch of the
    ray, holding no cut segment (``cut``: the first and last are). Returns the samples and
    lengths after merging: a long segment sampled at its middle, ``m ds`` long."""
    a = volume.world_to_index(o[None])[0]
    b = d / volume.spacing
    counts = np.array(multiplier.shape[::-1])  # x y z
    first_cut, last_cut = (k[0], k[-1]) if cut else (-1, -1)
    out_t, out_len = [], []
    i = 0
    while i < len(k):
        u = a + t[i] * b
        cell = np.clip(np.floor(np.floor(u) / block).astype(int), 0, counts - 1)
        with np.errstate(divide="ignore"):
            ends = (np.stack([cell, cell + 1]) * block - a) / b
        moving = b != 0
        enter = np.max(np.min(ends, axis=0)[moving])
        leave = np.min(np.max(ends, axis=0)[moving])
        m = int(multiplier[cell[2], cell[1], cell[0]])
        while m > 1:
            k0 = k[i] - k[i] % m
            if (k0 == k[i] and k0 * ds >= enter and (k0 + m) * ds <= leave
                    and k0 > first_cut and (last_cut < 0 or k0 + m <= last_cut)):
                break
            m //= 2
        if m > 1:
            out_t.append((k[i] + 0.5 * m) * ds)
            out_len.append(m * ds)
            i += m
        else:
            out_t.append(t[i])
            out_len.append(length[i] if np.ndim(length) else length)
            i += 1
    return np.array(out_t), np.array(out_len)


def preintegrated_segment(transfer, front, back, length, *, profile="linear", pieces=400):
    """One segment's opacity and premultiplied colour by brute force: the field runs from
    ``front`` to ``back`` (linearly, or as a step at the middle), cut into ``pieces`` equal
    parts each classified at its middle and composited front to back (eq 1.4, 1.7-1.8)."""
    u = (np.arange(pieces) + 0.5) / pieces
    values = front + (back - front) * u if profile == "linear" else np.where(u < 0.5, front,
                                                                             back)
    alpha = -np.expm1(-transfer.opacity_density(values) * length / pieces)
    seen = np.concatenate([[1.0], np.cumprod(1.0 - alpha)[:-1]])
    return 1.0 - np.prod(1.0 - alpha), (seen * alpha) @ transfer.emission(values)


def raycast_preintegrated_naive(volume, view, filt, transfer, step):
    """Pre-integrated ray casting by the book: every ray's stretch inside the box cut into
    the lattice's segments ``[k ds, (k + 1) ds)``, each classified by brute-force integration
    of the transfer function between the values at its two ends
    (:func:`preintegrated_segment`), its gradient opacity and shading from the gradient at
    its middle, composited front to back."""
    ds = step * float(volume.spacing.min())
    profile = "step" if filt.radius <= 0.5 else "linear"
    volume = coefficient_volume_naive(volume, filt)
    origins, directions = view.rays()
    lo, hi = volume.extent[:, 0], volume.extent[:, 1]
    image = np.zeros(view.shape + (4,))
    for r in range(view.height):
        for c in range(view.width):
            o, d = origins[r, c], directions[r, c]
            t_in, t_out = chord(o, d, lo, hi)
            if not t_out > t_in:
                continue
            k = np.arange(math.floor(t_in / ds), math.ceil(t_out / ds))
            a, b = np.maximum(k * ds, t_in), np.minimum((k + 1) * ds, t_out)
            ends = reconstruct_naive(volume, filt, volume.world_to_index(
                o + np.concatenate([a, b[-1:]])[:, None] * d))
            middle = o + 0.5 * (a + b)[:, None] * d
            _, grad = reconstruct_naive(volume, filt, volume.world_to_index(middle),
                                        gradient=True)
            world_grad = grad / volume.spacing
            acc = np.zeros(4)
            for i in range(len(k)):  # eqs 1.7-1.8
                alpha, colour = preintegrated_segment(transfer, ends[i], ends[i + 1],
                                                      b[i] - a[i], profile=profile)
                ramp = transfer.gradient_opacity
                if ramp is not None and alpha > 0.0:
                    factor = ramp.factor(np.linalg.norm(world_grad[i]))
                    scaled = -np.expm1(factor * np.log1p(-alpha))
                    colour, alpha = colour * scaled / alpha, scaled
                if transfer.shading is not None:
                    colour = (colour * transfer.shading.factor(world_grad[i:i + 1], -d)[0]
                              + transfer.shading.highlight(world_grad[i:i + 1], -d)[0] * alpha)
                acc = acc + (1.0 - acc[3]) * np.append(colour, alpha)
            image[r, c] = acc
    return image


def classified_voxel(volume, view, transfer, data, ix, iy, iz, dens, colour):
    """One voxel classified by its own gradient (central differences, one-sided on the faces)
    and shaded as seen from the eye: pre-shaded splatting by the book."""
    grad = []
    for axis, i in enumerate((ix, iy, iz)):
        n, h = data.shape[2 - axis], volume.spacing[axis]
        lo, hi = max(i - 1, 0), min(i + 1, n - 1)
        pick = [iz, iy, ix]
        pick[2 - axis] = hi
        f_hi = data[tuple(pick)]
        pick[2 - axis] = lo
        grad.append((f_hi - data[tuple(pick)]) / ((hi - lo) * h))
    grad = np.array(grad)
    if transfer.gradient_opacity is not None:
        dens *= float(transfer.gradient_opacity.factor(np.linalg.norm(grad)))
    shading = transfer.shading
    if shading is not None:
        centre = volume.index_to_world([ix, iy, iz])
        to_eye = view.eye - centre if view.is_perspective else -view.forward
        colour = colour * shading.factor(grad, to_eye) + shading.highlight(grad, to_eye)
    return dens, colour


def slanted_footprint(slant, filt, spacing, axis, origins, directions, centre, lo, hi):
    """Perspective footprints of a separable kernel, ray by ray: each ray crosses the voxel's
    slice plane at in-plane offsets ``(bp, bq)`` and moves ``(mp, mq)`` per unit along the
    axis; the whole line integral from the slanted table, a stretch ``[lo, hi]`` of the ray by
    exact quadrature between the kernel's knots (both in index units, times
    ``h_a / |d_a|``)."""
    from vrlib._kernels.footprint import slanted_integral

    p, q = [a for a in range(3) if a != axis]
    d_a = directions[..., axis]
    cross = (centre[axis] - origins[..., axis]) / d_a
    bp = (origins[..., p] + cross * directions[..., p] - centre[p]) / spacing[p]
    bq = (origins[..., q] + cross * directions[..., q] - centre[q]) / spacing[q]
    unit = d_a / spacing[axis]
    mp, mq = directions[..., p] / spacing[p] / unit, directions[..., q] / spacing[q] / unit
    scale = spacing[axis] / np.abs(d_a)
    whole = scale * slant(bp, bq, mp, mq)
    lo, hi = np.broadcast_to(lo, whole.shape), np.broadcast_to(hi, whole.shape)
    with np.errstate(invalid="ignore"):
        ends = np.sort(np.stack([(lo - cross) * unit, (hi - cross) * unit]), axis=0)
    nodes, weights = np.polynomial.legendre.leggauss(5)
    out = np.empty(whole.shape)
    for index in np.ndindex(whole.shape):
        if not hi[index] > lo[index]:
            out[index] = 0.0
        elif ends[0][index] <= -filt.radius and ends[1][index] >= filt.radius:
            out[index] = whole[index]
        else:
            out[index] = scale[index] * slanted_integral(
                *filt.code, float(filt.radius), bp[index], bq[index], mp[index], mq[index],
                nodes, weights, ends[0][index], ends[1][index], np.empty(64))
    return out


def splat_naive(volume, view, filt, transfer, mode, slab_width=1.0):
    """Splatting by the book: every voxel, every pixel, footprints from the same tables.

    The lattice is extended by ``ceil(r) - 1`` copies of its border samples beyond each face;
    a voxel within the radius ``r`` of a face has its line integral clipped to each ray's
    stretch inside the box. ``"sheet"``: slices along the major axis front to back, a slice's
    ``f_i FP`` summed per pixel and classified as one segment over the slice's share of the
    ray (``int k`` over the in-box stretch; shares under a quarter of a slab held for the next
    slice). ``"image-aligned"``: slabs of camera depth, each voxel adding its line integral's
    part inside the slab and the box, classified over the slab's in-box stretch.
    ``"direct"``: each voxel composited at once, ``1 - exp(-density(f_i) FP)``, colour
    ``E(f_i)``. A sheet mode with a transfer function that needs gradients sums each voxel's
    central-difference gradient (prefiltered as the values are) with the same footprints,
    and classifies each segment by its mean gradient too, seen along the pixel's ray.
    """
    from vrlib.footprint import footprint, running_integral, slanted
    from vrlib.view import principal_axis

    lighting = transfer.needs_gradient and mode != "direct"
    if lighting:
        field = np.asarray(volume.data, float)
        hx, hy, hz = volume.spacing
        # (held in float32, as vrlib.gradients stores them, before and after prefiltering)
        grads = [prefilter_naive(g.astype(np.float32).astype(float), filt,
                                 (0, 1, 2)).astype(np.float32).astype(float) for g in (
            np.gradient(field, hx, axis=2), np.gradient(field, hy, axis=1),
            np.gradient(field, hz, axis=0))]
    volume = coefficient_volume_naive(volume, filt)
    axis, ascending = principal_axis(view, volume)
    spacing = volume.spacing
    radial = filt.name == "gaussian" and np.ptp(spacing) == 0.0
    fp = footprint(filt, spacing, None if radial else view.basis)
    cumulative = running_integral(filt)
    slant = None
    if view.is_perspective and not radial:
        corners = np.array(np.meshgrid(*volume.extent, indexing="ij")).reshape(3, -1).T
        steps = (corners - view.eye) / spacing
        slant = slanted(filt, min(float(np.abs(np.delete(steps, axis, axis=1)
                                               / steps[:, axis:axis + 1]).max()), 4.0))
    ghost = max(math.ceil(filt.radius) - 1, 0)
    origins, directions = view.rays()
    t_in, t_out = _clip_to_box(origins, directions, volume.extent[:, 0], volume.extent[:, 1])
    image = np.zeros(view.shape + (4,))
    data = np.asarray(volume.data, dtype=np.float64)
    counts = np.array(volume.shape[::-1])
    p_axis, q_axis = [a for a in range(3) if a != axis]

    def voxels(s):
        """Slice ``s`` (ghosts included) in the kernel's order: in-plane p outer, q inner."""
        for p in range(-ghost, counts[p_axis] + ghost):
            for q in range(-ghost, counts[q_axis] + ghost):
                ijk = [0, 0, 0]
                ijk[axis], ijk[p_axis], ijk[q_axis] = s, p, q
                yield ijk

    def value_at(ijk):
        i, j, k = (min(max(ijk[a], 0), counts[a] - 1) for a in range(3))
        return data[k, j, i]

    def gradient_at(ijk):
        i, j, k = (min(max(ijk[a], 0), counts[a] - 1) for a in range(3))
        return np.array([g[k, j, i] for g in grads])

    def footprint_of(ijk, lo, hi):
        """The voxel's line integral on every ray between ray parameters ``lo`` and ``hi``
        (a rim voxel's clipped to the box)."""
        centre = volume.index_to_world(ijk)
        w = centre - origins  # (h, w, 3)
        t = np.einsum("hwc,hwc->hw", w, directions)
        offset = t[..., None] * directions - w  # ray point minus voxel, across the ray
        rim = any(ijk[a] < filt.radius or ijk[a] > counts[a] - 1 - filt.radius
                  for a in range(3))
        if rim:
            lo, hi = np.maximum(lo, t_in), np.minimum(hi, t_out)
        if slant is None:
            return fp.between(offset @ view.right, offset @ view.up, lo - t, hi - t,
                              rho2=np.einsum("hwc,hwc->hw", offset, offset))
        return slanted_footprint(slant, filt, spacing, axis, origins, directions, centre, lo,
                                 hi)

    def composite(value, length, where):
        density = transfer.opacity_density(value)
        colour = transfer.emission(value)
        if lighting:
            with np.errstate(divide="ignore", invalid="ignore"):
                grad = gsheet / np.where(where, length, 1.0)[..., None]
            if transfer.gradient_opacity is not None:
                density = density * transfer.gradient_opacity.factor(
                    np.linalg.norm(grad, axis=-1))
            if transfer.shading is not None:
                colour = (colour * transfer.shading.factor(grad, -directions)[..., None]
                          + transfer.shading.highlight(grad, -directions)[..., None])
        alpha = -np.expm1(-density * length)
        segment = np.concatenate([colour * alpha[..., None], alpha[..., None]], -1)
        return np.where(where[..., None], image + (1.0 - image[..., 3:4]) * segment, image)

    order = range(-ghost, counts[axis] + ghost)
    order = order if ascending else order[::-1]
    # A pixel a nonzero voxel drew on is "touched"; only touched pixels are classified, and
    # one stays touched while its sheet is held.
    sheet, touched = np.zeros(view.shape), np.zeros(view.shape, bool)
    gsheet = np.zeros(view.shape + (3,))
    if mode == "image-aligned":
        corners = np.array(np.meshgrid(*volume.extent, indexing="ij")).reshape(3, -1).T
        depths = view.to_camera(corners)[:, 2]
        width = slab_width * spacing.min()
        cosine = directions @ view.forward
        held_length = np.zeros(view.shape)
        for m in range(max(1, math.ceil((depths.max() - depths.min()) / width))):
            z_lo = depths.min() + m * width
            lo = np.maximum(z_lo / cosine, t_in)
            hi = np.minimum((z_lo + width) / cosine, t_out)
            for s in order:
                for ijk in voxels(s):
                    f = value_at(ijk)
                    weight = footprint_of(ijk, lo, hi)
                    sheet += f * weight
                    if lighting:
                        gsheet += gradient_at(ijk) * weight[..., None]
                    touched |= (f != 0.0) & (weight != 0.0)
            held_length += np.where(touched & (hi - lo > 0), hi - lo, 0.0)
            # A stretch under a quarter of the slab is held until the ray leaves the box.
            ready = touched & (held_length > 0) & (
                (held_length >= 0.25 * width / cosine) | ((z_lo + width) / cosine >= t_out))
            value = np.where(ready, sheet / np.where(ready, held_length, 1.0), 0.0)
            image = composite(value, held_length, ready)
            sheet, touched = np.where(ready, 0.0, sheet), touched & ~ready
            gsheet = np.where(ready[..., None], 0.0, gsheet)
            held_length = np.where(ready, 0.0, held_length)
    else:
        slab = spacing[axis] / np.abs(directions[..., axis])
        held_length, last_length = np.zeros(view.shape), np.zeros(view.shape)
        grid = np.linspace(-filt.radius, filt.radius, len(cumulative))
        for number, s in enumerate(order):
            for ijk in voxels(s):
                f = value_at(ijk)
                weight = footprint_of(ijk, -np.inf, np.inf)
                if mode == "sheet":
                    sheet += f * weight
                    if lighting:
                        gsheet += gradient_at(ijk) * weight[..., None]
                    touched |= (f != 0.0) & (weight != 0.0)
                    continue
                dens = float(transfer.opacity_density(np.array([f]))[0])
                colour = transfer.emission(np.array([f]))[0]
                if transfer.needs_gradient:
                    i, j, k = (min(max(ijk[a], 0), counts[a] - 1) for a in range(3))
                    dens, colour = classified_voxel(volume, view, transfer, data, i, j, k,
                                                    dens, colour)
                alpha = -np.expm1(-dens * weight)
                segment = np.concatenate([alpha[..., None] * colour, alpha[..., None]], -1)
                image = image + (1.0 - image[..., 3:4]) * segment
            if mode != "sheet":
                continue
            # The slice's share of each ray: int k((x_a(t) - x_s) / h) dt over the box.
            centre = volume.index_to_world([s] * 3)[axis]
            ends = [np.interp((origins[..., axis] + t * directions[..., axis] - centre)
                              / spacing[axis], grid, cumulative) for t in (t_in, t_out)]
            share = spacing[axis] / directions[..., axis] * (ends[1] - ends[0])
            held_length += np.where(touched & (t_out > t_in), share, 0.0)
            length = held_length.copy()
            ready = touched & (length >= 0.25 * slab)
            if number == len(order) - 1:  # what is still held goes after the last sheet
                rest = touched & ~ready
                small = rest & ~(np.abs(length) > 1e-6 * slab)
                length = np.where(small, np.where(last_length > 0, last_length,
                                                  t_out - t_in), length)
                ready |= (rest & ~small) | (small & (length > 0))
            value = np.where(ready, sheet / np.where(ready, length, 1.0), 0.0)
            image = composite(value, length, ready)
            sheet, touched = np.where(ready, 0.0, sheet), touched & ~ready
            gsheet = np.where(ready[..., None], 0.0, gsheet)
            held_length = np.where(ready, 0.0, held_length)
            last_length = np.where(ready, length, last_length)
    image = np.maximum(image, 0.0)  # negative lobes: clamped to transparent black
    image[..., 3] = np.minimum(image[..., 3], 1.0)
    return image


def shear_pass_naive(src, valid, out_shape, c0, c1, c2, offset, filt):
    """One 1-D resampling pass by the book: ``out[s, r, q] = sum_a k(pos - n_a) src[s, r, n_a]``
    at ``pos = (q - offset - c1 r - c2 s) / c0``. Each source line holds data where ``valid``
    (what the earlier pass computed): taps are clamped to that run and outputs whose source lies
    beyond it (and the filter's reach) stay zero. Returns the output and its validity."""
    out = np.zeros(out_shape)
    computed = np.zeros(out_shape, dtype=bool)
    taps = max(1, math.ceil(2 * filt.radius))
    for s in range(out_shape[0]):
        for r in range(out_shape[1]):
            where = np.flatnonzero(valid[s, r])
            if where.size == 0:
                continue
            lo, hi = where[0], where[-1]
            line = src[s, r].copy()
            line[lo:hi + 1] = prefilter_naive(line[lo:hi + 1], filt, (0,))
            for q in range(out_shape[2]):
                pos = (q - offset - c1 * r - c2 * s) / c0
                if not lo - filt.radius <= pos <= hi + filt.radius:
                    continue
                idx = math.floor(pos - filt.radius) + 1 + np.arange(taps)
                out[s, r, q] = np.sum(filt(pos - idx) * line[np.clip(idx, lo, hi)])
                computed[s, r, q] = True
    return out, computed


def line_at_naive(line, valid, pos, filt):
    """One line of a pass resampled at ``pos`` by the book (:func:`shear_pass_naive`'s sum for
    one output): 0 where the line holds no data within the filter's reach."""
    where = np.flatnonzero(valid)
    if where.size == 0:
        return 0.0
    lo, hi = where[0], where[-1]
    if not lo - filt.radius <= pos <= hi + filt.radius:
        return 0.0
    line = line.copy()
    line[lo:hi + 1] = prefilter_naive(line[lo:hi + 1], filt, (0,))
    taps = max(1, math.ceil(2 * filt.radius))
    idx = math.floor(pos - filt.radius) + 1 + np.arange(taps)
    return float(np.sum(filt(pos - idx) * line[np.clip(idx, lo, hi)]))


def shear_naive(volume, view, filt, transfer, step, passes, segment_ends="lattice"):
    """Three- (``passes=3``) or two-pass shear rendering with the kernels' plan, by the book:
    the passes above, then each pixel's samples composited in depth order, a sample counting
    only where it maps back inside the volume. With ``segment_ends="exact"`` (three passes)
    each depth sample ``z`` stands for ``[z - 1/2, z + 1/2]`` cut to the ray's stretch inside
    the volume, and a segment so cut is sampled at the middle of its part inside (pass 3's
    line resampled there), in order."""
    from vrlib.shear import plan_shear

    ds = step * float(volume.spacing.min())
    plan = plan_shear(volume, view, ds)
    u, v, w = plan.order
    h, wd = view.shape
    field = np.asarray(volume.data, float)
    channels = [field]
    if transfer.needs_gradient:  # the samples' central differences, world units, x y z
        hx, hy, hz = volume.spacing
        channels += [np.gradient(field, hx, axis=2), np.gradient(field, hy, axis=1),
                     np.gradient(field, hz, axis=0)]

    def resampled(channel):
        data = np.transpose(channel, (2 - w, 2 - v, 2 - u))
        nw, nv, nu = data.shape
        v1, ok1 = shear_pass_naive(data, np.ones(data.shape, bool), (nw, nv, wd), plan.a,
                                   plan.b, plan.c, plan.t0, filt)
        v2, ok2 = shear_pass_naive(v1.transpose(0, 2, 1), ok1.transpose(0, 2, 1), (nw, wd, h),
                                   plan.e, plan.d, plan.f, plan.t1, filt)
        v2, ok2 = v2.transpose(0, 2, 1), ok2.transpose(0, 2, 1)
        lines.append((v2.transpose(1, 2, 0), ok2.transpose(1, 2, 0)))  # [Y, X, w]
        if passes == 2:
            return v2
        v3, _ = shear_pass_naive(v2.transpose(1, 2, 0), ok2.transpose(1, 2, 0),
                                 (h, wd, plan.depth_samples), plan.i, plan.g, plan.h, plan.t2,
                                 filt)
        return v3.transpose(2, 0, 1)

    lines = []
    volumes = [resampled(channel) for channel in channels]
    if segment_ends == "exact" and passes == 3:
        return _shear3_exact_naive(view, transfer, filt, plan, channels, lines, volumes, ds)
    if segment_ends == "exact":
        return _shear2_exact_naive(view, transfer, plan, channels, volumes, ds)
    nw, nv, nu = np.transpose(field, (2 - w, 2 - v, 2 - u)).shape
    image = np.zeros(view.shape + (4,))
    limits = np.array([nu, nv, nw]) - 1.0
    if passes == 3:
        inverse = np.linalg.inv(plan.matrix)
        order = range(volumes[0].shape[0])
        length = ds
    else:
        order = range(nw) if plan.i > 0 else range(nw - 1, -1, -1)
        length = abs(plan.i) * ds  # half that for the end slices (below)
    samples = [(z, volumes[0][z], np.stack([g[z] for g in volumes[1:]], -1)
                if len(volumes) > 1 else None) for z in order]
    rows, cols = np.mgrid[0:h, 0:wd]
    for z, layer, grad in samples:
        if passes == 3:
            pts = np.stack([cols - plan.shift[0], rows - plan.shift[1],
                            np.full(rows.shape, z - plan.shift[2])], -1) @ inverse.T
            inside = np.all((pts >= 0) & (pts <= limits), axis=-1)
        else:
            m = plan.matrix
            rhs = np.stack([cols - plan.shift[0] - z * m[0, 2],
                            rows - plan.shift[1] - z * m[1, 2]], -1)
            uv = rhs @ np.linalg.inv(m[:2, :2]).T
            inside = np.all((uv >= 0) & (uv <= limits[:2]), axis=-1)
        end = passes == 2 and z in (0, nw - 1)  # end slices reach half a spacing in
        density = transfer.opacity_density(layer)
        colour = transfer.emission(layer)
        if grad is not None:
            if transfer.gradient_opacity is not None:
                density = density * transfer.gradient_opacity.factor(
                    np.linalg.norm(grad, axis=-1))
            if transfer.shading is not None:
                colour = (colour * transfer.shading.factor(grad, -view.forward)[..., None]
                          + transfer.shading.highlight(grad, -view.forward)[..., None])
        alpha = -np.expm1(-density * length * (0.5 if end else 1.0))
        alpha = alpha * inside
        segment = np.concatenate([colour * alpha[..., None], alpha[..., None]], -1)
        image = image + (1.0 - image[..., 3:4]) * segment
    return np.clip(image, 0.0, 1.0)


def _over_naive(pixel, values, transfer, view, length):
    """``pixel`` (premultiplied RGBA) with a segment of ``length`` (world units) composited
    behind it, classified from ``values`` (the value, then the gradient's components if the
    transfer function needs them) as seen along the view's direction."""
    density = transfer.opacity_density(np.array([values[0]]))[0]
    colour = transfer.emission(np.array([values[0]]))[0]
    if len(values) > 1:
        grad = np.array(values[1:])
        if transfer.gradient_opacity is not None:
            density *= transfer.gradient_opacity.factor(np.linalg.norm(grad))
        if transfer.shading is not None:
            colour = (colour * transfer.shading.factor(grad, -view.forward)
                      + transfer.shading.highlight(grad, -view.forward))
    alpha = -np.expm1(-density * length)
    return pixel + (1.0 - pixel[3]) * np.r_[colour * alpha, alpha]


def _shear2_exact_naive(view, transfer, plan, channels, volumes, ds):
    """:func:`shear_naive`'s two passes with exact segment ends, pixel by pixel: slice ``w``
    stands for ``[w - 1/2, w + 1/2]`` cut to the slab and to the ray's stretch inside; a cut
    segment takes its own slice's sample where that lies in the stretch, else the next
    slice's inward, with the cut part's length."""
    u, v, w = plan.order
    nw, nv, nu = np.transpose(channels[0], (2 - w, 2 - v, 2 - u)).shape
    limits = np.array([nu, nv]) - 1.0
    m = plan.matrix
    inverse = np.linalg.inv(m[:2, :2])
    order = range(nw) if plan.i > 0 else range(nw - 1, -1, -1)
    length = abs(plan.i) * ds
    image = np.zeros(view.shape + (4,))
    for y in range(view.height):
        for x in range(view.width):
            start = inverse @ np.array([x - plan.shift[0], y - plan.shift[1]])
            slope = inverse @ -np.array([m[0, 2], m[1, 2]])
            w_lo, w_hi = 0.0, nw - 1.0
            for a in range(2):  # where 0 <= start + w slope <= limits
                if slope[a] == 0.0:
                    if not 0.0 <= start[a] <= limits[a]:
                        w_lo, w_hi = 1.0, 0.0
                    continue
                ends = sorted(((0.0 - start[a]) / slope[a], (limits[a] - start[a]) / slope[a]))
                w_lo, w_hi = max(w_lo, ends[0]), min(w_hi, ends[1])
            w_lo = 0.0 if w_lo <= 1e-9 else w_lo  # within rounding of an end slice: on it
            w_hi = nw - 1.0 if w_hi >= nw - 1 - 1e-9 else w_hi
            pixel = np.zeros(4)
            for k in order:
                lo, hi = max(k - 0.5, 0.0), min(k + 0.5, nw - 1.0)
                cut_lo, cut_hi = max(lo, w_lo), min(hi, w_hi)
                if not cut_hi > cut_lo:
                    continue
                share = (cut_hi - cut_lo)  # of a segment (the end slices' halves: 0.5)
                take = k
                if (cut_lo, cut_hi) != (lo, hi) and not w_lo <= k <= w_hi:
                    take = k + 1 if k < w_lo else k - 1  # the next slice inward
                    if not w_lo <= take <= w_hi:
                        continue
                pixel = _over_naive(pixel, [vol[take, y, x] for vol in volumes], transfer,
                                    view, length * share)
            image[y, x] = pixel
    return np.clip(image, 0.0, 1.0)


def _shear3_exact_naive(view, transfer, filt, plan, channels, lines, volumes, ds):
    """:func:`shear_naive`'s three passes with exact segment ends, pixel by pixel."""
    u, v, w = plan.order
    nw, nv, nu = np.transpose(channels[0], (2 - w, 2 - v, 2 - u)).shape
    limits = np.array([nu, nv, nw]) - 1.0
    inverse = np.linalg.inv(plan.matrix)
    depth = volumes[0].shape[0]
    image = np.zeros(view.shape + (4,))
    for y in range(view.height):
        for x in range(view.width):
            start = inverse @ (np.array([x, y, 0.0]) - plan.shift)
            z_in, z_out = -np.inf, np.inf
            for a in range(3):  # where 0 <= start + z inverse[:, 2] <= limits
                slope = inverse[a, 2]
                if slope == 0.0:
                    if not 0.0 <= start[a] <= limits[a]:
                        z_in, z_out = 1.0, 0.0
                    continue
                ends = sorted(((0.0 - start[a]) / slope, (limits[a] - start[a]) / slope))
                z_in, z_out = max(z_in, ends[0]), min(z_out, ends[1])
            pixel = np.zeros(4)
            for z in range(depth):
                lo, hi = max(z - 0.5, z_in), min(z + 0.5, z_out)
                if not hi > lo:
                    continue
                if (lo, hi) == (z - 0.5, z + 0.5):  # whole: the lattice sample
                    values = [vol[z, y, x] for vol in volumes]
                else:  # cut by a face: its part's middle, pass 3 resampled there
                    position = (0.5 * (lo + hi) - plan.t2 - plan.g * x - plan.h * y) / plan.i
                    values = [line_at_naive(data[y, x], ok[y, x], position, filt)
                              for data, ok in lines]
                pixel = _over_naive(pixel, values, transfer, view, ds * (hi - lo))
            image[y, x] = pixel
    return np.clip(image, 0.0, 1.0)


def warp_naive(inter, volume, view, axis, q_axis, p_axis, kf, low):
    """Shear-warp's 2-D warp by the book: ``inter`` (the intermediate image: columns along
    ``q_axis``, rows along ``p_axis``, its pixel (0, 0) at plane coordinates ``low``) sampled
    bilinearly where each pixel's ray meets the plane of slice ``kf``, transparent outside it,
    clipped to [0, 1]."""
    h = volume.spacing
    height, width = inter.shape[:2]
    origins, directions = view.rays()
    plane = volume.origin[axis] + kf * volume.spacing[axis]
    t = (plane - origins[..., axis]) / directions[..., axis]
    points = origins + t[..., None] * directions
    x = (points[..., q_axis] - volume.origin[q_axis]) / h[q_axis] - low[0]
    y = (points[..., p_axis] - volume.origin[p_axis]) / h[p_axis] - low[1]
    out = np.zeros(view.shape + (4,))
    inside = (x >= 0) & (y >= 0) & (x <= width - 1) & (y <= height - 1)
    i0 = np.clip(np.floor(x).astype(int), 0, width - 2)
    j0 = np.clip(np.floor(y).astype(int), 0, height - 2)
    tx, ty = (x - i0)[..., None], (y - j0)[..., None]
    sample = ((1 - ty) * ((1 - tx) * inter[j0, i0] + tx * inter[j0, i0 + 1])
              + ty * ((1 - tx) * inter[j0 + 1, i0] + tx * inter[j0 + 1, i0 + 1]))
    out[inside] = sample[inside]
    return np.clip(out, 0.0, 1.0)


def shearwarp_naive(volume, view, filt, transfer, blend=None, planes=1,
                    segment_ends="lattice"):
    """Shear-warp by the book: the intermediate image lies on the front slice's plane at its
    resolution; each of its pixels follows its ray (parallel, or from the eye) through every
    slice, resamples the slice where the ray meets it with the 2-D filter and composites front
    to back, each segment as long as the ray's path between slices (half on the end slices);
    then the intermediate image is sampled bilinearly where each pixel's ray meets the plane.
    With ``planes`` > 1 the ray also meets ``planes - 1`` planes evenly between each two
    slices, where it samples both slices (at the same in-slice point) and interpolates them
    linearly, each segment ``1 / planes`` of the path between slices. With
    ``segment_ends="exact"`` each plane's segment is cut to the stretch of the ray inside the
    volume (found from where the ray meets the first and last slice), and a segment so cut
    is sampled at the middle of its part inside, interpolated between the slices about it.
    With ``blend`` ("maximum" or "average") a pixel takes the largest or the mean of its
    values instead, classified with the transfer function's unit distance, before the warp."""
    from vrlib.view import principal_axis

    axis, ascending = principal_axis(view, volume)
    p_axis, q_axis = [a for a in range(3) if a != axis]
    axes = [q_axis, p_axis, axis]
    slices = np.transpose(np.asarray(volume.data, float),
                          (2 - axis, 2 - p_axis, 2 - q_axis))
    slices = prefilter_naive(slices, filt, (1, 2))  # in-slice coefficients
    n_k, n_j, n_i = slices.shape
    h = volume.spacing[axes]
    kf = 0 if ascending else n_k - 1
    gradients = None
    if transfer.needs_gradient:  # central differences (world units, x y z), in slice order
        field = np.asarray(volume.data, float)
        hx, hy, hz = volume.spacing
        gradients = [prefilter_naive(np.transpose(g, (2 - axis, 2 - p_axis, 2 - q_axis)), filt,
                                     (1, 2)) for g in (
            np.gradient(field, hx, axis=2), np.gradient(field, hy, axis=1),
            np.gradient(field, hz, axis=0))]
    eye = None if view.eye is None else (view.eye - volume.origin)[axes] / h

    def hit(point, k):  # where the ray through plane point (i, j) meets slice k
        d = (view.forward[axes] / h) if eye is None else np.r_[point, kf] - eye
        return point + d[:2] * (k - kf) / d[2], np.linalg.norm(d * h) / abs(d[2])

    def to_eye(point):  # unit vector from the samples of point's ray back to the eye (world)
        d = (view.forward[axes] / h) if eye is None else np.r_[point, kf] - eye
        world = np.empty(3)
        world[axes] = d * h
        return -world / np.linalg.norm(world)

    # Plane extent: the end slices' corners projected back onto the plane.
    ext = []
    for k in (0, n_k - 1):
        for c in [(0, 0), (n_i - 1, n_j - 1)]:
            c = np.array(c, float)
            if eye is None:
                d = view.forward[axes] / h
                ext.append(c - d[:2] * (k - kf) / d[2])
            else:
                ext.append(eye[:2] + (c - eye[:2]) * (kf - eye[2]) / (k - eye[2]))
    low, high = np.min(ext, axis=0), np.max(ext, axis=0)
    width, height = (np.ceil(high - low - 1e-9).astype(int) + 1)
    inter = np.zeros((height, width, 4))
    taps = max(1, math.ceil(2 * filt.radius))
    for big_j in range(height):
        for big_i in range(width):
            point = np.array([big_i, big_j], float) + low
            values = []
            positions = np.arange(0, n_k - 1 + 0.5 / planes, 1.0 / planes)
            k_lo, k_hi = 0.0, n_k - 1.0  # the ray's stretch inside, in slice coordinates
            (i_a, j_a), _ = hit(point, 0.0)
            (i_b, j_b), _ = hit(point, n_k - 1.0)
            for at_first, at_last, limit in ((i_a, i_b, n_i - 1), (j_a, j_b, n_j - 1)):
                if at_first == at_last:
                    if not 0 <= at_first <= limit:
                        k_lo, k_hi = 1.0, 0.0
                    continue
                a, b = sorted(((0 - at_first) / (at_last - at_first),
                               (limit - at_first) / (at_last - at_first)))
                k_lo, k_hi = max(k_lo, a * (n_k - 1)), min(k_hi, b * (n_k - 1))
            # Within rounding of an end slice: on it (its half segment sampled on it).
            k_lo = 0.0 if k_lo <= 1e-9 else k_lo
            k_hi = n_k - 1.0 if k_hi >= n_k - 1 - 1e-9 else k_hi
            for k in (positions if ascending else positions[::-1]):
                part = 0.5 if k in (0, n_k - 1) else 1.0  # end slices reach half as far
                if segment_ends == "exact":
                    lo = max(k - 0.5 / planes, 0.0)
                    hi = min(k + 0.5 / planes, n_k - 1.0)
                    cut_lo, cut_hi = max(lo, k_lo), min(hi, k_hi)
                    if not cut_hi > cut_lo:
                        continue
                    if (cut_lo, cut_hi) != (lo, hi):  # cut by a side face: its middle
                        k, part = 0.5 * (cut_lo + cut_hi), (cut_hi - cut_lo) * planes
                (i, j), length = hit(point, k)
                length /= planes
                if segment_ends == "exact":
                    i, j = min(max(i, 0.0), n_i - 1.0), min(max(j, 0.0), n_j - 1.0)
                if not (0 <= i <= n_i - 1 and 0 <= j <= n_j - 1):
                    continue
                jdx = math.floor(j - filt.radius) + 1 + np.arange(taps)
                idx = math.floor(i - filt.radius) + 1 + np.arange(taps)
                taps_at = np.ix_(np.clip(jdx, 0, n_j - 1), np.clip(idx, 0, n_i - 1))
                k0 = min(int(math.floor(k)), n_k - 2)
                k1, w = k0 + 1, k - k0  # the slices about the plane

                def across(stack, k0=k0, k1=k1, w=w, taps_at=taps_at, i=i, j=j, idx=idx,
                           jdx=jdx):  # the 2-D filter on both slices, linear between
                    return ((1 - w) * (filt(j - jdx) @ stack[k0][taps_at] @ filt(i - idx))
                            + w * (filt(j - jdx) @ stack[k1][taps_at] @ filt(i - idx)))

                value = across(slices)
                if blend is not None:
                    values.append(value)
                    continue
                density = transfer.opacity_density(np.array([value]))[0]
                colour = transfer.emission(np.array([value]))[0]
                if gradients is not None:
                    grad = np.array([across(g) for g in gradients])
                    if transfer.gradient_opacity is not None:
                        density *= transfer.gradient_opacity.factor(np.linalg.norm(grad))
                    if transfer.shading is not None:
                        back = to_eye(point)
                        colour = (colour * transfer.shading.factor(grad, back)
                                  + transfer.shading.highlight(grad, back))
                alpha = -np.expm1(-density * length * part)
                inter[big_j, big_i] += (1 - inter[big_j, big_i, 3]) * np.r_[colour * alpha,
                                                                              alpha]
            if blend is not None and values:
                value = np.array([max(values) if blend == "maximum" else np.mean(values)])
                unit = getattr(transfer, "unit_distance", volume.spacing.min())
                alpha = -np.expm1(-transfer.opacity_density(value)[0] * unit)
                inter[big_j, big_i] = np.r_[transfer.emission(value)[0] * alpha, alpha]
    return warp_naive(inter, volume, view, axis, q_axis, p_axis, kf, low)


def classified_naive(volume, transfer, view, *, early_termination=1.0, min_opacity=0.0):
    """Pre-classified shear-warp by the book (:func:`vrlib.classify`): every voxel gets its
    extinction, emission and shaded colour; each intermediate pixel follows its ray through
    every slice, mixes the four voxels around it bilinearly (zero outside the slice, colour
    weighted by extinction) and composites front to back (half a spacing on the end slices),
    until its opacity reaches ``early_termination``; then the plane is sampled bilinearly where
    each pixel's ray meets it. No runs, no skipping, no tables but the normal codes."""
    from vrlib.classified import NORMAL_BINS, decode_normals, encode_normals
    from vrlib.view import principal_axis

    data = np.asarray(volume.data, float)
    h3 = volume.spacing
    sigma = transfer.opacity_density(data)
    code = np.full(data.shape, NORMAL_BINS**2)
    if transfer.needs_gradient:
        grad = np.stack(np.gradient(data, h3[2], h3[1], h3[0])[::-1], -1)
        if transfer.gradient_opacity is not None:
            sigma = sigma * transfer.gradient_opacity.factor(np.linalg.norm(grad, axis=-1))
        if transfer.shading is not None:
            code = encode_normals(grad)
    sigma = sigma.astype(np.float32).astype(float)
    sigma[sigma <= -math.log1p(-min_opacity) / h3[principal_axis(view, volume)[0]]] = 0.0
    start, inv, _, emit = transfer.value_table(data.min(), data.max())
    colour = emit[np.clip(np.rint((data - start) * inv), 0, len(emit) - 1).astype(int)]
    if transfer.shading is not None:
        normals = decode_normals()
        factor = transfer.shading.factor(normals, -view.forward)
        spec = transfer.shading.highlight(normals, -view.forward)
        colour = colour * factor[code][..., None] + spec[code][..., None]

    axis, ascending = principal_axis(view, volume)
    p_axis, q_axis = [a for a in range(3) if a != axis][::-1]
    axes = [q_axis, p_axis, axis]
    order = (2 - axis, 2 - p_axis, 2 - q_axis)
    ext = np.transpose(sigma, order)
    col = np.transpose(colour, order + (3,))
    n_k, n_j, n_i = ext.shape
    h = h3[axes]
    kf = 0 if ascending else n_k - 1
    d = view.forward[axes] / h
    length = np.linalg.norm(d * h) / abs(d[2])
    corners = [np.array(c, float) - d[:2] * (k - kf) / d[2]
               for k in (0, n_k - 1) for c in [(0, 0), (n_i - 1, n_j - 1)]]
    low, high = np.min(corners, axis=0), np.max(corners, axis=0)
    width, height = (np.ceil(high - low - 1e-9).astype(int) + 1)
    inter = np.zeros((height, width, 4))
    big_i, big_j = np.meshgrid(np.arange(width) + low[0], np.arange(height) + low[1])
    padded_ext = np.pad(ext, ((0, 0), (2, 2), (2, 2)))  # zero outside the slices
    padded_col = np.pad(col, ((0, 0), (2, 2), (2, 2), (0, 0)))
    for k in (range(n_k) if ascending else range(n_k - 1, -1, -1)):
        i = big_i + d[0] * (k - kf) / d[2]
        j = big_j + d[1] * (k - kf) / d[2]
        i0 = np.clip(np.floor(i).astype(int), -2, n_i)
        j0 = np.clip(np.floor(j).astype(int), -2, n_j)
        ti, tj = i - np.floor(i), j - np.floor(j)
        e = np.zeros(i.shape)
        c = np.zeros(i.shape + (3,))
        for dj_, wj in ((0, 1 - tj), (1, tj)):
            for di_, wi in ((0, 1 - ti), (1, ti)):
                q = wj * wi * padded_ext[k, j0 + dj_ + 2, i0 + di_ + 2]
                e += q
                c += q[..., None] * padded_col[k, j0 + dj_ + 2, i0 + di_ + 2]
        part = 0.5 if k in (0, n_k - 1) else 1.0
        alpha = -np.expm1(-e * length * part)
        rgb = np.where(e[..., None] > 0, c / np.where(e > 0, e, 1.0)[..., None], 0.0)
        live = inter[..., 3] < early_termination
        add = (1 - inter[..., 3])[..., None] * np.concatenate([rgb * alpha[..., None],
                                                               alpha[..., None]], -1)
        inter[live] += add[live]
    return warp_naive(inter, volume, view, axis, q_axis, p_axis, kf, low)


#: Each method's naive twin as ``twin(volume, view, filt, transfer)``, at :func:`vrlib.render`'s
#: defaults (step 0.5, sheet buffers): a new method adds its twin here.
TWINS = {
    "raycast": lambda volume, view, filt, transfer: raycast_naive(volume, view, filt, transfer,
                                                                  0.5),
    "splat": lambda volume, view, filt, transfer: splat_naive(volume, view, filt, transfer,
                                                              "sheet"),
    "shear3": lambda volume, view, filt, transfer: shear_naive(volume, view, filt, transfer,
                                                               0.5, 3),
    "shear2": lambda volume, view, filt, transfer: shear_naive(volume, view, filt, transfer,
                                                               0.5, 2),
    "shearwarp": shearwarp_naive,
}
