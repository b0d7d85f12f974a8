"""The classified shear-warp kernel: VolPack's way (Lacroute and Levoy 1994, sections 4-5).

The volume is classified once (:mod:`vrlib.classified`): per principal axis, every scanline of
every slice is run-length encoded into runs of visible voxels, each stored with its extinction
``sigma`` (per world unit), an emission code and a normal code, between two transparent guard
voxels. A frame walks bands of intermediate-image rows; for each slice, front to back, a row's
sample points lie between two voxel scanlines with the same bilinear weights for every point
of the slice. Only the points that a visible voxel of either scanline touches are visited (the
runs, merged into segments), and of those only the pixels not yet opaque: skip links with path
compression jump over runs of opaque pixels (the role of VolPack's run-length encoded
intermediate image).

A sample's extinction is the bilinear mix of its four voxels' ``sigma`` and its colour their
extinction-weighted mix (opacity-weighted colour interpolation, Wittenbrink, Malzbender and
Goss 1998), so that a segment of length ``L`` has opacity ``1 - exp(-sigma L)`` (eq 1.4)
and premultiplied colour ``C alpha`` (eq 1.9).
"""

from __future__ import annotations

import math

import numpy as np

from vrlib._kernels._jit import at, borrowed, helper_jit, jit, put
from vrlib._kernels.queue import take
from vrlib._kernels.shading import half_vector


@jit
def shade_table(normals, light, direction, ka, kd, ks, shininess, factor, highlight):
    """Phong's ``factor`` and ``highlight`` for every normal code (``normals``: ``(3, codes)``,
    one unit vector per code, zero for "no gradient"), lit from ``light`` and seen along
    ``direction``: shading as a table lookup per voxel, rebuilt once per frame (VolPack's
    lookup shader).

    :func:`vrlib._kernels.shading.phong_terms` code by code, its arithmetic in loops that
    LLVM vectorises (the normals' components in rows, the test for a zero normal a select,
    the power of a whole shininess by squaring across all codes at once): the same numbers,
    in a fifth of the time of a loop of calls (9217 codes a frame)."""
    hx, hy, hz = half_vector(light[0], light[1], light[2], direction[0], direction[1],
                             direction[2])
    lx, ly, lz = light[0], light[1], light[2]
    gx, gy, gz = normals[0], normals[1], normals[2]
    count = factor.shape[0]
    for n in range(count):
        norm = math.sqrt(gx[n] * gx[n] + gy[n] * gy[n] + gz[n] * gz[n])
        scale = norm if norm > 0.0 else 1.0  # the zero normal: lit as if facing the light
        lit = abs(gx[n] * lx + gy[n] * ly + gz[n] * lz) / scale
        half = abs(gx[n] * hx + gy[n] * hy + gz[n] * hz) / scale
        factor[n] = ka + kd * (lit if norm > 0.0 else 1.0)
        highlight[n] = half if norm > 0.0 else 1.0
    # ks |n.h|^shininess: power's squaring, one step for every code at a time.
    whole = int(shininess)
    if whole != shininess or whole < 0 or whole > 64:
        for n in range(count):
            highlight[n] = ks * highlight[n] ** shininess
        return
    result = np.ones(count)
    while whole > 0:
        if whole & 1:
            for n in range(count):
                result[n] *= highlight[n]
        for n in range(count):
            highlight[n] *= highlight[n]
        whole >>= 1
    for n in range(count):
        highlight[n] = ks * result[n]


@jit(inline="always")
def _open(links, row, i):
    """First pixel at or after ``i`` of ``row`` that is not opaque; compresses the path."""
    root = i
    while at(links, (row, root)) != root:
        root = at(links, (row, root))
    while at(links, (row, i)) != root:
        following = at(links, (row, i))
        put(links, (row, i), root)
        i = following
    return root


@jit(inline="always")
def _stream(run_start, run_end, run_voxel, c, e, s_i, before, pos, following):
    """One scanline's state at pixel ``pos``: its run cursor ``c`` (of runs ``c .. e - 1``)
    advanced past the runs that end before it, whether a run covers it (a run
    ``[start, end)`` covers the pixels ``[start - s_i - before, end - s_i)``), the base with
    ``voxel = base + pixel`` there, and ``following`` cut to where that state ends."""
    while c < e and at(run_end, c) - s_i <= pos:
        c += 1
    if c < e:
        lo = at(run_start, c) - s_i - before
        if lo <= pos:
            return c, True, at(run_voxel, c) + 1 - at(run_start, c) + s_i, min(
                following, at(run_end, c) - s_i)
        return c, False, 0, min(following, lo)
    return c, False, 0, following


