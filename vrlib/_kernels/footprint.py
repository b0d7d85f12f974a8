"""Footprint-table lookups inside kernels: the splatter draws with them, and the roofline
measures the rate they allow. The tables themselves are built by :mod:`vrlib.footprint`
(radial over ``rho^2``, or planar over the image plane's offsets ``(u, v)``)."""

from __future__ import annotations

import math

import numpy as np

from vrlib._kernels._jit import at, helper_jit, jit
from vrlib._kernels.filters import weight
from vrlib._kernels.queue import take

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
    return ((1.0 - ty) * ((1.0 - tx) * at(planar, (j, i)) + tx * at(planar, (j, i + 1)))
            + ty * ((1.0 - tx) * at(planar, (j + 1, i)) + tx * at(planar, (j + 1, i + 1))))


@helper_jit
def sort_prefix(values, count):
    """Sort ``values[:count]`` in place, ascending: insertion sort, for the few dozen cuts of
    a line integral (numba's own sort costs two seconds of a first render's compile).

    Callers pass ``count`` as an ``int64``: numba compiles a function once more for each
    literal integer it is called with (a count that starts at a constant is one, for a
    first pass of type inference)."""
    for n in range(1, count):
        item = values[n]
        m = n - 1
        while m >= 0 and values[m] > item:
            values[m + 1] = values[m]
            m -= 1
        values[m + 1] = item


@jit
def partial_table(kind, p0, p1, p2, radius, spacing, basis, extent_u, extent_v, extent_s,
                  nodes, weights, table, counter, cuts):
    """Partial line integrals of the separable kernel ``K(p) = prod_a k(p_a / h_a)``:
    ``table[j, i, m] = int_{-extent_s}^{s_m} K(u_i right + v_j up + t forward) dt`` on the grid
    ``u_i`` over ``[-extent_u, extent_u]``, ``v_j`` over ``[-extent_v, extent_v]`` and ``s_m``
    over ``[-extent_s, extent_s]`` (``basis``: the rows right, up, forward, flattened).

    Each stretch between grid points is cut where the line crosses a knot of ``k`` (the integers
    and half-integers within its ``radius``) and integrated by Gauss-Legendre
    ``nodes``/``weights`` on ``[-1, 1]`` (exact for the piecewise-polynomial kernels).

    A call takes the next row ``j`` from the shared queue ``counter``
    (:func:`vrlib._kernels.queue.take`) until none is left, several threads at once
    (:func:`vrlib._scheduling.on_threads`: a serial kernel compiles in a fraction of a
    ``prange``'s time); ``cuts`` (``12 ceil(radius) + 3`` floats) is the call's own scratch.
    """
    nv, nu, ns = table.shape
    reach = int(math.ceil(radius))
    n_knots = 4 * reach + 1
    fwd = (basis[6], basis[7], basis[8])
    ds = 2.0 * extent_s / (ns - 1)
    while True:
        j = take(counter)
        if j >= nv:
            break
        v = -extent_v + 2.0 * extent_v * j / (nv - 1)
        for i in range(nu):
            u = -extent_u + 2.0 * extent_u * i / (nu - 1)
            base = (u * basis[0] + v * basis[3], u * basis[1] + v * basis[4],
                    u * basis[2] + v * basis[5])
            count = np.int64(0)  # not a literal 0: see sort_prefix
            for a in range(3):
                if fwd[a] == 0.0:
                    continue
                for n in range(n_knots):
                    t = ((n - 2 * reach) * 0.5 * spacing[a] - base[a]) / fwd[a]
                    if -extent_s < t < extent_s:
                        cuts[count] = t
                        count += 1
            sort_prefix(cuts, count)
            total = 0.0
            table[j, i, 0] = 0.0
            c = 0
            for m in range(1, ns):
                lo = -extent_s + (m - 1) * ds
                hi = -extent_s + m * ds if m < ns - 1 else extent_s
                while c < count and cuts[c] <= lo:
                    c += 1
                while True:
                    stop = hi
                    if c < count and cuts[c] < hi:
                        stop = cuts[c]
                    half = 0.5 * (stop - lo)
                    mid = 0.5 * (stop + lo)
                    for g in range(nodes.shape[0]):
                        t = mid + half * nodes[g]
                        value = weights[g] * half
                        for a in range(3):
                            value *= weight(kind, p0, p1, p2,
                                            (base[a] + t * fwd[a]) / spacing[a])
                        total += value
                    if stop == hi:
                        break
                    lo = stop
                    c += 1
                table[j, i, m] = total


