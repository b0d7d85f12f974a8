"""Micro-kernels that measure what this machine allows: memory bandwidth and the peak rate of
trilinear and tricubic samples from a brick that stays in cache.

Each kernel does the work of a renderer's inner loop and nothing else: no classification, no
bounds checks (positions are kept inside the brick by construction), rays advanced
incrementally. They set the ceilings the renderers are measured against
(:mod:`vrlib.roofline`).
"""

from __future__ import annotations

from numba import prange

from vrlib._kernels._jit import parallel_jit
from vrlib._kernels.sampling import cubic_weights, lerp_corners


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
    one base index per sample, with no bounds checks (the rays stay inside it)."""
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
                wx = cubic_weights(tx, b, c)
                wy = cubic_weights(ty, b, c)
                wz = cubic_weights(tz, b, c)
                first = base - nxy - nx - 1
                for kz in range(4):
                    plane = 0.0
                    for ky in range(4):
                        row = first + kz * nxy + ky * nx
                        plane += wy[ky] * (wx[0] * flat[row] + wx[1] * flat[row + 1]
                                           + wx[2] * flat[row + 2] + wx[3] * flat[row + 3])
                    acc += wz[kz] * plane
            else:
                acc += lerp_corners(flat[base], flat[base + 1], flat[base + nx],
                                    flat[base + nx + 1], flat[base + nxy], flat[base + nxy + 1],
                                    flat[base + nxy + nx], flat[base + nxy + nx + 1], tx, ty, tz)
            ux += dx
            uy += dy
            uz += dz
        out[r] = acc
