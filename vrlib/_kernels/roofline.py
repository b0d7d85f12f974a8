"""Micro-kernels that measure what this machine allows: memory bandwidth, the peak rate of
trilinear and tricubic samples from a brick that stays in cache, and the peak rates of the other
methods' inner loops: footprint pixels (splatting), 1-D resampled samples (the shear passes)
and 2-D resampled slice samples (shear-warp).

Each kernel does the work of a renderer's inner loop and nothing else: no classification, no
bounds checks (positions are kept inside the brick by construction), rays advanced
incrementally. They set the ceilings the renderers are measured against
(:mod:`vrlib.roofline`). :func:`sample_packets` samples eight rays at a time in vector form
(:mod:`vrlib._kernels.packets`): the packet ceiling beside the scalar one.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from vrlib._kernels._jit import at, jit, parallel_jit
from vrlib._kernels.footprint import planar_at, planar_row
from vrlib._kernels.packets import LANES, trilinear_packet
from vrlib._kernels.sampling import cubic_weights, lerp_corners, trilinear
from vrlib._kernels.tables import entry, lookup


@parallel_jit
def triad(a, b, c, scalar):
    """STREAM triad ``a = b + scalar c``: 24 bytes of memory traffic per element (float64)."""
    for i in prange(a.shape[0]):
        a[i] = b[i] + scalar * c[i]


@parallel_jit
def sample_rays(brick, starts, direction, steps, cubic, b, c, out):
    """Sum of ``steps`` samples along each ray ``starts[r] + k direction`` (index coordinates
    ``(x, y, z)`` of ``brick[z, y, x]``), one sum per ray in ``out``: trilinear, or with
    ``cubic`` the Mitchell-Netravali (B, C) cubic's 4 x 4 x 4 taps. The brick is read flat from
    one base index per sample, with no bounds checks (the rays stay inside it) and no test for
    a negative index (:data:`~vrlib._kernels._jit.at`)."""
    flat = brick.reshape(-1)
    nx = brick.shape[2]
    nxy = brick.shape[1] * brick.shape[2]
    dx, dy, dz = direction[0], direction[1], direction[2]
    for r in prange(starts.shape[0]):
        ux, uy, uz = starts[r, 0], starts[r, 1], starts[r, 2]
        acc = 0.0
        for _ in range(steps):
            ix = int(ux)
            iy = int(uy)
            iz = int(uz)
            tx, ty, tz = ux - ix, uy - iy, uz - iz
            base = iz * nxy + iy * nx + ix
            if cubic:
                wx = cubic_weights(tx, b, c, 0.0)
                wy = cubic_weights(ty, b, c, 0.0)
                wz = cubic_weights(tz, b, c, 0.0)
                first = base - nxy - nx - 1
                for kz in range(4):
                    plane = 0.0
                    for ky in range(4):
                        row = first + kz * nxy + ky * nx
                        plane += wy[ky] * (wx[0] * at(flat, row) + wx[1] * at(flat, row + 1)
                                           + wx[2] * at(flat, row + 2)
                                           + wx[3] * at(flat, row + 3))
                    acc += wz[kz] * plane
            else:
                acc += lerp_corners(at(flat, base), at(flat, base + 1), at(flat, base + nx),
                                    at(flat, base + nx + 1), at(flat, base + nxy),
                                    at(flat, base + nxy + 1), at(flat, base + nxy + nx),
                                    at(flat, base + nxy + nx + 1), tx, ty, tz)
            ux += dx
            uy += dy
            uz += dz
        out[r] = acc


@jit(inline="always")
def _lanes(values, first, axis):
    """``values[first + l, axis]`` for the ``LANES`` (8) lanes of a packet, as a tuple."""
    return (values[first, axis], values[first + 1, axis], values[first + 2, axis],
            values[first + 3, axis], values[first + 4, axis], values[first + 5, axis],
            values[first + 6, axis], values[first + 7, axis])


@jit(inline="always")
def _every(value):
    """``value`` in each lane of a packet."""
    return (value, value, value, value, value, value, value, value)


@jit(inline="always")
def _plus(a, b):
    """Lane by lane ``a + b`` of two packets."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3], a[4] + b[4], a[5] + b[5],
            a[6] + b[6], a[7] + b[7])


