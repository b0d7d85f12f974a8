"""Reconstruction of a sampled volume at arbitrary points (eq 1.1), shared by the renderers.

Positions are *global* index coordinates ``(ux, uy, uz)``: ``ux = 0`` is the first sample of
the whole volume along x, whatever part of it ``data`` holds. ``offset`` is the global index of
``data[0, 0, 0]`` (z, y, x) and ``gshape`` the global shape; taps outside the whole volume are
clamped to its edge (the volume is extended by its border values), taps inside it must lie
in ``data`` (a brick carries ghost samples for that).
"""

from __future__ import annotations

import math

from vrlib._kernels._jit import jit
from vrlib._kernels.filters import CUBIC, TENT, derivative, weight

#: Largest number of taps per axis (a filter radius of at most 4 voxels).
MAX_TAPS = 8


@jit
def _clamp(i, n):
    if i < 0:
        return 0
    if i > n - 1:
        return n - 1
    return i


@jit
def reconstruct(data, offset, gshape, ux, uy, uz, fkind, fp0, fp1, fp2, radius, ntaps,
                wx, wy, wz):
    """Separable reconstruction ``sum f_ijk k(ux - i) k(uy - j) k(uz - k)`` at one point.

    ``wx, wy, wz`` are scratch arrays of at least ``ntaps`` entries. The sum runs z, then y,
    then x, in a fixed order, so the result does not depend on the caller's threading.
    """
    if fkind == TENT:
        return trilinear(data, offset, gshape, ux, uy, uz)
    if fkind == CUBIC:
        return tricubic(data, offset, gshape, ux, uy, uz, fp0, fp1)
    fx = int(math.floor(ux - radius)) + 1
    fy = int(math.floor(uy - radius)) + 1
    fz = int(math.floor(uz - radius)) + 1
    for a in range(ntaps):
        wx[a] = weight(fkind, fp0, fp1, fp2, ux - (fx + a))
        wy[a] = weight(fkind, fp0, fp1, fp2, uy - (fy + a))
        wz[a] = weight(fkind, fp0, fp1, fp2, uz - (fz + a))
    value = 0.0
    for c in range(ntaps):
        kz = _clamp(fz + c, gshape[0]) - offset[0]
        for b in range(ntaps):
            ky = _clamp(fy + b, gshape[1]) - offset[1]
            row = 0.0
            for a in range(ntaps):
                row += wx[a] * data[kz, ky, _clamp(fx + a, gshape[2]) - offset[2]]
            value += wz[c] * wy[b] * row
    return value


@jit
def trilinear(data, offset, gshape, ux, uy, uz):
    """The tent filter's two taps per axis, unrolled (the common case, kept fast)."""
    ix = int(math.floor(ux))
    iy = int(math.floor(uy))
    iz = int(math.floor(uz))
    tx, ty, tz = ux - ix, uy - iy, uz - iz
    x0 = _clamp(ix, gshape[2]) - offset[2]
    x1 = _clamp(ix + 1, gshape[2]) - offset[2]
    y0 = _clamp(iy, gshape[1]) - offset[1]
    y1 = _clamp(iy + 1, gshape[1]) - offset[1]
    z0 = _clamp(iz, gshape[0]) - offset[0]
    z1 = _clamp(iz + 1, gshape[0]) - offset[0]
    c00 = data[z0, y0, x0] + tx * (data[z0, y0, x1] - data[z0, y0, x0])
    c01 = data[z0, y1, x0] + tx * (data[z0, y1, x1] - data[z0, y1, x0])
    c10 = data[z1, y0, x0] + tx * (data[z1, y0, x1] - data[z1, y0, x0])
    c11 = data[z1, y1, x0] + tx * (data[z1, y1, x1] - data[z1, y1, x0])
    c0 = c00 + ty * (c01 - c00)
    c1 = c10 + ty * (c11 - c10)
    return c0 + tz * (c1 - c0)


