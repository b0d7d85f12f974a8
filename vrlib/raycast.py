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

import numba
import numpy as np

from vrlib._kernels import raycast as _kernel
from vrlib._kernels.filters import TENT
from vrlib._kernels.sampling import MAX_TAPS
from vrlib._scheduling import balanced_order
from vrlib.image import Image, RenderStats
from vrlib.skipping import empty_blocks, lattice_sums

__all__ = ["render_raycast", "operations_per_sample", "BLOCK"]

#: Cells per block (each axis) of the empty-space skipping grid.
BLOCK = 8
#: Pixels (rows, columns) of the image tiles that the parallel loop hands out.
TILE = (32, 32)


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
    recon = 30 if filt.code[0] == TENT else 30 * n + 2 * (n**3 + n**2)
    ops = 6 + recon + 20
    if shading:
        ops += 30 * n + 6 * n**3 + 30
    return ops


def reconstructed_range(volume, filt):
    """Bounds on every value the filter can reconstruct from this volume (overshoot of
    negative lobes and the Gaussian's ripple included; see :mod:`vrlib.skipping`)."""
    s_min, s_max, a_max = lattice_sums(filt)
    lo, hi = volume.value_range
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    return (min(centre * s_min, centre * s_max) - a_max * half,
            max(centre * s_min, centre * s_max) + a_max * half)


