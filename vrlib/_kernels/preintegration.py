"""Pre-integrated classification tables (Röttger et al. 2000; Engel, Kraus and Ertl 2001).

A segment of length ``L`` along which the field runs linearly from a front value ``a`` to a
back value ``b`` has, under the emission-absorption model (eqs 1.2-1.5, self-attenuation
included), optical depth and colour

    tau = L (Psi(b) - Psi(a)) / (b - a),        Psi(v) = int^v Omega
    C   = int E(v) exp(-tau(v)) dtau(v),         tau(v) = L (Psi(v) - Psi(a)) / (b - a)

The transfer function's density and emission are piecewise linear in value between the nodes
of its value grid (kinks on nodes, :meth:`vrlib.TransferFunction.value_table`), so ``Psi`` and
``Phi(v) = int^v E Omega`` are exact piecewise polynomials there.

* The opacity needs ``Psi`` alone: kernels evaluate it exactly from the value grid's density
  and its running integral (:func:`psi_at`), and take the mean density
  ``(Psi(b) - Psi(a)) / (b - a)`` (the density at the middle where ``a`` and ``b`` are too
  close for the difference), so the opacity is exact however steep the transfer function
  and whatever the two values.
* The colour needs a table over (front, back): :func:`mean_emission_table` stores the
  segment's colour over its opacity, the emission averaged with the weights the segment's
  light has. It evaluates ``Psi`` and ``Phi`` exactly at ``refine`` points per table cell;
  between two such points it takes the emission as its density-weighted mean ``dPhi / dPsi``
  with the attenuation exact, a second-order rule in the point spacing.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from vrlib._kernels._jit import jit, parallel_jit
from vrlib._kernels.tables import lookup


@jit
def cumulative_at(grid, density, emission, points, psi, phi):
    """``Psi`` and ``Phi`` (per colour channel) at increasing ``points`` inside ``grid``'s
    span: the integrals from ``grid[0]`` of the piecewise-linear density and of density times
    the piecewise-linear emission, exact (a quadratic and a cubic per grid cell)."""
    m = 0
    acc_psi = 0.0
    acc_phi = np.zeros(3)
    n = grid.shape[0]
    for q in range(points.shape[0]):
        u = points[q]
        while m < n - 2 and u > grid[m + 1]:
            dv = grid[m + 1] - grid[m]
            acc_psi += 0.5 * dv * (density[m] + density[m + 1])
            for c in range(3):
                e0, e1 = emission[m, c], emission[m + 1, c]
                o0, o1 = density[m], density[m + 1]
                acc_phi[c] += dv * (e0 * o0 / 3.0 + (e0 * o1 + e1 * o0) / 6.0 + e1 * o1 / 3.0)
            m += 1
        dv = grid[m + 1] - grid[m]
        x = min(max(u - grid[m], 0.0), dv)
        o0 = density[m]
        do = (density[m + 1] - o0) / dv
        psi[q] = acc_psi + o0 * x + 0.5 * do * x * x
        for c in range(3):
            e0 = emission[m, c]
            de = (emission[m + 1, c] - e0) / dv
            phi[q, c] = acc_phi[c] + e0 * o0 * x + 0.5 * (e0 * do + de * o0) * x * x \
                + de * do * x * x * x / 3.0


@parallel_jit
def mean_emission_table(psi, phi, emission_at, refine, length, out):
    """Fill ``out[i, j]`` with the colour over the opacity of a segment of ``length`` whose
    field runs linearly from table value ``i`` to table value ``j``: the emission averaged
    with the weights of the light the segment sends (``emission_at[i]`` on the diagonal, a
    constant field, and where the segment is transparent). ``psi`` and ``phi`` hold the
    cumulative integrals at ``refine`` points per table cell, and ``length`` is divided by
    the value spacing of those points."""
    n = out.shape[0]
    for i in prange(n):
        a = i * refine
        for j in range(n):
            b = j * refine
            scale = length / (b - a) if j != i else 0.0  # L / (value b - value a)
            tau = scale * (psi[b] - psi[a])
            if j == i or not tau > 0.0:
                for c in range(3):
                    out[i, j, c] = emission_at[i, c] if j == i else 0.5 * (
                        emission_at[i, c] + emission_at[j, c])
                continue
            step = 1 if j > i else -1
            seen = 1.0  # transparency in front of the current piece
            r = 0.0
            g = 0.0
            bl = 0.0
            q = a
            while q != b:
                dpsi = psi[q + step] - psi[q]
                if dpsi != 0.0:
                    piece = -math.expm1(-scale * dpsi)
                    weight = seen * piece / dpsi
                    r += weight * (phi[q + step, 0] - phi[q, 0])
                    g += weight * (phi[q + step, 1] - phi[q, 1])
                    bl += weight * (phi[q + step, 2] - phi[q, 2])
                    seen *= 1.0 - piece
                q += step
            alpha = -math.expm1(-tau)
            out[i, j, 0] = r / alpha
            out[i, j, 1] = g / alpha
            out[i, j, 2] = bl / alpha


@jit(inline="always")
def psi_at(v, start, inv, density, psi):
    """``Psi(v)``, the integral of the density from the grid's first value ``start`` (grid
    position ``(v - start) * inv``): exact for the density linear between the nodes and
    constant beyond the ends."""
    n = density.shape[0]
    x = (v - start) * inv
    if not x > 0.0:  # also NaN
        return density[0] * (v - start)
    if x >= n - 1:
        return psi[n - 1] + density[n - 1] * (x - (n - 1)) / inv
    i = int(x)
    f = x - i
    return psi[i] + (density[i] * f + 0.5 * (density[i + 1] - density[i]) * f * f) / inv


@jit(inline="always")
def bilinear_channel(tab, x, y, n, c):
    """Channel ``c`` of the 3-D table ``tab[i, j, c]`` at table positions ``(x, y)``,
    bilinear and clamped to ``n``."""
    i, wx = lookup(x, n)
    j, wy = lookup(y, n)
    top = tab[i, j, c] + wy * (tab[i, j + 1, c] - tab[i, j, c])
    bottom = tab[i + 1, j, c] + wy * (tab[i + 1, j + 1, c] - tab[i + 1, j, c])
    return top + wx * (bottom - top)
