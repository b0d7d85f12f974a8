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
from vrlib._kernels.raycast import _lookup
from vrlib._kernels.sampling import _clamp


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
def _classify_over(value, tstart, tinv, alpha_tab, color_tab, acc, half):
    """Classify one sample from the segment table and composite it under ``acc`` (eqs 1.7-1.8,
    colour E alpha: eq 1.9). With ``half`` the segment is half the table's length: the first
    and last slices of a volume reach only half a slice spacing into it, and
    ``1 - alpha_half = sqrt(1 - alpha)``."""
    i, w = _lookup((value - tstart) * tinv, alpha_tab.shape[0])
    alpha = alpha_tab[i] + w * (alpha_tab[i + 1] - alpha_tab[i])
    if alpha > 0.0:
        scale = 1.0
        if half:
            shorter = 1.0 - math.sqrt(1.0 - alpha)
            scale = shorter / alpha
            alpha = shorter
        remaining = 1.0 - acc[3]
        for ch in range(3):
            acc[ch] += remaining * scale * (color_tab[i, ch] + w * (color_tab[i + 1, ch]
                                                                      - color_tab[i, ch]))
        acc[3] += remaining * alpha


@parallel_jit
def composite_lattice(vol, inverse, shift, limits, tstart, tinv, alpha_tab, color_tab,
                      threshold, out, counts):
    """Three-pass compositing: ``vol[Z, Y, X]`` lies on the image lattice; each pixel takes its
    samples in order of increasing ``Z`` (front to back). A sample belongs to the volume when
    ``inverse @ ((X, Y, Z) - shift)`` lies within ``[0, limits]`` on every axis."""
    n_z, height, width = vol.shape
    for row_index in prange(height):
        y = np.int64(row_index)
        acc = np.zeros(4)
        done = 0
        for x in range(width):
            acc[:] = 0.0
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
                _classify_over(vol[z, y, x], tstart, tinv, alpha_tab, color_tab, acc, False)
                if acc[3] >= threshold:
                    break
            for ch in range(4):
                out[y, x, ch] = acc[ch]
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
        acc = np.zeros(4)
        done = 0
        for x in range(width):
            acc[:] = 0.0
            for step in range(n_w):
                w = step if front_to_back else n_w - 1 - step
                dx = x - shift[0] - w * shift[2]
                dy = y - shift[1] - w * shift[3]
                u = inverse2[0, 0] * dx + inverse2[0, 1] * dy
                v = inverse2[1, 0] * dx + inverse2[1, 1] * dy
                if u < 0.0 or u > limits[0] or v < 0.0 or v > limits[1]:
                    continue
                done += 1
                _classify_over(vol[w, y, x], tstart, tinv, alpha_tab, color_tab, acc,
                               w == 0 or w == n_w - 1)
                if acc[3] >= threshold:
                    break
            for ch in range(4):
                out[y, x, ch] = acc[ch]
        counts[y] = done


@parallel_jit
def shear_slices(slices, order, di, dj, fkind, fp0, fp1, fp2, radius, ntaps, tstart, tinv,
                 alpha_tab, color_tab, threshold, first, last, inter, counts):
    """Shear-warp's compositing into the intermediate image (Lacroute and Levoy 1994).

    ``slices[k, j, i]`` is the volume in slice order; slice ``k`` lands on the intermediate
    image translated so that intermediate pixel ``(I, J)`` samples the slice at
    ``(i, j) = (I + di[k], J + dj[k])``: one fractional offset per slice, so the filter's
    weights are the same for every pixel of it. Slices are taken in ``order`` (front to back)
    and composited into ``inter[J, I]`` (premultiplied RGBA), each a segment of the table's
    length but the first and last, half as long. Row ``j`` of slice ``k`` holds
    nothing visible outside columns ``first[k, j] .. last[k, j]``; pixels whose opacity has
    reached ``threshold`` take no more. Each task owns intermediate rows: no races.
    """
    n_k, n_j, n_i = slices.shape
    height, width = inter.shape[0], inter.shape[1]
    for row in prange(height):
        big_j = np.int64(row)
        wi = np.empty(8)
        wj = np.empty(8)
        done = 0
        for step in range(n_k):
            k = order[step]
            j = big_j + dj[k]
            if j < 0.0 or j > n_j - 1:
                continue
            j_first = int(math.floor(j - radius)) + 1
            for b in range(ntaps):
                wj[b] = weight(fkind, fp0, fp1, fp2, j - (j_first + b))
            # Columns this row can draw: the union of the tap rows' visible runs, widened.
            lo = n_i
            hi = -1
            for b in range(ntaps):
                jj = _clamp(j_first + b, n_j)
                if first[k, jj] <= last[k, jj]:
                    lo = min(lo, first[k, jj])
                    hi = max(hi, last[k, jj])
            if lo > hi:
                continue
            frac_first = int(math.floor(di[k] - radius)) + 1  # tap offset of I = 0
            for a in range(ntaps):
                wi[a] = weight(fkind, fp0, fp1, fp2, di[k] - (frac_first + a))
            i_lo = -di[k]  # intermediate columns whose sample lies in the slice
            i_hi = n_i - 1.0 - di[k]
            big_first = max(int(math.ceil(i_lo)), int(math.floor(lo - radius - di[k])))
            big_last = min(int(math.floor(i_hi)), int(math.ceil(hi + radius - di[k])), width - 1)
            for big_i in range(max(big_first, 0), big_last + 1):
                if inter[big_j, big_i, 3] >= threshold:
                    continue
                value = 0.0
                for b in range(ntaps):
                    jj = _clamp(j_first + b, n_j)
                    line = 0.0
                    for a in range(ntaps):
                        line += wi[a] * slices[k, jj, _clamp(big_i + frac_first + a, n_i)]
                    value += wj[b] * line
                done += 1
                _classify_over(value, tstart, tinv, alpha_tab, color_tab, inter[big_j, big_i],
                               k == 0 or k == n_k - 1)
        counts[big_j] = done


@parallel_jit
def warp(inter, coords, out):
    """The 2-D warp: ``out[r, c]`` is ``inter`` sampled bilinearly at ``coords[r, c] = (I, J)``
    (transparent outside)."""
    height, width = out.shape[0], out.shape[1]
    n_j, n_i = inter.shape[0], inter.shape[1]
    for row in prange(height):
        for c in range(width):
            x = coords[row, c, 0]
            y = coords[row, c, 1]
            for ch in range(4):
                out[row, c, ch] = 0.0
            if not (x >= 0.0 and y >= 0.0 and x <= n_i - 1 and y <= n_j - 1):
                continue
            i = min(int(x), n_i - 2)
            j = min(int(y), n_j - 2)
            tx = x - i
            ty = y - j
            for ch in range(4):
                top = (1 - tx) * inter[j, i, ch] + tx * inter[j, i + 1, ch]
                bottom = (1 - tx) * inter[j + 1, i, ch] + tx * inter[j + 1, i + 1, ch]
                out[row, c, ch] = (1 - ty) * top + ty * bottom
