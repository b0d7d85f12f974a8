"""Kernels of the volume-shearing renderers: 1-D resampling passes and compositing.

A pass resamples along the last axis of its (possibly transposed) source: output line
``out[s, r, :]`` takes, at output position ``q``, the source line ``src[s, r, :]`` at
``pos = (q - offset - c1 r - c2 s) / c0`` (a scaled shear, eq. "x' = Ax + B" of the thesis's
section 1.2), reconstructed with a 1-D filter whose taps are clamped at the line's ends. Only
outputs whose ``pos`` lies within the line (widened by the filter's reach) are computed; the
rest stay zero. Three-pass shearing's last pass runs along the rays and is fused with its
compositing; two-pass compositing reads the second intermediate volume along the view.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import prange

from vrlib._kernels._jit import at, borrowed, helper_jit, jit, parallel_jit, put
from vrlib._kernels.filters import CUBIC, MAX_TAPS, TENT, weight
from vrlib._kernels.packets import (
    LANES,
    warp_octet_colour,
    warp_octet_grey,
    warp_octet_grey_pairs,
)
from vrlib._kernels.queue import take
from vrlib._kernels.sampling import clamp, cubic_weights, filter_taps
from vrlib._kernels.shading import classify_by_gradient
from vrlib._kernels.tables import entry, lookup


@helper_jit
def _line_taps(fkind, fp0, fp1, fp2, radius, ntaps, pos, w):
    """First tap of position ``pos`` on a line, its ``ntaps`` weights in ``w``: closed forms for
    the tent (2 taps) and the cubics (4 taps, the pieces evaluated once each), the filter's
    definition tap by tap otherwise."""
    if fkind == TENT:
        first = int(math.floor(pos))
        t = pos - first
        w[0] = 1.0 - t
        w[1] = t
        return first
    if fkind == CUBIC:
        first = int(math.floor(pos)) - 1
        w[0], w[1], w[2], w[3] = cubic_weights(pos - (first + 1), fp0, fp1, fp2)
        return first
    return filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, pos, w)


@jit(inline="always")
def _resample(src, s, r, lo, hi, pos, fkind, fp0, fp1, fp2, radius, ntaps, w):
    """Line ``src[s, r]`` (data on ``lo .. hi``) reconstructed at ``pos``; taps clamped to the
    data only near its ends."""
    first = _line_taps(fkind, fp0, fp1, fp2, radius, ntaps, pos, borrowed(w))
    return _taps_sum(src, s, r, lo, hi, first, ntaps, w)


@jit(inline="always")
def _taps_sum(src, s, r, lo, hi, first, ntaps, w):
    """Taps ``first ..`` of line ``src[s, r]`` weighted by ``w``, clamped to ``lo .. hi``."""
    acc = 0.0
    if first >= lo and first + ntaps - 1 <= hi:
        for a in range(ntaps):
            acc += w[a] * src[s, r, first + a]
    else:
        for a in range(ntaps):
            acc += w[a] * src[s, r, min(max(first + a, lo), hi)]
    return acc


@parallel_jit
def shear_pass(src, out, c0, c1, c2, offset, line_lo, line_hi, fkind, fp0, fp1, fp2, radius,
               ntaps, across, counts, out_first, out_last):
    """One resampling pass (see the module docstring); ``counts[s]`` gets the outputs computed
    for outer index ``s``.

    Source line ``(s, r)`` holds data only on ``line_lo[s, r] .. line_hi[s, r]`` (the part an
    earlier pass filled); taps are clamped to it, and only outputs whose source lies within it,
    widened by the filter's reach, are computed: ``out_first[s, r] .. out_last[s, r]``.
    With ``across``, the lines of one ``s`` advance together, output ``q`` of every line before
    ``q + 1``: the order that reads and writes memory contiguously when the arrays are
    transposed views whose ``r`` axis is the contiguous one. The outputs are the same.
    """
    n_s, n_r, n_q = out.shape
    n = src.shape[2]
    for s_index in prange(n_s):
        s = np.int64(s_index)
        w = np.empty(MAX_TAPS)
        done = 0
        q_lo = n_q
        q_hi = -1
        for r in range(n_r):
            out_first[s, r] = 0
            out_last[s, r] = -1
            lo = max(0, line_lo[s, r])
            hi = min(n - 1, line_hi[s, r])
            if lo > hi:
                continue
            base = offset + c1 * r + c2 * s
            # Output positions q = base + c0 pos whose source lies in [lo - reach, hi + reach].
            q_a = base + c0 * (lo - radius)
            q_b = base + c0 * (hi + radius)
            out_first[s, r] = max(0, int(math.ceil(min(q_a, q_b))))
            out_last[s, r] = min(n_q - 1, int(math.floor(max(q_a, q_b))))
            if out_first[s, r] > out_last[s, r]:
                continue
            done += out_last[s, r] - out_first[s, r] + 1
            q_lo = min(q_lo, out_first[s, r])
            q_hi = max(q_hi, out_last[s, r])
            if across:
                continue
            for q in range(out_first[s, r], out_last[s, r] + 1):
                out[s, r, q] = _resample(src, s, r, lo, hi, (q - base) / c0, fkind, fp0, fp1,
                                         fp2, radius, ntaps, w)
        if across:
            for q in range(q_lo, q_hi + 1):
                for r in range(n_r):
                    if out_first[s, r] <= q <= out_last[s, r]:
                        out[s, r, q] = _resample(
                            src, s, r, max(0, line_lo[s, r]), min(n - 1, line_hi[s, r]),
                            (q - (offset + c1 * r + c2 * s)) / c0, fkind, fp0, fp1, fp2,
                            radius, ntaps, w)
        counts[s] += done


@parallel_jit
def filled(first, last, length, lo, hi):
    """For the next pass, whose lines run across this pass's: ``first[s, r] .. last[s, r]``
    are the outputs this pass computed on line ``(s, r)``; ``lo[s, q]`` and ``hi[s, q]`` get,
    for every ``q`` in ``[0, length)``, the first and last ``r`` whose range covers ``q``
    (``lo = n_r``, ``hi = -1`` where none does)."""
    n_s, n_r = first.shape
    for s_index in prange(n_s):
        s = np.int64(s_index)
        for q in range(length):
            lo[s, q] = n_r
            hi[s, q] = -1
        for r in range(n_r):
            for q in range(max(0, first[s, r]), min(length - 1, last[s, r]) + 1):
                lo[s, q] = min(lo[s, q], r)
                hi[s, q] = max(hi[s, q], r)


@jit(inline="always")
def _over(value, fraction, tstart, tinv, alpha_tab, color_tab, buf, y, x):
    """Classify one sample from the segment table and composite it under ``buf[y, x]``
    (premultiplied RGBA; eqs 1.7-1.8, colour E alpha: eq 1.9). ``fraction`` is the sample's
    segment length over the table's: ``1 - alpha' = (1 - alpha) ** fraction``, the colour
    scaled with the opacity (the first and last slices of a volume reach half a slice spacing
    into it; perspective rays cross the slices at their own angles)."""
    i, w = lookup((value - tstart) * tinv, alpha_tab.shape[0])
    alpha = entry(alpha_tab, i, w)
    if not alpha > 0.0:
        return
    scale = 1.0
    if fraction != 1.0:
        corrected = -math.expm1(fraction * math.log1p(-alpha))
        scale = corrected / alpha
        alpha = corrected
    remaining = 1.0 - buf[y, x, 3]
    for ch in range(3):
        buf[y, x, ch] += remaining * scale * (color_tab[i, ch] + w * (color_tab[i + 1, ch]
                                                                      - color_tab[i, ch]))
    buf[y, x, 3] += remaining * alpha


@jit(inline="always")
def _within(u0, slope, limit, t_lo, t_hi):
    """Narrow ``[t_lo, t_hi]`` to where ``0 <= u0 + slope t <= limit`` (empty: ``t_lo > t_hi``)."""
    if slope == 0.0:
        if u0 < 0.0 or u0 > limit:
            return 1.0, 0.0
        return t_lo, t_hi
    t0 = -u0 / slope
    t1 = (limit - u0) / slope
    return max(t_lo, min(t0, t1)), min(t_hi, max(t0, t1))


@jit(inline="always")
def _inside_range(inverse, shift, limits, x, y, n):
    """The ``z`` in ``[0, n)`` that can lie inside the volume on the lattice ray through
    ``(x, y)``: where ``0 <= inverse @ ((x, y, z) - shift) <= limits`` on every axis, widened
    by one sample (callers keep the exact test; this only bounds the loop)."""
    z_lo = 0.0
    z_hi = n - 1.0
    for a in range(3):
        u0 = inverse[a, 0] * (x - shift[0]) + inverse[a, 1] * (y - shift[1]) \
            - inverse[a, 2] * shift[2]
        z_lo, z_hi = _within(u0, inverse[a, 2], limits[a], z_lo, z_hi)
    if z_lo > z_hi:
        return 0, -1
    return max(0, int(math.floor(z_lo)) - 1), min(n - 1, int(math.ceil(z_hi)) + 1)


@jit(inline="always")
def _lit_views(alpha_tab, emit_tab, lit, ramp_x, ramp_y, buf):
    """The arrays :func:`_over_lit` takes, borrowed (:data:`~vrlib._kernels._jit.borrowed`):
    a call per sample would otherwise count references to each of them."""
    return (borrowed(alpha_tab), borrowed(emit_tab), borrowed(lit), borrowed(ramp_x),
            borrowed(ramp_y), borrowed(buf))


@helper_jit
def _over_lit(value, fraction, gx, gy, gz, tstart, tinv, alpha_tab, emit_tab, lit, ramp_x,
              ramp_y, buf, y, x, dx, dy, dz):
    """:func:`_over` for a sample classified by its gradient ``g`` too (shading, gradient
    opacity; ``lit``, ``ramp_x``, ``ramp_y`` from :func:`vrlib.gradients.kernel_lighting`),
    seen along the unit ray direction ``d`` (``lit[10:13]`` for an orthographic view; a
    headlight shines along ``-d``)."""
    i, w = lookup((value - tstart) * tinv, alpha_tab.shape[0])
    alpha = entry(alpha_tab, i, w)
    if not alpha > 0.0:
        return
    lx, ly, lz = (-dx, -dy, -dz) if lit[1] != 0.0 else (lit[7], lit[8], lit[9])
    alpha, cr, cg, cb = classify_by_gradient(
        alpha, i, w, emit_tab, gx, gy, gz, lit[2] != 0.0, ramp_x, ramp_y, lit[0] != 0.0,
        lx, ly, lz, dx, dy, dz, lit[3], lit[4], lit[5], lit[6])
    if not alpha > 0.0:
        return
    if fraction != 1.0:
        corrected = -math.expm1(fraction * math.log1p(-alpha))
        scale = corrected / alpha
        cr, cg, cb, alpha = cr * scale, cg * scale, cb * scale, corrected
    remaining = 1.0 - buf[y, x, 3]
    buf[y, x, 0] += remaining * cr
    buf[y, x, 1] += remaining * cg
    buf[y, x, 2] += remaining * cb
    buf[y, x, 3] += remaining * alpha


@jit(inline="always")
def _ray_sample(src, grads, lighting, y, x, lo, hi, position, fkind, fp0, fp1, fp2, radius,
                ntaps, w):
    """Pass 3's line of pixel ``(x, y)`` (data on ``lo .. hi``) resampled at ``position``, and
    with ``lighting`` the gradient's components too: ``(value, gx, gy, gz)``."""
    first = _line_taps(fkind, fp0, fp1, fp2, radius, ntaps, position, borrowed(w))
    value = _taps_sum(src, y, x, lo, hi, first, ntaps, w)
    gx = gy = gz = 0.0
    if lighting:
        gx = _taps_sum(grads[0], y, x, lo, hi, first, ntaps, w)
        gy = _taps_sum(grads[1], y, x, lo, hi, first, ntaps, w)
        gz = _taps_sum(grads[2], y, x, lo, hi, first, ntaps, w)
    return value, gx, gy, gz


