"""1-D reconstruction-filter weights for use inside numba kernels.

A filter reaches a kernel as plain scalars ``(kind, p0, p1, p2)`` (see
:attr:`vrlib.filters.Filter.code`, which derives them from the filter's one definition in
:mod:`vrlib.filters`), so one compiled kernel serves every filter:

============  ==========================================================
kind          parameters
============  ==========================================================
``BOX``       none: 1 on [-1/2, 1/2)
``TENT``      none: ``max(0, 1 - |x|)`` (the pyramid / trilinear filter)
``GAUSSIAN``  ``p0`` sigma, ``p1`` truncation radius, ``p2`` 1/normaliser
``CUBIC``     ``p0`` B, ``p1`` C of the Mitchell-Netravali family, plus ``p2`` times the
              cubic B-spline's second derivative (0 for the family itself; 1/42 with
              ``B = 1, C = 0`` is the cubic O-MOMS)
============  ==========================================================
"""

from __future__ import annotations

import math

from vrlib._kernels._jit import helper_jit, jit

BOX, TENT, GAUSSIAN, CUBIC = 0, 1, 2, 3
#: Most taps per axis a kernel takes (scratch arrays hold this many): filter radii up to 4.
MAX_TAPS = 8


@jit
def cubic_coefficients(b, c, d):
    """The two cubic pieces, times 6, in ascending powers of ``|x|`` (``near`` on [0, 1),
    ``far`` on [1, 2)) of the Mitchell-Netravali (B, C) kernel (Mitchell and Netravali 1988)
    plus ``d`` times the cubic B-spline's second derivative (``3|x| - 2`` near, ``2 - |x|``
    far). The one definition of the piecewise cubics: :class:`vrlib.filters.MitchellNetravali`,
    :class:`vrlib.filters.OMOMS` (``b, c, d = 1, 0, 1/42``; Blu, Thevenaz and Unser 2001) and
    every kernel read it. With ``d = 0`` the pieces are the family's, to the bit."""
    near = (6.0 - 2.0 * b - 12.0 * d, 18.0 * d, -18.0 + 12.0 * b + 6.0 * c,
            12.0 - 9.0 * b - 6.0 * c)
    far = (8.0 * b + 24.0 * c + 12.0 * d, -12.0 * b - 48.0 * c - 6.0 * d, 6.0 * b + 30.0 * c,
           -b - 6.0 * c)
    return near, far


@helper_jit
def cubic_piece(p, x):
    """A cubic piece of :func:`cubic_coefficients` at ``x >= 0`` (still times 6)."""
    return p[3] * x * x * x + p[2] * x * x + p[1] * x + p[0]


@helper_jit
def cubic_piece_slope(p, x):
    """The derivative of :func:`cubic_piece` at ``x`` (still times 6)."""
    return 3.0 * p[3] * x * x + 2.0 * p[2] * x + p[1]


@helper_jit
def tent_weight(x):
    """The tent filter's weight at offset ``x``: :func:`weight` for ``TENT`` alone, which a
    tent kernel calls without compiling the other filters' branches."""
    ax = abs(x)
    return 1.0 - ax if ax < 1.0 else 0.0


@helper_jit
def tent_derivative(x):
    """:func:`derivative` for ``TENT`` alone, as :func:`tent_weight`."""
    if x == 0.0 or abs(x) >= 1.0:
        return 0.0
    return -1.0 if x > 0.0 else 1.0


@jit
def weight(kind, p0, p1, p2, x):
    """Filter weight at offset ``x`` (voxels) from a sample."""
    if kind == TENT:
        return tent_weight(x)
    if kind == CUBIC:
        near, far = cubic_coefficients(p0, p1, p2)
        ax = abs(x)
        if ax < 1.0:
            return cubic_piece(near, ax) / 6.0
        if ax < 2.0:
            return cubic_piece(far, ax) / 6.0
        return 0.0
    if kind == GAUSSIAN:
        if abs(x) < p1:
            return math.exp(-0.5 * (x / p0) ** 2) * p2
        return 0.0
    # BOX: half-open so that neighbouring boxes tile the line exactly once.
    return 1.0 if -0.5 <= x < 0.5 else 0.0


@jit
def derivative(kind, p0, p1, p2, x):
    """Derivative of :func:`weight` with respect to ``x`` (zero where it is undefined)."""
    if kind == TENT:
        return tent_derivative(x)
    if kind == CUBIC:
        near, far = cubic_coefficients(p0, p1, p2)
        ax = abs(x)
        sign = 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)  # 0 at O-MOMS's kink
        if ax < 1.0:
            return sign * cubic_piece_slope(near, ax) / 6.0
        if ax < 2.0:
            return sign * cubic_piece_slope(far, ax) / 6.0
        return 0.0
    if kind == GAUSSIAN:
        if abs(x) < p1:
            return -x / (p0 * p0) * math.exp(-0.5 * (x / p0) ** 2) * p2
        return 0.0
    return 0.0
