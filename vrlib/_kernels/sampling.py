"""Reconstruction of a sampled volume at arbitrary points (eq 1.1), shared by the renderers.

Positions are *global* index coordinates ``(ux, uy, uz)``: ``ux = 0`` is the first sample of
the whole volume along x, whatever part of it ``data`` holds. ``offset`` is the global index of
``data[0, 0, 0]`` (z, y, x) and ``gshape`` the global shape; taps outside the whole volume are
clamped to its edge (the volume is extended by its border values), taps inside it must lie
in ``data`` (a brick carries ghost samples for that).
"""

from __future__ import annotations

import math

import numpy as np

from vrlib._kernels._jit import at, helper_jit, jit
from vrlib._kernels.filters import (
    BOX,
    GAUSSIAN,
    MAX_TAPS,
    cubic_coefficients,
    cubic_piece,
    derivative,
    tent_derivative,
    tent_weight,
    weight,
)


@helper_jit
def clamp(i, n):
    """Index ``i`` clamped to ``[0, n - 1]`` (the volume extended by its border values).
    Compiled once and inlined by LLVM: numba's own inlining at its many calls cost a first
    render 0.35 s of compile."""
    if i < 0:
        return 0
    if i > n - 1:
        return n - 1
    return i


@jit(inline="always")
def tap_scratch():
    """Scratch for :func:`reconstruct` and :func:`gradient`: weights along x, y and z and
    their derivatives, :data:`~vrlib._kernels.filters.MAX_TAPS` each."""
    return (np.empty(MAX_TAPS), np.empty(MAX_TAPS), np.empty(MAX_TAPS), np.empty(MAX_TAPS),
            np.empty(MAX_TAPS), np.empty(MAX_TAPS))


@jit(inline="always")
def filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, u, w, dw=None):
    """First tap index for position ``u`` on one axis; fills its weights ``w`` (and their
    derivatives ``dw`` when given)."""
    first = int(math.floor(u - radius)) + 1
    for a in range(ntaps):
        w[a] = weight(fkind, fp0, fp1, fp2, u - (first + a))
        if dw is not None:
            dw[a] = derivative(fkind, fp0, fp1, fp2, u - (first + a))
    return first


@jit
def reconstruct(data, offset, gshape, ux, uy, uz, fkind, fp0, fp1, fp2, radius, ntaps,
                wx, wy, wz):
    """Separable reconstruction ``sum f_ijk k(ux - i) k(uy - j) k(uz - k)`` at one point.

    ``wx, wy, wz`` are scratch arrays of at least ``ntaps`` entries. The sum runs z, then y,
    then x, in a fixed order, so the result does not depend on the caller's threading.
    """
    fx = filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, ux, wx)
    fy = filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, uy, wy)
    fz = filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, uz, wz)
    value = 0.0
    for c in range(ntaps):
        kz = clamp(fz + c, gshape[0]) - offset[0]
        for b in range(ntaps):
            ky = clamp(fy + b, gshape[1]) - offset[1]
            row = 0.0
            for a in range(ntaps):
                row += wx[a] * at(data, (kz, ky, clamp(fx + a, gshape[2]) - offset[2]))
            value += wz[c] * wy[b] * row
    return value


@jit(inline="always")
def trilinear(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ux, uy, uz):
    """The tent filter's two taps per axis, unrolled (the common case, kept fast).

    ``flat`` is the data raveled (C order, ``nx`` samples per row, ``nxy`` per plane);
    ``(oz, oy, ox)`` the global index of its first sample and ``(gz, gy, gx)`` the global
    shape. Cells inside the volume read their 8 corners at fixed offsets from one base index;
    cells on its border clamp each index.
    """
    ix = int(math.floor(ux))
    iy = int(math.floor(uy))
    iz = int(math.floor(uz))
    tx, ty, tz = ux - ix, uy - iy, uz - iz
    if 0 <= ix and ix + 1 < gx and 0 <= iy and iy + 1 < gy and 0 <= iz and iz + 1 < gz:
        return trilinear_inside(flat, nx, nxy, oz * nxy + oy * nx + ox, ix, iy, iz, tx, ty, tz)
    x0 = clamp(ix, gx) - ox
    x1 = clamp(ix + 1, gx) - ox
    y0 = (clamp(iy, gy) - oy) * nx
    y1 = (clamp(iy + 1, gy) - oy) * nx
    z0 = (clamp(iz, gz) - oz) * nxy
    z1 = (clamp(iz + 1, gz) - oz) * nxy
    return lerp_corners(at(flat, z0 + y0 + x0), at(flat, z0 + y0 + x1), at(flat, z0 + y1 + x0),
                        at(flat, z0 + y1 + x1), at(flat, z1 + y0 + x0), at(flat, z1 + y0 + x1),
                        at(flat, z1 + y1 + x0), at(flat, z1 + y1 + x1), tx, ty, tz)