@parallel_jit
def resample_composite(src, c0, c1, c2, offset, line_lo, line_hi, fkind, fp0, fp1, fp2, radius,
                       ntaps, n_z, inverse, shift, limits, tstart, tinv, alpha_tab, color_tab,
                       emit_tab, grads, lit, ramp_x, ramp_y, threshold, out, resampled,
                       composited, exact):
    """Three-pass shearing's last pass fused with its compositing: the pass-3 line of pixel
    ``(x, y)`` is that pixel's ray. ``src[y, x, w]`` is pass 2's output seen along the lines of
    pass 3 (``line_lo .. line_hi`` filled, as for :func:`shear_pass`); lattice sample ``z`` of
    the ray is the line resampled at ``(z - offset - c1 x - c2 y) / c0`` where :func:`shear_pass`
    would compute it and 0 elsewhere, and it is composited front to back (increasing ``z``) into
    ``out`` when it lies in the volume (the lattice sample ``inverse @ ((x, y, z) - shift)``
    within ``[0, limits]``). The pixels of a row advance together (contiguous reads of
    ``src``); opaque pixels take no more samples. ``resampled[y]`` and ``composited[y]`` count
    the work. With ``grads`` (``[3, y, x, w]``: the gradient's components after pass 2;
    ``no_gradients()`` for none) each sample's gradient is resampled with the same weights and
    the sample is classified by it too (:func:`_over_lit`). With ``exact`` segment ends,
    sample ``z`` stands for ``[z - 1/2, z + 1/2]``: only the samples whose whole segment lies
    in the volume are composited so, and the parts inside of the segments that its faces cut
    (before the first and after the last of those) are each sampled at their middle, with
    their length, and composited in front of and behind them after."""
    height, width = out.shape[0], out.shape[1]
    n = src.shape[2]
    lighting = lit[0] != 0.0 or lit[2] != 0.0  # shading or gradient opacity
    alpha_tab, emit_tab, lit, ramp_x, ramp_y, out = _lit_views(alpha_tab, emit_tab, lit,
                                                               ramp_x, ramp_y, out)
    for row_index in prange(height):
        y = np.int64(row_index)
        w = np.empty(MAX_TAPS)
        z_first = np.empty(width, np.int64)
        z_last = np.empty(width, np.int64)
        q_first = np.empty(width, np.int64)
        q_last = np.empty(width, np.int64)
        # Exact ends: each ray's stretch inside the volume, and its first and last sample
        # whose whole segment lies in it.
        stretch = np.empty((width, 2))
        whole = np.empty((width, 2), np.int64)
        part = np.zeros((1, 1, 4))
        row_lo = n_z
        row_hi = -1
        for x in range(width):
            z_first[x], z_last[x] = _inside_range(inverse, shift, limits, x, y, n_z)
            if exact:
                z_in, z_out = -math.inf, math.inf
                for a in range(3):
                    u0 = inverse[a, 0] * (x - shift[0]) + inverse[a, 1] * (y - shift[1]) \
                        - inverse[a, 2] * shift[2]
                    z_in, z_out = _within(u0, inverse[a, 2], limits[a], z_in, z_out)
                stretch[x, 0], stretch[x, 1] = z_in, z_out
                whole[x, 0], whole[x, 1] = 1, 0
                if z_in <= z_out:
                    whole[x, 0] = int(math.ceil(z_in + 0.5))
                    whole[x, 1] = int(math.floor(z_out - 0.5))
            q_first[x] = 0
            q_last[x] = -1
            lo = max(0, line_lo[y, x])
            hi = min(n - 1, line_hi[y, x])
            if lo <= hi:
                base = offset + c1 * x + c2 * y
                q_a = base + c0 * (lo - radius)
                q_b = base + c0 * (hi + radius)
                q_first[x] = max(0, int(math.ceil(min(q_a, q_b))))
                q_last[x] = min(n_z - 1, int(math.floor(max(q_a, q_b))))
            if z_first[x] <= z_last[x]:
                row_lo = min(row_lo, z_first[x])
                row_hi = max(row_hi, z_last[x])
        taken = 0
        done = 0
        for z in range(row_lo, row_hi + 1):
            for x in range(width):
                if not z_first[x] <= z <= z_last[x] or out[y, x, 3] >= threshold:
                    continue
                if exact and not whole[x, 0] <= z <= whole[x, 1]:
                    continue  # a segment the volume's faces cut: below
                inside = True
                for a in range(3):
                    u = (inverse[a, 0] * (x - shift[0]) + inverse[a, 1] * (y - shift[1])
                         + inverse[a, 2] * (z - shift[2]))
                    if u < 0.0 or u > limits[a]:
                        inside = False
                if not inside:
                    continue
                value = gx = gy = gz = 0.0
                if q_first[x] <= z <= q_last[x]:
                    value, gx, gy, gz = _ray_sample(
                        src, grads, lighting, y, x, max(0, line_lo[y, x]),
                        min(n - 1, line_hi[y, x]), (z - (offset + c1 * x + c2 * y)) / c0,
                        fkind, fp0, fp1, fp2, radius, ntaps, w)
                    taken += 1
                done += 1
                if lighting:
                    _over_lit(value, 1.0, gx, gy, gz, tstart, tinv, alpha_tab, emit_tab, lit,
                              ramp_x, ramp_y, out, y, x, lit[10], lit[11], lit[12])
                else:
                    _over(value, 1.0, tstart, tinv, alpha_tab, color_tab, out, y, x)
        for x in range(width):
            if not exact or stretch[x, 0] > stretch[x, 1]:
                continue
            z_in, z_out = stretch[x, 0], stretch[x, 1]
            low_end, high_start = whole[x, 0] - 0.5, whole[x, 1] + 0.5
            if whole[x, 0] > whole[x, 1]:  # within two segments: where they meet
                low_end = high_start = min(math.floor(z_in + 0.5) + 0.5, z_out)
            lo = max(0, line_lo[y, x])
            hi = min(n - 1, line_hi[y, x])
            base = offset + c1 * x + c2 * y
            for side in range(2):  # 0: in front (lower z), 1: behind
                a, b = (z_in, low_end) if side == 0 else (high_start, z_out)
                if not b > a:
                    continue
                position = (0.5 * (a + b) - base) / c0
                value = gx = gy = gz = 0.0
                if lo <= hi and lo - radius <= position <= hi + radius:
                    value, gx, gy, gz = _ray_sample(src, grads, lighting, y, x, lo, hi,
                                                    position, fkind, fp0, fp1, fp2, radius,
                                                    ntaps, w)
                    taken += 1
                done += 1
                part[0, 0, 0] = part[0, 0, 1] = part[0, 0, 2] = part[0, 0, 3] = 0.0
                if lighting:
                    _over_lit(value, b - a, gx, gy, gz, tstart, tinv, alpha_tab, emit_tab,
                              lit, ramp_x, ramp_y, part, 0, 0, lit[10], lit[11], lit[12])
                else:
                    _over(value, b - a, tstart, tinv, alpha_tab, color_tab, part, 0, 0)
                _in_front_or_behind(out, y, x, part, side == 0)
        resampled[y] = taken
        composited[y] = done


