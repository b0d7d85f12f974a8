"""The splatting kernel (Westover 1989, 1990): project each voxel's footprint onto the image.

Slices of voxels perpendicular to the volume axis most parallel to the view are taken front to
back. The image is cut into bands of rows, one parallel task each: a band walks every slice in
order and draws only the parts of footprints that fall on its own rows, so no two tasks write
the same pixel and the image does not depend on the number of threads.

Two ways to composite (``mode``):

* ``SHEET`` (Westover 1990, "sheet buffers"): a slice's footprints, weighted by the voxel
  values, are summed into a sheet; the sheet holds, per pixel, the integral of the slice's part
  of the reconstructed field along the ray (eq 1.1 integrated). It is classified as a segment
  of the slab's length ``L`` at the mean value ``S / L`` and composited (eqs 1.4, 1.7-1.9).
* ``DIRECT`` (Westover 1989): every voxel is classified by its own value and its footprint
  composited at once: optical depth ``density(f_i) FP``, colour ``E(f_i)`` (classification
  before reconstruction).

For the glow transfer function both give ``1 - exp(-k sum f_i FP)``: the exact line integral of
the reconstructed field.
"""

from __future__ import annotations

import math

from vrlib._kernels._jit import borrowed, helper_jit, jit
from vrlib._kernels.camera import (
    FORWARD,
    PIXEL,
    camera_coords,
    is_perspective,
    pixel_ray,
    project,
    ray_box,
)
from vrlib._kernels.footprint import (
    RADIAL,
    partial_at,
    partial_corner,
    planar_at,
    planar_row,
    radial_at,
    radial_partial,
    slanted_at,
    slanted_integral,
)
from vrlib._kernels.queue import take
from vrlib._kernels.shading import classify_by_gradient
from vrlib._kernels.tables import (
    interpolate,
    interpolate_channel,
    interpolate_rgb,
    lookup,
    piecewise_linear,
)

SHEET, DIRECT, IMAGE = 0, 1, 2


@helper_jit
def _q_range(camera, height, x0, y0, z0, dx, dy, dz, nq, row_lo, row_hi):
    """Indices ``q`` in ``[0, nq)`` of the points ``(x0, y0, z0) + q (dx, dy, dz)`` whose image
    row can lie in ``[row_lo, row_hi]``: a superset, found from the row's monotone (affine or,
    in perspective, linear-fractional) dependence on ``q``."""
    px = camera[PIXEL]
    _, a, c = camera_coords(camera, x0, y0, z0)
    _, a1, c1 = camera_coords(camera, x0 + dx, y0 + dy, z0 + dz)
    b, d = a1 - a, c1 - c
    if not is_perspective(camera):
        c, d = 1.0, 0.0
    elif c <= 0.0 or c + d * (nq - 1) <= 0.0:
        return 0, nq - 1  # part of the line is behind the eye: take it all
    # row(q) = h/2 - (a + b q) / (px (c + d q)), monotone on [0, nq - 1]: a target row beyond
    # the rows of the ends maps to that end, one between them is solved for.
    first = 0.5 * height - a / (px * c)
    last = 0.5 * height - (a + b * (nq - 1)) / (px * (c + d * (nq - 1)))
    if max(first, last) < row_lo or min(first, last) > row_hi:
        return 0, -1
    lo = math.inf
    hi = -math.inf
    for target in (row_lo, row_hi):
        if target <= min(first, last):
            q = 0.0 if first <= last else nq - 1.0
        elif target >= max(first, last):
            q = nq - 1.0 if first <= last else 0.0
        else:
            k = (0.5 * height - target) * px
            q = (k * c - a) / (b - k * d)
        lo = min(lo, q)
        hi = max(hi, q)
    return max(0, int(math.floor(lo)) - 1), min(nq - 1, int(math.ceil(hi)) + 1)


@jit
def row_extents(marks, axis, first, last, counter):
    """For each row ``(s, p)`` of the slicing order along ``axis``, the first and last ``q``
    with a nonzero entry in ``marks[z, y, x]`` (``first = nq``, ``last = -1`` when none).
    A call takes the next slice from the shared queue ``counter`` until none is left,
    several threads at once (:func:`vrlib._scheduling.on_threads`)."""
    nz, ny, nx = marks.shape
    counts = (nx, ny, nz)
    pa = 1 if axis == 0 else 0
    qa = 1 if axis == 2 else 2
    nq = counts[qa]
    while True:
        s = take(counter)
        if s >= counts[axis]:
            break
        for p in range(counts[pa]):
            lo = nq
            hi = -1
            for q in range(nq):
                i = s if axis == 0 else p
                j = s if axis == 1 else (p if axis == 0 else q)
                k = s if axis == 2 else q
                if marks[k, j, i] != 0:
                    if lo == nq:
                        lo = q
                    hi = q
            first[s, p] = lo
            last[s, p] = hi


