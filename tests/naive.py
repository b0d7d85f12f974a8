"""Naive NumPy twins of the numba kernels: slow, obvious, for small sizes.

Each twin follows the definition directly (per ray, per sample, per tap) so that a kernel's
optimisations (unrolled filters, skipping, tiling, threads) can be checked against it.
"""

import math

import numpy as np


def reconstruct_naive(volume, filt, points_index, *, gradient=False):
    """Separable reconstruction at index positions ``(n, 3)`` (x, y, z), edge-clamped.

    With ``gradient`` also returns ``(n, 3)`` derivatives in index units (one axis's weights
    replaced by the kernel's derivative).
    """
    data = np.asarray(volume.data, dtype=np.float64)
    nz, ny, nx = data.shape
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


def raycast_naive(volume, view, filt, transfer, step):
    """Ray casting by the book: samples at t = (k + 1/2) ds inside the volume box, opacity
    1 - exp(-density ds) (eq 1.4), colour E alpha (eq 1.9), composited front to back."""
    ds = step * float(volume.spacing.min())
    origins, directions = view.rays()
    lo, hi = volume.extent[:, 0], volume.extent[:, 1]
    image = np.zeros(view.shape + (4,))
    for r in range(view.height):
        for c in range(view.width):
            o, d = origins[r, c], directions[r, c]
            with np.errstate(divide="ignore", invalid="ignore"):
                ta, tb = (lo - o) / d, (hi - o) / d
            inside = d != 0
            if np.any(~inside & ((o < lo) | (o > hi))):
                continue
            t_in = max(0.0, np.max(np.minimum(ta, tb)[inside]))
            t_out = np.min(np.maximum(ta, tb)[inside])
            if not t_out > t_in:
                continue
            k = np.arange(math.ceil(t_in / ds - 0.5), math.ceil(t_out / ds - 0.5) + 1)
            t = (k + 0.5) * ds
            t = t[(t >= t_in) & (t < t_out)]
            points = o + t[:, None] * d
            values, grad = reconstruct_naive(volume, filt, volume.world_to_index(points),
                                             gradient=True)
            alpha = -np.expm1(-transfer.opacity_density(values) * ds)
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