@jit(inline="always")
def partial_corner(extent, extent_v, nu, nv, u, v):
    """Cell of the partial table holding plane offset ``(u, v)``: indices ``(j, i)`` and
    fractions ``(ty, tx)``; ``j = -1`` outside."""
    x = (u + extent) * ((nu - 1) / (2.0 * extent))
    y = (v + extent_v) * ((nv - 1) / (2.0 * extent_v))
    if not (x >= 0.0 and x <= nu - 1 and y >= 0.0 and y <= nv - 1):
        return -1, 0, 0.0, 0.0
    j = min(int(y), nv - 2)
    i = min(int(x), nu - 2)
    return j, i, y - j, x - i


@jit(inline="always")
def partial_at(partial, extent_s, j, i, ty, tx, s):
    """The partial table at cell ``(j, i, ty, tx)`` and line position ``s``: the kernel's
    integral along the line from its start to ``s`` (trilinear)."""
    ns = partial.shape[2]
    z = (s + extent_s) * ((ns - 1) / (2.0 * extent_s))
    if not z > 0.0:
        return 0.0
    m = ns - 2
    tz = 1.0
    if z < ns - 1:
        m = int(z)
        tz = z - m
    a = (1.0 - tz) * partial[j, i, m] + tz * partial[j, i, m + 1]
    b = (1.0 - tz) * partial[j, i + 1, m] + tz * partial[j, i + 1, m + 1]
    c = (1.0 - tz) * partial[j + 1, i, m] + tz * partial[j + 1, i, m + 1]
    d = (1.0 - tz) * partial[j + 1, i + 1, m] + tz * partial[j + 1, i + 1, m + 1]
    return (1.0 - ty) * ((1.0 - tx) * a + tx * b) + ty * ((1.0 - tx) * c + tx * d)


@jit(inline="always")
def radial_partial(extent, sigma, s_lo, s_hi, rho2):
    """Share of the ball-truncated Gaussian's line integral at squared distance ``rho2`` that
    lies between ``s_lo`` and ``s_hi`` along the line (closed form: the chord's Gaussian is
    ``exp(-t^2 / 2 sigma^2)`` on ``|t| < sqrt(extent^2 - rho2)``)."""
    chord = math.sqrt(max(extent * extent - rho2, 0.0))
    if chord == 0.0:
        return 0.0
    scale = 1.0 / (sigma * math.sqrt(2.0))
    lo = min(max(s_lo, -chord), chord)
    hi = min(max(s_hi, -chord), chord)
    if not hi > lo:
        return 0.0
    return (math.erf(hi * scale) - math.erf(lo * scale)) / (2.0 * math.erf(chord * scale))


