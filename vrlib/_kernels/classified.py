"""The classified shear-warp kernel: VolPack's way (Lacroute and Levoy 1994, sections 4-5).

The volume is classified once (:mod:`vrlib.classified`): per principal axis, every scanline of
every slice is run-length encoded into runs of visible voxels, each stored with its extinction
``sigma`` (per world unit), an emission code and a normal code. A frame walks the intermediate
image row by row; for each slice, front to back, the row's sample points lie between two voxel
scanlines with the same bilinear weights for every point of the slice. Only the points that a
visible voxel of either scanline touches are visited (the runs, merged), and of those only the
pixels not yet opaque: skip links with path compression jump over runs of opaque pixels (the
role of VolPack's run-length encoded intermediate image).

A sample's extinction is the bilinear mix of its four voxels' ``sigma`` and its colour their
extinction-weighted mix (opacity-weighted colour interpolation, Wittenbrink, Malzbender and
Goss 1998), so that a segment of length ``L`` has opacity ``1 - exp(-sigma L)`` (eq 1.4)
and premultiplied colour ``C alpha`` (eq 1.9).
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from vrlib._kernels._jit import jit, parallel_jit


@jit
def _open(links, i):
    """First pixel at or after ``i`` that is not opaque; compresses the path it walked."""
    root = i
    while links[root] != root:
        root = links[root]
    while links[i] != root:
        following = links[i]
        links[i] = root
        i = following
    return root


@jit
def _voxel(run_start, run_end, run_voxel, cursor, last, column):
    """Advance a scanline's run ``cursor`` (runs ``cursor .. last - 1``, increasing columns) to
    ``column``: returns the cursor and the stored voxel's index there, or -1 (transparent)."""
    while cursor < last and run_end[cursor] <= column:
        cursor += 1
    if cursor < last and run_start[cursor] <= column:
        return cursor, run_voxel[cursor] + column - run_start[cursor]
    return cursor, -1


@parallel_jit
def composite_classified(run_ptr, run_start, run_end, run_voxel, sigma, emission_code,
                         normal_code, n_j, order, di, dj, length, emission, factor, highlight,
                         grey, threshold, inter, counts):
    """Composite the slices ``order`` (front to back) into ``inter[J, I] = (r, g, b, a)``.

    Slice ``k``'s sample for intermediate pixel ``(I, J)`` lies at column ``I + di[k]`` and row
    ``J + dj[k]`` of the slice's ``n_j`` scanlines; scanline ``k * n_j + j`` holds runs
    ``run_ptr[.] .. run_ptr[. + 1] - 1`` (columns ``[run_start, run_end)``, first stored voxel
    ``run_voxel``). A voxel's colour is ``emission[e] * factor[n] + highlight[n]`` for its
    codes ``e`` and ``n`` (``grey``: ``factor[n] + highlight[n]``). Rows are independent and
    each is composited in a fixed order: the image does not depend on the thread count.
    ``counts[J]`` gets the samples row ``J`` composited.
    """
    height, width = inter.shape[0], inter.shape[1]
    for row in prange(height):
        links = np.arange(width + 1)
        opaque = 0
        taken = 0
        for step in range(order.shape[0]):
            if opaque == width:
                break
            k = order[step]
            y = row + dj[k]
            r0 = math.floor(y)
            fj = y - r0
            s_i = math.floor(di[k])
            fi = di[k] - s_i
            # The runs of the two scanlines around the row: r0 (weight 1 - fj), r0 + 1 (fj).
            a0 = b0 = a1 = b1 = 0
            if 0 <= r0 < n_j:
                a0 = run_ptr[k * n_j + r0]
                b0 = run_ptr[k * n_j + r0 + 1]
            if fj > 0.0 and 0 <= r0 + 1 < n_j:
                a1 = run_ptr[k * n_j + r0 + 1]
                b1 = run_ptr[k * n_j + r0 + 2]
            w00 = (1.0 - fi) * (1.0 - fj)
            w01 = fi * (1.0 - fj)
            w10 = (1.0 - fi) * fj
            w11 = fi * fj
            before = 1 if fi > 0.0 else 0  # a voxel also feeds the pixel to its left
            c00 = c01 = a0
            c10 = c11 = a1
            p0, p1 = a0, a1
            done = 0
            while p0 < b0 or p1 < b1:
                # The next run of either scanline, by first column: the pixels it touches.
                if p1 >= b1 or (p0 < b0 and run_start[p0] <= run_start[p1]):
                    first, stop = run_start[p0], run_end[p0]
                    p0 += 1
                else:
                    first, stop = run_start[p1], run_end[p1]
                    p1 += 1
                lo = max(first - s_i - before, done, 0)
                hi = min(stop - s_i, width)
                if lo >= hi:
                    continue
                done = hi
                pixel = _open(links, lo)
                while pixel < hi:
                    column = pixel + s_i
                    ext = 0.0
                    cr = 0.0
                    cg = 0.0
                    cb = 0.0
                    for corner in range(4):
                        if corner == 0:
                            c00, v = _voxel(run_start, run_end, run_voxel, c00, b0, column)
                            wt = w00
                        elif corner == 1:
                            if not fi > 0.0:
                                continue
                            c01, v = _voxel(run_start, run_end, run_voxel, c01, b0, column + 1)
                            wt = w01
                        elif corner == 2:
                            if not fj > 0.0:
                                continue
                            c10, v = _voxel(run_start, run_end, run_voxel, c10, b1, column)
                            wt = w10
                        else:
                            if not (fi > 0.0 and fj > 0.0):
                                continue
                            c11, v = _voxel(run_start, run_end, run_voxel, c11, b1, column + 1)
                            wt = w11
                        if v < 0:
                            continue
                        q = wt * sigma[v]
                        n = normal_code[v]
                        ext += q
                        if grey:
                            lum = factor[n] + highlight[n]
                            cr += q * lum
                        else:
                            e = emission_code[v]
                            cr += q * (emission[e, 0] * factor[n] + highlight[n])
                            cg += q * (emission[e, 1] * factor[n] + highlight[n])
                            cb += q * (emission[e, 2] * factor[n] + highlight[n])
                    taken += 1
                    if ext > 0.0:
                        # Segment opacity (eq 1.4) and colour (eq 1.9), composited front to
                        # back (eqs 1.7-1.8).
                        alpha = -math.expm1(-ext * length)
                        scale = alpha / ext
                        if grey:
                            cg = cr
                            cb = cr
                        remaining = 1.0 - inter[row, pixel, 3]
                        inter[row, pixel, 0] += remaining * cr * scale
                        inter[row, pixel, 1] += remaining * cg * scale
                        inter[row, pixel, 2] += remaining * cb * scale
                        inter[row, pixel, 3] += remaining * alpha
                        if inter[row, pixel, 3] >= threshold:
                            links[pixel] = pixel + 1
                            opaque += 1
                    pixel = _open(links, pixel + 1)
        counts[row] = taken
