"""Phong shading inside kernels: one definition for every renderer that shades
(:class:`vrlib.Phong` is its NumPy face)."""

from __future__ import annotations

import math

from vrlib._kernels._jit import jit


@jit(inline="always")
def half_vector(lx, ly, lz, dx, dy, dz):
    """The unit half-vector of the light direction ``l`` and the direction to the eye ``-d``
    (``l`` itself when they cancel)."""
    hx, hy, hz = lx - dx, ly - dy, lz - dz
    hn = math.sqrt(hx * hx + hy * hy + hz * hz)
    if hn > 0.0:
        return hx / hn, hy / hn, hz / hn
    return lx, ly, lz


@jit(inline="always")
def phong_terms(gx, gy, gz, lx, ly, lz, hx, hy, hz, ka, kd, ks, shininess):
    """``(factor, highlight)`` for gradient ``g``, light direction ``l`` and half-vector
    ``h``: ``ka + kd |n.l|`` and ``ks |n.h|^shininess`` with ``n = g / |g|`` (two-sided
    lighting); a zero gradient is lit as if facing the light."""
    norm = math.sqrt(gx * gx + gy * gy + gz * gz)
    if norm > 0.0:
        ndotl = abs(gx * lx + gy * ly + gz * lz) / norm
        ndoth = abs(gx * hx + gy * hy + gz * hz) / norm
    else:
        ndotl = 1.0
        ndoth = 1.0
    return ka + kd * ndotl, ks * power(ndoth, shininess)


@jit(inline="always")
def power(x, p):
    """``x**p``; for a whole ``p`` from 0 to 64 (the usual shininess) by repeated squaring,
    a few multiplications in place of a ``pow`` (which costs as much as the rest of a
    shading), agreeing with it to a few units in the last place."""
    n = int(p)
    if n != p or n < 0 or n > 64:
        return x**p
    result = 1.0
    while n > 0:
        if n & 1:
            result *= x
        x *= x
        n >>= 1
    return result


@jit
def phong(gx, gy, gz, lx, ly, lz, dx, dy, dz, ka, kd, ks, shininess):
    """``(factor, highlight)`` for gradient ``g``, unit direction ``l`` towards the light and
    unit ray direction ``d`` (from the eye): :func:`phong_terms` with the :func:`half_vector`
    of ``l`` and ``-d``."""
    hx, hy, hz = half_vector(lx, ly, lz, dx, dy, dz)
    return phong_terms(gx, gy, gz, lx, ly, lz, hx, hy, hz, ka, kd, ks, shininess)
