"""Empty-space skipping: which blocks of a volume cannot contribute to any image.

A block is empty when every value the filter can reconstruct inside it maps to zero opacity.
The block's sample range ``[m, M]`` comes from the volume's min-max pyramid, widened by the
filter's reach; the reconstructed value is then bounded by the filter's lattice sums: with
weights ``w`` at a point, ``R = sum w f`` lies within
``c * sum(w) +- sum(|w|) * h`` where ``c = (m + M) / 2`` and ``h = (M - m) / 2``. For filters
with negative lobes (Catmull-Rom, Mitchell) this allows for overshoot; for the Gaussian, whose
weights do not sum to one, for its ripple. The test is conservative, so skipping never changes
an image.

Slice-by-slice renderers (shear-warp) skip along rows instead: :func:`transparent_runs` gives,
for each row of each slice, the first and last sample above a transparency bound.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from vrlib.filters import make_filter

__all__ = ["empty_blocks", "lattice_sums", "filter_margin", "transparent_runs"]


@functools.lru_cache(maxsize=64)
def lattice_sums(filt):
    """``(s_min, s_max, a_max)`` of a filter's 3-D weights over every position.

    ``s`` is the sum of the weights (1 for filters that form a partition of unity) and ``a``
    the sum of their absolute values; 3-D values are the cubes of the 1-D ones, as the filters
    are separable. Found on a dense grid of offsets and widened by 1e-9 relative, which bounds
    the grid's error for these smooth sums.

    Examples
    --------
    >>> s_min, s_max, a_max = lattice_sums(make_filter("trilinear"))
    >>> round(s_min, 6), round(s_max, 6), round(a_max, 6)
    (1.0, 1.0, 1.0)
    >>> lattice_sums(make_filter("catmull-rom"))[2] > 1.0     # negative lobes
    True
    """
    filt = make_filter(filt)
    offsets = np.linspace(0.0, 1.0, 4097)
    taps = np.arange(-math.ceil(filt.radius) - 1, math.ceil(filt.radius) + 2)
    w = filt(offsets[:, None] - taps[None, :])
    s = w.sum(axis=1)
    a = np.abs(w).sum(axis=1)
    pad = 1.0 + 1e-9
    return float(s.min() ** 3 / pad), float(s.max() ** 3 * pad), float(a.max() ** 3 * pad)


def filter_margin(filt):
    """Samples beyond a cell's corners that a filter of this radius reaches: ceil(r) - 1.

    Examples
    --------
    >>> filter_margin(make_filter("trilinear")), filter_margin(make_filter("catmull-rom"))
    (0, 1)
    """
    return max(0, math.ceil(make_filter(filt).radius) - 1)


def empty_blocks(volume, filt, transfer, *, block=8):
    """Boolean array, one entry per level-0 block of ``volume``: True where nothing shows.

    Parameters
    ----------
    volume : Volume
    filt : Filter or filter name
    transfer : TransferFunction
    block : int
        Cells per block along each axis.

    Examples
    --------
    >>> from vrlib import Volume, Glow
    >>> data = np.zeros((17, 17, 17)); data[12, 12, 12] = 1.0
    >>> empty = empty_blocks(Volume(data), "trilinear", Glow(1.0), block=8)
    >>> empty.shape, int(empty.sum())
    ((2, 2, 2), 7)
    """
    filt = make_filter(filt)
    pyr = volume.minmax_pyramid(block, margin=filter_margin(filt))
    s_min, s_max, a_max = lattice_sums(filt)
    lo, hi = pyr.minimum[0].astype(np.float64), pyr.maximum[0].astype(np.float64)
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    reach = a_max * half
    low = np.minimum(centre * s_min, centre * s_max) - reach
    high = np.maximum(centre * s_min, centre * s_max) + reach
    return np.asarray(transfer.max_density(low, high)) <= 0.0


_RUNS_KEPT = 8  # run tables cached per volume (one per slicing axis and transfer function)


def transparent_runs(volume, axis, bound):
    """First and last sample above ``bound`` in each row of each slice along ``axis``.

    Slices and rows as :meth:`vrlib.Volume.slices` lays them out; the arrays are
    ``[slice, row]``, and ``first > last`` marks a row with nothing above ``bound``. Built
    once per volume, axis and bound and cached on the volume (the preprocessing of Lacroute
    and Levoy's run-length encoding); ``bound`` below every sample gives full rows without
    reading them.

    Examples
    --------
    >>> from vrlib import Volume
    >>> data = np.zeros((3, 3, 4)); data[1, 2, 1:3] = 1.0     # [z, y, x]
    >>> first, last = transparent_runs(Volume(data), 2, 0.5)
    >>> first[1].tolist(), last[1].tolist()                   # slice z = 1, rows y
    ([4, 4, 1], [-1, -1, 2])
    """
    slab = volume.slices(axis)
    n_k, n_j, n_i = slab.shape
    if bound < float(volume.value_range[0]):
        return np.zeros((n_k, n_j), np.int64), np.full((n_k, n_j), n_i - 1, np.int64)
    key = ("runs", axis, float(bound))
    derived = volume._derived
    if key not in derived:
        marks = slab > bound
        seen = marks.any(axis=2)
        first = np.where(seen, marks.argmax(axis=2), n_i).astype(np.int64)
        last = np.where(seen, n_i - 1 - marks[:, :, ::-1].argmax(axis=2), -1).astype(np.int64)
        first.flags.writeable = last.flags.writeable = False
        kept = [k for k in derived if k[0] == "runs"]
        for old in kept[: max(0, len(kept) - _RUNS_KEPT + 1)]:
            del derived[old]
        derived[key] = (first, last)
    return derived[key]