#: ``exp(-depth)`` as ``2^(-j / 32) exp(-r)``, ``j`` the nearest multiple of ln 2 / 32 and
#: ``|r| <= ln 2 / 64``: the table of ``2^(-j / 32)`` up to depth 44 (beyond it ``1 - exp`` is
#: 1 in float64), and ln 2 / 32 in two parts (fdlibm's split of ln 2: ``j`` times the first
#: is exact), so that ``r`` carries no rounding of ``j ln 2 / 32``.
_OPACITY_STEPS = 32
_LN2_HI, _LN2_LO = 6.93147180369123816490e-01, 1.90821492927058770002e-10
_DEEPEST = 44.0
_POWERS = np.arange(int(_DEEPEST * _OPACITY_STEPS / math.log(2.0)) + 2)
_EXP_TABLE = np.ldexp(np.power(2.0, -(_POWERS % _OPACITY_STEPS) / _OPACITY_STEPS),
                      -(_POWERS // _OPACITY_STEPS))


@jit(inline="always")
def _opacity(depth):
    """``1 - exp(-depth)`` (eq 1.4) for ``depth >= 0``, within about 3e-16 of it (a few
    units in the last place of ``exp``; libm's is within one): below 0.02, the faint
    segments of glowing volumes, its Taylor series to the fifth power (error under 1e-13);
    above, ``exp`` from :data:`_EXP_TABLE` and a polynomial of degree 6 (Estrin's scheme).
    Inline and without a branch: libm's ``exp`` was a call per sample, with the loop's
    registers saved around it, and the branch was mispredicted where faint samples mix with
    dense ones (VolPack's example: compositing 0.51 -> 0.47 ms a frame)."""
    taylor = depth * (1.0 - depth * (0.5 - depth * (1.0 / 6.0 - depth * (
        1.0 / 24.0 - depth * (1.0 / 120.0)))))
    d = min(depth, _DEEPEST)
    j = int(d * (_OPACITY_STEPS / math.log(2.0)) + 0.5)
    r = (d - j * (_LN2_HI / _OPACITY_STEPS)) - j * (_LN2_LO / _OPACITY_STEPS)
    r2 = r * r
    decay = (1.0 - r) + r2 * ((0.5 - r * (1.0 / 6.0)) + r2 * (
        (1.0 / 24.0 - r * (1.0 / 120.0)) + r2 * (1.0 / 720.0)))
    full = 1.0 - _EXP_TABLE[j] * decay
    return taylor if depth < 0.02 else full


@jit(inline="always")
def _pair(v, w_left, w_right, sigma, emission_code, normal_code, emission, factor, highlight,
          grey, shaded):
    """Voxels ``v`` (weight ``w_left``) and ``v + 1`` (``w_right``) of one scanline: their
    weighted extinction and colours ``(extinction, r, g, b)``, each colour weighted by its
    voxel's extinction (``grey``: white emission, and a shaded voxel's grey is ``factor``
    alone, the caller having added ``highlight`` to it; unless ``shaded``, ``factor`` is 1
    and ``highlight`` 0; both True or None, :func:`composite_classified`)."""
    q0 = w_left * at(sigma, v)
    q1 = w_right * at(sigma, v + 1)
    if grey is not None and shaded is None:
        return q0 + q1, q0 + q1, 0.0, 0.0
    if grey is not None:
        n0, n1 = at(normal_code, v), at(normal_code, v + 1)
        return q0 + q1, q0 * at(factor, n0) + q1 * at(factor, n1), 0.0, 0.0
    e0, e1 = at(emission_code, v), at(emission_code, v + 1)
    if shaded is None:
        return (q0 + q1, q0 * at(emission, (e0, 0)) + q1 * at(emission, (e1, 0)),
                q0 * at(emission, (e0, 1)) + q1 * at(emission, (e1, 1)),
                q0 * at(emission, (e0, 2)) + q1 * at(emission, (e1, 2)))
    n0, n1 = at(normal_code, v), at(normal_code, v + 1)
    return (q0 + q1,
            q0 * (at(emission, (e0, 0)) * at(factor, n0) + at(highlight, n0))
            + q1 * (at(emission, (e1, 0)) * at(factor, n1) + at(highlight, n1)),
            q0 * (at(emission, (e0, 1)) * at(factor, n0) + at(highlight, n0))
            + q1 * (at(emission, (e1, 1)) * at(factor, n1) + at(highlight, n1)),
            q0 * (at(emission, (e0, 2)) * at(factor, n0) + at(highlight, n0))
            + q1 * (at(emission, (e1, 2)) * at(factor, n1) + at(highlight, n1)))


@jit
def composite_classified(run_ptr, run_start, run_end, run_voxel, sigma, emission_code,
                         normal_code, n_j, order, di, dj, length, emission, factor, highlight,
                         grey, shaded, threshold, band_rows, bands, counter, inter, counts):
    """Composite the slices ``order`` (front to back) into ``inter[J, I] = (r, g, b, a)``
    (``grey``: ``(r, a)``, or red and opacity of four channels).

    Slice ``k``'s sample for intermediate pixel ``(I, J)`` lies at column ``I + di[k]`` and row
    ``J + dj[k]`` of the slice's ``n_j`` scanlines and stands for a segment of ``length``
    (half that for the first and last slices); scanline ``k * n_j + j`` holds runs
    ``run_ptr[.] .. run_ptr[. + 1] - 1`` of columns ``[run_start, run_end)`` whose voxels are
    stored from ``run_voxel + 1`` on, between two transparent guard voxels (so that a sample at
    a run's edge reads a zero neighbour without a test). A voxel's colour is
    ``emission[e] * factor[n] + highlight[n]`` for its codes ``e`` and ``n`` (``grey``: white
    emission, and ``factor`` holds ``factor + highlight``: one table read per voxel; unless
    ``shaded``, ``factor`` is 1 and ``highlight`` 0). ``grey`` and ``shaded`` are True or
    None, not False: the kernel compiles for the kind of volume it composites, each None
    dropping its branches (and the colour channels a grey image does not hold) from the
    loop over pixels, where a run-time flag cost 5% of the compositing (VolPack's example,
    one thread: 0.65 -> 0.61 ms a frame).

    The image is cut into bands of ``band_rows`` rows. Several threads make the call at once
    (:func:`vrlib._scheduling.on_threads`); each takes the next band of ``bands`` (the heaviest
    first) from ``counter`` (:func:`vrlib._kernels.queue.take`) until none is left. A band
    walks the slices front to back and, in each, its rows in order, so that it reads the
    encoding sequentially (VolPack's object order). Each row is composited in a fixed order:
    the image does not depend on the thread count. ``counts[J]`` gets the samples row ``J``
    composited.
    """
    # A band's scratch: each row's skip links, its opaque pixels and its samples.
    links = np.empty((band_rows, inter.shape[1] + 1), dtype=np.int64)
    opaque = np.empty(band_rows, dtype=np.int64)
    taken = np.empty(band_rows, dtype=np.int64)
    while True:
        it = take(counter)
        if it >= bands.shape[0]:
            break
        _composite_band(run_ptr, run_start, run_end, run_voxel, sigma, emission_code,
                        normal_code, n_j, order, di, dj, length, emission, factor, highlight,
                        grey, shaded, threshold, band_rows, bands[it], inter, counts, links,
                        opaque, taken)


@helper_jit
def _composite_band(run_ptr, run_start, run_end, run_voxel, sigma, emission_code, normal_code,
                    n_j, order, di, dj, length, emission, factor, highlight, grey, shaded,
                    threshold, band_rows, band, inter, counts, links, opaque, taken):
    """Band ``band`` of :func:`composite_classified` (the same arguments, and the band's
    scratch ``links``, ``opaque`` and ``taken``, one row each per row of the band).

    Every array is borrowed (:func:`vrlib._kernels._jit.borrowed`), so that no helper called
    in the loops over pixels keeps reference counts (an atomic increment and decrement per
    array and call: the warp, :func:`vrlib._kernels.shear.warp_rows`, ran at half its speed
    with them)."""
    run_ptr, run_start, run_end = borrowed(run_ptr), borrowed(run_start), borrowed(run_end)
    run_voxel, sigma, emission = borrowed(run_voxel), borrowed(sigma), borrowed(emission)
    emission_code, normal_code = borrowed(emission_code), borrowed(normal_code)
    order, di, dj = borrowed(order), borrowed(di), borrowed(dj)
    factor, highlight, inter = borrowed(factor), borrowed(highlight), borrowed(inter)
    links, opaque, taken = borrowed(links), borrowed(opaque), borrowed(taken)
    height, width = inter.shape[0], inter.shape[1]
    last = inter.shape[2] - 1  # opacity; grey images hold red and opacity alone
    first_row = band * band_rows
    rows = min(band_rows, height - first_row)
    for r in range(rows):
        for i in range(width + 1):
            links[r, i] = i
        opaque[r] = 0
        taken[r] = 0
    for step in range(order.shape[0]):
        k = order[step]
        # The scanlines the band's rows read in this slice (rows first_row .. + rows - 1
        # read r0 and r0 + 1 of row + dj[k]): none holds a run, nothing to do.
        lo_line = min(max(math.floor(first_row + dj[k]), 0), n_j)
        hi_line = min(max(math.floor(first_row + rows - 1 + dj[k]) + 2, 0), n_j)
        if run_ptr[k * n_j + hi_line] == run_ptr[k * n_j + lo_line]:
            continue
        # The end slices stand for half a spacing (the volume's box ends there).
        seg = 0.5 * length if step == 0 or step == order.shape[0] - 1 else length
        s_i = math.floor(di[k])
        fi = di[k] - s_i
        before = 1 if fi > 0.0 else 0  # a voxel also feeds the pixel to its left
        for r in range(rows):
            if opaque[r] == width:
                continue
            row = first_row + r
            y = row + dj[k]
            r0 = math.floor(y)
            fj = y - r0
            # Two streams, the scanlines around the row: r0 (weight 1 - fj), r0 + 1 (fj).
            # A run [start, end) of either touches the pixels [start - s_i - before,
            # end - s_i); the runs of one scanline touch disjoint pixels.
            c0 = e0 = c1 = e1 = 0
            if 0 <= r0 < n_j:
                c0 = run_ptr[k * n_j + r0]
                e0 = run_ptr[k * n_j + r0 + 1]
            if fj > 0.0 and 0 <= r0 + 1 < n_j:
                c1 = run_ptr[k * n_j + r0 + 1]
                e1 = run_ptr[k * n_j + r0 + 2]
            # The pixels the two scanlines touch at all; none open there: nothing to do.
            lo = width
            hi = 0
            if c0 < e0:
                lo = min(lo, run_start[c0] - s_i - before)
                hi = max(hi, run_end[e0 - 1] - s_i)
            if c1 < e1:
                lo = min(lo, run_start[c1] - s_i - before)
                hi = max(hi, run_end[e1 - 1] - s_i)
            hi = min(hi, width)
            if lo >= hi:
                continue
            pos = _open(links, r, max(lo, 0))
            if pos >= hi:
                continue
            w00 = (1.0 - fi) * (1.0 - fj)
            w01 = fi * (1.0 - fj)
            w10 = (1.0 - fi) * fj
            w11 = fi * fj
            # Walk the segments over which each stream stays inside one run or outside all:
            # within one, a run's voxel for the pixel is base + pixel (VolPack's run
            # merging), and the loop over the segment's open pixels keeps no books.
            visited = closed = 0
            while True:
                pos = _open(links, r, pos)  # past opaque pixels: their voxels are skipped
                if pos >= hi:
                    break
                following = hi
                c0, in0, base0, following = _stream(run_start, run_end, run_voxel, c0, e0,
                                                    s_i, before, pos, following)
                c1, in1, base1, following = _stream(run_start, run_end, run_voxel, c1, e1,
                                                    s_i, before, pos, following)
                if not (in0 or in1):
                    pos = following
                    continue
                pixel = pos
                while pixel < following:
                    ext = cr = cg = cb = 0.0
                    if in0:
                        e, r_, g_, b_ = _pair(base0 + pixel, w00, w01, sigma, emission_code,
                                              normal_code, emission, factor, highlight, grey,
                                              shaded)
                        ext += e
                        cr += r_
                        cg += g_
                        cb += b_
                    if in1:
                        e, r_, g_, b_ = _pair(base1 + pixel, w10, w11, sigma, emission_code,
                                              normal_code, emission, factor, highlight, grey,
                                              shaded)
                        ext += e
                        cr += r_
                        cg += g_
                        cb += b_
                    visited += 1
                    if ext > 0.0:
                        # Segment opacity (eq 1.4) and colour (eq 1.9), composited front to
                        # back (eqs 1.7-1.8).
                        alpha = _opacity(ext * seg)
                        scale = alpha / ext
                        acc = at(inter, (row, pixel, last))
                        remaining = 1.0 - acc
                        put(inter, (row, pixel, 0),
                            at(inter, (row, pixel, 0)) + remaining * (cr * scale))
                        if grey is None:  # grey: red alone (the warp copies it)
                            put(inter, (row, pixel, 1),
                                at(inter, (row, pixel, 1)) + remaining * (cg * scale))
                            put(inter, (row, pixel, 2),
                                at(inter, (row, pixel, 2)) + remaining * (cb * scale))
                        acc += remaining * alpha
                        put(inter, (row, pixel, last), acc)
                        # Opaque now: linked past. Without a branch: the test waits on
                        # the whole chain of the sample (its exp), and a branch on it
                        # would often be mispredicted, faint samples among opaque ones.
                        now_opaque = np.int64(acc >= threshold)
                        put(links, (r, pixel), pixel + now_opaque)
                        closed += now_opaque
                    pixel = _open(links, r, pixel + 1)
                pos = following
            taken[r] += visited
            opaque[r] += closed
    for r in range(rows):
        counts[first_row + r] = taken[r]
