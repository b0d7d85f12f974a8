"""The ray-casting kernel: resample along rays, classify, composite front to back.

Every ray takes its samples on one global lattice: sample ``k`` lies at ``t = (k + 1/2) ds``
from the ray's origin (the view's origin plane, or the eye), and stands for the segment
``[k ds, (k + 1) ds)``. A volume split into bricks therefore takes exactly the same samples as
the whole volume: a brick renders those of its samples with ``t`` in ``[t_in, t_out)`` of its
own box, and no sample is taken twice or missed at a boundary.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from vrlib._kernels._jit import jit, parallel_jit
from vrlib._kernels.filters import CUBIC, TENT
from vrlib._kernels.sampling import MAX_TAPS, gradient, reconstruct, tricubic, trilinear
from vrlib._kernels.transfer import GLOW, density, emission


@jit
def ray_box(o, d, lo, hi):
    """Parameters ``(t_in, t_out)`` where the ray ``o + t d`` crosses the box ``[lo, hi]``
    (``t_in >= t_out`` when it misses)."""
    t_in = -math.inf
    t_out = math.inf
    for a in range(3):
        if d[a] == 0.0:
            if o[a] < lo[a] or o[a] > hi[a]:
                return 0.0, 0.0
        else:
            ta = (lo[a] - o[a]) / d[a]
            tb = (hi[a] - o[a]) / d[a]
            if ta > tb:
                ta, tb = tb, ta
            t_in = max(t_in, ta)
            t_out = min(t_out, tb)
    return t_in, t_out


@jit
def _block_of(u, block, nblocks):
    b = int(u) // block
    if b < 0:
        return 0
    if b > nblocks - 1:
        return nblocks - 1
    return b


@jit
def _in_empty_block(empty, block, ux, uy, uz):
    return empty[_block_of(uz, block, empty.shape[0]), _block_of(uy, block, empty.shape[1]),
                 _block_of(ux, block, empty.shape[2])]


@jit
def _block_exit(o, d, origin, spacing, block, ux, uy, uz, nb):
    """Ray parameter at which the ray leaves the block holding index position (ux, uy, uz)."""
    t_exit = math.inf
    u = (ux, uy, uz)
    for a in range(3):
        if d[a] == 0.0:
            continue
        b = _block_of(u[a], block, nb[a])
        edge = b + 1 if d[a] > 0.0 else b
        bound = origin[a] + edge * block * spacing[a]
        t_exit = min(t_exit, (bound - o[a]) / d[a])
    return t_exit


@parallel_jit
def raycast(data, offset, gshape, origin, spacing, box_lo, box_hi, ray_o, ray_d, ds,
            fkind, fp0, fp1, fp2, radius, ntaps,
            tkind, tscale, tvmin, tvmax, dtab, ctab,
            shade, ka, kd, ks, shininess, light, headlight,
            threshold, empty, block, tile, order, out, samples):
    """Render ``out[row, col] = (r, g, b, a)`` premultiplied; count samples per tile.

    The image is cut into ``tile x tile`` pixel tiles: neighbouring rays read neighbouring
    voxels, so a tile keeps its voxels in cache. ``order`` lists the tiles in the order the
    parallel loop takes them (spread over the image so that threads share the work evenly).
    Each pixel is computed independently and in a fixed order, so the image does not depend on
    the number of threads. ``block = 0`` turns empty-space skipping off; ``threshold = 1``
    turns early ray termination off.
    """
    height, width = ray_o.shape[0], ray_o.shape[1]
    tiles_across = (width + tile - 1) // tile
    nb = np.array(empty.shape[::-1]) if block > 0 else np.ones(3, np.int64)
    inv = 1.0 / spacing
    for it in prange(order.shape[0]):
        tile_id = order[it]
        row0 = (tile_id // tiles_across) * tile
        col0 = (tile_id % tiles_across) * tile
        wx = np.empty(MAX_TAPS)
        wy = np.empty(MAX_TAPS)
        wz = np.empty(MAX_TAPS)
        dx = np.empty(MAX_TAPS)
        dy = np.empty(MAX_TAPS)
        dz = np.empty(MAX_TAPS)
        taken = 0
        for p in range(tile * tile):
            r = row0 + p // tile
            c = col0 + p % tile
            if r >= height or c >= width:
                continue
            o = ray_o[r, c]
            d = ray_d[r, c]
            out[r, c, 0] = 0.0
            out[r, c, 1] = 0.0
            out[r, c, 2] = 0.0
            out[r, c, 3] = 0.0
            t_in, t_out = ray_box(o, d, box_lo, box_hi)
            t_in = max(t_in, 0.0)
            if not t_out > t_in:
                continue
            acc_r = 0.0
            acc_g = 0.0
            acc_b = 0.0
            acc_a = 0.0
            # Index position of sample k: a + t b, the same for every brick of a volume.
            ax = (o[0] - origin[0]) * inv[0]
            ay = (o[1] - origin[1]) * inv[1]
            az = (o[2] - origin[2]) * inv[2]
            bx = d[0] * inv[0]
            by = d[1] * inv[1]
            bz = d[2] * inv[2]
            k = math.ceil(t_in / ds - 0.5)
            while True:
                t = (k + 0.5) * ds
                if t >= t_out:
                    break
                ux = ax + t * bx
                uy = ay + t * by
                uz = az + t * bz
                if block > 0 and _in_empty_block(empty, block, ux, uy, uz):
                    # Skip to the first sample past this block; step back over any sample that
                    # rounding placed in a block that is not empty, so the image is unchanged.
                    t_exit = _block_exit(o, d, origin, spacing, block, ux, uy, uz, nb)
                    k_next = max(math.ceil(t_exit / ds - 0.5), k + 1)
                    while k_next > k + 1:
                        tb = (k_next - 0.5) * ds
                        if _in_empty_block(empty, block, ax + tb * bx, ay + tb * by,
                                           az + tb * bz):
                            break
                        k_next -= 1
                    k = k_next
                    continue
                # The two common filters unrolled, the others through the general loop.
                if fkind == TENT:
                    value = trilinear(data, offset, gshape, ux, uy, uz)
                elif fkind == CUBIC:
                    value = tricubic(data, offset, gshape, ux, uy, uz, fp0, fp1)
                else:
                    value = reconstruct(data, offset, gshape, ux, uy, uz, fkind, fp0, fp1, fp2,
                                        radius, ntaps, wx, wy, wz)
                taken += 1
                k += 1
                dens = density(tkind, tscale, tvmin, tvmax, dtab, value)
                if not dens > 0.0:
                    continue  # a transparent segment adds exactly nothing
                alpha = -math.expm1(-dens * ds)  # eq 1.4
                if tkind == GLOW:
                    er = eg = eb = 1.0
                else:
                    er = emission(tkind, tvmin, tvmax, ctab, value, 0)
                    eg = emission(tkind, tvmin, tvmax, ctab, value, 1)
                    eb = emission(tkind, tvmin, tvmax, ctab, value, 2)
                if shade:
                    gx, gy, gz = gradient(data, offset, gshape, ux, uy, uz, fkind, fp0, fp1,
                                          fp2, radius, ntaps, wx, wy, wz, dx, dy, dz)
                    gx *= inv[0]
                    gy *= inv[1]
                    gz *= inv[2]
                    norm = math.sqrt(gx * gx + gy * gy + gz * gz)
                    if headlight:
                        lx, ly, lz = -d[0], -d[1], -d[2]
                    else:
                        lx, ly, lz = light[0], light[1], light[2]
                    # Half-vector of the light and the direction to the eye (-d).
                    hx, hy, hz = lx - d[0], ly - d[1], lz - d[2]
                    hn = math.sqrt(hx * hx + hy * hy + hz * hz)
                    if hn > 0.0:
                        hx, hy, hz = hx / hn, hy / hn, hz / hn
                    else:
                        hx, hy, hz = lx, ly, lz
                    if norm > 0.0:
                        ndotl = abs(gx * lx + gy * ly + gz * lz) / norm
                        ndoth = abs(gx * hx + gy * hy + gz * hz) / norm
                    else:
                        ndotl = 1.0
                        ndoth = 1.0
                    factor = ka + kd * ndotl
                    spec = ks * ndoth**shininess
                    er = er * factor + spec
                    eg = eg * factor + spec
                    eb = eb * factor + spec
                # Front-to-back over, eqs 1.7-1.8, with premultiplied colour E * alpha (eq 1.9).
                w = (1.0 - acc_a) * alpha
                acc_r += w * er
                acc_g += w * eg
                acc_b += w * eb
                acc_a += w
                if acc_a >= threshold:
                    break
            out[r, c, 0] = acc_r
            out[r, c, 1] = acc_g
            out[r, c, 2] = acc_b
            out[r, c, 3] = acc_a
        samples[tile_id] = taken