@jit(inline="always")
def _deposit(mode, f, fp, dens, er, eg, eb, threshold, sheet, touched, opaque, out, r, r0, c,
             lighting, gsheet, g0, g1, g2):
    """One footprint pixel: into the sheet (``SHEET``, ``IMAGE``; with ``lighting`` the
    voxel's gradient ``g`` into the gradient sheets ``gsheet`` too), or composited at once
    (``DIRECT``)."""
    if mode != DIRECT:
        sheet[r - r0, c] += f * fp
        touched[r - r0, c] = True
        if lighting is not None:
            gsheet[0, r - r0, c] += g0 * fp
            gsheet[1, r - r0, c] += g1 * fp
            gsheet[2, r - r0, c] += g2 * fp
        return
    alpha = -math.expm1(-dens * fp)
    remaining = 1.0 - out[r, c, 3]
    out[r, c, 0] += remaining * er * alpha
    out[r, c, 1] += remaining * eg * alpha
    out[r, c, 2] += remaining * eb * alpha
    out[r, c, 3] += remaining * alpha
    opaque[r - r0, c] = out[r, c, 3] >= threshold


@jit
def _composite(out, r, c, value, length, vstart, vinv, dens_tab, emit_tab):
    """Composite a segment of ``length`` at the constant ``value`` (eqs 1.4, 1.7)."""
    dens = interpolate(dens_tab, vstart, vinv, value)
    if not dens > 0.0:
        return
    weight = (1.0 - out[r, c, 3]) * -math.expm1(-dens * length)
    for ch in range(3):
        out[r, c, ch] += weight * interpolate_channel(emit_tab, vstart, vinv, value, ch)
    out[r, c, 3] += weight


@helper_jit
def _composite_lit(out, r, c, value, gx, gy, gz, length, vstart, vinv, dens_tab, emit_tab, lit,
                   ramp_x, ramp_y, dx, dy, dz):
    """:func:`_composite` for a segment classified by its mean gradient ``g`` too (shading,
    gradient opacity; ``lit``, ``ramp_x``, ``ramp_y`` from
    :func:`vrlib.gradients.kernel_lighting`), seen along the unit ray direction ``d``."""
    i, w = lookup((value - vstart) * vinv, dens_tab.shape[0])
    dens = dens_tab[i] + w * (dens_tab[i + 1] - dens_tab[i])
    if lit[2] != 0.0:  # gradient opacity scales the density
        dens *= piecewise_linear(ramp_x, ramp_y, math.sqrt(gx * gx + gy * gy + gz * gz))
    if not dens > 0.0:
        return
    # (a segment's length, and so its opacity, may be negative, as in _composite: a kernel's
    # negative lobes)
    lx, ly, lz = (-dx, -dy, -dz) if lit[1] != 0.0 else (lit[7], lit[8], lit[9])
    alpha, cr, cg, cb = classify_by_gradient(
        -math.expm1(-dens * length), i, w, emit_tab, gx, gy, gz, False, ramp_x, ramp_y,
        lit[0] != 0.0, lx, ly, lz, dx, dy, dz, lit[3], lit[4], lit[5], lit[6])
    remaining = 1.0 - out[r, c, 3]
    out[r, c, 0] += remaining * cr
    out[r, c, 1] += remaining * cg
    out[r, c, 2] += remaining * cb
    out[r, c, 3] += remaining * alpha


@helper_jit
def cumulated(cumulative, radius, x):
    """The running integral of the 1-D kernel up to ``x`` (voxels), from its table over
    ``[-radius, radius]``."""
    n = cumulative.shape[0]
    y = (x + radius) * ((n - 1) / (2.0 * radius))
    if not y > 0.0:
        return 0.0
    if y >= n - 1:
        return cumulative[n - 1]
    m = int(y)
    return cumulative[m] + (y - m) * (cumulative[m + 1] - cumulative[m])