@parallel_jit
def composite_slices(vol, front_to_back, inverse2, shift, limits, tstart, tinv, alpha_tab,
                     color_tab, emit_tab, grads, lit, ramp_x, ramp_y, threshold, out, counts,
                     exact):
    """Two-pass compositing: ``vol[w, Y, X]`` holds slice ``w`` resampled onto the image's
    rows and columns; each pixel composites the slices in view order, each a segment of the
    same length (the table's) but the first and last, which reach half as far into the volume.
    Sample ``(X, Y)`` of slice ``w`` belongs to the volume when
    ``(u, v) = inverse2 @ ((X, Y) - shift[:2] - w shift[2:])`` lies within ``limits``. The
    pixels of a row advance together, slice by slice (contiguous reads); each pixel visits only
    the slices its ray can meet inside the volume. With ``grads`` (``[3, w, Y, X]``, the
    gradient's components resampled like ``vol``; ``no_gradients()`` for none) samples are
    classified by their gradient too (:func:`_over_lit`). With ``exact`` segment ends, slice
    ``w`` stands for ``[w - 1/2, w + 1/2]`` (cut to ``[0, n_w - 1]``): only the slices whose
    whole segment lies in the volume on the pixel's ray are composited so, and the part
    inside of each segment that a side face cuts (before the first and after the last of
    those) after, in front of or behind them, with its length, by the sample of its own slice
    where that lies inside, else of the next slice inward (a segment away at most: the
    pixel's ray meets the slices only at their samples). A ray that meets no slice inside the
    volume takes nothing either way."""
    n_w, height, width = vol.shape
    lighting = lit[0] != 0.0 or lit[2] != 0.0  # shading or gradient opacity
    alpha_tab, emit_tab, lit, ramp_x, ramp_y, out = _lit_views(alpha_tab, emit_tab, lit,
                                                               ramp_x, ramp_y, out)
    for row_index in prange(height):
        y = np.int64(row_index)
        w_first = np.empty(width, np.int64)
        w_last = np.empty(width, np.int64)
        stretch = np.empty((width, 2))
        whole = np.empty((width, 2), np.int64)
        part = np.zeros((1, 1, 4))
        for x in range(width):
            # (u, v) are linear in w: the slices inside, widened by one (the test is exact).
            w_lo = 0.0
            w_hi = n_w - 1.0
            for a in range(2):
                u0 = (inverse2[a, 0] * (x - shift[0]) + inverse2[a, 1] * (y - shift[1]))
                slope = -(inverse2[a, 0] * shift[2] + inverse2[a, 1] * shift[3])
                w_lo, w_hi = _within(u0, slope, limits[a], w_lo, w_hi)
            stretch[x, 0], stretch[x, 1] = w_lo, w_hi
            whole[x, 0], whole[x, 1] = _whole_segments(w_lo, w_hi, n_w)
            if w_lo > w_hi:
                w_first[x], w_last[x] = 0, -1
            else:
                w_first[x] = max(0, int(math.floor(w_lo)) - 1)
                w_last[x] = min(n_w - 1, int(math.ceil(w_hi)) + 1)
        done = 0
        for step in range(n_w):
            w = step if front_to_back else n_w - 1 - step
            end = 0.5 if w == 0 or w == n_w - 1 else 1.0
            for x in range(width):
                if not w_first[x] <= w <= w_last[x] or out[y, x, 3] >= threshold:
                    continue
                if exact and not whole[x, 0] <= w <= whole[x, 1]:
                    continue  # a segment a side face cuts: below
                dx = x - shift[0] - w * shift[2]
                dy = y - shift[1] - w * shift[3]
                u = inverse2[0, 0] * dx + inverse2[0, 1] * dy
                v = inverse2[1, 0] * dx + inverse2[1, 1] * dy
                if u < 0.0 or u > limits[0] or v < 0.0 or v > limits[1]:
                    continue
                done += 1
                if lighting:
                    _over_lit(vol[w, y, x], end, grads[0, w, y, x], grads[1, w, y, x],
                              grads[2, w, y, x], tstart, tinv, alpha_tab, emit_tab, lit,
                              ramp_x, ramp_y, out, y, x, lit[10], lit[11], lit[12])
                else:
                    _over(vol[w, y, x], end, tstart, tinv, alpha_tab, color_tab, out, y, x)
        for x in range(width):
            w_lo, w_hi = stretch[x, 0], stretch[x, 1]
            if not exact or w_lo > w_hi:
                continue
            low_end, high_start = _cut_bounds(w_lo, w_hi, whole[x, 0], whole[x, 1], n_w, 1)
            for side in range(2):  # 0: the low end (slice 0's side), 1: the high end
                a, b = (w_lo, low_end) if side == 0 else (high_start, w_hi)
                if not b > a:
                    continue
                w = int(math.floor(0.5 * (a + b) + 0.5))  # the segment's own slice
                if w < w_lo:
                    w += 1
                elif w > w_hi:
                    w -= 1
                if not w_lo <= w <= w_hi:
                    continue  # no slice inside the volume on this ray
                done += 1
                part[0, 0, 0] = part[0, 0, 1] = part[0, 0, 2] = part[0, 0, 3] = 0.0
                if lighting:
                    _over_lit(vol[w, y, x], b - a, grads[0, w, y, x], grads[1, w, y, x],
                              grads[2, w, y, x], tstart, tinv, alpha_tab, emit_tab, lit,
                              ramp_x, ramp_y, part, 0, 0, lit[10], lit[11], lit[12])
                else:
                    _over(vol[w, y, x], b - a, tstart, tinv, alpha_tab, color_tab, part, 0, 0)
                _in_front_or_behind(out, y, x, part, (side == 0) == front_to_back)
        counts[y] = done


