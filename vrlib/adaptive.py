"""Adaptive steps: per block, the longest step that keeps a ray within an error budget.

A ray caster at step ``ds`` may take, inside a block where the classified field changes
slowly, one sample for ``m`` of its segments (``m`` a power of two): the segment
``[K ds, (K + m) ds)`` with ``K`` a multiple of ``m``, sampled at its middle, with the
opacity of ``m`` segments, ``1 - (1 - alpha)^m`` (eq 1.4). Aligned to the global lattice,
these long segments are the same for every brick and rank.

How far the image can move. A segment of length ``H`` sampled at its middle misses the
integral of a channel ``f`` along it by at most ``osc(f') H^2 / 4``, ``osc(f')`` the most
the channel's rate of change varies along the segment (``f(t) - f(mid) - f'(mid)(t - mid)``
is at most ``osc(f') |t - mid|``): ``osc(f') H / 4`` per unit length of ray. The long
segment and the base step's short ones both miss by at most that (``osc`` grows with ``H``),
so they differ by at most ``osc(f') H / 2`` per unit length; the opacity's share also dims
everything behind, at most ``E`` times as bright (``E``: :func:`vrlib.raycast.brightest`).
For ``f = F(v)``, ``osc(f') <= S osc(v') + T``, with ``S`` the transfer function's steepest
slope and ``T`` the variation of its slope over the block's values
(:func:`transfer_slopes`). Along a ray the tent filter's field bends inside a cell by at
most twice its mixed second differences and kinks at a cell face by its second difference
along that axis: ``osc(v') <= H (M_axis + 2 M_mixed) + sqrt(3) J`` (per world unit, from
:func:`block_differences`); any filter's ``v'`` varies by at most twice its bound ``G``
(:func:`gradient_bounds`), the bound other filters use. A block takes the largest ``m`` (at
most :data:`MAX_MULTIPLIER`) whose rate times the longest chord through the volume stays
within the budget, so every pixel moves by at most the budget from the image at step ``ds``
(each segment's classification taken as exact for its own values, as the base step takes it;
shading and gradient opacity, which vary with the gradient's direction, are not covered and
are refused).
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

from vrlib._kernels.filters import TENT
from vrlib.transfer import range_maximum
from vrlib.value_bounds import value_bounds
from vrlib.volume import block_extremes

__all__ = ["MAX_MULTIPLIER", "BlockDifferences", "block_differences", "derivative_sums",
           "gradient_bounds", "transfer_slopes", "step_multipliers"]

#: The longest step, in base steps: a long segment must fit inside one block of 8 cells.
MAX_MULTIPLIER = 8


@functools.lru_cache(maxsize=64)
def derivative_sums(filt):
    """``(p, r, a)`` of a filter's 1-D weights over every position ``x`` in a cell.

    The derivative of a reconstruction along one axis, ``sum_i f_i k'(x - i)``, is by
    summation by parts ``f_last R - sum_i (f_(i+1) - f_i) K_i`` with ``K_i`` the running
    sums of ``k'(x - j)`` over the taps ``j <= i`` and ``R`` their total: at most
    ``|f| r + max|f_(i+1) - f_i| p``, with ``p = max sum_i |K_i|`` and ``r = max |R|`` (0 for
    a partition of unity, a ripple for the Gaussian); ``a = max sum_i |k(x - i)|`` bounds
    each of the other two axes' weights. Found on a dense grid and widened by 1e-9 relative
    (the filters' derivatives are smooth between the lattice's positions).

    Examples
    --------
    >>> from vrlib import make_filter
    >>> [round(s, 6) for s in derivative_sums(make_filter("trilinear"))]
    [1.0, 0.0, 1.0]
    """
    offsets = np.linspace(0.0, 1.0, 4097)
    reach = int(np.ceil(filt.radius)) + 1
    taps = np.arange(-reach, reach + 1)
    x = offsets[:, None] - taps[None, :]
    slopes = filt.derivative(x)
    running = np.cumsum(slopes, axis=1)
    pad = 1.0 + 1e-9
    return (float(np.abs(running[:, :-1]).sum(axis=1).max() * pad),
            float(np.abs(running[:, -1]).max() * pad),
            float(np.abs(filt(x)).sum(axis=1).max() * pad))


class BlockDifferences(NamedTuple):
    """Per block of a volume (each array on the block grid), the largest magnitudes of its
    samples (``absolute``), their differences along x, y and z (``first``, a tuple), second
    differences along each axis (``second``) and mixed differences of the pairs xy, xz and yz
    (``mixed``), over each block's samples widened by ``margin``."""

    absolute: np.ndarray
    first: tuple
    second: tuple
    mixed: tuple