@helper_jit
def _window(base, slope, lo, hi, first, last):
    """The integers ``x`` in ``[first, last]`` with ``base + slope x`` in ``[lo, hi]``
    (``first > last`` when none), widened by one for rounding."""
    if slope == 0.0:
        if lo <= base <= hi:
            return first, last
        return first, first - 1
    a = (lo - base) / slope
    b = (hi - base) / slope
    if a > b:
        a, b = b, a
    if not (b >= first - 1 and a <= last + 1):
        return first, first - 1
    a = max(a, first - 1.0)
    b = min(b, last + 1.0)
    return max(first, int(math.floor(a)) - 1), min(last, int(math.ceil(b)) + 1)


@helper_jit
def _clipped(fkind, extent, extent_v, extent_s, sigma, radial, planar, partial, u, v, rho2,
             s_lo, s_hi):
    """The footprint at plane offsets ``(u, v)`` restricted to ``[s_lo, s_hi]`` along the line
    (``s`` from the line's point nearest the voxel): whole, partial, or zero."""
    if not s_hi > s_lo or s_hi <= -extent_s or s_lo >= extent_s:
        return 0.0
    if fkind == RADIAL:
        whole = radial_at(extent, radial, rho2)
        if s_lo <= -extent_s and s_hi >= extent_s or whole == 0.0:
            return whole
        return whole * radial_partial(extent, sigma, s_lo, s_hi, rho2)
    if s_lo <= -extent_s and s_hi >= extent_s:
        j, ty = planar_row(extent_v, planar, v)
        return 0.0 if j < 0 else planar_at(extent, planar, j, ty, u)
    j, i, ty, tx = partial_corner(extent, extent_v, partial.shape[1], partial.shape[0], u, v)
    if j < 0:
        return 0.0
    return (partial_at(partial, extent_s, j, i, ty, tx, s_hi)
            - partial_at(partial, extent_s, j, i, ty, tx, s_lo))


@helper_jit
def _support_image(camera, height, width, x, y, z, hx, hy, hz, row_c, col_c, depth, extent_s):
    """Rows and columns ``(row_lo, row_hi, col_lo, col_hi)`` spanned by the image of the box
    ``(x, y, z) +- (hx, hy, hz)`` in perspective: its corners' projections, or where a corner
    lies behind the eye the image of the bounding ball, stretched by up to ``1 + r^2`` off
    the axis (``r`` the image-plane radius at unit distance)."""
    row_lo = math.inf
    row_hi = -math.inf
    col_lo = math.inf
    col_hi = -math.inf
    for corner in range(8):
        cx = x + (hx if corner & 1 else -hx)
        cy = y + (hy if corner & 2 else -hy)
        cz = z + (hz if corner & 4 else -hz)
        row, col, corner_depth = project(camera, height, width, cx, cy, cz)
        if not corner_depth > 0.0:
            px = camera[PIXEL]
            r2 = ((col_c - 0.5 * width) ** 2 + (row_c - 0.5 * height) ** 2) * px * px
            reach = extent_s / px / depth * (1.0 + r2)
            return row_c - reach, row_c + reach, col_c - reach, col_c + reach
        row_lo = min(row_lo, row)
        row_hi = max(row_hi, row)
        col_lo = min(col_lo, col)
        col_hi = max(col_hi, col)
    return row_lo, row_hi, col_lo, col_hi


@helper_jit
def _slanted(table, reach, slope, kind, p0, p1, p2, radius, nodes, weights, cuts, o, d, vx,
             vy, vz, spacing, axis, pa, qa, lo, hi):
    """Perspective footprint of a separable kernel for the ray ``o + t d`` itself: from the
    slanted table (:class:`vrlib.footprint.Slanted`) when the whole line integral counts, by
    exact quadrature over ``[lo, hi]`` along the ray when it is clipped."""
    voxel = (vx, vy, vz)
    da = d[axis]
    if da == 0.0 or not hi > lo:
        return 0.0
    # Where the ray crosses the voxel's slice plane, and how it moves per unit along the axis.
    cross = (voxel[axis] - o[axis]) / da
    bp = (o[pa] + cross * d[pa] - voxel[pa]) / spacing[pa]
    bq = (o[qa] + cross * d[qa] - voxel[qa]) / spacing[qa]
    unit = da / spacing[axis]
    mp = d[pa] / spacing[pa] / unit
    mq = d[qa] / spacing[qa] / unit
    # The stretch [lo, hi] of the ray in axis units from the slice plane.
    a = (lo - cross) * unit
    e = (hi - cross) * unit
    if a > e:
        a, e = e, a
    if a <= -radius and e >= radius:
        return spacing[axis] / abs(da) * slanted_at(table, reach, slope, bp, bq, mp, mq)
    return spacing[axis] / abs(da) * slanted_integral(kind, p0, p1, p2, radius, bp, bq, mp, mq,
                                                      nodes, weights, a, e, cuts)