#: Slice coordinates within this of an end slice count as on it (:func:`_whole_segments`,
#: :func:`vrlib.shearwarp.whole_planes`): the intermediate image's and the two-pass slices'
#: pixels lie on the front slice's lattice, so rays through its edge meet the side faces
#: there, at 0 or a rounding from it.
SLAB_EDGE = 1e-9


@jit(inline="always")
def _whole_segments(k_lo, k_hi, n_k):
    """The first and last slice whose segment (``[k - 1/2, k + 1/2]`` cut to ``[0, n_k -
    1]``) lies wholly in the stretch ``[k_lo, k_hi]`` of slice coordinates; first > last where
    none does (:func:`vrlib.shearwarp.whole_planes` with one plane per slice)."""
    if k_lo > k_hi:
        return 1, 0
    first = 0 if k_lo <= SLAB_EDGE else int(math.ceil(k_lo + 0.5))
    last = n_k - 1 if k_hi >= n_k - 1.0 - SLAB_EDGE else int(math.floor(k_hi - 0.5))
    return first, last


@jit(inline="always")
def _cut_bounds(k_lo, k_hi, first, last, n_k, planes):
    """Where the stretch ``[k_lo, k_hi]`` of slice coordinates has its cut parts, on
    ``planes`` planes per slice spacing from slice 0 whose segments ``first .. last`` (plane
    numbers) lie wholly in it: ``(low_end, high_start)``, the parts being ``[k_lo,
    low_end]`` and ``[high_start, k_hi]`` (empty beside an end slice whose half segment is
    whole). With no whole segment (``first > last``) the stretch meets two segments at
    most, and both bounds are where they meet."""
    h = 1.0 / planes
    if first > last:
        meet = min(math.floor(k_lo * planes + 0.5) * h + 0.5 * h, n_k - 1.0, k_hi)
        return meet, meet
    return (k_lo if first == 0 else max(first * h - 0.5 * h, k_lo),
            k_hi if last == (n_k - 1) * planes else min(last * h + 0.5 * h, k_hi))


