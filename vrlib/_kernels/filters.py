"""1-D reconstruction-filter weights for use inside numba kernels.

A filter reaches a kernel as plain scalars ``(kind, p0, p1, p2)`` (see
:attr:`vrlib.filters.Filter.code`), so one compiled kernel serves every filter:

============  ==========================================================
kind          parameters
============  ==========================================================
``BOX``       none: 1 on [-1/2, 1/2)
``TENT``      none: ``max(0, 1 - |x|)`` (the pyramid / trilinear filter)
``GAUSSIAN``  ``p0`` sigma, ``p1`` truncation radius, ``p2`` 1/normaliser
``CUBIC``     ``p0`` B, ``p1`` C of the Mitchell-Netravali family
============  ==========================================================
"""

from __future__ import annotations

import math

from vrlib._kernels._jit import jit

BOX, TENT, GAUSSIAN, CUBIC = 0, 1, 2, 3


@jit
def weight(kind, p0, p1, p2, x):
    """Filter weight at offset ``x`` (voxels) from a sample."""
    if kind == TENT:
        ax = abs(x)
        return 1.0 - ax if ax < 1.0 else 0.0
    if kind == CUBIC:
        b, c = p0, p1
        ax = abs(x)
        if ax < 1.0:
            return (
                (12.0 - 9.0 * b - 6.0 * c) * ax * ax * ax
                + (-18.0 + 12.0 * b + 6.0 * c) * ax * ax
                + (6.0 - 2.0 * b)
            ) / 6.0
        if ax < 2.0:
            return (
                (-b - 6.0 * c) * ax * ax * ax
                + (6.0 * b + 30.0 * c) * ax * ax
                + (-12.0 * b - 48.0 * c) * ax
                + (8.0 * b + 24.0 * c)
            ) / 6.0
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
        if x == 0.0 or abs(x) >= 1.0:
            return 0.0
        return -1.0 if x > 0.0 else 1.0
    if kind == CUBIC:
        b, c = p0, p1
        ax = abs(x)
        sign = 1.0 if x >= 0.0 else -1.0
        if ax < 1.0:
            return sign * (
                3.0 * (12.0 - 9.0 * b - 6.0 * c) * ax * ax
                + 2.0 * (-18.0 + 12.0 * b + 6.0 * c) * ax
            ) / 6.0
        if ax < 2.0:
            return sign * (
                3.0 * (-b - 6.0 * c) * ax * ax
                + 2.0 * (6.0 * b + 30.0 * c) * ax
                + (-12.0 * b - 48.0 * c)
            ) / 6.0
        return 0.0
    if kind == GAUSSIAN:
        if abs(x) < p1:
            return -x / (p0 * p0) * math.exp(-0.5 * (x / p0) ** 2) * p2
        return 0.0
    return 0.0