@helper_jit
def _flush(mode, s, r0, r1, width, axis, origin, spacing, radius, cumulative, z_lo, z_hi,
           slab_width, last_pass, sheet, touched, opaque, t_in, t_out, enter, leave, along,
           cosines, held_length, last_length, out, threshold, vstart, vinv, dens_tab, emit_tab,
           lighting, gsheet, lit, ramp_x, ramp_y, camera, height):
    """Classify a band's sheet per pixel as one segment and composite it (eqs 1.4, 1.7), after
    a pass of :func:`splat`: the slice ``s`` (SHEET) or the slab ``[z_lo, z_hi]`` (IMAGE).
    Compiled apart from :func:`splat`, which it would otherwise make slow to compile.

    IMAGE: the segment is the slab's stretch of the ray inside the box (a stretch under a
    quarter of the slab, where the ray enters, is held for the next slab). SHEET: the slice's
    share of the ray inside the box, ``int k((x_a(t) - x_s) / h) dt`` over it (the shares of
    all slices, ghosts included, sum to the stretch); a share under a quarter of a slab's
    length (the slice near where the ray enters or leaves) is held for the next slice, and
    what is held at the end is composited after the last one (over its own share, which may
    be negative for kernels with negative lobes). With ``lighting`` (True; None compiles the
    gradients away) the segment is classified by its mean gradient too (the gradient sheets
    ``gsheet`` over its length), seen along the pixel's ray (``camera``, an image ``height``
    rows high).
    """
    for r in range(r0, r1):
        for c in range(width):
            if not touched[r - r0, c]:
                continue
            a = t_in[r - r0, c]
            e = t_out[r - r0, c]
            direction = along[r - r0, c]
            if mode == IMAGE:
                cosine = cosines[r - r0, c]
                stretch = min(e, z_hi / cosine) - max(a, z_lo / cosine)
                if stretch > 0.0:
                    held_length[r - r0, c] += stretch
                length = held_length[r - r0, c]
                if not (length >= 0.25 * slab_width / cosine
                        or z_hi / cosine >= e) or not length > 0.0:
                    continue
                held_length[r - r0, c] = 0.0
            else:
                if direction != 0.0 and e > a:
                    centre = origin[axis] + s * spacing[axis]
                    share = spacing[axis] / direction * (
                        cumulated(cumulative, radius,
                                  (leave[r - r0, c] - centre) / spacing[axis])
                        - cumulated(cumulative, radius,
                                    (enter[r - r0, c] - centre) / spacing[axis]))
                    held_length[r - r0, c] += share
                length = held_length[r - r0, c]
                slab = spacing[axis] / abs(direction)
                if not length >= 0.25 * slab:
                    if not last_pass:
                        continue
                    if not abs(length) > 1e-6 * slab:
                        # No share to divide by: the last composited length (or the
                        # whole stretch) stands for it.
                        length = last_length[r - r0, c]
                        if not length > 0.0:
                            length = e - a
                            if not length > 0.0:
                                continue
                held_length[r - r0, c] = 0.0
                last_length[r - r0, c] = length
            touched[r - r0, c] = False
            value = sheet[r - r0, c] / length
            sheet[r - r0, c] = 0.0
            if lighting is not None:
                gx = gsheet[0, r - r0, c] / length
                gy = gsheet[1, r - r0, c] / length
                gz = gsheet[2, r - r0, c] / length
                gsheet[0, r - r0, c] = 0.0
                gsheet[1, r - r0, c] = 0.0
                gsheet[2, r - r0, c] = 0.0
                d = pixel_ray(camera, height, width, r, c)[1]
                _composite_lit(out, r, c, value, gx, gy, gz, length, vstart, vinv, dens_tab,
                               emit_tab, lit, ramp_x, ramp_y, d[0], d[1], d[2])
            else:
                _composite(out, r, c, value, length, vstart, vinv, dens_tab, emit_tab)
            opaque[r - r0, c] = out[r, c, 3] >= threshold