@helper_jit
def _slice_sum(slices, k, rows, i0, ntaps, wi, wj):
    """Slice ``k`` at taps ``i0 ..`` of rows ``rows``, weighted ``wi`` along and ``wj`` across
    the rows; columns clamped to the slice only near its ends."""
    n_i = slices.shape[2]
    value = 0.0
    if i0 >= 0 and i0 + ntaps <= n_i:
        for b in range(ntaps):
            line = 0.0
            for a in range(ntaps):
                line += wi[a] * slices[k, rows[b], i0 + a]
            value += wj[b] * line
    else:
        for b in range(ntaps):
            line = 0.0
            for a in range(ntaps):
                line += wi[a] * slices[k, rows[b], clamp(i0 + a, n_i)]
            value += wj[b] * line
    return value


@jit(inline="always")
def _in_front_or_behind(buf, y, x, part, in_front):
    """Composite ``part[0, 0]`` (premultiplied RGBA, alone) in front of ``buf[y, x]`` or behind
    it: the over operator is associative, so a segment composited so after the others gives
    the image composited in order."""
    if in_front:
        behind = 1.0 - part[0, 0, 3]
        for ch in range(4):
            buf[y, x, ch] = part[0, 0, ch] + behind * buf[y, x, ch]
    else:
        front = 1.0 - buf[y, x, 3]
        for ch in range(4):
            buf[y, x, ch] += front * part[0, 0, ch]


@jit(inline="always")
def _plane_sum(slices, k, k2, w, rows, i0, ntaps, wi, wj):
    """:func:`_slice_sum` on the plane ``w`` of the way from slice ``k`` to slice ``k2``:
    slice ``k`` itself where ``w`` is 0, else the two slices' sums interpolated linearly."""
    if w == 0.0:
        return _slice_sum(slices, k, rows, i0, ntaps, wi, wj)
    return ((1.0 - w) * _slice_sum(slices, k, rows, i0, ntaps, wi, wj)
            + w * _slice_sum(slices, k2, rows, i0, ntaps, wi, wj))


@parallel_jit
def shear_slices(slices, order, other, between, scale, di, dj, fraction, fkind, fp0, fp1, fp2,
                 radius, ntaps, tstart, tinv, alpha_tab, color_tab, emit_tab, grads, lit, ramp_x,
                 ramp_y, rays, threshold, first, last, inter, counts, lattice, full_first,
                 full_last):
    """Shear-warp's compositing into the intermediate image (Lacroute and Levoy 1994).

    ``slices[k, j, i]`` is the volume in slice order. The sample planes are taken front to
    back: plane ``p`` lies ``between[p]`` of the way from slice ``order[p]`` to slice
    ``other[p]`` (0: the slice itself; planes between two slices interpolate them linearly,
    the tent filter across slices). Intermediate pixel ``(I, J)`` samples plane ``p`` at
    ``(i, j) = scale[p] (I, J) + (di[p], dj[p])``: a translation (orthographic, ``scale =
    1``: one fractional offset per plane, so one set of filter weights serves the whole
    plane) or a translation and scale (perspective). Each plane is composited into
    ``inter[J, I]`` (premultiplied RGBA, zeros on entry) as a segment of the table's length
    times ``fraction[J, I]`` (shape ``(1, 1)``: 1 everywhere), halved on the volume's end
    slices. Row ``j`` of slice ``k`` holds nothing visible outside columns ``first[k, j] ..
    last[k, j]`` (a plane between two slices, nothing outside the union of theirs: the
    filter has no negative lobes where runs are skipped); pixels whose opacity has reached
    ``threshold`` take no more. With exact segment ends (``full_first`` of shape
    ``inter.shape[:2]``; ``(1, 1)`` for none), pixel ``(I, J)`` takes plane ``p`` only where
    ``full_first[J, I] <= lattice[p] <= full_last[J, I]`` (``lattice[p]``: the plane's place
    on the planes' lattice, from slice 0): the planes whose whole segment lies inside the
    volume; :func:`shear_cut_ends` adds the parts of the others. Each task owns intermediate
    rows: no races. With ``grads`` (``[3, k, j, i]``, the gradient's components in slice
    order; ``no_gradients()`` for none) each sample's gradient is resampled with the same
    weights and the sample classified by it too (:func:`_over_lit`),
    seen along ``rays[J, I]`` (world unit directions, shape ``(1, 1, 3)``: the view's one
    direction).
    """
    lighting = lit[0] != 0.0 or lit[2] != 0.0  # shading or gradient opacity
    n_k, n_j, n_i = slices.shape
    height, width = inter.shape[0], inter.shape[1]
    uniform = fraction.shape[0] == 1
    exact = full_first.shape[0] > 1
    alpha_tab, emit_tab, lit, ramp_x, ramp_y, inter = _lit_views(alpha_tab, emit_tab, lit,
                                                                 ramp_x, ramp_y, inter)
    slices, grads = borrowed(slices), borrowed(grads)
    for row in prange(height):
        big_j = np.int64(row)
        wi = np.empty(8)
        wj = np.empty(8)
        rows = np.empty(8, np.int64)
        done = 0
        for p in range(order.shape[0]):
            k, k2, w = order[p], other[p], between[p]
            s = scale[p]
            j = s * big_j + dj[p]
            if j < 0.0 or j > n_j - 1:
                continue
            j_first = int(math.floor(j - radius)) + 1
            # Columns this row can draw: the union of the tap rows' visible runs (of both
            # slices, on a plane between two), widened.
            lo = n_i
            hi = -1
            for b in range(ntaps):
                wj[b] = weight(fkind, fp0, fp1, fp2, j - (j_first + b))
                rows[b] = clamp(j_first + b, n_j)
                if first[k, rows[b]] <= last[k, rows[b]]:
                    lo = min(lo, first[k, rows[b]])
                    hi = max(hi, last[k, rows[b]])
                if w != 0.0 and first[k2, rows[b]] <= last[k2, rows[b]]:
                    lo = min(lo, first[k2, rows[b]])
                    hi = max(hi, last[k2, rows[b]])
            if lo > hi:
                continue
            i_lo = max(0.0, lo - radius)
            i_hi = min(n_i - 1.0, hi + radius)
            big_first = max(0, int(math.ceil((i_lo - di[p]) / s)))
            big_last = min(width - 1, int(math.floor((i_hi - di[p]) / s)))
            shared = s == 1.0
            tap0 = int(math.floor(di[p] - radius)) + 1  # orthographic: first tap - I
            if shared:
                for a in range(ntaps):
                    wi[a] = weight(fkind, fp0, fp1, fp2, di[p] - (tap0 + a))
            end = 0.5 if w == 0.0 and (k == 0 or k == n_k - 1) else 1.0
            for big_i in range(big_first, big_last + 1):
                if inter[big_j, big_i, 3] >= threshold:
                    continue
                if exact and not (full_first[big_j, big_i] <= lattice[p]
                                  <= full_last[big_j, big_i]):
                    continue  # a segment the volume's faces cut: shear_cut_ends
                if shared:
                    i0 = big_i + tap0
                else:
                    i = s * big_i + di[p]
                    i0 = int(math.floor(i - radius)) + 1
                    for a in range(ntaps):
                        wi[a] = weight(fkind, fp0, fp1, fp2, i - (i0 + a))
                value = _plane_sum(slices, k, k2, w, borrowed(rows), i0, ntaps, borrowed(wi),
                                   borrowed(wj))
                done += 1
                part = end if uniform else end * fraction[big_j, big_i]
                if lighting:
                    # Perspective: each intermediate pixel's own ray direction.
                    ray_j, ray_i = (0, 0) if rays.shape[0] == 1 else (big_j, big_i)
                    _over_lit(value, part, _plane_sum(grads[0], k, k2, w, borrowed(rows), i0,
                                                      ntaps, borrowed(wi), borrowed(wj)),
                              _plane_sum(grads[1], k, k2, w, borrowed(rows), i0, ntaps,
                                         borrowed(wi), borrowed(wj)),
                              _plane_sum(grads[2], k, k2, w, borrowed(rows), i0, ntaps,
                                         borrowed(wi), borrowed(wj)), tstart, tinv,
                              alpha_tab, emit_tab, lit, ramp_x, ramp_y, inter, big_j, big_i,
                              rays[ray_j, ray_i, 0], rays[ray_j, ray_i, 1],
                              rays[ray_j, ray_i, 2])
                else:
                    _over(value, part, tstart, tinv, alpha_tab, color_tab, inter, big_j, big_i)
        counts[big_j] = done


