"""Scale-space error bounds: how well a filter reconstructs a feature of a given size.

The feature is a Gaussian ``f(x) = exp(-x^2 / (2 sigma^2))`` sampled at spacing ``h`` with an
arbitrary grid offset and reconstructed with a filter ``k``: ``R(x) = sum_n f(x_n) k(x - x_n)``.
Its error ``E(sigma / h)`` is the worst case over position and grid offset of
``|R(x) - f(x)| / f(0)`` (the thesis's scale-space idea, chapter 1; the construction is derived in
docs/derivations.md). Two numbers per filter and ratio:

* :func:`feature_error` measures it: a dense search over positions and offsets in 1-D, and in
  3-D the exact worst case over the product of the 1-D searches (see its notes).
* :func:`fourier_bound` bounds it from the filter's frequency response ``K`` (for a prefiltered
  filter its effective response, the kernel's over the sampled kernel's) and the feature's
  spectrum ``F(w) = sigma sqrt(2 pi) exp(-sigma^2 w^2 / 2)`` (``h = 1``, ``w`` in radians per
  sample): passband loss plus aliasing, ``(1/2pi) int |1 - K| |F| + |K| sum_{m != 0}
  |F(w - 2 pi m)| dw``, valid for every position and offset because it drops the phases.

A prefiltered filter reconstructs ``R(x) = sum_n c_n k(x - x_n)`` from the samples'
coefficients (:mod:`vrlib.prefilter`). Filters are separable, so the 3-D feature
``exp(-|x|^2 / 2 sigma^2)`` is reconstructed as the product of three 1-D reconstructions.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from vrlib import validate
from vrlib.filters import make_filter
from vrlib.prefilter import coefficients

__all__ = ["feature_error", "fourier_bound", "required_ratio", "error_samples"]

_OFFSETS = 65  # grid offsets searched over [0, 1/2] (the other half mirrors them)
_PER_SAMPLE = 256  # positions searched per sample spacing
_PERIODS = 300  # periods of the frequency response integrated on each side


def _check(ratio, dims):
    ratio = validate.finite_number("ratio", ratio, low=0.0, low_open=True)
    if dims not in (1, 3):
        raise ValueError(f"dims must be 1 or 3, got {dims!r}")
    return ratio


def error_samples(filt, ratio, *, offsets=_OFFSETS, per_sample=_PER_SAMPLE):
    """The feature and its reconstruction over positions and grid offsets, in 1-D.

    Parameters
    ----------
    filt : Filter or filter name
    ratio : float
        ``sigma / h`` (> 0).
    offsets : int
        Grid offsets in ``[0, 1/2]`` (a mirror image covers the rest).
    per_sample : int
        Positions per sample spacing.

    Returns
    -------
    f, r : ndarray, shape (offsets, positions)
        ``f(x)`` and ``R(x)`` for the feature centred ``offset`` samples from a lattice point.

    Examples
    --------
    >>> f, r = error_samples("trilinear", 1.0, offsets=3, per_sample=4)
    >>> f.shape == r.shape, float(np.abs(r - f).max()) < 0.15
    (True, True)
    """
    filt = make_filter(filt)
    sigma = _check(ratio, 1)
    reach = 7.0 * sigma + filt.radius + 1.0  # beyond it f < 1e-10 and no sample reaches
    x = np.arange(-reach, reach, 1.0 / per_sample)
    centres = np.linspace(0.0, 0.5, offsets)[:, None]
    f = np.exp(-0.5 * ((x - centres) / sigma) ** 2)
    # R(x) = sum_n f(n) k(x - n) over the filter's taps: the weights depend on x alone.
    first = np.floor(x - filt.radius).astype(np.int64) + 1
    lattice = np.arange(first.min(), first.max() + filt.taps)
    samples = np.exp(-0.5 * ((lattice - centres) / sigma) ** 2)
    if filt.prefiltered:  # the feature is below 1e-10 at the lattice's ends: no edge effect
        samples = coefficients(samples, filt.poles, axes=[1])
    r = np.zeros_like(f)
    for tap in range(filt.taps):
        n = first + tap
        r += filt(x - n) * samples[:, n - lattice[0]]
    return f, r


def feature_error(filt, ratio, *, dims=1):
    """Worst-case relative error ``E(sigma / h)`` of reconstructing a Gaussian feature.

    Parameters
    ----------
    filt : Filter or filter name
    ratio : float
        Feature scale over sample spacing, ``sigma / h`` (> 0).
    dims : {1, 3}

    Returns
    -------
    float

    Notes
    -----
    In 1-D, the largest ``|R - f|`` over 65 grid offsets and 256 positions per sample. In 3-D
    the error at a point is ``|R1 R2 R3 - f1 f2 f3|`` with one 1-D pair ``(f_i, R_i)`` per
    axis, each drawn from a 1-D search (9 offsets, 16 positions per sample: the worst cases lie
    at offsets 0 and 1/2 and at lattice points, and a search 16 times denser finds the same
    values to 6 digits for these filters). For two axes
    fixed it is the absolute value of a linear function of the third axis's pair, so its
    maximum over that axis's set lies at a vertex of the set's convex hull; likewise for the
    products of two axes' pairs. The worst
    case over the product of the searches is therefore found exactly from hull vertices.

    Examples
    --------
    >>> round(feature_error("trilinear", 4.0) * 8 * 4.0**2, 1)     # -> h^2 / (8 sigma^2)
    1.0
    >>> feature_error("catmull-rom", 2.0) < feature_error("trilinear", 2.0)
    True
    """
    ratio = _check(ratio, dims)
    if dims == 1:
        f, r = error_samples(filt, ratio)
        return float(np.abs(r - f).max())
    f, r = error_samples(filt, ratio, offsets=9, per_sample=16)
    vertices = _hull(np.column_stack([f.ravel(), r.ravel()]))
    # Pairs of axes: (f1 f2, R1 R2); the third axis meets them linearly, so only the pairs'
    # hull vertices matter.
    pairs = _hull(np.column_stack([np.multiply.outer(vertices[:, 0], vertices[:, 0]).ravel(),
                                   np.multiply.outer(vertices[:, 1], vertices[:, 1]).ravel()]))
    triple = (np.multiply.outer(pairs[:, 1], vertices[:, 1])
              - np.multiply.outer(pairs[:, 0], vertices[:, 0]))
    return float(np.abs(triple).max())


def _hull(points):
    """The vertices of the convex hull of 2-D ``points`` (all of them if they are collinear)."""
    from scipy.spatial import ConvexHull  # a quarter of a second to import: only when needed

    try:
        return points[ConvexHull(points).vertices]
    except Exception:  # degenerate (collinear) sets: scipy's Qhull refuses them
        return np.unique(points, axis=0)


def fourier_bound(filt, ratio, *, dims=1):
    """Upper bound on :func:`feature_error` from the filter's frequency response.

    In 3-D, ``(1 + E1)^3 - 1`` with ``E1`` the 1-D bound: the product error telescopes into
    ``e1 R2 R3 + f1 e2 R3 + f1 f2 e3`` with ``|f| <= 1`` and ``|R| <= 1 + E1``. ``inf`` for
    the box filter, whose response (a sinc) is not absolutely integrable.

    Examples
    --------
    >>> bound, measured = fourier_bound("catmull-rom", 1.0), feature_error("catmull-rom", 1.0)
    >>> measured <= bound < 2 * measured
    True
    """
    filt = make_filter(filt)
    sigma = _check(ratio, dims)
    if filt.name == "box":
        return math.inf

    def spectrum(omega):
        return sigma * math.sqrt(2 * math.pi) * np.exp(-0.5 * (sigma * omega) ** 2)

    # Passband loss: F is negligible beyond 40 / sigma.
    w = np.linspace(-40.0 / sigma, 40.0 / sigma, 20001)
    loss = np.sum(np.abs(1.0 - filt.effective_response(w)) * spectrum(w)) * (w[1] - w[0])
    # Aliasing: w = 2 pi m + t. The sum of every alias, P(t) = sum_m F(t - 2 pi m), is
    # periodic; the aliases of frequency w are P(t) - F(w). |K| is integrated over
    # _PERIODS periods each side, and the tail beyond them estimated from the last period
    # assuming |K| falls as w^-2 (the slowest decay among these filters but the box's).
    t = np.linspace(-math.pi, math.pi, 512, endpoint=False) + math.pi / 512
    m = np.arange(-_PERIODS, _PERIODS + 1)
    near = np.arange(-math.ceil(6.0 / sigma) - 2, math.ceil(6.0 / sigma) + 3)
    periodic = spectrum(t[None, :] - 2 * math.pi * near[:, None]).sum(axis=0)
    omega = 2 * math.pi * m[:, None] + t[None, :]
    alias = np.abs(filt.effective_response(omega)) * np.maximum(periodic - spectrum(omega), 0.0)
    per_period = alias.sum(axis=1) * (t[1] - t[0])
    tail = (per_period[0] + per_period[-1]) * _PERIODS
    bound = float((loss + per_period.sum() + tail) / (2 * math.pi))
    return bound if dims == 1 else (1.0 + bound) ** 3 - 1.0


def required_ratio(filt, target, *, dims=1, low=0.25, high=8.0):
    """Smallest ``sigma / h`` at and beyond which :func:`feature_error` stays at or below
    ``target``: found by walking down a grid of 8 ratios per octave from ``high`` to the first
    ratio whose error is above ``target``, then bisecting. ``inf`` if the error is above
    ``target`` at ``high`` (a filter whose error has a floor, such as a truncated Gaussian's
    ripple); ``low`` if it never rises above it.

    Examples
    --------
    >>> round(required_ratio("trilinear", 0.05), 2)
    1.56
    """
    target = validate.finite_number("target", target, low=0.0, low_open=True)
    filt = make_filter(filt)
    grid = np.geomspace(low, high, int(8 * math.log2(high / low)) + 1)[::-1]
    if _error(filt, float(grid[0]), dims) > target:
        return math.inf
    for above, below in zip(grid[1:], grid[:-1], strict=True):
        if _error(filt, float(above), dims) > target:
            a, b = float(above), float(below)
            for _ in range(12):
                mid = math.sqrt(a * b)
                a, b = (mid, b) if _error(filt, mid, dims) > target else (a, mid)
            return b
    return float(low)


@functools.lru_cache(maxsize=4096)
def _error(filt, ratio, dims):
    return feature_error(filt, ratio, dims=dims)