def _block_max(arr, block, margin, shape, front=0):
    """The largest entry of ``arr`` (padded with zeros to ``shape``: differences past the
    last sample are 0, the border extends; ``front`` of them before the first, so that a
    second difference sits at its middle sample) over each block of ``block`` cells (both
    end samples) widened by ``margin`` samples each side."""
    widths = [(0, n - m) for n, m in zip(shape, arr.shape, strict=True)]
    widths = [(front, w[1] - front) if w[1] else w for w in widths]
    return block_extremes(np.pad(arr, widths), block, np.max, margin=margin)


def block_differences(volume, *, block=8, margin=0):
    """:class:`BlockDifferences` of ``volume``'s samples, built on first use and cached
    with the volume.

    Examples
    --------
    >>> from vrlib import Volume
    >>> z, y, x = np.mgrid[:9, :9, :9]
    >>> d = block_differences(Volume(0.5 * x * x))
    >>> [float(a.max()) for a in d.first], [float(a.max()) for a in d.second]
    ([7.5, 0.0, 0.0], [1.0, 0.0, 0.0])
    """
    def build():
        data = np.asarray(volume.data, dtype=np.float64)
        shape = data.shape

        def most(arr, front=0):
            return _block_max(np.abs(arr), block, margin, shape, front)

        axes = (2, 1, 0)  # x y z
        return BlockDifferences(
            most(data),
            tuple(most(np.diff(data, axis=a)) for a in axes),
            tuple(most(np.diff(data, 2, axis=a), front=1) for a in axes),
            tuple(most(np.diff(np.diff(data, axis=a), axis=b))
                  for a, b in ((2, 1), (2, 0), (1, 0))))

    return volume.cached(("block differences", block, margin), build, keep=2)


def gradient_bounds(volume, filt, *, block=8):
    """A bound on the reconstructed field's gradient magnitude (per world unit) in each
    block of ``volume`` (the samples the filter reconstructs from: a prefiltered filter's
    coefficients), from the largest difference of neighbouring samples along each axis
    (:func:`derivative_sums`).

    Examples
    --------
    >>> from vrlib import Volume, make_filter
    >>> z, y, x = np.mgrid[:9, :9, :9]
    >>> g = gradient_bounds(Volume(0.5 * x + 0.0 * z), make_filter("trilinear"))
    >>> g.shape, round(float(g.max()), 6)    # 0.5 per voxel of 0.25 along x
    ((1, 1, 1), 2.0)
    """
    p, r, a = derivative_sums(filt)
    diffs = block_differences(volume, block=block, margin=filt.margin)
    squares = 0.0
    for first, spacing in zip(diffs.first, volume.spacing, strict=True):
        along = (diffs.absolute * r + first * p) * a * a / spacing
        squares = squares + along * along
    return np.sqrt(squares)


def _bend_bounds(volume, block):
    """For the tent filter, per block: ``(C, J)`` with ``osc(v') <= H C + sqrt(3) J`` over a
    stretch ``H`` of any ray (module docstring; per world unit)."""
    diffs = block_differences(volume, block=block)
    s = volume.spacing
    axis = np.max([d / (h * h) for d, h in zip(diffs.second, s, strict=True)], axis=0)
    pairs = ((0, 1), (0, 2), (1, 2))
    mixed = np.max([d / (s[i] * s[j]) for d, (i, j) in zip(diffs.mixed, pairs, strict=True)],
                   axis=0)
    kink = np.max([d / h for d, h in zip(diffs.second, s, strict=True)], axis=0)
    return axis + 2.0 * mixed, kink