def coarsen(empty, factor=4):
    """Blocks of ``factor^3`` blocks that are all empty (edge blocks padded as empty)."""
    pad = [(0, -n % factor) for n in empty.shape]
    padded = np.pad(empty, pad, constant_values=True)
    shape = []
    for n in padded.shape:
        shape += [n // factor, factor]
    return padded.reshape(shape).all(axis=(1, 3, 5))


def visible_box(volume, empty, block, lo, hi):
    """World box around every non-empty block (a sliver larger, so that samples on its faces
    are taken whatever the rounding), clipped to ``[lo, hi]``; empty if nothing is visible."""
    full = np.argwhere(~empty)
    if full.size == 0:
        return lo, lo.copy()  # t_out <= t_in for every ray
    first = full.min(axis=0)[::-1] * block  # cells, x y z
    last = (full.max(axis=0)[::-1] + 1) * block
    sliver = 1e-9 * (hi - lo)
    box_lo = np.maximum(volume.origin + first * volume.spacing - sliver, lo)
    box_hi = np.minimum(volume.origin + last * volume.spacing + sliver, hi)
    return box_lo, box_hi


def footprint_mask(view, volume, empty, block):
    """Pixels whose rays can meet a non-empty block: the union of the blocks' projected
    bounding rectangles, one pixel wider all round (exact when conservative: a ray outside it
    crosses only empty blocks, whose samples add nothing)."""
    full = np.argwhere(~empty)[:, ::-1]  # block indices, x y z
    corners = np.array(np.meshgrid([0, 1], [0, 1], [0, 1], indexing="ij")).reshape(3, -1).T
    cells = (full[:, None, :] + corners[None, :, :]) * block
    cells = np.minimum(cells, np.array(volume.shape[::-1]) - 1)
    projected = view.project(volume.origin + cells * volume.spacing)  # (blocks, 8, 3)
    if not np.all(np.isfinite(projected)) or np.any(projected[..., 2] <= 0.0):
        return np.ones(view.shape, dtype=bool)  # a block reaches behind the eye: keep all
    r0 = np.clip(np.floor(projected[..., 0].min(axis=1)).astype(int) - 1, 0, view.height)
    r1 = np.clip(np.floor(projected[..., 0].max(axis=1)).astype(int) + 2, 0, view.height)
    c0 = np.clip(np.floor(projected[..., 1].min(axis=1)).astype(int) - 1, 0, view.width)
    c1 = np.clip(np.floor(projected[..., 1].max(axis=1)).astype(int) + 2, 0, view.width)
    marks = np.zeros((view.height + 1, view.width + 1), dtype=np.int64)
    np.add.at(marks, (r0, c0), 1)
    np.add.at(marks, (r0, c1), -1)
    np.add.at(marks, (r1, c0), -1)
    np.add.at(marks, (r1, c1), 1)
    return marks.cumsum(axis=0).cumsum(axis=1)[:-1, :-1] > 0


def render_raycast(volume, view, *, filt, transfer, step, early_termination,
                   empty_space_skipping):
    """Ray-cast ``volume`` (arguments already validated by :func:`vrlib.render`)."""
    extent = volume.extent
    box_lo, box_hi = extent[:, 0].copy(), extent[:, 1].copy()
    skip = None
    if empty_space_skipping:
        empty = empty_blocks(volume, filt, transfer, block=BLOCK)
        if empty.any():  # with nothing to skip, checking would only cost time
            box_lo, box_hi = visible_box(volume, empty, BLOCK, box_lo, box_hi)
            skip = (empty, coarsen(empty), BLOCK, footprint_mask(view, volume, empty, BLOCK))
    start = time.perf_counter()
    rgba, taken = cast_rays(
        volume.data, offset=(0, 0, 0), global_shape=volume.shape, origin=volume.origin,
        spacing=volume.spacing, box=(box_lo, box_hi), view=view, filt=filt, transfer=transfer,
        ds=step * float(volume.spacing.min()), value_range=reconstructed_range(volume, filt),
        early_termination=early_termination, skip=skip,
    )
    stats = RenderStats(
        samples=taken,
        operations=taken * operations_per_sample(filt, shading=transfer.shading is not None),
        bytes=int(volume.data.nbytes + rgba.nbytes),
        seconds=time.perf_counter() - start,
    )
    return Image(rgba, stats)


def cast_rays(data, *, offset, global_shape, origin, spacing, box, view, filt, transfer, ds,
              value_range, early_termination, skip=None):
    """Ray-cast samples ``data`` (all of a volume, or a brick of it with ghost samples).

    Parameters
    ----------
    data : ndarray (nz, ny, nx)
        Samples from global index ``offset`` (z, y, x) on, of a volume of ``global_shape``
        whose first sample lies at world ``origin`` with ``spacing`` (x, y, z).
    box : (ndarray, ndarray)
        World box whose samples these rays take (a brick's own region, without ghosts).
    ds : float
        Sample spacing along rays, world units.
    value_range : (float, float)
        Bounds on reconstructed values (for the classification table).
    skip : (empty, coarse, block, mask) or None
        Empty-space skipping grids (global blocks) and the pixels whose rays can meet a
        non-empty block, or None to sample everywhere.

    Returns
    -------
    rgba : ndarray (height, width, 4)
    samples : int
        Samples reconstructed.
    """
    ntaps = taps_per_axis(filt)
    if ntaps > MAX_TAPS:
        raise ValueError(
            f"filter radius {filt.radius:g} needs {ntaps} taps per axis; ray casting takes at "
            f"most {MAX_TAPS} (radius <= {MAX_TAPS // 2})"
        )
    tables = transfer.segment_table(ds, *value_range)
    shading = transfer.shading
    if shading is None:
        lighting = (False, 0.0, 0.0, 0.0, 1.0, np.zeros(3), True)
    else:
        light = np.zeros(3) if shading.light is None else np.asarray(shading.light, float)
        lighting = (True, shading.ambient, shading.diffuse, shading.specular,
                    shading.shininess, light, shading.light is None)
    if skip is None:
        skip = (np.zeros((1, 1, 1), dtype=bool), np.zeros((1, 1, 1), dtype=bool), 0,
                np.ones(view.shape, dtype=bool))
    grey = shading is None and bool(np.all(tables[4] == 1.0))  # colour equals opacity
    out = np.empty(view.shape + (4,))
    rows, cols = -(-view.height // TILE[0]), -(-view.width // TILE[1])
    samples = np.zeros(rows * cols, dtype=np.int64)
    # Cost of a tile: the pixels whose rays can meet something visible (plus a little for the
    # rest), so that threads share the work evenly.
    mask = skip[3]
    padded = np.zeros((rows * TILE[0], cols * TILE[1]))
    padded[: view.height, : view.width] = mask + 0.05
    costs = padded.reshape(rows, TILE[0], cols, TILE[1]).sum(axis=(1, 3)).ravel()
    _kernel.raycast(
        data, np.asarray(offset, np.int64), np.asarray(global_shape, np.int64),
        np.asarray(origin, np.float64), np.asarray(spacing, np.float64),
        np.asarray(box[0], np.float64), np.asarray(box[1], np.float64), view.packed(),
        view.height, view.width,
        ds, *filt.code, filt.radius, ntaps, *tables, *lighting, early_termination, *skip, *TILE,
        balanced_order(costs, numba.get_num_threads()), out, samples, grey,
    )
    np.clip(out[..., 3], 0.0, 1.0, out=out[..., 3])
    return out, int(samples.sum())
