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

import numpy as np
from numba import prange

from vrlib._kernels._jit import jit, parallel_jit
from vrlib._kernels.camera import (
    FORWARD,
    PIXEL,
    camera_coords,
    is_perspective,
    on_plane,
    pixel_ray,
    project,
)
from vrlib._kernels.footprint import (
    RADIAL,
    footprint_at,
    planar_at,
    planar_row,
    radial_at,
)
from vrlib._kernels.tables import interpolate, interpolate_channel

SHEET, DIRECT = 0, 1


@jit
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
    # row(q) = h/2 - (a + b q) / (px (c + d q)); solve row(q) = R for both ends.
    lo = math.inf
    hi = -math.inf
    for target in (row_lo, row_hi):
        k = (0.5 * height - target) * px
        denom = b - k * d
        if abs(denom) < 1e-300:
            row = 0.5 * height - a / (px * c)
            if row_lo <= row <= row_hi:
                return 0, nq - 1
            return 0, -1
        q = (k * c - a) / denom
        lo = min(lo, q)
        hi = max(hi, q)
    return max(0, int(math.floor(lo)) - 1), min(nq - 1, int(math.ceil(hi)) + 1)


@parallel_jit
def row_extents(marks, axis, first, last):
    """For each row ``(s, p)`` of the slicing order along ``axis``, the first and last ``q``
    with a nonzero entry in ``marks[z, y, x]`` (``first = nq``, ``last = -1`` when none)."""
    nz, ny, nx = marks.shape
    counts = (nx, ny, nz)
    pa = 1 if axis == 0 else 0
    qa = 1 if axis == 2 else 2
    nq = counts[qa]
    for slice_index in prange(counts[axis]):
        s = np.int64(slice_index)  # prange counts unsigned; keep the index arithmetic signed
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
def _deposit(mode, f, fp, dens, er, eg, eb, threshold, sheet, touched, opaque, out, r, r0, c):
    """One footprint pixel: into the sheet (``SHEET``), or composited at once (``DIRECT``)."""
    if mode == SHEET:
        sheet[r - r0, c] += f * fp
        touched[r - r0, c] = True
        return
    alpha = -math.expm1(-dens * fp)
    remaining = 1.0 - out[r, c, 3]
    out[r, c, 0] += remaining * er * alpha
    out[r, c, 1] += remaining * eg * alpha
    out[r, c, 2] += remaining * eb * alpha
    out[r, c, 3] += remaining * alpha
    opaque[r - r0, c] = out[r, c, 3] >= threshold