@jit(inline="always")
def trilinear_inside(flat, nx, nxy, shift, ix, iy, iz, tx, ty, tz):
    """:func:`trilinear` in a cell whose 8 corners lie inside the volume: cell
    ``(ix, iy, iz)`` (global indices) at fractions ``(tx, ty, tz)``, its corners read at fixed
    offsets from one index. ``shift = oz nxy + oy nx + ox`` turns a global sample's flat index
    into ``flat``'s."""
    base = iz * nxy + iy * nx + ix - shift
    return lerp_corners(at(flat, base), at(flat, base + 1), at(flat, base + nx),
                        at(flat, base + nx + 1), at(flat, base + nxy), at(flat, base + nxy + 1),
                        at(flat, base + nxy + nx), at(flat, base + nxy + nx + 1), tx, ty, tz)


@jit(inline="always")
def lerp_corners(d000, d001, d010, d011, d100, d101, d110, d111, tx, ty, tz):
    """Trilinear interpolation of a cell's corners ``d_zyx`` at fractions ``(tx, ty, tz)``:
    along x, then y, then z."""
    c00 = d000 + tx * (d001 - d000)
    c01 = d010 + tx * (d011 - d010)
    c10 = d100 + tx * (d101 - d100)
    c11 = d110 + tx * (d111 - d110)
    c0 = c00 + ty * (c01 - c00)
    c1 = c10 + ty * (c11 - c10)
    return c0 + tz * (c1 - c0)


@jit(inline="always")
def cubic_weights(t, b, c, d):
    """Weights of a piecewise cubic (:func:`~vrlib._kernels.filters.cubic_coefficients`) for
    the taps at offsets -1, 0, 1, 2 from a point at fraction ``t`` in [0, 1) past tap 0
    (distances 1 + t, t, 1 - t, 2 - t)."""
    near, far = cubic_coefficients(b, c, d)
    return (cubic_piece(far, 1.0 + t) / 6.0, cubic_piece(near, t) / 6.0,
            cubic_piece(near, 1.0 - t) / 6.0, cubic_piece(far, 2.0 - t) / 6.0)


@jit(inline="always")
def tricubic(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ux, uy, uz, b, c, d):
    """A piecewise cubic's 4 x 4 x 4 taps (:func:`cubic_weights`); arguments as for
    :func:`trilinear`."""
    ix = int(math.floor(ux))
    iy = int(math.floor(uy))
    iz = int(math.floor(uz))
    return four_taps(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ix - 1, iy - 1, iz - 1,
                     cubic_weights(ux - ix, b, c, d), cubic_weights(uy - iy, b, c, d),
                     cubic_weights(uz - iz, b, c, d))


@jit(inline="always")
def _four_weights(fkind, fp0, fp1, fp2, u, first):
    if fkind == GAUSSIAN:
        # exp(-(d - a)^2 / 2s^2) = exp(-d^2 / 2s^2) exp(d / s^2)^a exp(-a^2 / 2s^2): two
        # exponentials per axis instead of four.
        d = u - first
        inv = 1.0 / (fp0 * fp0)
        w0 = math.exp(-0.5 * d * d * inv) * fp2
        step = math.exp(d * inv)
        c1 = math.exp(-0.5 * inv)
        w1 = w0 * step * c1
        w2 = w1 * step * c1 * c1 * c1
        w3 = w2 * step * c1 * c1 * c1 * c1 * c1
        return (w0 if abs(d) < fp1 else 0.0, w1 if abs(d - 1.0) < fp1 else 0.0,
                w2 if abs(d - 2.0) < fp1 else 0.0, w3 if abs(d - 3.0) < fp1 else 0.0)
    return (weight(fkind, fp0, fp1, fp2, u - first),
            weight(fkind, fp0, fp1, fp2, u - first - 1),
            weight(fkind, fp0, fp1, fp2, u - first - 2),
            weight(fkind, fp0, fp1, fp2, u - first - 3))


