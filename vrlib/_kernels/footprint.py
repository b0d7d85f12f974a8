"""Footprint-table lookups inside kernels: the splatter draws with them, and the roofline
measures the rate they allow. The tables themselves are built by :mod:`vrlib.footprint`
(radial over ``rho^2``, or planar over the image plane's offsets ``(u, v)``)."""

from __future__ import annotations

from vrlib._kernels._jit import jit

RADIAL, PLANAR = 0, 1


@jit(inline="always")
def radial_at(extent, radial, rho2):
    """Radial footprint table (linear in rho^2) at squared distance ``rho2``."""
    n = radial.shape[0]
    x = rho2 / (extent * extent) * (n - 1)
    if x >= n - 1:
        return 0.0
    i = int(x)
    w = x - i
    return radial[i] + w * (radial[i + 1] - radial[i])


@jit(inline="always")
def planar_row(extent_v, planar, v):
    """Row of the planar footprint table at offset ``v``: its index ``j`` and fraction ``ty``
    (``j = -1`` outside the table)."""
    n = planar.shape[0]
    y = (v + extent_v) * ((n - 1) / (2.0 * extent_v))
    if not (y >= 0.0 and y <= n - 1):
        return -1, 0.0
    j = min(int(y), n - 2)
    return j, y - j


@jit(inline="always")
def planar_at(extent, planar, j, ty, u):
    """Planar footprint table, bilinear, at offset ``u`` on the row found by
    :func:`planar_row`."""
    n = planar.shape[0]
    x = (u + extent) * ((n - 1) / (2.0 * extent))
    if not (x >= 0.0 and x <= n - 1):
        return 0.0
    i = min(int(x), n - 2)
    tx = x - i
    return ((1.0 - ty) * ((1.0 - tx) * planar[j, i] + tx * planar[j, i + 1])
            + ty * ((1.0 - tx) * planar[j + 1, i] + tx * planar[j + 1, i + 1]))


@jit(inline="always")
def footprint_at(kind, extent, extent_v, radial, planar, u, v):
    """Footprint at plane offsets (u, v): linear in rho^2 (radial) or bilinear (planar)."""
    if kind == RADIAL:
        return radial_at(extent, radial, u * u + v * v)
    j, ty = planar_row(extent_v, planar, v)
    if j < 0:
        return 0.0
    return planar_at(extent, planar, j, ty, u)
