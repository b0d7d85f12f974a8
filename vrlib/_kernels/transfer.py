"""Transfer-function evaluation inside numba kernels.

A transfer function reaches a kernel as ``(kind, scale, vmin, vmax, density, color)`` (see
:attr:`vrlib.transfer.TransferFunction.code`):

* ``GLOW``: opacity density ``scale * max(value, 0)`` per world unit, white emission (eq 1.9);
* ``TABLE``: densities and colours tabulated at evenly spaced values over ``[vmin, vmax]``,
  linearly interpolated and clamped at the ends.
"""

from __future__ import annotations

from vrlib._kernels._jit import jit

GLOW, TABLE = 0, 1


@jit
def _table_position(vmin, vmax, n, value):
    """Index of the left table entry and the interpolation weight for ``value``."""
    t = (value - vmin) / (vmax - vmin) * (n - 1)
    if not t > 0.0:  # also catches NaN
        return 0, 0.0
    if t >= n - 1:
        return n - 2, 1.0
    i = int(t)
    return i, t - i


@jit
def density(kind, scale, vmin, vmax, dtab, value):
    """Opacity density (per world unit) at a reconstructed ``value``."""
    if kind == GLOW:
        return scale * value if value > 0.0 else 0.0
    i, w = _table_position(vmin, vmax, dtab.shape[0], value)
    return dtab[i] + w * (dtab[i + 1] - dtab[i])


@jit
def emission(kind, vmin, vmax, ctab, value, channel):
    """Emitted colour ``channel`` (0, 1, 2) at a reconstructed ``value``."""
    if kind == GLOW:
        return 1.0
    i, w = _table_position(vmin, vmax, ctab.shape[0], value)
    return ctab[i, channel] + w * (ctab[i + 1, channel] - ctab[i, channel])