@helper_jit
def separable4(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ux, uy, uz, fkind, fp0, fp1, fp2,
               radius):
    """Any filter with 4 taps per axis (radius in (1.5, 2]), e.g. the Gaussian; arguments as
    for :func:`trilinear` plus the filter."""
    fx = int(math.floor(ux - radius)) + 1
    fy = int(math.floor(uy - radius)) + 1
    fz = int(math.floor(uz - radius)) + 1
    return four_taps(flat, nx, nxy, oz, oy, ox, gz, gy, gx, fx, fy, fz,
                     _four_weights(fkind, fp0, fp1, fp2, ux, fx),
                     _four_weights(fkind, fp0, fp1, fp2, uy, fy),
                     _four_weights(fkind, fp0, fp1, fp2, uz, fz))


@jit(inline="always")
def four_taps(flat, nx, nxy, oz, oy, ox, gz, gy, gx, fx, fy, fz, wx, wy, wz):
    """Sum of 4 x 4 x 4 samples from global index ``(fx, fy, fz)`` on, weighted by the
    4-tuples ``wx, wy, wz``, unrolled along x and reading from one base index inside the
    volume (indices clamped at its border)."""
    value = 0.0
    if 0 <= fx and fx + 3 < gx and 0 <= fy and fy + 3 < gy and 0 <= fz and fz + 3 < gz:
        base = (fz - oz) * nxy + (fy - oy) * nx + (fx - ox)
        for cz in range(4):
            plane = 0.0
            for cy in range(4):
                row = base + cz * nxy + cy * nx
                plane += wy[cy] * (wx[0] * at(flat, row) + wx[1] * at(flat, row + 1)
                                   + wx[2] * at(flat, row + 2) + wx[3] * at(flat, row + 3))
            value += wz[cz] * plane
        return value
    x0 = clamp(fx, gx) - ox
    x1 = clamp(fx + 1, gx) - ox
    x2 = clamp(fx + 2, gx) - ox
    x3 = clamp(fx + 3, gx) - ox
    for cz in range(4):
        kz = (clamp(fz + cz, gz) - oz) * nxy
        plane = 0.0
        for cy in range(4):
            row = kz + (clamp(fy + cy, gy) - oy) * nx
            plane += wy[cy] * (wx[0] * at(flat, row + x0) + wx[1] * at(flat, row + x1)
                               + wx[2] * at(flat, row + x2) + wx[3] * at(flat, row + x3))
        value += wz[cz] * plane
    return value


@jit
def gradient(data, offset, gshape, ux, uy, uz, fkind, fp0, fp1, fp2, radius, ntaps,
             wx, wy, wz, dx, dy, dz):
    """Gradient of the reconstruction, ``(dF/dux, dF/duy, dF/duz)`` in index units.

    The derivative of the separable sum: one axis's weights replaced by the kernel's
    derivative. ``dx, dy, dz`` are scratch arrays like ``wx``. The box filter's derivative
    is zero, so it takes the sampled gradient instead (:func:`sampled_gradient`), as the
    other methods and VTK's nearest-sample interpolation do.
    """
    if fkind == BOX:
        return sampled_gradient(data, offset, gshape, ux, uy, uz)
    fx = filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, ux, wx, dx)
    fy = filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, uy, wy, dy)
    fz = filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, uz, wz, dz)
    gx = 0.0
    gy = 0.0
    gz = 0.0
    for c in range(ntaps):
        kz = clamp(fz + c, gshape[0]) - offset[0]
        for b in range(ntaps):
            ky = clamp(fy + b, gshape[1]) - offset[1]
            row = 0.0
            drow = 0.0
            for a in range(ntaps):
                v = at(data, (kz, ky, clamp(fx + a, gshape[2]) - offset[2]))
                row += wx[a] * v
                drow += dx[a] * v
            gx += wz[c] * wy[b] * drow
            gy += wz[c] * dy[b] * row
            gz += dz[c] * wy[b] * row
    return gx, gy, gz


