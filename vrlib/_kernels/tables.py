"""Classification tables inside kernels: one linearly interpolated lookup for every renderer.

A table holds values at evenly spaced grid positions (:meth:`vrlib.TransferFunction.
segment_table`, :meth:`~vrlib.TransferFunction.value_table`); a value becomes a grid position
``x = (value - start) * inv`` and is read between its two neighbouring entries.
"""

from __future__ import annotations

from vrlib._kernels._jit import at, helper_jit, jit


@jit(inline="always")
def lookup(x, n):
    """Left table entry and weight for grid position ``x`` (clamped to a table of ``n``)."""
    if not x > 0.0:  # also catches NaN
        return 0, 0.0
    if x >= n - 1:
        return n - 2, 1.0
    i = int(x)
    return i, x - i


@jit(inline="always")
def entry(tab, i, w):
    """1-D table ``tab`` at grid position ``i + w`` (``i, w`` from :func:`lookup`, so both
    neighbours lie inside it: read without numba's test for a negative index)."""
    return at(tab, i) + w * (at(tab, i + 1) - at(tab, i))


@jit(inline="always")
def entry_channel(tab, i, w, channel):
    """Column ``channel`` of the 2-D table ``tab`` at grid position ``i + w``, as
    :func:`entry`."""
    return at(tab, (i, channel)) + w * (at(tab, (i + 1, channel)) - at(tab, (i, channel)))


@helper_jit
def interpolate(tab, start, inv, value):
    """1-D table ``tab`` at ``value``, linearly interpolated and clamped."""
    i, w = lookup((value - start) * inv, tab.shape[0])
    return entry(tab, i, w)


@helper_jit
def interpolate_channel(tab, start, inv, value, channel):
    """Column ``channel`` of the 2-D table ``tab`` at ``value``, as :func:`interpolate`."""
    i, w = lookup((value - start) * inv, tab.shape[0])
    return entry_channel(tab, i, w, channel)


@helper_jit
def interpolate_rgb(tab, start, inv, value):
    """Columns 0, 1 and 2 of the 2-D table ``tab`` at ``value``, as :func:`interpolate`: one
    compiled function (:func:`interpolate_channel` called with the constants 0, 1 and 2 is
    compiled once for each, as numba specialises a call on a literal integer)."""
    i, w = lookup((value - start) * inv, tab.shape[0])
    return entry_channel(tab, i, w, 0), entry_channel(tab, i, w, 1), entry_channel(tab, i, w, 2)


@helper_jit
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