@parallel_jit
def sample_packets(brick, starts, direction, steps, out):
    """:func:`sample_rays` with the trilinear filter, ``LANES`` rays at a time: each packet
    of neighbouring rays (``starts[p LANES:(p + 1) LANES]``; their number a multiple of
    ``LANES``) takes its samples together, in vector form
    (:func:`~vrlib._kernels.packets.trilinear_packet`)."""
    flat = brick.reshape(-1)
    nx = brick.shape[2]
    nxy = brick.shape[1] * brick.shape[2]
    dx, dy, dz = _every(direction[0]), _every(direction[1]), _every(direction[2])
    for p in prange(starts.shape[0] // LANES):
        first = p * LANES
        ux, uy, uz = _lanes(starts, first, 0), _lanes(starts, first, 1), _lanes(starts, first, 2)
        acc = _every(0.0)
        for _ in range(steps):
            acc = _plus(acc, trilinear_packet(flat, nx, nxy, ux, uy, uz))
            ux, uy, uz = _plus(ux, dx), _plus(uy, dy), _plus(uz, dz)
        for lane in range(LANES):
            out[first + lane] = acc[lane]


@parallel_jit
def draw_footprints(planar, extent, extent_v, px, centres, sheets):
    """Splatting's inner loop alone: footprint ``planar`` (a planar table reaching ``extent``
    and ``extent_v`` world units along the image's right and up, pixels ``px`` wide) drawn at
    each ``centres[n] = (row, col)`` into one cache-resident sheet per task (``sheets[t]``),
    over the pixels the table reaches, with unit voxel values. Orthographic: each row's table
    row is found once. Returns the pixels drawn."""
    tasks = sheets.shape[0]
    reach_u = extent / px
    reach_v = extent_v / px
    per_task = centres.shape[0] // tasks
    drawn = 0
    for task in prange(tasks):
        sheet = sheets[task]
        count = 0
        for n in range(task * per_task, (task + 1) * per_task):
            row_c = centres[n, 0]
            col_c = centres[n, 1]
            top = int(math.ceil(row_c - reach_v - 0.5))
            bottom = int(math.floor(row_c + reach_v - 0.5))
            left = int(math.ceil(col_c - reach_u - 0.5))
            right = int(math.floor(col_c + reach_u - 0.5))
            for r in range(top, bottom + 1):
                row, ty = planar_row(extent_v, planar, (row_c - r - 0.5) * px)
                if row < 0:
                    continue
                for c in range(left, right + 1):
                    sheet[r, c] += planar_at(extent, planar, row, ty, (c + 0.5 - col_c) * px)
                count += right - left + 1
        drawn += count
    return drawn


@parallel_jit
def resample_lines(lines, scale, shift, ntaps, b, c, out):
    """A shear pass's inner loop alone: output line ``out[n]`` is line ``lines[n % len(lines)]``
    (a few lines, so they stay in cache) resampled at ``q / scale + shift`` for each output
    ``q``, with per-output weights: the tent (``ntaps = 2``) or the Mitchell-Netravali (B, C)
    cubic (``ntaps = 4``), no clamping (the positions stay inside the line)."""
    for n in prange(out.shape[0]):
        src = n % lines.shape[0]
        w = np.empty(4)
        for q in range(out.shape[1]):
            pos = q / scale + shift
            first = int(math.floor(pos))
            t = pos - first
            if ntaps == 2:
                w[0] = 1.0 - t
                w[1] = t
            else:
                w[0], w[1], w[2], w[3] = cubic_weights(t, b, c, 0.0)
                first -= 1
            acc = 0.0
            for a in range(ntaps):
                acc += w[a] * lines[src, first + a]
            out[n, q] = acc


@parallel_jit
def resample_slices(slices, ntaps, wi, wj, out):
    """Shear-warp's inner loop alone (orthographic): ``out[k]`` takes slice
    ``slices[k % len(slices)]`` (a few slices, so they stay in cache) resampled at a
    translation, the same ``ntaps x ntaps`` weights (``wi`` along rows, ``wj`` across) for every
    pixel."""
    for k in prange(out.shape[0]):
        src = k % slices.shape[0]
        for j in range(out.shape[1]):
            for i in range(out.shape[2]):
                value = 0.0
                for bj in range(ntaps):
                    line = 0.0
                    for ai in range(ntaps):
                        line += wi[ai] * slices[src, j + bj, i + ai]
                    value += wj[bj] * line
                out[k, j, i] = value


@parallel_jit
def march_rays(brick, starts, direction, steps, classify, tstart, tinv, alpha_tab, out):
    """The ray caster's own per-sample work on a cache-resident brick, for the ladder from the
    sampling ceiling to the renderer: positions from the sample's parameter (the global
    lattice), the renderer's :func:`~vrlib._kernels.sampling.trilinear` (floor, bounds check);
    with ``classify``, each sample's segment opacity from the table and front-to-back
    compositing (``out`` is the ray's opacity), else the plain sum of the samples."""
    flat = brick.reshape(-1)
    nz, ny, nx = brick.shape
    nxy = ny * nx
    ntab = alpha_tab.shape[0]
    for r in prange(starts.shape[0]):
        ax, ay, az = starts[r, 0], starts[r, 1], starts[r, 2]
        acc = 0.0
        for k in range(steps):
            t = float(k)
            value = trilinear(flat, nx, nxy, 0, 0, 0, nz, ny, nx, ax + t * direction[0],
                              ay + t * direction[1], az + t * direction[2])
            if classify:
                i, w = lookup((value - tstart) * tinv, ntab)
                alpha = entry(alpha_tab, i, w)
                acc += (1.0 - acc) * alpha
            else:
                acc += value
        out[r] = acc
