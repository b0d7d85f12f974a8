"""Classification tables inside kernels: one linearly interpolated lookup for every renderer.

A table holds values at evenly spaced grid positions (:meth:`vrlib.TransferFunction.
segment_table`, :meth:`~vrlib.TransferFunction.value_table`); a value becomes a grid position
``x = (value - start) * inv`` and is read between its two neighbouring entries.
"""

from __future__ import annotations

from vrlib._kernels._jit import jit


@jit(inline="always")
def lookup(x, n):
    """Left table entry and weight for grid position ``x`` (clamped to a table of ``n``)."""
    if not x > 0.0:  # also catches NaN
        return 0, 0.0
    if x >= n - 1:
        return n - 2, 1.0
    i = int(x)
    return i, x - i


@jit
def interpolate(tab, start, inv, value):
    """1-D table ``tab`` at ``value``, linearly interpolated and clamped."""
    i, w = lookup((value - start) * inv, tab.shape[0])
    return tab[i] + w * (tab[i + 1] - tab[i])


@jit
def interpolate_channel(tab, start, inv, value, channel):
    """Column ``channel`` of the 2-D table ``tab`` at ``value``, as :func:`interpolate`."""
    i, w = lookup((value - start) * inv, tab.shape[0])
    return tab[i, channel] + w * (tab[i + 1, channel] - tab[i, channel])


@jit
def piecewise_linear(xs, ys, x):
    """The piecewise-linear function through points ``(xs, ys)`` (``xs`` increasing) at ``x``,
    constant beyond the ends (as ``numpy.interp``); a short table, searched in order."""
    n = xs.shape[0]
    if not x > xs[0]:  # also catches NaN
        return ys[0]
    for i in range(1, n):
        if x <= xs[i]:
            return ys[i - 1] + (x - xs[i - 1]) / (xs[i] - xs[i - 1]) * (ys[i] - ys[i - 1])
    return ys[n - 1]