@parallel_jit
def splat(data, origin, spacing, camera, height, width, axis, slices,
          fkind, extent, extent_v, radial, planar, mode, vstart, vinv, dens_tab, emit_tab,
          per_voxel, voxel_density, voxel_colour, threshold, cull, row_first, row_last,
          reach_max, band, order, out, voxels, pixels):
    """Splat ``data[z, y, x]`` into ``out`` (premultiplied RGBA), bands of ``band`` rows.

    ``axis`` (0, 1, 2 for x, y, z) is the slicing axis and ``slices`` its indices front to
    back. Footprints are ``fkind`` tables (:mod:`vrlib.footprint`) reaching ``extent`` (along
    the image's right) and ``extent_v`` (up) world units. Classification reads density and
    emission tables over values (``vstart``, ``vinv``), or in direct mode with ``per_voxel``
    each voxel's own ``voxel_density`` and ``voxel_colour`` (classified and shaded from its
    gradient beforehand). With ``cull``, voxels of value zero are
    never drawn (they add nothing to a sheet) and in direct mode neither are voxels of zero
    density. Pixels whose opacity has reached ``threshold`` take no more (1 turns that off).
    ``row_first[s, p]`` and ``row_last[s, p]`` bound the voxels of each row of each slice that
    can be drawn (the rest are culled: a run-length skip over empty rows and their ends).
    ``reach_max`` bounds the footprint's reach in pixels over the volume. ``voxels`` and
    ``pixels`` count, per band, the voxels whose centre falls on it and the footprint pixels
    drawn.
    """
    nz, ny, nx = data.shape
    counts = (nx, ny, nz)
    # In-plane axes p, q of the slices.
    pa = 1 if axis == 0 else 0
    qa = 1 if axis == 2 else 2
    np_, nq = counts[pa], counts[qa]
    px = camera[PIXEL]
    perspective = is_perspective(camera)
    fwd = (camera[FORWARD], camera[FORWARD + 1], camera[FORWARD + 2])
    length_ortho = spacing[axis] / max(abs(fwd[axis]), 1e-300)
    for it in prange(order.shape[0]):
        b = order[it]
        r0 = b * band
        r1 = min(r0 + band, height)
        sheet = np.zeros((r1 - r0, width))
        touched = np.zeros((r1 - r0, width), dtype=np.bool_)
        opaque = np.zeros((r1 - r0, width), dtype=np.bool_)  # out[.., 3] >= threshold
        for r in range(r0, r1):
            for c in range(width):
                opaque[r - r0, c] = out[r, c, 3] >= threshold
        drawn = 0
        counted = 0
        qx = spacing[0] if qa == 0 else 0.0
        qy = spacing[1] if qa == 1 else 0.0
        qz = spacing[2] if qa == 2 else 0.0
        for s in slices:
            for p in range(np_):
                if row_first[s, p] > row_last[s, p]:
                    continue  # nothing to draw in this row
                # Voxel (i, j, k) of slice s, in-plane row p, and q = 0.
                i = s if axis == 0 else p
                j = s if axis == 1 else (p if axis == 0 else 0)
                k = s if axis == 2 else 0
                q_first, q_last = _q_range(
                    camera, height, origin[0] + i * spacing[0], origin[1] + j * spacing[1],
                    origin[2] + k * spacing[2], qx, qy, qz, nq, r0 - reach_max - 1.0,
                    r1 + reach_max + 1.0)
                q_first = max(q_first, row_first[s, p])
                q_last = min(q_last, row_last[s, p])
                for q in range(q_first, q_last + 1):
                    if qa == 1:
                        j = q
                    else:
                        k = q
                    f = data[k, j, i]
                    dens = 0.0
                    if cull and f == 0.0:
                        continue  # adds nothing to a sheet, and has no density to draw
                    if mode == DIRECT:
                        if per_voxel:
                            dens = voxel_density[k, j, i]
                        else:
                            dens = interpolate(dens_tab, vstart, vinv, f)
                        if cull and not dens > 0.0:
                            continue
                    x = origin[0] + i * spacing[0]
                    y = origin[1] + j * spacing[1]
                    z = origin[2] + k * spacing[2]
                    row_c, col_c, depth = project(camera, height, width, x, y, z)
                    if not depth > 0.0 or row_c != row_c:
                        continue
                    reach_u = extent / px / depth if perspective else extent / px
                    reach_v = extent_v / px / depth if perspective else extent_v / px
                    top = max(r0, int(math.ceil(row_c - reach_v - 0.5)))
                    bottom = min(r1 - 1, int(math.floor(row_c + reach_v - 0.5)))
                    if top > bottom:
                        continue
                    left = max(0, int(math.ceil(col_c - reach_u - 0.5)))
                    right = min(width - 1, int(math.floor(col_c + reach_u - 0.5)))
                    if left > right:
                        continue
                    if r0 <= row_c < r1 or (b == 0 and row_c < 0) or (
                            r1 == height and row_c >= height):
                        counted += 1
                    er = eg = eb = 0.0
                    if mode == DIRECT and per_voxel:
                        er = voxel_colour[k, j, i, 0]
                        eg = voxel_colour[k, j, i, 1]
                        eb = voxel_colour[k, j, i, 2]
                    elif mode == DIRECT:
                        er = interpolate_channel(emit_tab, vstart, vinv, f, 0)
                        eg = interpolate_channel(emit_tab, vstart, vinv, f, 1)
                        eb = interpolate_channel(emit_tab, vstart, vinv, f, 2)
                    for r in range(top, bottom + 1):
                        if perspective:
                            for c in range(left, right + 1):
                                if opaque[r - r0, c]:
                                    continue
                                o, d = pixel_ray(camera, height, width, r, c)
                                wx, wy, wz = x - o[0], y - o[1], z - o[2]
                                t = wx * d[0] + wy * d[1] + wz * d[2]
                                # Ray point minus voxel, perpendicular to the ray.
                                ox_, oy_, oz_ = t * d[0] - wx, t * d[1] - wy, t * d[2] - wz
                                u, v = on_plane(camera, ox_, oy_, oz_)
                                fp = footprint_at(fkind, extent, extent_v, radial, planar, u, v)
                                if fp != 0.0:
                                    drawn += 1
                                    _deposit(mode, f, fp, dens, er, eg, eb, threshold, sheet,
                                             touched, opaque, out, r, r0, c)
                            continue
                        # Orthographic: the row's offset v and its table row are shared.
                        v = (row_c - r - 0.5) * px
                        if fkind == RADIAL:
                            vv = v * v
                            for c in range(left, right + 1):
                                u = (c + 0.5 - col_c) * px
                                fp = radial_at(extent, radial, u * u + vv)
                                if fp != 0.0 and not opaque[r - r0, c]:
                                    drawn += 1
                                    _deposit(mode, f, fp, dens, er, eg, eb, threshold, sheet,
                                             touched, opaque, out, r, r0, c)
                        else:
                            row, ty = planar_row(extent_v, planar, v)
                            if row < 0:
                                continue
                            for c in range(left, right + 1):
                                u = (c + 0.5 - col_c) * px
                                fp = planar_at(extent, planar, row, ty, u)
                                if fp != 0.0 and not opaque[r - r0, c]:
                                    drawn += 1
                                    _deposit(mode, f, fp, dens, er, eg, eb, threshold, sheet,
                                             touched, opaque, out, r, r0, c)
            if mode == SHEET:
                # Classify the sheet as one segment per pixel and composite it (eqs 1.4, 1.7).
                for r in range(r0, r1):
                    for c in range(width):
                        if not touched[r - r0, c]:
                            continue
                        touched[r - r0, c] = False
                        integral = sheet[r - r0, c]
                        sheet[r - r0, c] = 0.0
                        if perspective:
                            o, d = pixel_ray(camera, height, width, r, c)
                            length = spacing[axis] / max(abs(d[axis]), 1e-300)
                        else:
                            length = length_ortho
                        value = integral / length
                        dens = interpolate(dens_tab, vstart, vinv, value)
                        if not dens > 0.0:
                            continue
                        weight = (1.0 - out[r, c, 3]) * -math.expm1(-dens * length)
                        out[r, c, 0] += weight * interpolate_channel(emit_tab, vstart, vinv,
                                                                             value, 0)
                        out[r, c, 1] += weight * interpolate_channel(emit_tab, vstart, vinv,
                                                                             value, 1)
                        out[r, c, 2] += weight * interpolate_channel(emit_tab, vstart, vinv,
                                                                             value, 2)
                        out[r, c, 3] += weight
                        opaque[r - r0, c] = out[r, c, 3] >= threshold
        voxels[b] = counted
        pixels[b] = drawn
