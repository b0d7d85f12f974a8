"""Phong shading inside kernels: one definition for every renderer that shades
(:class:`vrlib.Phong` is its NumPy face)."""

from __future__ import annotations

import math

from vrlib._kernels._jit import jit


@jit
def phong(gx, gy, gz, lx, ly, lz, dx, dy, dz, ka, kd, ks, shininess):
    """``(factor, highlight)`` for gradient ``g``, unit direction ``l`` towards the light and
    unit ray direction ``d`` (from the eye): ``ka + kd |n.l|`` and ``ks |n.h|^shininess`` with
    ``n = g / |g|`` and ``h`` the unit half-vector of ``l`` and ``-d`` (two-sided lighting);
    a zero gradient is lit as if facing the light."""
    hx, hy, hz = lx - dx, ly - dy, lz - dz
    hn = math.sqrt(hx * hx + hy * hy + hz * hz)
    if hn > 0.0:
        hx, hy, hz = hx / hn, hy / hn, hz / hn
    else:
        hx, hy, hz = lx, ly, lz
    norm = math.sqrt(gx * gx + gy * gy + gz * gz)
    if norm > 0.0:
        ndotl = abs(gx * lx + gy * ly + gz * lz) / norm
        ndoth = abs(gx * hx + gy * hy + gz * hz) / norm
    else:
        ndotl = 1.0
        ndoth = 1.0
    return ka + kd * ndotl, ks * ndoth**shininess
