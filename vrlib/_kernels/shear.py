"""Kernels of the volume-shearing renderers: 1-D resampling passes and compositing.

A pass resamples along the last axis of its (possibly transposed) source: output line
``out[s, r, :]`` takes, at output position ``q``, the source line ``src[s, r, :]`` at
``pos = (q - offset - c1 r - c2 s) / c0`` (a scaled shear, eq. "x' = Ax + B" of the thesis's
section 1.2), reconstructed with a 1-D filter whose taps are clamped at the line's ends. Only
outputs whose ``pos`` lies within the line (widened by the filter's reach) are computed; the
rest stay zero. The compositing kernels read the last intermediate volume along the view.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from vrlib._kernels._jit import jit, parallel_jit
from vrlib._kernels.filters import weight
from vrlib._kernels.sampling import clamp
from vrlib._kernels.tables import lookup


@parallel_jit
def shear_pass(src, out, c0, c1, c2, offset, line_lo, line_hi, fkind, fp0, fp1, fp2, radius,
               ntaps, counts, out_first, out_last):
    """One resampling pass (see the module docstring); ``counts[s]`` gets the outputs computed
    for outer index ``s``.

    Source line ``(s, r)`` holds data only on ``line_lo[s, r] .. line_hi[s, r]`` (the part an
    earlier pass filled); taps are clamped to it, and only outputs whose source lies within it,
    widened by the filter's reach, are computed: ``out_first[s, r] .. out_last[s, r]``.
    """
    n_s, n_r, n_q = out.shape
    n = src.shape[2]
    for s_index in prange(n_s):
        s = np.int64(s_index)
        done = 0
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
            q_first = max(0, int(math.ceil(min(q_a, q_b))))
            q_last = min(n_q - 1, int(math.floor(max(q_a, q_b))))
            out_first[s, r] = q_first
            out_last[s, r] = q_last
            for q in range(q_first, q_last + 1):
                pos = (q - base) / c0
                first = int(math.floor(pos - radius)) + 1
                acc = 0.0
                for a in range(ntaps):
                    tap = min(max(first + a, lo), hi)
                    acc += weight(fkind, fp0, fp1, fp2, pos - (first + a)) * src[s, r, tap]
                out[s, r, q] = acc
                done += 1
        counts[s] += done


@jit
def _over(value, fraction, tstart, tinv, alpha_tab, color_tab, buf, y, x):
    """Classify one sample from the segment table and composite it under ``buf[y, x]``
    (premultiplied RGBA; eqs 1.7-1.8, colour E alpha: eq 1.9). ``fraction`` is the sample's
    segment length over the table's: ``1 - alpha' = (1 - alpha) ** fraction``, the colour
    scaled with the opacity (the first and last slices of a volume reach half a slice spacing
    into it; perspective rays cross the slices at their own angles)."""
    i, w = lookup((value - tstart) * tinv, alpha_tab.shape[0])
    alpha = alpha_tab[i] + w * (alpha_tab[i + 1] - alpha_tab[i])
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


@parallel_jit
def composite_lattice(vol, inverse, shift, limits, tstart, tinv, alpha_tab, color_tab,
                      threshold, out, counts):
    """Three-pass compositing: ``vol[Z, Y, X]`` lies on the image lattice; each pixel takes its
    samples in order of increasing ``Z`` (front to back) into ``out`` (zeros). A sample belongs
    to the volume when ``inverse @ ((X, Y, Z) - shift)`` lies within ``[0, limits]`` on every
    axis."""
    n_z, height, width = vol.shape
    for row_index in prange(height):
        y = np.int64(row_index)
        done = 0
        for x in range(width):
            for z in range(n_z):
                inside = True
                for a in range(3):
                    u = (inverse[a, 0] * (x - shift[0]) + inverse[a, 1] * (y - shift[1])
                         + inverse[a, 2] * (z - shift[2]))
                    if u < 0.0 or u > limits[a]:
                        inside = False
                if not inside:
                    continue
                done += 1
                _over(vol[z, y, x], 1.0, tstart, tinv, alpha_tab, color_tab, out, y, x)
                if out[y, x, 3] >= threshold:
                    break
        counts[y] = done


@parallel_jit
def composite_slices(vol, front_to_back, inverse2, shift, limits, tstart, tinv, alpha_tab,
                     color_tab, threshold, out, counts):
    """Two-pass compositing: ``vol[w, Y, X]`` holds slice ``w`` resampled onto the image's
    rows and columns; each pixel composites the slices in view order, each a segment of the
    same length (the table's) but the first and last, which reach half as far into the volume.
    Sample ``(X, Y)`` of slice ``w`` belongs to the volume when
    ``(u, v) = inverse2 @ ((X, Y) - shift[:2] - w shift[2:])`` lies within ``limits``."""
    n_w, height, width = vol.shape
    for row_index in prange(height):
        y = np.int64(row_index)
        done = 0
        for x in range(width):
            for step in range(n_w):
                w = step if front_to_back else n_w - 1 - step
                dx = x - shift[0] - w * shift[2]
                dy = y - shift[1] - w * shift[3]
                u = inverse2[0, 0] * dx + inverse2[0, 1] * dy
                v = inverse2[1, 0] * dx + inverse2[1, 1] * dy
                if u < 0.0 or u > limits[0] or v < 0.0 or v > limits[1]:
                    continue
                done += 1
                end = 0.5 if w == 0 or w == n_w - 1 else 1.0
                _over(vol[w, y, x], end, tstart, tinv, alpha_tab, color_tab, out, y, x)
                if out[y, x, 3] >= threshold:
                    break
        counts[y] = done


@parallel_jit
def shear_slices(slices, order, scale, di, dj, fraction, fkind, fp0, fp1, fp2, radius, ntaps,
                 tstart, tinv, alpha_tab, color_tab, threshold, first, last, inter, counts):
    """Shear-warp's compositing into the intermediate image (Lacroute and Levoy 1994).

    ``slices[k, j, i]`` is the volume in slice order. Intermediate pixel ``(I, J)`` samples
    slice ``k`` at ``(i, j) = scale[k] (I, J) + (di[k], dj[k])``: a translation (orthographic,
    ``scale = 1``: one fractional offset per slice, so one set of filter weights serves the
    whole slice) or a translation and scale (perspective). Slices are taken in ``order`` (front
    to back) and composited into ``inter[J, I]`` (premultiplied RGBA, zeros on entry), each a
    segment of the table's length times ``fraction[J, I]`` (shape ``(1, 1)``: 1 everywhere),
    halved on the first and last slice. Row ``j`` of slice ``k`` holds nothing visible outside
    columns ``first[k, j] .. last[k, j]``; pixels whose opacity has reached ``threshold`` take
    no more. Each task owns intermediate rows: no races.
    """
    n_k, n_j, n_i = slices.shape
    height, width = inter.shape[0], inter.shape[1]
    uniform = fraction.shape[0] == 1
    for row in prange(height):
        big_j = np.int64(row)
        wi = np.empty(8)
        wj = np.empty(8)
        rows = np.empty(8, np.int64)
        done = 0
        for step in range(n_k):
            k = order[step]
            s = scale[k]
            j = s * big_j + dj[k]
            if j < 0.0 or j > n_j - 1:
                continue
            j_first = int(math.floor(j - radius)) + 1
            # Columns this row can draw: the union of the tap rows' visible runs, widened.
            lo = n_i
            hi = -1
            for b in range(ntaps):
                wj[b] = weight(fkind, fp0, fp1, fp2, j - (j_first + b))
                rows[b] = clamp(j_first + b, n_j)
                if first[k, rows[b]] <= last[k, rows[b]]:
                    lo = min(lo, first[k, rows[b]])
                    hi = max(hi, last[k, rows[b]])
            if lo > hi:
                continue
            i_lo = max(0.0, lo - radius)
            i_hi = min(n_i - 1.0, hi + radius)
            big_first = max(0, int(math.ceil((i_lo - di[k]) / s)))
            big_last = min(width - 1, int(math.floor((i_hi - di[k]) / s)))
            shared = s == 1.0
            tap0 = int(math.floor(di[k] - radius)) + 1  # orthographic: first tap - I
            if shared:
                for a in range(ntaps):
                    wi[a] = weight(fkind, fp0, fp1, fp2, di[k] - (tap0 + a))
            end = 0.5 if k == 0 or k == n_k - 1 else 1.0
            for big_i in range(big_first, big_last + 1):
                if inter[big_j, big_i, 3] >= threshold:
                    continue
                if shared:
                    i0 = big_i + tap0
                else:
                    i = s * big_i + di[k]
                    i0 = int(math.floor(i - radius)) + 1
                    for a in range(ntaps):
                        wi[a] = weight(fkind, fp0, fp1, fp2, i - (i0 + a))
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
                done += 1
                part = end if uniform else end * fraction[big_j, big_i]
                _over(value, part, tstart, tinv, alpha_tab, color_tab, inter, big_j, big_i)
        counts[big_j] = done


@jit(inline="always")
def _warp_pixel(inter, x, y, out, row, c, grey):
    """``out[row, c]`` = ``inter`` sampled bilinearly at ``(x, y)``, clipped to [0, 1];
    transparent outside it, or where all four neighbours are (colours are premultiplied).
    ``grey``: red, green and blue are equal, and only red is interpolated."""
    n_j, n_i = inter.shape[0], inter.shape[1]
    if x >= 0.0 and y >= 0.0 and x <= n_i - 1 and y <= n_j - 1:
        i = min(int(x), n_i - 2)
        j = min(int(y), n_j - 2)
        if not (inter[j, i, 3] == 0.0 and inter[j, i + 1, 3] == 0.0
                and inter[j + 1, i, 3] == 0.0 and inter[j + 1, i + 1, 3] == 0.0):
            tx = x - i
            ty = y - j
            for ch in range(4):
                if grey and (ch == 1 or ch == 2):
                    continue
                top = (1 - tx) * inter[j, i, ch] + tx * inter[j, i + 1, ch]
                bottom = (1 - tx) * inter[j + 1, i, ch] + tx * inter[j + 1, i + 1, ch]
                out[row, c, ch] = min(max((1 - ty) * top + ty * bottom, 0.0), 1.0)
            if grey:
                out[row, c, 1] = out[row, c, 0]
                out[row, c, 2] = out[row, c, 0]
            return
    for ch in range(4):
        out[row, c, ch] = 0.0


@parallel_jit
def _warp_affine(inter, m, out, grey):
    height, width = out.shape[0], out.shape[1]
    for row in prange(height):
        ax = m[0, 1] * row + m[0, 2]
        ay = m[1, 1] * row + m[1, 2]
        for c in range(width):
            _warp_pixel(inter, m[0, 0] * c + ax, m[1, 0] * c + ay, out, row, c, grey)


@parallel_jit
def _warp_projective(inter, m, out, grey):
    height, width = out.shape[0], out.shape[1]
    for row in prange(height):
        for c in range(width):
            d = m[2, 0] * c + m[2, 1] * row + m[2, 2]
            if d > 0.0:
                _warp_pixel(inter, (m[0, 0] * c + m[0, 1] * row + m[0, 2]) / d,
                            (m[1, 0] * c + m[1, 1] * row + m[1, 2]) / d, out, row, c, grey)
            else:
                for ch in range(4):
                    out[row, c, ch] = 0.0


def warp(inter, homography, out, grey=False):
    """The 2-D warp: ``out[r, c]`` is ``inter`` sampled bilinearly at ``(I, J) = (A, B) / D``
    with ``(A, B, D) = homography @ (c, r, 1)`` (transparent outside, or where ``D <= 0``: the
    pixel's ray never meets the intermediate image's plane), clipped to [0, 1]. An affine
    homography (orthographic views: ``D = 1``) takes no division; ``grey`` images (red, green
    and blue equal) interpolate one colour channel."""
    if homography[2, 0] == 0.0 and homography[2, 1] == 0.0 and homography[2, 2] == 1.0:
        _warp_affine(inter, homography, out, grey)
    else:
        _warp_projective(inter, homography, out, grey)
