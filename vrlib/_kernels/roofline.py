"""Micro-kernels that measure what this machine allows: memory bandwidth and the peak rate of
trilinear and tricubic samples from a brick that stays in cache.

Each kernel does the work of a renderer's inner loop and nothing else: no classification, no
bounds checks (positions are kept inside the brick by construction), rays advanced
incrementally. They set the ceilings the renderers are measured against
(:mod:`vrlib.roofline`).
"""

from __future__ import annotations

import numpy as np
from numba import prange

from vrlib._kernels._jit import parallel_jit
from vrlib._kernels.filters import cubic_coefficients, cubic_piece


@parallel_jit
def triad(a, b, c, scalar):
    """STREAM triad ``a = b + scalar c``: 24 bytes of memory traffic per element (float64)."""
    for i in prange(a.shape[0]):
        a[i] = b[i] + scalar * c[i]


@parallel_jit
def trilinear_rays(brick, starts, direction, steps, out):
    """Sum of ``steps`` trilinear samples along each ray ``starts[r] + k direction`` (index
    coordinates ``(x, y, z)`` of ``brick[z, y, x]``); one sum per ray in ``out``. The brick is
    read flat through unsigned offsets from one base index (no negative-index fix-ups)."""
    flat = brick.reshape(-1)
    nx = np.uint64(brick.shape[2])
    nxy = np.uint64(brick.shape[1] * brick.shape[2])
    one = np.uint64(1)
    dx, dy, dz = direction[0], direction[1], direction[2]
    for r in prange(starts.shape[0]):
        ux, uy, uz = starts[r, 0], starts[r, 1], starts[r, 2]
        acc = 0.0
        for _ in range(steps):
            ix = np.uint64(ux)
            iy = np.uint64(uy)
            iz = np.uint64(uz)
            tx, ty, tz = ux - ix, uy - iy, uz - iz
            base = iz * nxy + iy * nx + ix
            d000 = flat[base]
            d001 = flat[base + one]
            d010 = flat[base + nx]
            d011 = flat[base + nx + one]
            d100 = flat[base + nxy]
            d101 = flat[base + nxy + one]
            d110 = flat[base + nxy + nx]
            d111 = flat[base + nxy + nx + one]
            c00 = d000 + tx * (d001 - d000)
            c01 = d010 + tx * (d011 - d010)
            c10 = d100 + tx * (d101 - d100)
            c11 = d110 + tx * (d111 - d110)
            c0 = c00 + ty * (c01 - c00)
            c1 = c10 + ty * (c11 - c10)
            acc += c0 + tz * (c1 - c0)
            ux += dx
            uy += dy
            uz += dz
        out[r] = acc


@parallel_jit
def tricubic_rays(brick, starts, direction, steps, b, c, out):
    """As :func:`trilinear_rays` with the Mitchell-Netravali (B, C) cubic's 4 x 4 x 4 taps
    (weights from its pieces scaled once; rows of 4 taps unrolled, reduced along x, y, z)."""
    near6, far6 = cubic_coefficients(b, c)
    near = (near6[0] / 6.0, near6[1] / 6.0, near6[2] / 6.0, near6[3] / 6.0)
    far = (far6[0] / 6.0, far6[1] / 6.0, far6[2] / 6.0, far6[3] / 6.0)
    flat = brick.reshape(-1)
    nx = np.uint64(brick.shape[2])
    nxy = np.uint64(brick.shape[1] * brick.shape[2])
    one = np.uint64(1)
    dx, dy, dz = direction[0], direction[1], direction[2]
    for r in prange(starts.shape[0]):
        ux, uy, uz = starts[r, 0], starts[r, 1], starts[r, 2]
        acc = 0.0
        for _ in range(steps):
            ix = np.uint64(ux)
            iy = np.uint64(uy)
            iz = np.uint64(uz)
            tx, ty, tz = ux - ix, uy - iy, uz - iz
            wx0, wx1 = cubic_piece(far, 1.0 + tx), cubic_piece(near, tx)
            wx2, wx3 = cubic_piece(near, 1.0 - tx), cubic_piece(far, 2.0 - tx)
            wy = (cubic_piece(far, 1.0 + ty), cubic_piece(near, ty),
                  cubic_piece(near, 1.0 - ty), cubic_piece(far, 2.0 - ty))
            wz = (cubic_piece(far, 1.0 + tz), cubic_piece(near, tz),
                  cubic_piece(near, 1.0 - tz), cubic_piece(far, 2.0 - tz))
            base = (iz - one) * nxy + (iy - one) * nx + ix - one
            value = 0.0
            for kz in range(4):
                plane = 0.0
                for ky in range(4):
                    row = base + np.uint64(kz) * nxy + np.uint64(ky) * nx
                    plane += wy[ky] * (wx0 * flat[row] + wx1 * flat[row + one]
                                       + wx2 * flat[row + one + one]
                                       + wx3 * flat[row + one + one + one])
                value += wz[kz] * plane
            acc += value
            ux += dx
            uy += dy
            uz += dz
        out[r] = acc