@jit
def splat(data, origin, spacing, camera, height, width, axis, slices, ghost, radius,
          cumulative, fkind, extent, extent_v, extent_s, sigma, radial, planar, partial,
          slanted, slanted_reach, slanted_slope, fcode, gauss, mode,
          slab_start, slab_width, n_slabs, vstart, vinv, dens_tab, emit_tab,
          per_voxel, voxel_density, voxel_colour, grads, lit, ramp_x, ramp_y, threshold, cull,
          row_first, row_last, near, reach_max, band, order, counter, out, voxels, pixels,
          perspective, lighting, planes, gplanes, flags, cuts):
    """Splat ``data[z, y, x]`` into ``out`` (premultiplied RGBA), bands of ``band`` rows: a
    call takes the next band of ``order`` from the shared queue ``counter``
    (:func:`vrlib._kernels.queue.take`) until none is left, and several threads make the
    call at once (:func:`vrlib._scheduling.on_threads`); each band is composited in a fixed
    order, whichever thread takes it. ``planes`` (9 x ``band`` x ``width``), ``gplanes``
    (3 x ``band`` x ``width``), ``flags`` (2 x ``band`` x ``width``, bool) and ``cuts``
    (``12 ceil(radius) + 5``) are the call's own scratch: a band's sheets and per-pixel
    records, and the exact footprints' cuts.

    ``axis`` (0, 1, 2 for x, y, z) is the slicing axis and ``slices`` its indices front to
    back, ``ghost`` slices beyond each face included: the lattice is extended by repeating its
    border samples (as every renderer reconstructs), so that the field inside the box is the
    ray caster's. ``cumulative`` tabulates ``int k`` over ``[-radius, radius]`` (the 1-D
    kernel's running integral). A perspective camera reads planar filters' footprints ray by
    ray from the ``slanted`` table (offsets to ``slanted_reach``, slopes to
    ``slanted_slope``), or where clipped integrate the kernel (``fcode``: kind and parameters)
    along the ray with the Gauss-Legendre rule ``gauss`` (nodes, weights). Footprints are
    ``fkind`` tables (:mod:`vrlib.footprint`) reaching ``extent`` (along the image's right),
    ``extent_v`` (up) and ``extent_s`` (along the line) world units; a voxel within the
    filter's ``radius`` (voxels) of a face has its line integrals clipped to the stretch of
    each ray inside the box (``partial`` table, or ``sigma`` for the radial Gaussian's closed
    form). ``mode``: ``SHEET`` and ``DIRECT`` walk the slices, one pass each; ``IMAGE``
    walks ``n_slabs`` slabs of camera depth ``slab_width`` from ``slab_start``, each voxel
    adding the part of its line integral that lies in the slab.
    Classification reads density and emission tables over values (``vstart``, ``vinv``), or in
    direct mode with ``per_voxel`` each voxel's own ``voxel_density`` and ``voxel_colour``. In
    the sheet modes, a transfer function that needs gradients (``lit``, ``ramp_x``,
    ``ramp_y`` from :func:`vrlib.gradients.kernel_lighting`) has each voxel's gradient
    ``grads[:, z, y, x]`` splatted into three gradient sheets beside the value's, and each
    segment classified by its mean gradient too. With ``cull``, voxels of value zero are never
    drawn (unless their gradients are splatted) and in direct mode neither are voxels of zero
    density. Pixels whose opacity has reached ``threshold`` take no more (1 turns that
    off). ``row_first[s, p]`` and ``row_last[s, p]`` bound the voxels of each row of each
    slice that can be drawn. Voxels nearer than camera depth ``near`` are not drawn (ghosts
    beside an eye close to a face). ``reach_max`` bounds the footprint's reach in pixels over the
    volume. ``voxels`` and ``pixels`` count, per band, the footprints drawn and the footprint
    pixels drawn.

    ``perspective`` and ``lighting`` are True for a perspective camera and for gradient
    sheets (the sheet modes with ``lit``), else None: numba drops the branches a None
    leaves out before it types the kernel, so that an orthographic or unlit render compiles
    none of their code (a first render's wait).
    """
    # Views without reference counts for the calls per voxel and per pixel (the caller
    # keeps the arrays).
    data, origin, spacing, camera = borrowed(data), borrowed(origin), borrowed(spacing), \
        borrowed(camera)
    cumulative, radial, planar, partial = borrowed(cumulative), borrowed(radial), \
        borrowed(planar), borrowed(partial)
    slanted, fcode, dens_tab, emit_tab = borrowed(slanted), borrowed(fcode), \
        borrowed(dens_tab), borrowed(emit_tab)
    voxel_density, voxel_colour, grads = borrowed(voxel_density), borrowed(voxel_colour), \
        borrowed(grads)
    lit, ramp_x, ramp_y, out = borrowed(lit), borrowed(ramp_x), borrowed(ramp_y), borrowed(out)
    nodes, weights = borrowed(gauss[0]), borrowed(gauss[1])
    planes, gplanes, flags, cuts = borrowed(planes), borrowed(gplanes), borrowed(flags), \
        borrowed(cuts)
    # A band's sheet and gradient sheets; per pixel, whether the sheet holds anything,
    # whether the pixel is opaque (out[.., 3] >= threshold), the ray's stretch inside the
    # box, where it enters and leaves along the slicing axis, its direction's component along
    # that axis and its cosine with the view's axis; the share of the stretch held in the
    # sheet, and the length the last composited sheet stood for.
    sheet, gsheet, touched, opaque = planes[0], gplanes, flags[0], flags[1]
    t_in, t_out, enter, leave = planes[1], planes[2], planes[3], planes[4]
    along, cosines, held_length, last_length = planes[5], planes[6], planes[7], planes[8]
    nz, ny, nx = data.shape
    counts = (nx, ny, nz)
    pa = 1 if axis == 0 else 0
    qa = 1 if axis == 2 else 2
    ns_, np_, nq = counts[axis], counts[pa], counts[qa]
    px = camera[PIXEL]
    fwd = (camera[FORWARD], camera[FORWARD + 1], camera[FORWARD + 2])
    lo_box = (origin[0], origin[1], origin[2])
    hi_box = (origin[0] + (nx - 1) * spacing[0], origin[1] + (ny - 1) * spacing[1],
              origin[2] + (nz - 1) * spacing[2])
    # Camera depth is affine in the voxel index: depth0 + s ds + p dp + q dq.
    depth0 = camera_coords(camera, origin[0], origin[1], origin[2])[2]
    ds = spacing[axis] * fwd[axis]
    dp = spacing[pa] * fwd[pa]
    dq = spacing[qa] * fwd[qa]
    q_lo = min(dq * -ghost, dq * (nq - 1 + ghost))
    q_hi = max(dq * -ghost, dq * (nq - 1 + ghost))
    reach_depth = 2.0 * extent_s if perspective is not None else extent_s
    widened = radius + 2.0 * slanted_reach / (slanted.shape[2] - 1)
    passes = n_slabs if mode == IMAGE else slices.shape[0]
    while True:
        it = take(counter)
        if it >= order.shape[0]:
            break
        b = order[it]
        r0 = b * band
        r1 = min(r0 + band, height)
        sheet[:] = 0.0
        if lighting is not None:
            gsheet[:] = 0.0
        touched[:] = False
        held_length[:] = 0.0
        last_length[:] = 0.0
        for r in range(r0, r1):
            for c in range(width):
                opaque[r - r0, c] = out[r, c, 3] >= threshold
                o, d = pixel_ray(camera, height, width, r, c)
                a, e = ray_box(o, d, lo_box, hi_box)
                t_in[r - r0, c] = a
                t_out[r - r0, c] = e
                enter[r - r0, c] = o[axis] + a * d[axis]
                leave[r - r0, c] = o[axis] + e * d[axis]
                along[r - r0, c] = d[axis]
                cosines[r - r0, c] = d[0] * fwd[0] + d[1] * fwd[1] + d[2] * fwd[2]
        drawn = 0
        counted = 0
        qx = spacing[0] if qa == 0 else 0.0
        qy = spacing[1] if qa == 1 else 0.0
        qz = spacing[2] if qa == 2 else 0.0
        for pass_index in range(passes):
            z_lo = -math.inf
            z_hi = math.inf
            first_slice = pass_index
            last_slice = pass_index
            if mode == IMAGE:
                z_lo = slab_start + pass_index * slab_width
                z_hi = z_lo + slab_width
                first_slice = 0
                last_slice = slices.shape[0] - 1
            for slice_index in range(first_slice, last_slice + 1):
                s = slices[slice_index]
                sc = min(max(s, 0), ns_ - 1)
                base_s = depth0 + s * ds
                p_first, p_last = -ghost, np_ - 1 + ghost
                if mode == IMAGE:
                    p_first, p_last = _window(base_s, dp, z_lo - reach_depth - q_hi,
                                              z_hi + reach_depth - q_lo, p_first, p_last)
                for p in range(p_first, p_last + 1):
                    pc = min(max(p, 0), np_ - 1)
                    if row_first[sc, pc] > row_last[sc, pc]:
                        continue  # nothing to draw in this row
                    q_first = row_first[sc, pc] if row_first[sc, pc] > 0 else -ghost
                    q_last = row_last[sc, pc] if row_last[sc, pc] < nq - 1 else nq - 1 + ghost
                    if mode == IMAGE:
                        q_first, q_last = _window(base_s + p * dp, dq, z_lo - reach_depth,
                                                  z_hi + reach_depth, q_first, q_last)
                        if q_first > q_last:
                            continue
                    # Voxel (i, j, k) of slice s, in-plane row p, and q = -ghost.
                    i = s if axis == 0 else p
                    j = s if axis == 1 else (p if axis == 0 else -ghost)
                    k = s if axis == 2 else -ghost
                    band_first, band_last = _q_range(
                        camera, height, origin[0] + i * spacing[0],
                        origin[1] + j * spacing[1], origin[2] + k * spacing[2], qx, qy, qz,
                        nq + 2 * ghost, r0 - reach_max - 1.0, r1 + reach_max + 1.0)
                    q_first = max(q_first, band_first - ghost)
                    q_last = min(q_last, band_last - ghost)
                    for q in range(q_first, q_last + 1):
                        if qa == 1:
                            j = q
                        else:
                            k = q
                        ic = min(max(i, 0), nx - 1)
                        jc = min(max(j, 0), ny - 1)
                        kc = min(max(k, 0), nz - 1)
                        f = data[kc, jc, ic]
                        dens = 0.0
                        if cull and f == 0.0 and lighting is None:
                            continue  # adds nothing to a sheet, and has no density to draw
                        g0 = g1 = g2 = 0.0
                        if lighting is not None:
                            g0 = grads[0, kc, jc, ic]
                            g1 = grads[1, kc, jc, ic]
                            g2 = grads[2, kc, jc, ic]
                        if mode == DIRECT:
                            if per_voxel:
                                dens = voxel_density[kc, jc, ic]
                            else:
                                dens = interpolate(dens_tab, vstart, vinv, f)
                            if cull and not dens > 0.0:
                                continue
                        x = origin[0] + i * spacing[0]
                        y = origin[1] + j * spacing[1]
                        z = origin[2] + k * spacing[2]
                        row_c, col_c, depth = project(camera, height, width, x, y, z)
                        if row_c != row_c or depth < near:
                            continue  # behind a perspective eye, or too near it
                        # The footprint's pixels: those whose centres fall within the image of
                        # the kernel's support (in perspective, of its box's corners).
                        row_lo = row_c - extent_v / px
                        row_hi = row_c + extent_v / px
                        col_lo = col_c - extent / px
                        col_hi = col_c + extent / px
                        if perspective is not None:
                            # (widened by a step of the slanted table, whose interpolation
                            # reaches that far past the support)
                            row_lo, row_hi, col_lo, col_hi = _support_image(
                                camera, height, width, x, y, z, widened * spacing[0],
                                widened * spacing[1], widened * spacing[2], row_c, col_c,
                                depth, extent_s)
                        top = max(r0, int(math.ceil(row_lo - 0.5)))
                        bottom = min(r1 - 1, int(math.floor(row_hi - 0.5)))
                        if top > bottom:
                            continue
                        left = max(0, int(math.ceil(col_lo - 0.5)))
                        right = min(width - 1, int(math.floor(col_hi - 0.5)))
                        if left > right:
                            continue
                        # Clipped: within the filter's radius of a face, or split into slabs.
                        clipped = mode == IMAGE or (
                            i < radius or i > nx - 1 - radius or j < radius
                            or j > ny - 1 - radius or k < radius or k > nz - 1 - radius)
                        if r0 <= row_c < r1 or (b == 0 and row_c < 0) or (
                                r1 == height and row_c >= height):
                            counted += 1
                        er = eg = eb = 0.0
                        if mode == DIRECT and per_voxel:
                            er = voxel_colour[kc, jc, ic, 0]
                            eg = voxel_colour[kc, jc, ic, 1]
                            eb = voxel_colour[kc, jc, ic, 2]
                        elif mode == DIRECT:
                            er, eg, eb = interpolate_rgb(emit_tab, vstart, vinv, f)
                        for r in range(top, bottom + 1):
                            if perspective is not None or clipped:
                                for c in range(left, right + 1):
                                    if opaque[r - r0, c]:
                                        continue
                                    lo = t_in[r - r0, c] if clipped else -math.inf
                                    hi = t_out[r - r0, c] if clipped else math.inf
                                    if mode == IMAGE:
                                        lo = max(lo, z_lo / cosines[r - r0, c])
                                        hi = min(hi, z_hi / cosines[r - r0, c])
                                    if perspective is not None:
                                        o, d = pixel_ray(camera, height, width, r, c)
                                        if fkind != RADIAL:
                                            fp = _slanted(slanted, slanted_reach, slanted_slope,
                                                          int(fcode[0]), fcode[1], fcode[2],
                                                          fcode[3], radius, nodes,
                                                          weights, cuts, o, d, x, y, z,
                                                          spacing, axis, pa, qa, lo, hi)
                                        else:
                                            # Ray point minus voxel, across the ray: its
                                            # length is all the radial footprint needs.
                                            wx, wy, wz = x - o[0], y - o[1], z - o[2]
                                            t = wx * d[0] + wy * d[1] + wz * d[2]
                                            rho2 = ((t * d[0] - wx) ** 2 + (t * d[1] - wy) ** 2
                                                    + (t * d[2] - wz) ** 2)
                                            fp = _clipped(fkind, extent, extent_v, extent_s,
                                                          sigma, radial, planar, partial, 0.0,
                                                          0.0, rho2, lo - t, hi - t)
                                    else:
                                        v = (row_c - r - 0.5) * px
                                        u = (c + 0.5 - col_c) * px
                                        fp = _clipped(fkind, extent, extent_v, extent_s, sigma,
                                                      radial, planar, partial, u, v,
                                                      u * u + v * v, lo - depth, hi - depth)
                                    if fp != 0.0:
                                        drawn += 1
                                        _deposit(mode, f, fp, dens, er, eg, eb, threshold,
                                                 sheet, touched, opaque, out, r, r0, c,
                                                 lighting, gsheet, g0, g1, g2)
                                continue
                            # Orthographic, whole footprints: the row's offset v and its table
                            # row are shared.
                            v = (row_c - r - 0.5) * px
                            if fkind == RADIAL:
                                vv = v * v
                                for c in range(left, right + 1):
                                    u = (c + 0.5 - col_c) * px
                                    fp = radial_at(extent, radial, u * u + vv)
                                    if fp != 0.0 and not opaque[r - r0, c]:
                                        drawn += 1
                                        _deposit(mode, f, fp, dens, er, eg, eb, threshold,
                                                 sheet, touched, opaque, out, r, r0, c,
                                                 lighting, gsheet, g0, g1, g2)
                            else:
                                row, ty = planar_row(extent_v, planar, v)
                                if row < 0:
                                    continue
                                for c in range(left, right + 1):
                                    u = (c + 0.5 - col_c) * px
                                    fp = planar_at(extent, planar, row, ty, u)
                                    if fp != 0.0 and not opaque[r - r0, c]:
                                        drawn += 1
                                        _deposit(mode, f, fp, dens, er, eg, eb, threshold,
                                                 sheet, touched, opaque, out, r, r0, c,
                                                 lighting, gsheet, g0, g1, g2)
            if mode != DIRECT:
                # (IMAGE passes are slabs, which may outnumber the slices: no slice to name)
                sheet_slice = slices[pass_index] if mode == SHEET else 0
                last_pass = pass_index == passes - 1
                _flush(mode, sheet_slice, r0, r1, width, axis, origin, spacing, radius,
                       cumulative, z_lo, z_hi, slab_width, last_pass, sheet, touched, opaque,
                       t_in, t_out, enter, leave, along, cosines, held_length, last_length,
                       out, threshold, vstart, vinv, dens_tab, emit_tab, lighting, gsheet, lit,
                       ramp_x, ramp_y, camera, height)
        voxels[b] = counted
        pixels[b] = drawn