@jit
def shear_cut_ends(slices, planes, ascending, ends, fraction, fkind, fp0, fp1, fp2, radius,
                   ntaps, tstart, tinv, alpha_tab, color_tab, emit_tab, grads, lit, ramp_x,
                   ramp_y, rays, inside, full_first, full_last, inter, counts):
    """Shear-warp's exact segment ends: the parts inside the volume of the segments that its
    side faces cut, composited in front of and behind what :func:`shear_slices` composited
    into ``inter`` (the operator is associative: the same image as in order, but for
    rounding and for early termination, which :func:`shear_slices` decides without the front
    part).

    The planes lie ``1 / planes`` apart from slice 0; plane ``q``'s segment is ``[q h - h/2,
    q h + h/2]`` in slice coordinates, cut to ``[0, n_k - 1]`` (the end slices' halves).
    Pixel ``(I, J)``'s ray lies inside the volume for slice coordinates ``inside[J, I] =
    (k_lo, k_hi)`` (empty: ``k_lo > k_hi``), and at ``(i, j) = s (I, J) + (di, dj)`` on slice
    coordinate ``k``, where ``ends[:, 0]`` and ``ends[:, 1]`` are ``(s, di, dj)`` on the
    first and last slice and all three are linear in ``k``. The planes ``full_first ..
    full_last`` lie wholly inside; the part of the ray inside before the first of them (or
    the parts of the one or two segments it meets, where none is) and after the last are
    each one segment's part (:func:`_cut_bounds`), sampled at its middle (the two slices
    about it interpolated linearly, as a plane between them), of length over ``h`` times
    ``fraction[J, I]`` (perspective) the table's. Serial: two samples a ray at most, where
    numba's parallel passes would lengthen its compile by more than it runs."""
    lighting = lit[0] != 0.0 or lit[2] != 0.0
    n_k, n_j, n_i = slices.shape
    height, width = inter.shape[0], inter.shape[1]
    h = 1.0 / planes
    alpha_tab, emit_tab, lit, ramp_x, ramp_y, inter = _lit_views(alpha_tab, emit_tab, lit,
                                                                 ramp_x, ramp_y, inter)
    slices, grads = borrowed(slices), borrowed(grads)
    wi = np.empty(8)
    wj = np.empty(8)
    rows = np.empty(8, np.int64)
    part = np.zeros((1, 1, 4))
    for big_j in range(height):
        done = 0
        for big_i in range(width):
            k_lo, k_hi = inside[big_j, big_i, 0], inside[big_j, big_i, 1]
            if k_lo > k_hi:
                continue
            low_end, high_start = _cut_bounds(k_lo, k_hi, full_first[big_j, big_i],
                                              full_last[big_j, big_i], n_k, planes)
            for side in range(2):  # 0: the low end (slice 0's side), 1: the high end
                a, b = (k_lo, low_end) if side == 0 else (high_start, k_hi)
                if not b > a:
                    continue
                k = 0.5 * (a + b)
                t = k / (n_k - 1.0)
                s = ends[0, 0] + (ends[0, 1] - ends[0, 0]) * t
                i = s * big_i + (ends[1, 0] + (ends[1, 1] - ends[1, 0]) * t)
                j = s * big_j + (ends[2, 0] + (ends[2, 1] - ends[2, 0]) * t)
                i = min(max(i, 0.0), n_i - 1.0)  # on the face, where rounding put it past
                j = min(max(j, 0.0), n_j - 1.0)
                j_first = int(math.floor(j - radius)) + 1
                for c in range(ntaps):
                    wj[c] = weight(fkind, fp0, fp1, fp2, j - (j_first + c))
                    rows[c] = clamp(j_first + c, n_j)
                i0 = int(math.floor(i - radius)) + 1
                for c in range(ntaps):
                    wi[c] = weight(fkind, fp0, fp1, fp2, i - (i0 + c))
                k0 = min(int(math.floor(k)), n_k - 2)
                w = k - k0
                value = _plane_sum(slices, k0, k0 + 1, w, borrowed(rows), i0, ntaps,
                                   borrowed(wi), borrowed(wj))
                done += 1
                length = (b - a) / h * (fraction[0, 0] if fraction.shape[0] == 1
                                        else fraction[big_j, big_i])
                part[0, 0, 0] = part[0, 0, 1] = part[0, 0, 2] = part[0, 0, 3] = 0.0
                if lighting:
                    ray_j, ray_i = (0, 0) if rays.shape[0] == 1 else (big_j, big_i)
                    _over_lit(value, length, _plane_sum(grads[0], k0, k0 + 1, w,
                                                        borrowed(rows), i0, ntaps,
                                                        borrowed(wi), borrowed(wj)),
                              _plane_sum(grads[1], k0, k0 + 1, w, borrowed(rows), i0, ntaps,
                                         borrowed(wi), borrowed(wj)),
                              _plane_sum(grads[2], k0, k0 + 1, w, borrowed(rows), i0, ntaps,
                                         borrowed(wi), borrowed(wj)), tstart, tinv,
                              alpha_tab, emit_tab, lit, ramp_x, ramp_y, part, 0, 0,
                              rays[ray_j, ray_i, 0], rays[ray_j, ray_i, 1],
                              rays[ray_j, ray_i, 2])
                else:
                    _over(value, length, tstart, tinv, alpha_tab, color_tab, part, 0, 0)
                _in_front_or_behind(inter, big_j, big_i, part, (side == 0) == ascending)
        counts[big_j] += done


