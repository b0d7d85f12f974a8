"""Bounds on reconstructed values: what a filter can make of samples within a range.

With weights ``w`` at a point, the reconstruction ``R = sum w f`` of samples ``f`` in
``[m, M]`` lies within ``c * sum(w) +- sum(|w|) * h``, where ``c = (m + M) / 2`` and
``h = (M - m) / 2``. The extreme sums over every position are the filter's *lattice sums*
(:func:`lattice_sums`): for filters with negative lobes (Catmull-Rom, Mitchell) they allow for
overshoot, for the Gaussian, whose weights do not sum to one, for its ripple. Classification
tables span these bounds (:func:`reconstructed_range`), and empty-space skipping
(:mod:`vrlib.skipping`) tests blocks against them.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from vrlib.prefilter import coefficients

__all__ = ["lattice_sums", "value_bounds", "subset_bounds", "reconstructed_range"]

_CARDINAL_REACH = 24  # samples a cardinal kernel is summed over each side (|p|^24 < 1e-11)


def _weights(filt, offsets, cardinal):
    """Weights at ``offsets`` in [0, 1] of every lattice point the reconstruction reaches:
    the kernel's, or with ``cardinal`` a prefiltered filter's cardinal kernel
    ``eta(x) = sum_j c_j k(x - j)``, ``c`` the prefiltered unit impulse."""
    if not (cardinal and filt.prefiltered):
        taps = np.arange(-math.ceil(filt.radius) - 1, math.ceil(filt.radius) + 2)
        return filt(offsets[:, None] - taps[None, :])
    reach = _CARDINAL_REACH
    impulse = coefficients(np.eye(1, 2 * reach + 1, reach)[0], filt.poles)
    taps = np.arange(-reach - 3, reach + 4)
    x = offsets[:, None] - taps[None, :]
    return sum(c * filt(x - (j - reach)) for j, c in enumerate(impulse))


@functools.lru_cache(maxsize=64)
def lattice_sums(filt, *, cardinal=False):
    """``(s_min, s_max, a_max)`` of a filter's 3-D weights over every position.

    ``s`` is the sum of the weights (1 for filters that form a partition of unity) and ``a``
    the sum of their absolute values; 3-D values are the cubes of the 1-D ones, as the filters
    are separable. Found on a dense grid of offsets and widened by 1e-9 relative, which bounds
    the grid's error for these smooth sums.

    Parameters
    ----------
    filt : Filter
    cardinal : bool, default False
        For a prefiltered filter, the sums of the reconstruction from the samples (its
        cardinal kernel, prefilter included) instead of its kernel's (which reconstructs from
        coefficients).

    Examples
    --------
    >>> from vrlib import make_filter
    >>> s_min, s_max, a_max = lattice_sums(make_filter("trilinear"))
    >>> round(s_min, 6), round(s_max, 6), round(a_max, 6)
    (1.0, 1.0, 1.0)
    >>> lattice_sums(make_filter("catmull-rom"))[2] > 1.0     # negative lobes
    True
    >>> [round(lattice_sums(make_filter("cardinal-bspline"), cardinal=c)[2] ** (1 / 3), 4)
    ...  for c in (False, True)]                             # the interpolating spline rings
    [1.0, 1.549]
    """
    offsets = np.linspace(0.0, 1.0, 4097)
    w = _weights(filt, offsets, cardinal)
    s = w.sum(axis=1)
    a = np.abs(w).sum(axis=1)
    pad = 1.0 + 1e-9
    return float(s.min() ** 3 / pad), float(s.max() ** 3 * pad), float(a.max() ** 3 * pad)


def value_bounds(low, high, filt, *, cardinal=False):
    """Bounds ``(lo, hi)`` on every value ``filt``'s kernel reconstructs from values within
    ``[low, high]`` (floats or arrays of them, elementwise); with ``cardinal``, what a
    prefiltered filter reconstructs from samples within it (:func:`lattice_sums`).

    Examples
    --------
    >>> from vrlib import make_filter
    >>> value_bounds(0.0, 1.0, make_filter("trilinear"))
    (0.0, 1.0)
    >>> lo, hi = value_bounds(0.0, 1.0, make_filter("catmull-rom"))
    >>> bool(lo < 0.0 and hi > 1.0)                           # overshoot
    True
    """
    s_min, s_max, a_max = lattice_sums(filt, cardinal=cardinal)
    centre, half = 0.5 * (low + high), 0.5 * (high - low)
    lo = np.minimum(centre * s_min, centre * s_max) - a_max * half
    hi = np.maximum(centre * s_min, centre * s_max) + a_max * half
    if np.ndim(lo) == 0:
        return float(lo), float(hi)
    return lo, hi


def subset_bounds(low, high, filt):
    """Bounds ``(lo, hi)`` on ``sum_{j in S} w_j f_j`` for every subset ``S`` of the samples
    that ``filt``'s kernel weights at one point, with the samples within ``[low, high]``
    (floats or arrays): what a splatter's sheet can hold at a point when some voxels are not
    drawn. The weights' positive and negative parts sum to at most ``(a + s_max) / 2`` and
    ``(a - s_min) / 2`` (:func:`lattice_sums`).

    Examples
    --------
    >>> from vrlib import make_filter
    >>> [round(b, 6) for b in subset_bounds(0.2, 0.5, make_filter("trilinear"))]
    [0.0, 0.5]
    >>> lo, hi = subset_bounds(0.2, 0.5, make_filter("catmull-rom"))
    >>> bool(lo < 0.0 and hi > 0.5)                            # negative lobes
    True
    """
    s_min, s_max, a_max = lattice_sums(filt)
    positive, negative = 0.5 * (a_max + s_max), max(0.5 * (a_max - s_min), 0.0)
    low, high = np.minimum(low, 0.0), np.maximum(high, 0.0)
    lo = positive * low - negative * high
    hi = positive * high - negative * low
    if np.ndim(lo) == 0:
        return float(lo), float(hi)
    return lo, hi


def reconstructed_range(volume, filt, *, cardinal=False):
    """Bounds on every value ``filt`` can reconstruct from ``volume`` (``cardinal``: from its
    samples through the prefilter, :func:`value_bounds`)."""
    return value_bounds(*volume.value_range, filt, cardinal=cardinal)