def transfer_slopes(transfer, low, high, value_range, brightest):
    """``(S, T)`` over each value interval ``[low, high]`` (arrays): the steepest slope
    ``S = max(|f'|, |sigma'|) + 2 E |sigma'|`` of the classified channels ``f = E sigma``
    and the density ``sigma`` per unit value, and ``T``, the most those slopes vary there
    (their total variation, kinks included), read from the transfer function's table over
    ``value_range`` (density and emission piecewise linear: ``f`` is piecewise quadratic).

    Examples
    --------
    >>> from vrlib import Glow
    >>> s, t = transfer_slopes(Glow(2.0), np.array([0.2]), np.array([0.5]), (0.0, 1.0), 1.0)
    >>> s.tolist(), t.round(9).tolist()        # sigma = 2 v: slope 2, plus twice 2
    ([6.0], [0.0])
    """
    start, inverse, density, emission = transfer.value_table(*value_range)
    h = 1.0 / inverse
    d_sigma = np.diff(density) / h
    d_emit = np.diff(emission, axis=0) / h
    ends = [d_emit * density[end, None] + emission[end] * d_sigma[:, None]  # (E sigma)'
            for end in (slice(None, -1), slice(1, None))]
    steepest = np.maximum(np.abs(ends[0]), np.abs(ends[1])).max(axis=1)
    steepest = np.maximum(steepest, np.abs(d_sigma)) + 2.0 * brightest * np.abs(d_sigma)
    # The slopes' variation: inside each piece, and the jumps at its nodes.
    inside = np.abs(ends[1] - ends[0]).max(axis=1)
    jump_f = np.abs(ends[0][1:] - ends[1][:-1]).max(axis=1)
    jump_sigma = (1.0 + 2.0 * brightest) * np.abs(np.diff(d_sigma))
    total = np.concatenate([[0.0], np.cumsum(inside)])
    kinks = np.concatenate([[0.0], np.cumsum(np.maximum(jump_f, jump_sigma))])
    n = steepest.shape[0]
    first = np.clip(np.floor((np.asarray(low) - start) * inverse).astype(np.int64), 0, n - 1)
    last = np.clip(np.ceil((np.asarray(high) - start) * inverse).astype(np.int64), 1, n)
    last = np.maximum(last, first + 1)
    variation = total[last] - total[first] + kinks[last - 1] - kinks[first]
    return range_maximum(steepest, first, last), variation


def step_multipliers(volume, filt, transfer, ds, budget, *, value_range, brightest, block=8):
    """Per block of ``volume``, the number of base steps ``ds`` one sample may stand for: the
    largest power of two ``m`` up to :data:`MAX_MULTIPLIER` whose error rate
    ``(S osc(v') + T) m ds / 2`` times the volume's diagonal is at most ``budget`` (module
    docstring); 1 where none is, and in the blocks that reach past the volume's far faces.

    Examples
    --------
    >>> from vrlib import Glow, Volume, make_filter
    >>> z, y, x = np.mgrid[:17, :9, :9]
    >>> def multipliers(data, budget):
    ...     return step_multipliers(Volume(data), make_filter("trilinear"), Glow(1.0), 0.05,
    ...                             budget, value_range=(0.0, 1.0), brightest=1.0)
    >>> multipliers(0.01 * x, 1e-4).ravel().tolist()      # a ramp: integrated exactly
    [8, 8]
    >>> [multipliers(0.01 * x + 0.002 * z * z, b).ravel().tolist() for b in (1e-1, 1e-2)]
    [[4, 4], [1, 1]]
    """
    pyr = volume.minmax_pyramid(block, margin=filt.margin)
    low, high = value_bounds(pyr.minimum[0].astype(np.float64),
                             pyr.maximum[0].astype(np.float64), filt)
    slope, variation = transfer_slopes(transfer, low.ravel(), high.ravel(), value_range,
                                       brightest)
    slope, variation = slope.reshape(low.shape), variation.reshape(low.shape)
    swing = 2.0 * gradient_bounds(volume, filt, block=block)  # osc(v') for any filter
    if filt.code[0] == TENT:
        bend, kink = _bend_bounds(volume, block)
    diagonal = float(np.linalg.norm((np.array(volume.shape[::-1]) - 1) * volume.spacing))
    multiplier = np.ones(low.shape, dtype=np.int64)
    m = 2
    while m <= MAX_MULTIPLIER:
        length = m * ds
        oscillation = swing
        if filt.code[0] == TENT:
            oscillation = np.minimum(swing, length * bend + np.sqrt(3.0) * kink)
        rate = (slope * oscillation + variation) * length / 2.0
        multiplier[rate * diagonal <= budget] = m
        m *= 2
    # A block that reaches past the volume's far face keeps the base step, so that no long
    # segment stands for segments beyond the face.
    for axis, n in enumerate(volume.shape):
        if (n - 1) % block:
            multiplier[(slice(None),) * axis + (-1,)] = 1
    return multiplier