@jit
def slanted_integral(kind, p0, p1, p2, radius, bp, bq, mp, mq, nodes, weights, s_lo, s_hi,
                     cuts):
    """``int k(s) k(bp + mp s) k(bq + mq s) ds`` over ``[s_lo, s_hi]`` (index units): the
    line integral of the separable kernel along a line that crosses the voxel's slice plane at
    in-plane offsets ``(bp, bq)`` and moves ``(mp, mq)`` in-plane per unit along the slicing
    axis ``s``. Cut where any factor has a knot (integers and half-integers within
    ``radius``), each piece by Gauss-Legendre ``nodes``/``weights`` (5 are exact for the
    piecewise cubics); ``cuts`` is scratch space for ``12 ceil(radius) + 5`` numbers."""
    reach = int(math.ceil(radius))
    lo = max(-radius, s_lo)
    hi = min(radius, s_hi)
    # The stretch where every factor can be non-zero.
    for b, m in ((bp, mp), (bq, mq)):
        if m == 0.0:
            if not abs(b) < radius:
                return 0.0
            continue
        a = (-radius - b) / m
        e = (radius - b) / m
        if a > e:
            a, e = e, a
        lo = max(lo, a)
        hi = min(hi, e)
    if not hi > lo:
        return 0.0
    n_knots = 4 * reach + 1
    cuts[0] = lo
    cuts[1] = hi
    count = np.int64(2)  # not a literal 2: see sort_prefix
    for n in range(n_knots):
        knot = (n - 2 * reach) * 0.5
        if lo < knot < hi:
            cuts[count] = knot
            count += 1
        for b, m in ((bp, mp), (bq, mq)):
            if m != 0.0:
                t = (knot - b) / m
                if lo < t < hi:
                    cuts[count] = t
                    count += 1
    sort_prefix(cuts, count)
    total = 0.0
    for c in range(count - 1):
        half = 0.5 * (cuts[c + 1] - cuts[c])
        mid = 0.5 * (cuts[c + 1] + cuts[c])
        for g in range(nodes.shape[0]):
            s = mid + half * nodes[g]
            total += (weights[g] * half * weight(kind, p0, p1, p2, s)
                      * weight(kind, p0, p1, p2, bp + mp * s)
                      * weight(kind, p0, p1, p2, bq + mq * s))
    return total


@jit
def slanted_table(kind, p0, p1, p2, radius, reach, slope, nodes, weights, table, counter,
                  cuts):
    """:func:`slanted_integral` on a grid: ``table[a, b, i, j]`` at slopes ``(mp, mq)`` over
    ``[-slope, slope]`` (indices ``a``, ``b``) and offsets ``(bp, bq)`` over
    ``[-reach, reach]`` (``i``, ``j``). A call takes the next pair of slopes from the shared
    queue ``counter`` until none is left, several threads at once, as
    :func:`partial_table`; ``cuts`` (``12 ceil(radius) + 5`` floats) is its own scratch."""
    nm = table.shape[0]
    nb = table.shape[2]
    while True:
        ab = take(counter)
        if ab >= nm * nm:
            break
        a = ab // nm
        b = ab % nm
        mp = -slope + 2.0 * slope * a / (nm - 1)
        mq = -slope + 2.0 * slope * b / (nm - 1)
        for i in range(nb):
            bp = -reach + 2.0 * reach * i / (nb - 1)
            for j in range(nb):
                bq = -reach + 2.0 * reach * j / (nb - 1)
                table[a, b, i, j] = slanted_integral(kind, p0, p1, p2, radius, bp, bq, mp, mq,
                                                     nodes, weights, -radius, radius, cuts)


@jit(inline="always")
def slanted_at(table, reach, slope, bp, bq, mp, mq):
    """The slanted table (:func:`slanted_table`) at offsets ``(bp, bq)`` and slopes
    ``(mp, mq)``: linear in each of the four (slopes clamped to the table)."""
    nm = table.shape[0]
    nb = table.shape[2]
    x = (bp + reach) * ((nb - 1) / (2.0 * reach))
    y = (bq + reach) * ((nb - 1) / (2.0 * reach))
    if not (x >= 0.0 and x <= nb - 1 and y >= 0.0 and y <= nb - 1):
        return 0.0
    i = min(int(x), nb - 2)
    j = min(int(y), nb - 2)
    tx = x - i
    ty = y - j
    u = min(max((mp + slope) * ((nm - 1) / (2.0 * slope)), 0.0), nm - 1.0)
    w = min(max((mq + slope) * ((nm - 1) / (2.0 * slope)), 0.0), nm - 1.0)
    a = min(int(u), nm - 2)
    b = min(int(w), nm - 2)
    tu = u - a
    tw = w - b
    total = 0.0
    for da in range(2):
        fa = tu if da == 1 else 1.0 - tu
        for db in range(2):
            fb = tw if db == 1 else 1.0 - tw
            total += fa * fb * (
                (1.0 - tx) * ((1.0 - ty) * table[a + da, b + db, i, j]
                              + ty * table[a + da, b + db, i, j + 1])
                + tx * ((1.0 - ty) * table[a + da, b + db, i + 1, j]
                        + ty * table[a + da, b + db, i + 1, j + 1]))
    return total
