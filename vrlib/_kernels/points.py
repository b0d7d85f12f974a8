"""Reconstruction at arbitrary points (:func:`vrlib.reconstruct`): the renderers' separable
sum (:mod:`vrlib._kernels.sampling`), one point at a time, in parallel over blocks of points."""

from __future__ import annotations

import numpy as np
from numba import prange

from vrlib._kernels._jit import borrowed, parallel_jit
from vrlib._kernels.sampling import gradient, reconstruct, tap_scratch

#: Points per parallel task (each task holds its own scratch weights).
BLOCK = 1024


@parallel_jit
def reconstruct_points(data, index, fkind, fp0, fp1, fp2, radius, ntaps, derivative, out):
    """The field (``out[:, 0]``) or its index-space gradient (``out[:, 0:3]``, x y z) at index
    positions ``index[n] = (ux, uy, uz)`` of ``data`` (the whole volume, taps clamped to it).
    Every point is independent, so the result does not depend on the thread count."""
    offset = np.zeros(3, dtype=np.int64)
    gshape = np.array(data.shape, dtype=np.int64)
    data = borrowed(data)
    for block in prange((index.shape[0] + BLOCK - 1) // BLOCK):
        wx, wy, wz, dx, dy, dz = tap_scratch()
        for n in range(block * BLOCK, min(index.shape[0], (block + 1) * BLOCK)):
            ux, uy, uz = index[n, 0], index[n, 1], index[n, 2]
            # Borrowed views (no reference counts) for the call per point: offset, gshape
            # and the scratch stay alive through the loop.
            if derivative:
                out[n, 0], out[n, 1], out[n, 2] = gradient(
                    data, borrowed(offset), borrowed(gshape), ux, uy, uz, fkind, fp0, fp1,
                    fp2, radius, ntaps, borrowed(wx), borrowed(wy), borrowed(wz),
                    borrowed(dx), borrowed(dy), borrowed(dz))
            else:
                out[n, 0] = reconstruct(data, borrowed(offset), borrowed(gshape), ux, uy, uz,
                                        fkind, fp0, fp1, fp2, radius, ntaps, borrowed(wx),
                                        borrowed(wy), borrowed(wz))