@jit
def _cubic_weights(t, b, c):
    """Mitchell-Netravali weights of the taps at offsets -1, 0, 1, 2 from a point at fraction
    ``t`` in [0, 1) past tap 0 (distances 1 + t, t, 1 - t, 2 - t)."""
    u = 1.0 + t
    w0 = ((-b - 6 * c) * u * u * u + (6 * b + 30 * c) * u * u + (-12 * b - 48 * c) * u
          + (8 * b + 24 * c)) / 6.0
    w1 = ((12 - 9 * b - 6 * c) * t * t * t + (-18 + 12 * b + 6 * c) * t * t + (6 - 2 * b)) / 6.0
    v = 1.0 - t
    w2 = ((12 - 9 * b - 6 * c) * v * v * v + (-18 + 12 * b + 6 * c) * v * v + (6 - 2 * b)) / 6.0
    u = 2.0 - t
    w3 = ((-b - 6 * c) * u * u * u + (6 * b + 30 * c) * u * u + (-12 * b - 48 * c) * u
          + (8 * b + 24 * c)) / 6.0
    return w0, w1, w2, w3


@jit
def tricubic(data, offset, gshape, ux, uy, uz, b, c):
    """A Mitchell-Netravali (B, C) cubic's 4 x 4 x 4 taps, unrolled (as fast as it gets)."""
    ix = int(math.floor(ux))
    iy = int(math.floor(uy))
    iz = int(math.floor(uz))
    wx = _cubic_weights(ux - ix, b, c)
    wy = _cubic_weights(uy - iy, b, c)
    wz = _cubic_weights(uz - iz, b, c)
    x0 = _clamp(ix - 1, gshape[2]) - offset[2]
    x1 = _clamp(ix, gshape[2]) - offset[2]
    x2 = _clamp(ix + 1, gshape[2]) - offset[2]
    x3 = _clamp(ix + 2, gshape[2]) - offset[2]
    value = 0.0
    for cz in range(4):
        kz = _clamp(iz - 1 + cz, gshape[0]) - offset[0]
        plane = 0.0
        for cy in range(4):
            ky = _clamp(iy - 1 + cy, gshape[1]) - offset[1]
            row = (wx[0] * data[kz, ky, x0] + wx[1] * data[kz, ky, x1]
                   + wx[2] * data[kz, ky, x2] + wx[3] * data[kz, ky, x3])
            plane += wy[cy] * row
        value += wz[cz] * plane
    return value


@jit
def gradient(data, offset, gshape, ux, uy, uz, fkind, fp0, fp1, fp2, radius, ntaps,
             wx, wy, wz, dx, dy, dz):
    """Gradient of the reconstruction, ``(dF/dux, dF/duy, dF/duz)`` in index units.

    The derivative of the separable sum: one axis's weights replaced by the kernel's
    derivative. ``dx, dy, dz`` are scratch arrays like ``wx``.
    """
    fx = int(math.floor(ux - radius)) + 1
    fy = int(math.floor(uy - radius)) + 1
    fz = int(math.floor(uz - radius)) + 1
    for a in range(ntaps):
        wx[a] = weight(fkind, fp0, fp1, fp2, ux - (fx + a))
        wy[a] = weight(fkind, fp0, fp1, fp2, uy - (fy + a))
        wz[a] = weight(fkind, fp0, fp1, fp2, uz - (fz + a))
        dx[a] = derivative(fkind, fp0, fp1, fp2, ux - (fx + a))
        dy[a] = derivative(fkind, fp0, fp1, fp2, uy - (fy + a))
        dz[a] = derivative(fkind, fp0, fp1, fp2, uz - (fz + a))
    gx = 0.0
    gy = 0.0
    gz = 0.0
    for c in range(ntaps):
        kz = _clamp(fz + c, gshape[0]) - offset[0]
        for b in range(ntaps):
            ky = _clamp(fy + b, gshape[1]) - offset[1]
            row = 0.0
            drow = 0.0
            for a in range(ntaps):
                v = data[kz, ky, _clamp(fx + a, gshape[2]) - offset[2]]
                row += wx[a] * v
                drow += dx[a] * v
            gx += wz[c] * wy[b] * drow
            gy += wz[c] * dy[b] * row
            gz += dz[c] * wy[b] * row
    return gx, gy, gz