@parallel_jit
def project_slices(slices, order, scale, di, dj, fkind, fp0, fp1, fp2, radius, ntaps, maximum,
                   value, count):
    """Shear-warp's maximum- (``maximum``) or average-intensity projection into the
    intermediate image: ``value[J, I]`` the largest, or the sum, of the values that
    intermediate pixel ``(I, J)`` samples in the slices (at the same points, with the same
    weights, as :func:`shear_slices`), ``count[J, I]`` how many (both zeros on entry). No
    run is skipped: a projection's value may lie anywhere along the ray. Each task owns
    intermediate rows and takes the slices in ``order``: the image does not depend on the
    thread count."""
    n_k, n_j, n_i = slices.shape
    height, width = value.shape[0], value.shape[1]
    slices = borrowed(slices)
    for row in prange(height):
        wi = np.empty(8)
        wj = np.empty(8)
        rows = np.empty(8, np.int64)
        for step in range(n_k):
            k = order[step]
            s = scale[k]
            j = s * row + dj[k]
            if j < 0.0 or j > n_j - 1:
                continue
            j_first = filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, j, borrowed(wj))
            for b in range(ntaps):
                rows[b] = clamp(j_first + b, n_j)
            big_first = max(0, int(math.ceil(-di[k] / s)))
            big_last = min(width - 1, int(math.floor((n_i - 1.0 - di[k]) / s)))
            # Orthographic: one fractional offset per slice, one set of weights for it all.
            shared = s == 1.0
            tap0 = (filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, di[k], borrowed(wi))
                    if shared else 0)
            for big_i in range(big_first, big_last + 1):
                if shared:
                    i0 = big_i + tap0
                else:
                    i0 = filter_taps(fkind, fp0, fp1, fp2, radius, ntaps, s * big_i + di[k],
                                     borrowed(wi))
                v = _slice_sum(slices, k, borrowed(rows), i0, ntaps, borrowed(wi), borrowed(wj))
                if not maximum:
                    value[row, big_i] += v
                elif count[row, big_i] == 0 or v > value[row, big_i]:
                    value[row, big_i] = v
                count[row, big_i] += 1


@jit(inline="always")
def _warp_pixel(inter, x, y, out, row, c, grey):
    """``out[row, c]`` = ``inter`` sampled bilinearly at ``(x, y)``, clipped to [0, 1];
    transparent outside it, or where all four neighbours are (colours are premultiplied).
    ``grey``: red, green and blue are equal, and only red is interpolated."""
    n_j, n_i = inter.shape[0], inter.shape[1]
    red = green = blue = alpha = 0.0
    if x >= 0.0 and y >= 0.0 and x <= n_i - 1 and y <= n_j - 1:
        i = min(int(x), n_i - 2)
        j = min(int(y), n_j - 2)
        last = inter.shape[2] - 1  # opacity
        a00, a01 = at(inter, (j, i, last)), at(inter, (j, i + 1, last))
        a10, a11 = at(inter, (j + 1, i, last)), at(inter, (j + 1, i + 1, last))
        if not (a00 == 0.0 and a01 == 0.0 and a10 == 0.0 and a11 == 0.0):
            tx = x - i
            ty = y - j
            alpha = _clipped((1 - ty) * ((1 - tx) * a00 + tx * a01)
                             + ty * ((1 - tx) * a10 + tx * a11))
            red = green = blue = _bilinear(inter, j, i, 0, tx, ty)
            if not grey:
                green = _bilinear(inter, j, i, 1, tx, ty)
                blue = _bilinear(inter, j, i, 2, tx, ty)
    put(out, (row, c, 0), red)
    put(out, (row, c, 1), green)
    put(out, (row, c, 2), blue)
    put(out, (row, c, 3), alpha)


def _warp_octet_lanes(inter, src, mx, ax, my, ay, out, flat, row, c, grey):
    """:func:`warp_octet` one pixel at a time (without the JIT): :func:`_warp_pixel`."""
    for lane in range(LANES):
        _warp_pixel(inter, mx * (c + lane) + ax, my * (c + lane) + ay, out, row, c + lane,
                    grey)


@jit(inline="always")
def _warp_octet_compiled(inter, src, mx, ax, my, ay, out, flat, row, c, grey):
    at_out = (row * out.shape[1] + c) * 4
    if grey and inter.shape[2] == 2:
        warp_octet_grey_pairs(src, inter.shape[1], inter.shape[0], flat, at_out, c, mx, ax,
                              my, ay)
    elif grey:
        warp_octet_grey(src, inter.shape[1], inter.shape[0], flat, at_out, c, mx, ax, my, ay)
    else:
        warp_octet_colour(src, inter.shape[1], inter.shape[0], flat, at_out, c, mx, ax, my, ay)


warp_octet = _warp_octet_lanes if numba.config.DISABLE_JIT else _warp_octet_compiled
"""``warp_octet(inter, src, mx, ax, my, ay, out, flat, row, c, grey)``: pixels
``c .. c + LANES - 1`` of row ``row`` of the affine warp (:func:`warp_rows`; pixel ``c``
samples ``inter`` at ``(mx c + ax, my c + ay)``) at once, in vector form
(:func:`vrlib._kernels.packets.warp_octet_grey_pairs`, ``_grey`` and ``_colour``, for
``inter`` of two channels or four): :func:`_warp_pixel`'s arithmetic lane by lane, so the
image is the same bit for bit. ``inter`` and ``out`` C-contiguous, ``src`` and ``flat``
their raveled views."""


