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

import numba
import numpy as np

from vrlib import validate
from vrlib._kernels import footprint as _kernel
from vrlib._scheduling import on_threads
from vrlib.filters import Gaussian, make_filter

__all__ = ["Footprint", "footprint", "Slanted", "slanted", "running_integral", "RADIAL",
           "PLANAR"]

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
    table : ndarray
        The samples: 1-D (radial) or 2-D (planar).
    extent_v : float
        Planar: the same along ``v`` (the kernel's support projected on the view's up).
    partial : ndarray or None
        Planar: ``partial[j, i, m]``, the line integral from the support's start to ``s_m``
        (``s`` over ``[-extent_s, extent_s]`` along the view, from the point of the line
        nearest the voxel), on a ``(v, u)`` grid over the same extents (at most 129 a side);
        the last entry is the whole footprint. Clipped footprints (a line that leaves the
        volume inside the kernel's support, or a slab of the line) are differences of two
        entries.
    extent_s : float
        Reach of the support along the line.
    sigma : float
        Radial: the Gaussian's standard deviation in world units (partial integrals of the
        radial footprint are in closed form).
    """

    kind: int
    extent: float
    table: np.ndarray
    extent_v: float = 0.0
    partial: np.ndarray | None = None
    extent_s: float = 0.0
    sigma: float = 0.0

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

    def between(self, u, v, s_lo, s_hi, rho2=None):
        """The footprint at plane offsets ``(u, v)`` counting only the stretch ``[s_lo, s_hi]``
        of the line (``s`` from the line's point nearest the voxel), as the kernels read it:
        trilinear in the partial table (planar) or the closed form times the radial table.
        ``rho2`` is the squared distance of the line from the voxel (radial; default
        ``u^2 + v^2``).

        Examples
        --------
        >>> import numpy as np
        >>> fp = footprint("trilinear", (1.0, 1.0, 1.0), np.eye(3))
        >>> whole = float(fp.between(0.0, 0.0, -np.inf, np.inf))
        >>> front = float(fp.between(0.0, 0.0, -np.inf, 0.0))
        >>> round(whole, 6), round(front / whole, 6)   # half of a symmetric kernel
        (1.0, 0.5)
        """
        from scipy.special import erf

        u, v, s_lo, s_hi = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64)
                                                 for a in (u, v, s_lo, s_hi)))
        lo = np.clip(s_lo, -self.extent_s, self.extent_s)
        hi = np.clip(s_hi, -self.extent_s, self.extent_s)
        if self.kind == RADIAL:
            rho2 = u * u + v * v if rho2 is None else np.asarray(rho2, dtype=np.float64)
            n = self.table.shape[0]
            whole = np.interp(rho2 / self.extent**2 * (n - 1), np.arange(n), self.table,
                              right=0.0)
            chord = np.sqrt(np.maximum(self.extent**2 - rho2, 0.0))
            scale = 1.0 / (self.sigma * np.sqrt(2.0))
            a, b = np.clip(lo, -chord, chord), np.clip(hi, -chord, chord)
            with np.errstate(invalid="ignore", divide="ignore"):
                share = (erf(b * scale) - erf(a * scale)) / (2.0 * erf(chord * scale))
            return np.where((hi > lo) & (b > a), whole * share, 0.0)
        nv, nu, ns = self.partial.shape
        x = (u + self.extent) * (nu - 1) / (2.0 * self.extent)
        y = (v + self.extent_v) * (nv - 1) / (2.0 * self.extent_v)
        inside = (x >= 0) & (x <= nu - 1) & (y >= 0) & (y <= nv - 1) & (hi > lo)
        i = np.clip(np.floor(x).astype(int), 0, nu - 2)
        j = np.clip(np.floor(y).astype(int), 0, nv - 2)
        tx, ty = x - i, y - j

        def running(s):
            z = (s + self.extent_s) * (ns - 1) / (2.0 * self.extent_s)
            m = np.clip(np.floor(z).astype(int), 0, ns - 2)
            tz = np.clip(z - m, 0.0, 1.0)
            p = self.partial

            def at(jj, ii):
                return (1.0 - tz) * p[jj, ii, m] + tz * p[jj, ii, m + 1]
            value = ((1.0 - ty) * ((1.0 - tx) * at(j, i) + tx * at(j, i + 1))
                     + ty * ((1.0 - tx) * at(j + 1, i) + tx * at(j + 1, i + 1)))
            return np.where(z > 0.0, value, 0.0)
        return np.where(inside, running(hi) - running(lo), 0.0)


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
    return Footprint(RADIAL, big_r, fp * h**3 / mass, extent_s=big_r, sigma=s)


def _planar(filt, spacing, basis, resolution):
    """Partial line integrals of the separable kernel along the view, on a grid over the
    plane and along the line (:func:`vrlib._kernels.footprint.partial_table`); the whole
    footprint is the last entry."""
    right, up, _ = basis
    h = np.asarray(spacing, dtype=np.float64)
    # The support is the box radius * h; its projections on the plane's axes bound the table,
    # and its circumscribed ball bounds the line's stretch through it.
    extent_u = filt.radius * float(np.abs(right) @ h)
    extent_v = filt.radius * float(np.abs(up) @ h)
    extent_s = filt.radius * float(np.linalg.norm(h))
    nodes, weights = np.polynomial.legendre.leggauss(6)  # stretches are under 0.11 h long

    def build(entries, stretches):
        table = np.empty((entries, entries, stretches + 1))
        _on_rows(_kernel.partial_table, (*filt.code, float(filt.radius), h,
                                          np.ascontiguousarray(basis).ravel(), extent_u,
                                          extent_v, extent_s, nodes, weights, table),
                 12 * math.ceil(filt.radius) + 3)
        return table

    # The partial table (clipped footprints) stops at 129 x 129 x 65 (8.6 MB); a finer whole
    # footprint is built on its own grid.
    partial = build(min(resolution, 129), min(resolution // 2, 64))
    whole = partial[..., -1] if resolution <= 129 else build(resolution, 1)[..., -1]
    return Footprint(PLANAR, extent_u, np.ascontiguousarray(whole), extent_v, partial, extent_s)


@dataclass(frozen=True)
class Slanted:
    """Footprints of a separable kernel for lines of any direction, in index units: the
    view-independent table that perspective splatting reads, one ray at a time.

    A line that crosses the plane of a voxel's slice (perpendicular to the slicing axis) at
    in-plane offsets ``(bp, bq)`` from the voxel, and moves ``(mp, mq)`` in-plane per unit along
    the axis (all in voxels), has the line integral ``int k(s) k(bp + mp s) k(bq + mq s) ds``
    (times ``h_a / |d_a|`` in world units, for the spacing ``h_a`` and the direction's component
    ``d_a`` along the axis).

    Attributes
    ----------
    table : ndarray (nm, nm, nb, nb) float32
        Indexed ``[mp, mq, bp, bq]``, slopes over ``[-slope, slope]`` and offsets over
        ``[-reach, reach]``.
    reach, slope : float
    """

    table: np.ndarray
    reach: float
    slope: float

    def __call__(self, bp, bq, mp, mq):
        """The table's interpolation, linear in each of the four arguments, as the kernel
        reads it (slopes clamped to the table).

        Examples
        --------
        >>> table = slanted("trilinear", 0.5)
        >>> round(float(table(0.0, 0.0, 0.0, 0.0)), 6)    # along the axis: int tent = 1
        1.0
        """
        nm, nb = self.table.shape[0], self.table.shape[2]
        bp, bq, mp, mq = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64)
                                               for v in (bp, bq, mp, mq)))
        x = (bp + self.reach) * ((nb - 1) / (2.0 * self.reach))
        y = (bq + self.reach) * ((nb - 1) / (2.0 * self.reach))
        inside = (x >= 0) & (x <= nb - 1) & (y >= 0) & (y <= nb - 1)
        u = np.clip((mp + self.slope) * ((nm - 1) / (2.0 * self.slope)), 0.0, nm - 1.0)
        w = np.clip((mq + self.slope) * ((nm - 1) / (2.0 * self.slope)), 0.0, nm - 1.0)
        i, j = (np.clip(np.floor(v).astype(int), 0, nb - 2) for v in (x, y))
        a, b = (np.clip(np.floor(v).astype(int), 0, nm - 2) for v in (u, w))
        tx, ty, tu, tw = x - i, y - j, u - a, w - b
        total = np.zeros(x.shape)
        for da, fa in ((0, 1.0 - tu), (1, tu)):
            for db, fb in ((0, 1.0 - tw), (1, tw)):
                t = self.table
                ma, mb = a + da, b + db
                total += fa * fb * ((1.0 - tx) * ((1.0 - ty) * t[ma, mb, i, j]
                                                  + ty * t[ma, mb, i, j + 1])
                                    + tx * ((1.0 - ty) * t[ma, mb, i + 1, j]
                                            + ty * t[ma, mb, i + 1, j + 1]))
        return np.where(inside, total, 0.0)


#: Grid steps of the slanted table: offsets (voxels) and slopes, each coarsened where needed
#: to keep at most 193 offsets and 17 slopes a side (43 MB in float32).
SLANTED_OFFSET_STEP, SLANTED_SLOPE_STEP = 1.0 / 16.0, 0.15


@functools.lru_cache(maxsize=4)
def _slanted(filt, slope):
    reach = filt.radius * (1.0 + slope)
    nb = min(2 * math.ceil(reach / SLANTED_OFFSET_STEP) + 1, 193)
    nm = min(2 * math.ceil(slope / SLANTED_SLOPE_STEP) + 1, 17)
    table = np.empty((nm, nm, nb, nb), np.float32)
    nodes, weights = np.polynomial.legendre.leggauss(5)  # exact for cubic x cubic x cubic
    _on_rows(_kernel.slanted_table,
             (*filt.code, float(filt.radius), reach, slope, nodes, weights, table),
             12 * math.ceil(filt.radius) + 5)
    return Slanted(table, reach, slope)


def _on_rows(kernel, arguments, cuts):
    """Fill a table with ``kernel(*arguments, counter, scratch)`` on every thread at once,
    each taking the table's next row from the shared ``counter``, with scratch of its own
    for ``cuts`` floats (a line's cuts; a cache line apart from the next thread's)."""
    threads = numba.get_num_threads()
    counter = np.zeros(1, np.int64)
    scratch = np.zeros((threads, cuts + 8))
    on_threads(lambda i: kernel(*arguments, counter, scratch[i]), threads)


def slanted(filt, slope):
    """The :class:`Slanted` table of a separable filter for slopes up to ``slope``, rounded up
    to a quarter so that nearby views share one table (cached, four at a time).

    Parameters
    ----------
    filt : Filter or filter name
    slope : float
        Largest in-plane move per unit along the slicing axis (index units) of the lines the
        table serves, from 0 to 4; beyond about 2 the slopes' grid coarsens (17 a side).
    """
    filt = make_filter(filt)
    slope = validate.finite_number("slope", slope, low=0.0, high=4.0)
    return _slanted(filt, max(0.25, math.ceil(slope * 4.0) / 4.0))


@functools.lru_cache(maxsize=32)
def running_integral(filt, entries=2049):
    """The 1-D kernel's running integral ``int_{-r}^x k`` on ``entries`` points over
    ``[-r, r]`` (``r`` the radius), each cell integrated by 4-point Gauss-Legendre (exact for
    the piecewise cubics, whose knots fall on the grid): the share of a ray that a slice of
    voxels stands for.

    Examples
    --------
    >>> table = running_integral(make_filter("trilinear"), 5)
    >>> table.tolist()                       # tent over [-1, 1] at -1, -0.5, 0, 0.5, 1
    [0.0, 0.125, 0.5, 0.875, 1.0]
    """
    filt = make_filter(filt)
    edges = np.linspace(-filt.radius, filt.radius, entries)
    nodes, weights = np.polynomial.legendre.leggauss(4)
    half = 0.5 * (edges[1] - edges[0])
    points = 0.5 * (edges[:-1] + edges[1:])[:, None] + half * nodes
    cells = (filt(points.ravel()).reshape(points.shape) * weights).sum(axis=1) * half
    return np.concatenate([[0.0], np.cumsum(cells)])


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
