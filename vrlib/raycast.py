"""Ray casting (Levoy 1988; the first of the thesis's three methods).

For every pixel a ray is resampled at a constant step, each sample reconstructed with the
chosen filter (eq 1.1), classified by the transfer function and composited front to back
(eqs 1.7-1.8). Two skips leave out work a scene does not need: empty-space skipping jumps over
blocks of the volume that cannot be visible (the image is unchanged, bit for bit), and early
ray termination stops a ray once its opacity reaches a threshold (the image changes by at most
``1 - threshold`` times the brightest emission).
"""

from __future__ import annotations

import math
import time

import numpy as np

from vrlib._kernels import raycast as _kernel
from vrlib._kernels.sampling import MAX_TAPS
from vrlib.image import Image, RenderStats
from vrlib.skipping import empty_blocks

__all__ = ["render_raycast", "operations_per_sample", "BLOCK"]

#: Cells per block (each axis) of the empty-space skipping grid.
BLOCK = 8
#: Pixels per side of the image tiles that the parallel loop hands out.
TILE = 32


def taps_per_axis(filt):
    """Lattice samples per axis that a filter of this radius can weight at one point."""
    return max(1, math.ceil(2.0 * filt.radius))


def operations_per_sample(filt, *, shading=False):
    """Arithmetic operations for one ray sample, by this renderer's count.

    Position (6), reconstruction (trilinear: 7 lerps of 3 operations plus 9 for the fractions;
    other filters: 3n weight evaluations of about 10 operations and n^3 + n^2 multiply-adds),
    classification and compositing (about 20), and with shading the gradient (3 more sums of
    n^3 terms, 3n derivative evaluations) and lighting (about 30).

    Examples
    --------
    >>> from vrlib import make_filter
    >>> operations_per_sample(make_filter("trilinear"))
    56
    """
    n = taps_per_axis(filt)
    recon = 30 if filt.code[0] == _kernel_tent() else 30 * n + 2 * (n**3 + n**2)
    ops = 6 + recon + 20
    if shading:
        ops += 30 * n + 6 * n**3 + 30
    return ops


def _kernel_tent():
    from vrlib._kernels.filters import TENT

    return TENT


def spread_order(n):
    """The tiles ``0 .. n-1`` in an order that spreads neighbours apart (a coprime stride), so
    that a parallel loop's equal chunks hold equal shares of every part of the image.

    Examples
    --------
    >>> spread_order(5).tolist()
    [0, 3, 1, 4, 2]
    """
    stride = max(1, round(n * 0.618))
    while math.gcd(stride, n) != 1:
        stride += 1
    return (np.arange(n, dtype=np.int64) * stride) % n


def render_raycast(volume, view, *, filt, transfer, step, early_termination,
                   empty_space_skipping):
    """Ray-cast ``volume`` (arguments already validated by :func:`vrlib.render`)."""
    ntaps = taps_per_axis(filt)
    if ntaps > MAX_TAPS:
        raise ValueError(
            f"filter radius {filt.radius:g} needs {ntaps} taps per axis; ray casting takes at "
            f"most {MAX_TAPS} (radius <= {MAX_TAPS // 2})"
        )
    ds = step * float(volume.spacing.min())
    origins, directions = view.rays()
    fkind, fp0, fp1, fp2 = filt.code
    tkind, tscale, tvmin, tvmax, dtab, ctab = transfer.code
    shading = transfer.shading
    if shading is None:
        shade, ka, kd, ks, shininess, light, headlight = False, 0.0, 0.0, 0.0, 1.0, None, True
    else:
        shade, ka, kd, ks, shininess = (True, shading.ambient, shading.diffuse,
                                        shading.specular, shading.shininess)
        light, headlight = shading.light, shading.light is None
    light = np.zeros(3) if light is None else np.asarray(light, dtype=np.float64)
    if empty_space_skipping:
        empty, block = empty_blocks(volume, filt, transfer, block=BLOCK), BLOCK
    else:
        empty, block = np.zeros((1, 1, 1), dtype=bool), 0
    extent = volume.extent
    out = np.empty(view.shape + (4,))
    tiles = -(-view.height // TILE) * -(-view.width // TILE)
    samples = np.zeros(tiles, dtype=np.int64)
    start = time.perf_counter()
    _kernel.raycast(
        volume.data, np.zeros(3, np.int64), np.array(volume.shape, np.int64),
        np.ascontiguousarray(extent[:, 0]), volume.spacing, np.ascontiguousarray(extent[:, 0]),
        np.ascontiguousarray(extent[:, 1]), origins, directions, ds,
        fkind, fp0, fp1, fp2, filt.radius, ntaps,
        tkind, tscale, tvmin, tvmax, dtab, ctab,
        shade, ka, kd, ks, shininess, light, headlight,
        early_termination, empty, block, TILE, spread_order(tiles), out, samples,
    )
    seconds = time.perf_counter() - start
    taken = int(samples.sum())
    stats = RenderStats(
        samples=taken,
        operations=taken * operations_per_sample(filt, shading=shade),
        bytes=int(volume.data.nbytes + out.nbytes + origins.nbytes + directions.nbytes),
        seconds=seconds,
    )
    np.clip(out[..., 3], 0.0, 1.0, out=out[..., 3])
    return Image(out, stats)