@jit(inline="always")
def _bilinear(inter, j, i, ch, tx, ty):
    """Channel ``ch`` of ``inter`` at ``(i + tx, j + ty)``, clipped to [0, 1]."""
    top = (1 - tx) * at(inter, (j, i, ch)) + tx * at(inter, (j, i + 1, ch))
    bottom = (1 - tx) * at(inter, (j + 1, i, ch)) + tx * at(inter, (j + 1, i + 1, ch))
    return _clipped((1 - ty) * top + ty * bottom)


@jit(inline="always")
def _clipped(value):
    return min(max(value, 0.0), 1.0)


@jit
def seen_box(inter):
    """The columns and rows of ``inter`` that hold a pixel that is not transparent,
    ``(i_lo, i_hi, j_lo, j_hi)`` as floats; ``-3`` each where none does (no column then
    meets the box). Each row is scanned from its two ends inwards, so only the transparent
    margins are read in full."""
    n_j, n_i, last = inter.shape[0], inter.shape[1], inter.shape[2] - 1  # opacity: last
    i_lo, i_hi, j_lo, j_hi = n_i, -1, n_j, -1
    for j in range(n_j):
        i = 0
        while i < min(i_lo, n_i) and at(inter, (j, i, last)) == 0.0:
            i += 1
        if i == n_i:  # a transparent row
            continue
        j_lo = min(j_lo, j)
        j_hi = j
        i_lo = min(i_lo, i)
        i = n_i - 1
        while i > i_hi and at(inter, (j, i, last)) == 0.0:
            i -= 1
        i_hi = max(i_hi, i)
    if j_hi < 0:
        return np.array([-3.0, -3.0, -3.0, -3.0])
    return np.array([float(i_lo), float(i_hi), float(j_lo), float(j_hi)])


@jit(inline="always")
def _columns_within(a, b, lo, hi, width):
    """The columns ``c`` of ``[0, width)`` with ``lo <= a c + b <= hi``, widened by one
    column each way (rounding): ``(first, stop)``, empty when ``first >= stop``."""
    if a == 0.0:  # parallel to the box's sides
        return (0, width) if not lo > b and not b > hi else (0, 0)
    c0 = (lo - b) / a
    c1 = (hi - b) / a
    if not (c0 == c0 and c1 == c1):  # NaN
        return (0, width) if not lo > b and not b > hi else (0, 0)
    if c0 > c1:
        c0, c1 = c1, c0
    c0 = min(max(c0, 0.0), float(width))  # clipped before the conversion to an integer
    c1 = min(max(c1, -2.0), float(width))
    return max(int(math.floor(c0)) - 1, 0), min(int(math.ceil(c1)) + 2, width)


@jit
def warp_rows(inter, m, out, grey, seen, band_rows, counter):
    """The 2-D warp (:func:`vrlib.shearwarp.warp`): ``out[r, c]`` is ``inter`` sampled
    bilinearly at ``(I, J) = (A, B) / D`` with ``(A, B, D) = m @ (c, r, 1)``, transparent
    outside, or where ``D <= 0`` (the pixel's ray never meets the intermediate image's plane),
    clipped to [0, 1]; ``grey`` images (red, green and blue equal) interpolate one colour
    channel, and may hold red and opacity alone (two channels: opacity is the last).

    An affine ``m`` (orthographic views: ``D = 1``) takes no division and visits only the
    columns that can meet the intermediate image's non-transparent box ``seen = (i_lo, i_hi,
    j_lo, j_hi)`` (:func:`seen_box`); the rest of each row is transparent without a look, as
    every pixel there reads four transparent neighbours. Several threads make the call at once
    (:func:`vrlib._scheduling.on_threads`); each takes the next band of ``band_rows`` rows from
    ``counter`` (:func:`vrlib._kernels.queue.take`) until none is left. Rows are independent:
    the image does not depend on the thread count.
    """
    inter, m, out, seen = borrowed(inter), borrowed(m), borrowed(out), borrowed(seen)
    height, width = out.shape[0], out.shape[1]
    affine = m[2, 0] == 0.0 and m[2, 1] == 0.0 and m[2, 2] == 1.0
    src, flat = inter.reshape(-1), out.reshape(-1)
    while True:
        first_row = take(counter) * band_rows
        if first_row >= height:
            break
        for row in range(first_row, min(first_row + band_rows, height)):
            if affine:
                _warp_affine_row(inter, src, m, out, flat, grey, seen, row, width)
                continue
            for c in range(width):
                d = m[2, 0] * c + m[2, 1] * row + m[2, 2]
                if d > 0.0:
                    _warp_pixel(inter, (m[0, 0] * c + m[0, 1] * row + m[0, 2]) / d,
                                (m[1, 0] * c + m[1, 1] * row + m[1, 2]) / d, out, row, c, grey)
                else:
                    for ch in range(4):
                        put(out, (row, c, ch), 0.0)


@jit(inline="always")
def _warp_affine_row(inter, src, m, out, flat, grey, seen, row, width):
    """Row ``row`` of the affine warp (:func:`warp_rows`)."""
    ax = m[0, 1] * row + m[0, 2]
    ay = m[1, 1] * row + m[1, 2]
    mx, my = m[0, 0], m[1, 0]  # in locals: the stores to ``out`` need not reload them
    # A pixel reads columns int(x) and int(x) + 1: it can meet the box only for
    # i_lo - 1 <= x < i_hi + 1 (and likewise for y).
    x0, x1 = _columns_within(mx, ax, seen[0] - 1.0, seen[1] + 1.0, width)
    y0, y1 = _columns_within(my, ay, seen[2] - 1.0, seen[3] + 1.0, width)
    first = max(x0, y0)
    stop = max(min(x1, y1), first)
    for c in range(first):
        for ch in range(4):
            put(out, (row, c, ch), 0.0)
    octets = first + (stop - first) // LANES * LANES
    for c in range(first, octets, LANES):  # LANES pixels at once, in vector form
        warp_octet(inter, src, mx, ax, my, ay, out, flat, row, c, grey)
    for c in range(octets, stop):
        _warp_pixel(inter, mx * c + ax, my * c + ay, out, row, c, grey)
    for c in range(stop, width):
        for ch in range(4):
            put(out, (row, c, ch), 0.0)
