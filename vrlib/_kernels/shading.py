"""Phong shading inside kernels: one definition for every renderer that shades
(:class:`vrlib.Phong` is its NumPy face)."""

from __future__ import annotations

import math

from vrlib._kernels._jit import jit
from vrlib._kernels.tables import piecewise_linear


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


@jit(inline="always")
def opacity_by_gradient(alpha, gx, gy, gz, ramp_x, ramp_y):
    """Opacity ``alpha`` with its density multiplied by the piecewise-linear factor through
    ``(ramp_x, ramp_y)`` of the gradient magnitude ``|g|``: ``1 - (1 - alpha)^factor``
    (eq 1.4); 0 where the factor is 0."""
    factor = piecewise_linear(ramp_x, ramp_y, math.sqrt(gx * gx + gy * gy + gz * gz))
    if not factor > 0.0:
        return 0.0
    if factor < 1.0 and alpha < 1.0:
        return -math.expm1(factor * math.log1p(-alpha))
    return alpha


@jit(inline="always")
def classify_by_gradient(alpha, i, w, emit_tab, gx, gy, gz, by_gradient, ramp_x, ramp_y,
                         shade, lx, ly, lz, dx, dy, dz, ka, kd, ks, shininess):
    """A sample's segment opacity and premultiplied colour when its classification needs its
    gradient ``g`` (world units): ``alpha`` and the table position ``(i, w)`` come from its
    value; with ``by_gradient`` the density is multiplied by the piecewise-linear factor through
    ``(ramp_x, ramp_y)`` of ``|g|`` (``alpha = 1 - (1 - alpha)^factor``, eq 1.4); with
    ``shade`` the emission ``emit_tab`` is Phong-shaded for light direction ``l`` and ray
    direction ``d``. Returns ``(alpha, r, g, b)``; ``alpha = 0`` adds nothing."""
    if by_gradient:
        alpha = opacity_by_gradient(alpha, gx, gy, gz, ramp_x, ramp_y)
        if not alpha > 0.0:
            return 0.0, 0.0, 0.0, 0.0
    er = emit_tab[i, 0] + w * (emit_tab[i + 1, 0] - emit_tab[i, 0])
    eg = emit_tab[i, 1] + w * (emit_tab[i + 1, 1] - emit_tab[i, 1])
    eb = emit_tab[i, 2] + w * (emit_tab[i + 1, 2] - emit_tab[i, 2])
    if shade:
        lit, spec = phong(gx, gy, gz, lx, ly, lz, dx, dy, dz, ka, kd, ks, shininess)
        return (alpha, (er * lit + spec) * alpha, (eg * lit + spec) * alpha,
                (eb * lit + spec) * alpha)
    return alpha, er * alpha, eg * alpha, eb * alpha


@jit(inline="always")
def modulate_by_gradient(alpha, r, g, b, gx, gy, gz, by_gradient, ramp_x, ramp_y, shade,
                         lx, ly, lz, dx, dy, dz, ka, kd, ks, shininess):
    """A classified segment (opacity ``alpha``, premultiplied colour ``(r, g, b)``, e.g.
    pre-integrated) modulated by the gradient ``g`` (world units) at its middle: with
    ``by_gradient`` its density is scaled by the factor of ``|g|`` (``alpha = 1 - (1 -
    alpha)^factor``, eq 1.4, the colour in proportion), with ``shade`` its colour is
    Phong-shaded (``colour * factor + highlight * alpha``), as :func:`classify_by_gradient`
    does for one value. Returns ``(alpha, r, g, b)``."""
    if by_gradient:
        scaled = opacity_by_gradient(alpha, gx, gy, gz, ramp_x, ramp_y)
        if not scaled > 0.0:
            return 0.0, 0.0, 0.0, 0.0
        r *= scaled / alpha
        g *= scaled / alpha
        b *= scaled / alpha
        alpha = scaled
    if shade:
        lit, spec = phong(gx, gy, gz, lx, ly, lz, dx, dy, dz, ka, kd, ks, shininess)
        return alpha, r * lit + spec * alpha, g * lit + spec * alpha, b * lit + spec * alpha
    return alpha, r, g, b
