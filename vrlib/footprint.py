"""Splat footprints: the line integral of a voxel's 3-D reconstruction kernel.

A voxel at ``x_i`` contributes ``f_i K(x - x_i)`` to the reconstructed field (eq 1.1), with
``K(p) = prod_a k(p_a / h_a)`` for a separable filter of 1-D kernel ``k`` and spacing ``h``.
Along a ray at perpendicular offset ``(u, v)`` (world units, in the view's right and up
directions) from ``x_i``, that contribution integrates to ``f_i FP(u, v)``, with the footprint
``FP(u, v) = int K(u r + v w + t d) dt``. Summing ``f_i FP`` over the voxels gives the ray's
line integral of the reconstructed field, exactly up to the table's interpolation.

Two kinds of table:

* **radial**: the Gaussian with equal spacing on every axis is made rotation invariant by
  truncating it to a ball of its radius; then ``FP`` depends only on the distance ``rho`` of the
  ray from the voxel, in closed form, and one table (over ``rho^2``) serves every view;
* **planar**: every other filter (and the Gaussian on anisotropic lattices): ``FP`` depends on
  the view direction and is tabulated per view on a ``resolution x resolution`` grid over the
  footprint's extent, by Gauss-Legendre quadrature between the points where the line crosses
  the kernel's knots (exact for the piecewise-polynomial kernels).

Deviation from the ray caster: the ray caster's Gaussian is truncated per axis (a cube), the
splatter's radial one to a ball; with the default radius of 2 voxels and sigma 0.6 their
footprints differ by under 1% of the peak.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from vrlib import validate
from vrlib.filters import Gaussian, make_filter

__all__ = ["Footprint", "footprint", "RADIAL", "PLANAR"]

RADIAL, PLANAR = 0, 1


@dataclass(frozen=True)
class Footprint:
    """A tabulated footprint.

    Attributes
    ----------
    kind : int
        :data:`RADIAL` (table over ``rho^2`` in ``[0, extent^2]``) or :data:`PLANAR` (table over
        ``(v, u)`` in ``[-extent_v, extent_v] x [-extent, extent]``, rows along ``v``).
    extent : float
        World distance (radial), or offset along ``u`` (planar), beyond which the footprint is
        zero.
    extent_v : float
        Planar: the same along ``v`` (the kernel's support projected on the view's up).
    table : ndarray
        The samples: 1-D (radial) or 2-D (planar).
    """

    kind: int
    extent: float
    table: np.ndarray
    extent_v: float = 0.0

    def __call__(self, u, v):
        """Footprint at plane offsets ``(u, v)`` by the table's linear (radial) or bilinear
        (planar) interpolation, as the kernels read it.

        Examples
        --------
        >>> fp = footprint("gaussian", (1.0, 1.0, 1.0), None)
        >>> round(float(fp(0.0, 0.0)) * 2 * np.pi * 0.6**2, 3)   # 2-D Gaussian peak, truncated
        1.0
        """
        u = np.asarray(u, dtype=np.float64)
        v = np.asarray(v, dtype=np.float64)
        n = self.table.shape[0]
        if self.kind == RADIAL:
            pos = (u * u + v * v) / self.extent**2 * (n - 1)
            return np.interp(pos, np.arange(n), self.table, right=0.0)
        x = (u + self.extent) * (n - 1) / (2.0 * self.extent)
        y = (v + self.extent_v) * (n - 1) / (2.0 * self.extent_v)
        inside = (x >= 0) & (x <= n - 1) & (y >= 0) & (y <= n - 1)
        x0 = np.clip(np.floor(x).astype(int), 0, n - 2)
        y0 = np.clip(np.floor(y).astype(int), 0, n - 2)
        tx, ty = x - x0, y - y0
        t = self.table
        value = ((1 - ty) * ((1 - tx) * t[y0, x0] + tx * t[y0, x0 + 1])
                 + ty * ((1 - tx) * t[y0 + 1, x0] + tx * t[y0 + 1, x0 + 1]))
        return np.where(inside, value, 0.0)


def _radial_gaussian(filt, h, resolution):
    """Closed form for the ball-truncated Gaussian: with ``s = sigma h``, ``R = radius h``,
    ``FP(rho) = exp(-rho^2 / 2s^2) s sqrt(2 pi) erf(sqrt(R^2 - rho^2) / (s sqrt 2)) / Z`` where
    ``Z`` normalises the 3-D kernel to ``h^3``."""
    from scipy import special

    s, big_r = filt.sigma * h, filt.radius * h
    # Integral of exp(-r^2 / 2s^2) over the ball of radius R.
    mass = (2 * math.pi * s * s) ** 1.5 * (
        math.erf(big_r / (s * math.sqrt(2)))
        - math.sqrt(2 / math.pi) * (big_r / s) * math.exp(-0.5 * (big_r / s) ** 2)
    )
    rho2 = np.linspace(0.0, big_r * big_r, resolution * resolution)
    chord = np.sqrt(np.maximum(big_r * big_r - rho2, 0.0))
    fp = (np.exp(-rho2 / (2 * s * s)) * s * math.sqrt(2 * math.pi)
          * special.erf(chord / (s * math.sqrt(2))))
    return Footprint(RADIAL, big_r, fp * h**3 / mass)


def _planar(filt, spacing, basis, resolution):
    """Quadrature of the separable kernel along the view direction, split at its knots."""
    right, up, forward = basis
    h = np.asarray(spacing, dtype=np.float64)
    radius = filt.radius
    # The support is the box radius * h; its projections on the plane's axes bound the table.
    extent_u = radius * float(np.abs(right) @ h)
    extent_v = radius * float(np.abs(up) @ h)
    extent = radius * float(np.linalg.norm(h))  # bounds the line's span through the support
    grid_u = np.linspace(-extent_u, extent_u, resolution)
    grid_v = np.linspace(-extent_v, extent_v, resolution)
    # Knots: where the line crosses p_a / h_a = integer or half-integer (box) for some axis.
    knots = np.arange(-math.ceil(radius), math.ceil(radius) + 0.5, 0.5)
    nodes, weights = np.polynomial.legendre.leggauss(12 if isinstance(filt, Gaussian) else 6)
    table = np.empty((resolution, resolution))
    rows = max(1, 2048 // resolution)  # table rows per pass, to bound temporary memory
    for first in range(0, resolution, rows):
        v, u = np.meshgrid(grid_v[first:first + rows], grid_u, indexing="ij")
        base = u[..., None] * right + v[..., None] * up  # world offsets on the plane
        cuts = [np.full(u.shape + (1,), -2 * extent), np.full(u.shape + (1,), 2 * extent)]
        for a in range(3):
            if forward[a] != 0.0:
                cuts.append((knots * h[a] - base[..., a:a + 1]) / forward[a])
        cuts = np.sort(np.clip(np.concatenate(cuts, axis=-1), -2 * extent, 2 * extent), axis=-1)
        lo, hi = cuts[..., :-1], cuts[..., 1:]
        half = 0.5 * (hi - lo)
        t = 0.5 * (lo + hi)[..., None] + half[..., None] * nodes
        kernel = np.ones(t.shape)
        for a in range(3):
            kernel *= filt((base[..., None, None, a] + t * forward[a]) / h[a])
        table[first:first + rows] = np.sum(kernel * weights * half[..., None], axis=(-1, -2))
    return Footprint(PLANAR, extent_u, table, extent_v)


@functools.lru_cache(maxsize=32)
def _cached(filt, spacing, basis, resolution):
    if basis is None:
        return _radial_gaussian(filt, spacing[0], resolution)
    return _planar(filt, spacing, np.array(basis).reshape(3, 3), resolution)


def footprint(filt, spacing, basis, *, resolution=129):
    """The footprint table of a filter on a lattice of ``spacing`` (x, y, z), for a view.

    Parameters
    ----------
    filt : Filter or filter name
    spacing : 3 floats
        World spacing of the lattice.
    basis : ndarray (3, 3) or None
        The view's rows ``right, up, forward``; ``None`` is allowed for the radial Gaussian,
        whose table serves every view.
    resolution : int, default 129
        Table entries per axis (planar; odd puts a node at the centre) or ``resolution^2``
        entries over ``rho^2`` (radial); from 8 to 1024. The interpolation error falls with
        the resolution (as ``1 / resolution`` near the kinks of the tent and cubic footprints,
        ``1 / resolution^2`` where they are smooth).

    Examples
    --------
    >>> import numpy as np
    >>> basis = np.eye(3)[[0, 1, 2]]
    >>> fp = footprint("trilinear", (1.0, 1.0, 1.0), basis)
    >>> round(float(fp(0.0, 0.0)), 6)      # int of tent(t) dt over t: 1
    1.0
    """
    filt = make_filter(filt)
    resolution = validate.positive_int("footprint resolution", resolution, minimum=8)
    if resolution > 1024:
        raise ValueError(f"footprint resolution must be at most 1024, got {resolution}")
    spacing = tuple(float(s) for s in spacing)
    radial = isinstance(filt, Gaussian) and len(set(spacing)) == 1
    if basis is None:
        if not radial:
            raise ValueError("only the Gaussian on an even lattice has a view-independent table")
        key = None
    else:
        key = tuple(np.asarray(basis, dtype=np.float64).ravel().round(15))
    return _cached(filt, spacing, None if radial else key, resolution)