@helper_jit
def tent_gradient(data, offset, gshape, ux, uy, uz):
    """:func:`gradient` for the tent filter: the same sums in the same order, so the same
    result bit for bit, with its two taps a side written out. A shaded kernel of the tent
    filter compiles this instead of :func:`gradient` (whose loops serve every filter), and
    runs it without the scratch arrays."""
    fx = int(math.floor(ux - 1.0)) + 1
    fy = int(math.floor(uy - 1.0)) + 1
    fz = int(math.floor(uz - 1.0)) + 1
    wx0, wx1 = tent_weight(ux - fx), tent_weight(ux - (fx + 1))
    wy0, wy1 = tent_weight(uy - fy), tent_weight(uy - (fy + 1))
    wz0, wz1 = tent_weight(uz - fz), tent_weight(uz - (fz + 1))
    dx0, dx1 = tent_derivative(ux - fx), tent_derivative(ux - (fx + 1))
    dy0, dy1 = tent_derivative(uy - fy), tent_derivative(uy - (fy + 1))
    dz0, dz1 = tent_derivative(uz - fz), tent_derivative(uz - (fz + 1))
    x0 = clamp(fx, gshape[2]) - offset[2]
    x1 = clamp(fx + 1, gshape[2]) - offset[2]
    gx = 0.0
    gy = 0.0
    gz = 0.0
    for c in range(2):
        kz = clamp(fz + c, gshape[0]) - offset[0]
        wzc, dzc = (wz0, dz0) if c == 0 else (wz1, dz1)
        for b in range(2):
            ky = clamp(fy + b, gshape[1]) - offset[1]
            wyb, dyb = (wy0, dy0) if b == 0 else (wy1, dy1)
            v0 = at(data, (kz, ky, x0))
            v1 = at(data, (kz, ky, x1))
            row = 0.0 + wx0 * v0
            row += wx1 * v1
            drow = 0.0 + dx0 * v0
            drow += dx1 * v1
            gx += wzc * wyb * drow
            gy += wzc * dyb * row
            gz += dzc * wyb * row
    return gx, gy, gz


@helper_jit
def sampled_gradient(data, offset, gshape, ux, uy, uz):
    """The samples' gradient at the sample the box filter takes at ``(ux, uy, uz)`` (the
    nearest, ``floor(u + 1/2)``, clamped to the volume), in index units: central differences
    inside, one-sided on the volume's faces, as :func:`numpy.gradient` (and
    :func:`vrlib.gradients.gradient_volumes`) compute them. A brick needs one ghost sample."""
    i = clamp(int(math.floor(ux + 0.5)), gshape[2])
    j = clamp(int(math.floor(uy + 0.5)), gshape[1])
    k = clamp(int(math.floor(uz + 0.5)), gshape[0])
    z, y, x = k - offset[0], j - offset[1], i - offset[2]
    gx = gy = gz = 0.0
    if gshape[2] > 1:
        lo, hi = max(i - 1, 0) - offset[2], min(i + 1, gshape[2] - 1) - offset[2]
        gx = (data[z, y, hi] - data[z, y, lo]) / (hi - lo)
    if gshape[1] > 1:
        lo, hi = max(j - 1, 0) - offset[1], min(j + 1, gshape[1] - 1) - offset[1]
        gy = (data[z, hi, x] - data[z, lo, x]) / (hi - lo)
    if gshape[0] > 1:
        lo, hi = max(k - 1, 0) - offset[0], min(k + 1, gshape[0] - 1) - offset[0]
        gz = (data[hi, y, x] - data[lo, y, x]) / (hi - lo)
    return gx, gy, gz
