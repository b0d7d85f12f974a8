"""The ray-casting kernel: resample along rays, classify, composite front to back.

Every ray takes its samples on one global lattice: sample ``k`` lies at ``t = (k + 1/2) ds``
from the ray's origin (the view's origin plane, or the eye), and stands for the segment
``[k ds, (k + 1) ds)``. A volume split into bricks therefore takes exactly the same samples as
the whole volume: a brick renders those of its samples with ``t`` in ``[t_in, t_out)`` of its
own box, and no sample is taken twice or missed at a boundary.

With exact segment ends (``exact``), the two segments that the volume's outer faces cut
count only their part inside the volume's box: a ray that enters at ``T_in`` and leaves at
``T_out`` takes, for the cut segment ``k``, one sample at the middle of
``[max(k ds, T_in), min((k + 1) ds, T_out))`` and gives it that length's opacity
``1 - (1 - alpha)^(length / ds)`` (eq 1.4). Every other sample stays on the lattice, and only
the volume's faces cut, never a brick's, so bricks still take exactly the serial samples. This
removes the error of first order in the step that the faces give a field that is not zero
there (docs/kernel.md).

Classification reads a per-render table of segment opacity and colour
(:meth:`vrlib.transfer.TransferFunction.segment_table`), linearly interpolated.

A sample's position as computed is monotone in ``k``, so the samples whose cells lie inside
the volume form one run per ray (or per stretch between skip checks). With the tent filter
and no shading, eight rays' runs are taken together in vector form, with no test per sample
and the same arithmetic, bit for bit (:mod:`vrlib._kernels.packets`, docs/kernel.md).

A first render's quick start (:data:`vrlib.raycast.QUICK_START_SAMPLES`) takes a kernel of its
own, :func:`raycast_quick`: the same arithmetic, each ray alone, in the fewest lines numba
has to compile.
"""

from __future__ import annotations

import math

import numpy as np

from vrlib._kernels._jit import borrowed, compiled_apart, helper_jit, jit, trailing_zeros
from vrlib._kernels.camera import pixel_ray, ray_box
from vrlib._kernels.filters import CUBIC, TENT
from vrlib._kernels.packets import (
    ALPHA,
    AX,
    AY,
    AZ,
    BLUE,
    BX,
    BY,
    BZ,
    END,
    GREEN,
    LANES,
    RAY_ROWS,
    RED,
    K,
    inside_runs,
)
from vrlib._kernels.preintegration import bilinear_channel, psi_at
from vrlib._kernels.queue import take
from vrlib._kernels.sampling import (
    gradient,
    reconstruct,
    separable4,
    tent_gradient,
    tricubic,
    trilinear,
)
from vrlib._kernels.shading import classify_by_gradient, modulate_by_gradient
from vrlib._kernels.tables import entry, entry_channel, interpolate, interpolate_rgb, lookup

# The rest of a lane's ray state in the kernel (beside vrlib._kernels.packets' rays and
# steps): rows of a float and an integer array, one column per lane; and its status.
_D0, _D1, _D2, _T_IN, _T_OUT, _T_FIRST, _T_LAST, _SPENT, _T_CHECK, _T_ENTER = range(10)
_STATE_ROWS = 10
_K, _K_FIRST, _K_LAST, _M_BLOCK, _INSIDE_END = range(5)
_STEP_ROWS = 5
DONE, MARCH, RUN = 0, 1, 2


def lanes(threads):
    """Each thread's lanes for :func:`raycast` (``[thread]`` of each array): its rays and
    packet state (:mod:`vrlib._kernels.packets`), the rest of each ray's state, and whether
    it is marching, waiting for the packet or done. Allocated by the caller, so that the
    kernel compiles no allocation (``np.zeros`` cost a first render 0.4 s). A row holds
    ``LANES`` 8-byte items, a cache line; one unused row between two threads' rows keeps
    them off each other's lines (without it, two threads writing their lanes' state took
    turns at a shared line: a sparse scene rendered 1.3 times faster on two threads than on
    one, instead of 1.8)."""

    def rows(count, dtype=np.float64):
        return np.zeros((threads, count + 1, LANES), dtype)[:, :count]

    return (rows(RAY_ROWS), rows(2, np.int64), rows(_STATE_ROWS), rows(_STEP_ROWS, np.int64),
            rows(1, np.int64)[:, 0])


@helper_jit
def _cell(u, cells, count):
    """Block holding index position ``u`` on a grid of ``count`` blocks of ``cells`` cells
    (a power of two: the floor division is a shift)."""
    b = int(math.floor(u)) >> trailing_zeros(cells)
    if b < 0:
        return 0
    if b > count - 1:
        return count - 1
    return b


@helper_jit
def _is_empty(empty, cells, ux, uy, uz):
    return empty[_cell(uz, cells, empty.shape[0]), _cell(uy, cells, empty.shape[1]),
                 _cell(ux, cells, empty.shape[2])]


@helper_jit
def _block_bound(bound, cells, ux, uy, uz):
    return bound[_cell(uz, cells, bound.shape[0]), _cell(uy, cells, bound.shape[1]),
                 _cell(ux, cells, bound.shape[2])]


@helper_jit
def _exit(ax, ay, az, bx, by, bz, cells, counts, ux, uy, uz, reach):
    """Ray parameter where the ray (index position ``a + t b``) leaves the cube of
    ``2 reach - 1`` blocks a side centred on the block that holds ``(ux, uy, uz)``, on a grid
    of ``cells``-cell blocks (``counts`` blocks per axis, z y x): that block itself for
    ``reach = 1``."""
    t_exit = math.inf
    for a, b, u, n in ((ax, bx, ux, counts[2]), (ay, by, uy, counts[1]),
                       (az, bz, uz, counts[0])):
        if b != 0.0:
            block = _cell(u, cells, n)
            edge = (block + reach) * cells if b > 0.0 else (block + 1 - reach) * cells
            t_exit = min(t_exit, (edge - a) / b)
    return t_exit


@helper_jit
def _entry(ax, ay, az, bx, by, bz, cells, counts, ux, uy, uz):
    """Ray parameter where the ray (index position ``a + t b``) enters the block that holds
    ``(ux, uy, uz)``: :func:`_exit`'s other end."""
    t_entry = -math.inf
    for a, b, u, n in ((ax, bx, ux, counts[2]), (ay, by, uy, counts[1]),
                       (az, bz, uz, counts[0])):
        if b != 0.0:
            block = _cell(u, cells, n)
            edge = block * cells if b > 0.0 else (block + 1) * cells
            t_entry = max(t_entry, (edge - a) / b)
    return t_entry


@jit(inline="always")
def _long_segment(k, m, ds, t_enter, t_exit, k_first, k_last):
    """The longest aligned segment ``[k0 ds, (k0 + m) ds)`` (``m`` a power of two, at most
    the block's ``m``, ``k0`` a multiple of it) that holds segment ``k``, lies inside the
    block's stretch ``[t_enter, t_exit]`` of the ray and holds no segment the volume's faces
    cut: ``(k0, m)``, ``m = 1`` where none does. A function of ``k`` and the block alone, so
    that every brick and rank finds the same long segments."""
    while m > 1:
        k0 = k - k % m
        if (k0 * ds >= t_enter and (k0 + m) * ds <= t_exit and k0 > k_first
                and (k_last < 0 or k0 + m <= k_last)):
            return k0, m
        m //= 2
    return k, 1


@jit(inline="always")
def _cut_segment(k, ds, t_first, t_last):
    """Sample position and length (as a fraction of ``ds``) of segment ``k`` cut to the
    volume's ``[t_first, t_last)``."""
    a = max(k * ds, t_first)
    b = min((k + 1) * ds, t_last)
    return 0.5 * (a + b), (b - a) / ds


@helper_jit
def _inside(k, ds, ax, ay, az, bx, by, bz, gx1, gy1, gz1, t_in, t_out):
    """Whether sample ``k`` lies in ``[t_in, t_out)`` and in a cell whose 8 corners lie
    inside the volume (``0 <= u < g - 1`` on each axis, ``g1 = g - 1``): where
    :func:`~vrlib._kernels.sampling.trilinear` takes its fast path. Compiled once, not
    inlined at its three calls: inlining it cost the first render 0.3 s of compile."""
    t = (k + 0.5) * ds
    ux = ax + t * bx
    uy = ay + t * by
    uz = az + t * bz
    return (t_in <= t < t_out and 0.0 <= ux < gx1 and 0.0 <= uy < gy1
            and 0.0 <= uz < gz1)


@jit(inline="always")
def _put_pixel(out, r, c, red, green, blue, alpha):
    """A ray's colour and opacity into its pixel, the opacity clipped to [0, 1] (rounding
    can carry a sum of segments a unit in the last place past 1)."""
    out[r, c, 0] = red
    out[r, c, 1] = green
    out[r, c, 2] = blue
    out[r, c, 3] = min(max(alpha, 0.0), 1.0)


@helper_jit
def _before(t_check, ds, k, end):
    """``end`` cut to the first sample after ``k`` at or past ``t_check`` (the general
    loop's next skip check; none when it is infinite). Compiled apart, as
    :func:`_inside_end`."""
    if not (-math.inf < t_check < math.inf):
        return end
    limit = max(math.ceil(t_check / ds - 0.5), k + 1)
    while limit > k + 1 and (limit - 0.5) * ds >= t_check:
        limit -= 1
    while (limit + 0.5) * ds < t_check:
        limit += 1
    return min(end, limit)


@helper_jit
def _inside_end(k, ds, ax, ay, az, bx, by, bz, gx1, gy1, gz1, t_in, t_out, k_last):
    """End (exclusive) of the run of samples from ``k`` on that are :func:`_inside` and
    before the cut segment ``k_last`` (-1: none), for a sample ``k`` that is. A sample's
    index position, as computed, is monotone in ``k`` (rounding keeps the order of exact
    values), so the run is one interval: guessed from where the ray leaves the cells, then
    corrected by testing its end. Compiled once, apart from the kernel that calls it once a
    run: inlined, it and :func:`_before` cost a first render 0.25 s of compile."""
    t_end = t_out
    for a, b, g1 in ((ax, bx, gx1), (ay, by, gy1), (az, bz, gz1)):
        if b > 0.0:
            t_end = min(t_end, (g1 - a) / b)
        elif b < 0.0:
            t_end = min(t_end, -a / b)
    end = max(min(math.floor(t_end / ds + 0.5), k_last if k_last >= 0 else 1 << 62), k + 1)
    while end > k + 1 and not _inside(end - 1, ds, ax, ay, az, bx, by, bz, gx1, gy1, gz1,
                                      t_in, t_out):
        end -= 1
    while (k_last < 0 or end < k_last) and _inside(end, ds, ax, ay, az, bx, by, bz, gx1, gy1,
                                                   gz1, t_in, t_out):
        end += 1
    return end


@jit(inline="always")
def _part_of_segment(alpha, fraction):
    """Opacity of ``fraction`` of a segment whose whole opacity is ``alpha`` (eq 1.4)."""
    return -math.expm1(fraction * math.log1p(-alpha)) if alpha < 1.0 else 1.0


@jit(inline="always")
def _cut_to(fraction, alpha, red, green, blue):
    """``fraction`` of a segment of opacity ``alpha`` and premultiplied colour ``(red, green,
    blue)``: ``(alpha, red, green, blue)`` of that part (eq 1.4, the colour scaled with the
    opacity)."""
    part = _part_of_segment(alpha, fraction)
    return part, red * (part / alpha), green * (part / alpha), blue * (part / alpha)


@jit(inline="always")
def _over(acc_r, acc_g, acc_b, acc_a, red, green, blue, alpha):
    """A ray's sums with a segment of premultiplied colour ``(red, green, blue)`` and
    opacity ``alpha`` composited behind them, front to back (eqs 1.7-1.8)."""
    remaining = 1.0 - acc_a
    return (acc_r + remaining * red, acc_g + remaining * green, acc_b + remaining * blue,
            acc_a + remaining * alpha)


@helper_jit
def _other_value(data, flat, nx, nxy, oz, oy, ox, gz, gy, gx, offset, gshape, ux, uy, uz,
                 fkind, fp0, fp1, fp2, radius, ntaps, wx, wy, wz):
    """The value at global index position ``(ux, uy, uz)`` for every filter but the tent,
    as the point-sampling loop computes it: the piecewise cubics and 4-tap filters unrolled,
    the others through the general loop. The layout comes as scalars (``nx``, ``nxy``, the
    offset ``oz, oy, ox`` and the global shape ``gz, gy, gx``); a call, not inlined, so that
    the loops around it stay small."""
    if fkind == CUBIC:
        return tricubic(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ux, uy, uz, fp0, fp1, fp2)
    if ntaps == 4:
        return separable4(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ux, uy, uz, fkind, fp0, fp1,
                          fp2, radius)
    return reconstruct(data, offset, gshape, ux, uy, uz, fkind, fp0, fp1, fp2, radius, ntaps,
                       wx, wy, wz)


@jit(inline="always")
def _skip(k, ux, uy, uz, ax, ay, az, bx, by, bz, ds, by_front, empty, clearance, block,
          fine_counts, bound, budget, spent, k_first, k_last, t_first, t_last, blockwise):
    """Skipping at segment ``k``, whose check point (its sample, or its front end when
    ``by_front``: a pre-integrated segment) lies at index position ``u``: returns
    ``(k_next, t_check, spent)``. ``k_next > k`` skips to segment ``k_next``; otherwise
    the segment is taken, and so are those before ``t_check`` (their block is not empty).

    From an empty block the ray jumps out of the cube of empty blocks around it (its
    ``clearance``: :func:`vrlib.skipping.clearance`), then any segment that rounding placed
    in a block that is not empty is stepped back over: the image is unchanged. By its front
    end, only the segments that also end inside an empty block are jumped, so that the whole
    run lies in one empty box. In a block that is not empty, ``t_check`` is where the ray
    leaves the cube around it that its clearance gives (blocks that are not empty, and
    empty ones beside them: a sample that lies in an empty block adds exactly nothing), or
    the block itself with a ``budget`` or when ``blockwise``
    (adaptive steps: a step per block). With a budget, a block that is not empty is left out
    while the bounds of what the ray has left out stay within ``budget`` (``spent`` so
    far)."""
    reach = _block_bound(clearance, block, ux, uy, uz)
    if reach <= 0:  # a block that is not empty
        if budget > 0.0 or blockwise:
            # The block itself (an int64 1, not a literal: numba would compile _exit once
            # more for it).
            t_exit = _exit(ax, ay, az, bx, by, bz, block, fine_counts, ux, uy, uz,
                           np.int64(1))
        else:
            # No block within the clearance is one to jump from: sample on to the cube's
            # face.
            t_exit = _exit(ax, ay, az, bx, by, bz, block, fine_counts, ux, uy, uz, -reach)
        if budget > 0.0:
            cost = _block_bound(bound, block, ux, uy, uz)
            if spent + cost <= budget:
                # Skipping by the error budget: leave out what this block could add.
                if by_front:
                    return max(math.ceil(t_exit / ds), k + 1), -math.inf, spent + cost
                return max(math.ceil(t_exit / ds - 0.5), k + 1), -math.inf, spent + cost
        return k, t_exit, spent
    # Every block within the clearance is empty: leave the cube of them in one jump.
    t_exit = _exit(ax, ay, az, bx, by, bz, block, fine_counts, ux, uy, uz, reach)
    if by_front:
        k_next = math.floor(t_exit / ds)
        while k_next > k:
            tb = k_next * ds
            if _is_empty(empty, block, ax + tb * bx, ay + tb * by, az + tb * bz):
                break
            k_next -= 1
        return k_next, -math.inf, spent
    k_next = max(math.ceil(t_exit / ds - 0.5), k + 1)
    while k_next > k + 1:
        tb = (k_next - 0.5) * ds
        if k_next - 1 == k_first or k_next - 1 == k_last:
            tb = _cut_segment(k_next - 1, ds, t_first, t_last)[0]
        if _is_empty(empty, block, ax + tb * bx, ay + tb * by, az + tb * bz):
            break
        k_next -= 1
    return k_next, -math.inf, spent


@helper_jit
def _preintegrated_tile(filtering, row0, col0, tile_h, tile_w, camera, height, width, mask,
                        box_lo, box_hi, vol_lo, vol_hi, origin, out, data, flat, offset,
                        gshape, inv, ds, fkind, fp0, fp1, fp2, radius, ntaps, start, vinv,
                        density, psi, emission, step, grey, col_start, col_inv, mean, shade,
                        ka, kd, ks, shininess, light, headlight, ramp_x, ramp_y, by_gradient,
                        threshold, empty, clearance, block, fine_counts, bound, budget, wx, wy,
                        wz, dx, dy, dz):
    """The rays of one tile (``tile_h x tile_w`` pixels from ``(row0, col0)``), each
    pre-integrated: each segment ``[k ds, (k + 1) ds)`` (cut at the volume's faces)
    classified from its values at its two ends (the back of one is the front of the next),
    front to back from the ray's first segment while its middle lies before ``t_out``, into
    ``out``. Returns the samples taken. ``filtering`` is None for the tent filter, as in
    :func:`raycast`: numba drops the other filters' code before typing, so the tent filter's
    loop holds no call (a call in the loop, even one not taken, made it three times slower).
    A call per tile, not per ray (3 to 7% faster on the MNI152 template at 512^2, one
    thread). The other arguments are :func:`raycast`'s (the table's named without ``pre_``), and
    ``wx ... dz`` scratch for the filter's weights
    (:func:`~vrlib._kernels.sampling.tap_scratch`)."""
    nx = data.shape[2]
    nxy = data.shape[1] * data.shape[2]
    oz, oy, ox = offset[0], offset[1], offset[2]
    gz, gy, gx = gshape[0], gshape[1], gshape[2]
    taken = 0
    for p in range(tile_h * tile_w):
        r = row0 + p // tile_w
        c = col0 + p % tile_w
        hit, d, t_in, t_out, ax, ay, az, bx, by, bz, k, k_first, k_last, t_first, t_last = \
            _pixel_start(r, c, camera, height, width, mask, box_lo, box_hi, vol_lo, vol_hi,
                         True, origin, inv, ds)
        if not hit:
            continue
        acc_r = 0.0
        acc_g = 0.0
        acc_b = 0.0
        acc_a = 0.0
        spent = 0.0
        t_check = -math.inf if block > 0 else math.inf
        k_front = -1  # the segment whose front value (and its Psi) `front` holds
        front = 0.0
        psi_front = 0.0
        while True:
            t = (k + 0.5) * ds
            cut = k == k_first or k == k_last
            if cut:
                t = _cut_segment(k, ds, t_first, t_last)[0]
                if t < t_in:  # another brick's segment
                    k += 1
                    continue
            if t >= t_out:
                break
            t_a = k * ds
            t_b = t_a + ds
            if cut:
                t_a = max(t_a, t_first)
                t_b = min(t_b, t_last)
            if t_a >= t_check:
                k_next, t_check, spent = _skip(
                    k, ax + t_a * bx, ay + t_a * by, az + t_a * bz, ax, ay, az, bx, by, bz, ds,
                    True, empty, clearance, block, fine_counts, bound, budget, spent,
                    k_first, k_last, t_first, t_last, False)
                if k_next > k:
                    k = k_next
                    continue
            if k != k_front:
                if filtering is None:
                    front = trilinear(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ax + t_a * bx,
                                      ay + t_a * by, az + t_a * bz)
                else:
                    front = _other_value(data, flat, nx, nxy, oz, oy, ox, gz, gy, gx, offset,
                                         gshape, ax + t_a * bx, ay + t_a * by, az + t_a * bz,
                                         fkind, fp0, fp1, fp2, radius, ntaps, wx, wy, wz)
                psi_front = psi_at(front, start, vinv, density, psi)
                taken += 1
            if filtering is None:
                back = trilinear(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ax + t_b * bx,
                                 ay + t_b * by, az + t_b * bz)
            else:
                back = _other_value(data, flat, nx, nxy, oz, oy, ox, gz, gy, gx, offset, gshape,
                                    ax + t_b * bx, ay + t_b * by, az + t_b * bz, fkind, fp0, fp1,
                                    fp2, radius, ntaps, wx, wy, wz)
            psi_back = psi_at(back, start, vinv, density, psi)
            taken += 1
            # A cut segment's own length: its opacity is exact, its colour's mean emission that
            # of a whole segment.
            length = t_b - t_a if cut else ds
            if step:
                alpha, cr, cg, cb = _step_segment(front, back, length, start, vinv, density,
                                                  emission, grey)
            else:
                # A linear ramp: the opacity exact from the density's running integral (eq 1.4
                # with the mean density), the colour from the table of the mean emission.
                if abs(back - front) * vinv < 1e-6:
                    mean_density = interpolate(density, start, vinv, 0.5 * (front + back))
                elif psi_back == psi_front:  # no density between them (a zero division
                    mean_density = 0.0           # saved: the same zero)
                else:
                    mean_density = (psi_back - psi_front) / (back - front)
                alpha = -math.expm1(-length * mean_density)
                cr = cg = cb = alpha
                if alpha > 0.0 and not grey:
                    px = (front - col_start) * col_inv
                    py = (back - col_start) * col_inv
                    n = mean.shape[0]
                    cr = alpha * bilinear_channel(mean, px, py, n, 0)
                    cg = alpha * bilinear_channel(mean, px, py, n, 1)
                    cb = alpha * bilinear_channel(mean, px, py, n, 2)
            front = back
            psi_front = psi_back
            k += 1
            k_front = k
            if not alpha > 0.0:
                continue
            if shade or by_gradient:
                # The gradient at the segment's middle modulates the segment.
                ux, uy, uz = ax + t * bx, ay + t * by, az + t * bz
                if filtering is None:
                    gx_, gy_, gz_ = tent_gradient(data, offset, gshape, ux, uy, uz)
                else:
                    gx_, gy_, gz_ = gradient(data, offset, gshape, ux, uy, uz, fkind, fp0, fp1,
                                             fp2, radius, ntaps, wx, wy, wz, dx, dy, dz)
                if headlight:
                    lx, ly, lz = -d[0], -d[1], -d[2]
                else:
                    lx, ly, lz = light[0], light[1], light[2]
                alpha, cr, cg, cb = modulate_by_gradient(
                    alpha, cr, cg, cb, gx_ * inv[0], gy_ * inv[1], gz_ * inv[2], by_gradient,
                    ramp_x, ramp_y, shade, lx, ly, lz, d[0], d[1], d[2], ka, kd, ks, shininess)
                if not alpha > 0.0:
                    continue
            acc_r, acc_g, acc_b, acc_a = _over(acc_r, acc_g, acc_b, acc_a, cr, cg, cb, alpha)
            if acc_a >= threshold:
                break
        _put_pixel(out, r, c, acc_r, acc_g, acc_b, acc_a)
    return taken


@helper_jit
def _step_segment(front, back, length, start, inv, density, emission, grey):
    """A pre-integrated segment of ``length`` across a step at its middle (the box filter):
    half a segment at the front value over half at the back value, exactly. Returns
    ``(alpha, r, g, b)``."""
    half_a = -math.expm1(-0.5 * length * interpolate(density, start, inv, front))
    half_b = -math.expm1(-0.5 * length * interpolate(density, start, inv, back))
    alpha = 1.0 - (1.0 - half_a) * (1.0 - half_b)
    if grey or not alpha > 0.0:
        return alpha, alpha, alpha, alpha
    behind = (1.0 - half_a) * half_b
    front_r, front_g, front_b = interpolate_rgb(emission, start, inv, front)
    back_r, back_g, back_b = interpolate_rgb(emission, start, inv, back)
    return (alpha, half_a * front_r + behind * back_r, half_a * front_g + behind * back_g,
            half_a * front_b + behind * back_b)


@jit(inline="always")
def _pixel_start(r, c, camera, height, width, mask, box_lo, box_hi, vol_lo, vol_hi, exact,
                 origin, inv, ds):
    """Pixel ``(r, c)``'s ray and where it takes samples:
    ``(hit, d, t_in, t_out, ax, ay, az, bx, by, bz, k, k_first, k_last, t_first, t_last)``.
    ``hit`` is False for a pixel outside the image or the ``mask``, or a ray that misses the
    box ``[box_lo, box_hi]``; ``d`` is the ray's direction, ``[t_in, t_out)`` its stretch in
    the box, ``a + t b`` its index position, ``k`` the first segment; with ``exact``, the
    segments ``k_first`` and ``k_last`` that the volume's
    faces cut at ``t_first`` and ``t_last`` (-1 without; a cut segment's sample may lie
    before segment ``k``'s, so ``k`` starts there)."""
    if r >= height or c >= width:
        return (False, (0.0, 0.0, 0.0), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, -1, -1,
                0.0, 0.0)
    if not mask[r, c]:  # a ray that meets nothing visible: no set-up at all
        return (False, (0.0, 0.0, 0.0), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, -1, -1,
                0.0, 0.0)
    o, d = pixel_ray(camera, height, width, r, c)
    t_in, t_out = ray_box(o, d, box_lo, box_hi)
    t_in = max(t_in, 0.0)
    # Index position of sample k: a + t b, the same for every brick of a volume.
    ax = (o[0] - origin[0]) * inv[0]
    ay = (o[1] - origin[1]) * inv[1]
    az = (o[2] - origin[2]) * inv[2]
    bx = d[0] * inv[0]
    by = d[1] * inv[1]
    bz = d[2] * inv[2]
    k = math.ceil(t_in / ds - 0.5) if t_out > t_in else 0
    k_first = k_last = -1
    t_first = t_last = 0.0
    if exact is not None and exact and t_out > t_in:
        t_first, t_last = ray_box(o, d, vol_lo, vol_hi)
        t_first = max(t_first, 0.0)
        k_first = math.floor(t_first / ds)
        k_last = math.ceil(t_last / ds) - 1
        if k - 1 == k_first or k - 1 == k_last:
            k -= 1
    hit = t_out > t_in
    return hit, d, t_in, t_out, ax, ay, az, bx, by, bz, k, k_first, k_last, t_first, t_last


#: :func:`_pixel_start` and :func:`~vrlib._kernels.sampling.trilinear` compiled apart, for a
#: quick start's kernel (:data:`vrlib.raycast.QUICK_START_SAMPLES`): called there rather
#: than inlined, they shorten that kernel's compile, a first render's wait (its one-off
#: render of Marschner-Lobb 41^3 at 256^2 took 15.5 ms instead of 13). Every other kernel
#: keeps them inline: called, :func:`_pixel_start` cost the tent filter's kernel with packets
#: 5 to 17% of a render whose rays take few samples (MNI152 at 4 voxels a step), and
#: Catmull-Rom's 9 to 11%.
_pixel_start_apart = compiled_apart(_pixel_start)
_trilinear_apart = compiled_apart(trilinear)


@jit(inline="always")
def _open_tile(entry, tiles_across, tile_h, tile_w, out):
    """The tile an entry of the kernels' ``order`` names: its number, first row and first
    column, and whether its rays are cast (an entry ``-1 - tile`` names a tile none of whose
    rays can meet anything). Its pixels are made transparent first: ``out`` comes
    uncleared, so that each thread clears the tiles it takes (clearing a 512^2 image before
    the render took 0.9 ms on one thread, a tenth of a sparse render on two)."""
    tile = entry if entry >= 0 else -1 - entry
    row0 = (tile // tiles_across) * tile_h
    col0 = (tile % tiles_across) * tile_w
    for r in range(row0, min(row0 + tile_h, out.shape[0])):
        for c in range(col0, min(col0 + tile_w, out.shape[1])):
            for channel in range(4):
                out[r, c, channel] = 0.0
    return tile, row0, col0, entry >= 0


@jit(inline="always")
def _loop_views(data, offset, gshape, origin, spacing, camera, light, ramp_x, ramp_y, empty,
                clearance, bound, scratch):
    """What both ray-casting kernels hand to the calls in their loops, as views without
    reference counts (:func:`~vrlib._kernels._jit.borrowed`; the kernel's caller keeps the
    arrays): the arguments as given, then ``flat`` (``data`` raveled), ``inv`` (the inverse
    spacing), ``fine_counts`` (the skip grid's shape) and the filter's scratch ``wx, wy, wz,
    dx, dy, dz`` (the rows of this call's ``scratch``)."""
    data = borrowed(data)
    return (data, borrowed(offset), borrowed(gshape), borrowed(origin), borrowed(camera),
            borrowed(light), borrowed(ramp_x), borrowed(ramp_y), borrowed(empty),
            borrowed(clearance), borrowed(bound), data.reshape(-1),
            (1.0 / spacing[0], 1.0 / spacing[1], 1.0 / spacing[2]), empty.shape,
            borrowed(scratch[0]), borrowed(scratch[1]), borrowed(scratch[2]),
            borrowed(scratch[3]), borrowed(scratch[4]), borrowed(scratch[5]))


@jit(inline="always")
def _tile_views(mask, box_lo, box_hi, vol_lo, vol_hi, out, order, counter, samples):
    """The pixels' and tiles' arrays both kernels take, borrowed as :func:`_loop_views`'s:
    without it, numba counted references to them at every ray's set-up and every packet, a
    quarter of a render whose rays take few samples."""
    return (borrowed(mask), borrowed(box_lo), borrowed(box_hi), borrowed(vol_lo),
            borrowed(vol_hi), borrowed(out), borrowed(order), borrowed(counter),
            borrowed(samples))


@jit
def raycast_preintegrated(data, offset, gshape, origin, spacing, box_lo, box_hi, vol_lo,
                          vol_hi, camera, height, width, ds, fkind, fp0, fp1, fp2, radius,
                          ntaps, pre_start, pre_inv, pre_density, pre_psi, pre_emission,
                          pre_step, pre_grey, col_start, col_inv, pre_mean, shade, ka, kd, ks,
                          shininess, light, headlight, ramp_x, ramp_y, by_gradient, threshold,
                          empty, clearance, block, mask, bound, budget, tile_h, tile_w, order,
                          counter, out, samples, filtering, scratch):
    """:func:`raycast` with pre-integrated classification (a kernel of its own, so that a
    render compiles only the loop it runs): each segment is classified from its values at
    its two ends (:func:`_preintegrated_tile`), always cut at the volume's faces. The
    opacity comes from the mean density (``pre_density`` and its running integral
    ``pre_psi`` on the grid ``(value - pre_start) * pre_inv``), the colour as the opacity
    times the mean emission ``pre_mean[front, back]`` (grid ``(value - col_start) *
    col_inv``) unless ``pre_grey``; with ``pre_step`` (the box filter) half a segment at
    each end's value, ``pre_emission`` on the density's grid
    (:class:`vrlib.transfer.PreintegratedTable`). The other arguments are as for
    :func:`raycast` (``filtering`` its kind: None for the tent filter drops the others'
    code)."""
    data, offset, gshape, origin, camera, light, ramp_x, ramp_y, empty, clearance, bound, \
        flat, inv, fine_counts, wx, wy, wz, dx, dy, dz = _loop_views(
            data, offset, gshape, origin, spacing, camera, light, ramp_x, ramp_y, empty,
            clearance, bound, scratch)
    pre_density, pre_psi = borrowed(pre_density), borrowed(pre_psi)
    pre_emission, pre_mean = borrowed(pre_emission), borrowed(pre_mean)
    mask, box_lo, box_hi, vol_lo, vol_hi, out, order, counter, samples = _tile_views(
        mask, box_lo, box_hi, vol_lo, vol_hi, out, order, counter, samples)
    tiles_across = (width + tile_w - 1) // tile_w
    while True:
        it = take(counter)
        if it >= order.shape[0]:
            break
        tile_id, row0, col0, cast = _open_tile(order[it], tiles_across, tile_h, tile_w, out)
        if not cast:
            continue
        samples[tile_id] = _preintegrated_tile(
            filtering, row0, col0, tile_h, tile_w, camera, height, width, mask, box_lo,
            box_hi, vol_lo, vol_hi, origin, out, data, flat, offset, gshape, inv, ds, fkind,
            fp0, fp1, fp2, radius, ntaps, pre_start, pre_inv, pre_density, pre_psi,
            pre_emission, pre_step, pre_grey, col_start, col_inv, pre_mean, shade, ka, kd, ks,
            shininess, light, headlight, ramp_x, ramp_y, by_gradient, threshold, empty,
            clearance, block, fine_counts, bound, budget, wx, wy, wz, dx, dy, dz)


@jit
def raycast(data, offset, gshape, origin, spacing, box_lo, box_hi, vol_lo, vol_hi, exact,
            camera, height, width, ds,
            fkind, fp0, fp1, fp2, radius, ntaps,
            tstart, tinv, alpha_tab, color_tab, emit_tab,
            shade, ka, kd, ks, shininess, light, headlight, ramp_x, ramp_y, by_gradient,
            threshold, empty, clearance, block, mask, bound, budget, multiplier, tile_h, tile_w,
            order, counter, out, samples, colour, filtering, lighting, skipping, packets,
            scratch, rays, steps, ray_state, ray_steps, status):
    """Render ``out[row, col] = (r, g, b, a)`` premultiplied (``out`` comes uncleared: each
    tile is made transparent when taken, and a pixel whose ray meets nothing stays so);
    count samples per tile.

    ``data`` holds the samples from global index ``offset`` on (the whole volume, or a brick
    with ghost samples) of a volume of global shape ``gshape`` whose sample 0 is at world
    ``origin``; the rays of the packed view ``camera`` (one per pixel of a ``height x width``
    image) sample the world box ``[box_lo, box_hi]`` of a volume whose own box is
    ``[vol_lo, vol_hi]`` (cut exactly at its faces when ``exact``). The image is cut into
    ``tile_h x tile_w`` pixel tiles; a call takes the next tile of ``order`` (the heaviest
    first, then as ``-1 - tile`` those that are only cleared: :func:`_open_tile`) from the
    shared queue ``counter`` (:func:`vrlib._kernels.queue.take`) until none is left. Several
    threads make the call at once (:func:`vrlib._scheduling.on_threads`; the kernel releases
    the GIL) and finish together however unevenly the tiles cost; neighbouring rays read
    neighbouring voxels, so a tile keeps them in cache. Each pixel is computed independently
    and in a fixed order: the image depends neither on the number of threads nor on which
    thread took which tile.

    Skips: ``empty`` flags blocks of ``block`` cells per axis that nothing visible can come
    from, and ``clearance`` (per block, an integer array of the same shape) how far a ray
    may go from the block unchecked, in blocks (:func:`vrlib.skipping.clearance`; ``block =
    0`` turns skipping off), and ``mask`` the pixels whose rays can meet a non-empty block;
    ``threshold = 1`` turns early ray termination off. With ``budget > 0`` a ray also skips
    blocks that are not empty while the bounds ``bound`` (per block: the most a ray can
    change any channel by leaving the block out) of the blocks it skipped add up to at most
    ``budget``: each pixel changes by at most ``budget``.
    Adaptive steps: where ``multiplier`` (per block of the skip grid, a power of two; a
    ``(1, 1, 1)`` array of 1 turns them off) exceeds 1, one sample stands for that many
    segments (:func:`_long_segment`, :mod:`vrlib.adaptive`).
    ``colour`` None or False says the emission is 1 everywhere and unshaded, so colour
    equals opacity (True: the colour comes from ``color_tab`` or the shading; None compiles
    the kernel without the colour, for the tent filter unshaded). ``by_gradient``
    multiplies the density by the piecewise-linear factor through ``(ramp_x, ramp_y)`` of
    the gradient magnitude (per world unit).

    Compiled per kind of render: ``filtering`` None compiles only the tent filter, ``lighting``
    None only a table's colour (no shading, no gradient opacity), ``colour`` None no colour at
    all, and ``skipping`` None leaves out the skipping (``block = 0``). numba drops a branch on
    a None argument before it types the function, so such a kernel compiles in a fraction of
    the time (a first render's wait); ``True`` compiles that path. ``packets`` True (for the
    tent filter without shading: ``filtering`` and ``lighting`` None) compiles the packets
    below, None leaves them out (every other kind; a quick start,
    :data:`vrlib.raycast.QUICK_START_SAMPLES`, takes :func:`raycast_quick` instead).
    ``scratch`` (6 x ``MAX_TAPS``, this call's own) holds the filter's weights and their
    derivatives along x, y and z; ``rays, steps, ray_state, ray_steps, status`` are this
    call's lanes (:func:`lanes`).

    Rays go in groups of ``LANES`` pixels of a tile row. Each ray is marched alone (the
    checked samples: cut segments, borders, skips, other filters, shading) up to where its
    samples run inside the volume (with the tent filter and no shading); the group's runs
    are then taken together as one packet in vector form
    (:func:`vrlib._kernels.packets.inside_runs`: lane by lane the scalar loop's arithmetic,
    so the image is the same bit for bit), and the rays march on until all have ended.
    """
    data, offset, gshape, origin, camera, light, ramp_x, ramp_y, empty, clearance, bound, \
        flat, inv, fine_counts, wx, wy, wz, dx, dy, dz = _loop_views(
            data, offset, gshape, origin, spacing, camera, light, ramp_x, ramp_y, empty,
            clearance, bound, scratch)
    emit_tab, multiplier = borrowed(emit_tab), borrowed(multiplier)
    alpha_tab, color_tab = borrowed(alpha_tab), borrowed(color_tab)
    mask, box_lo, box_hi, vol_lo, vol_hi, out, order, counter, samples = _tile_views(
        mask, box_lo, box_hi, vol_lo, vol_hi, out, order, counter, samples)
    rays, steps, ray_state = borrowed(rays), borrowed(steps), borrowed(ray_state)
    ray_steps, status = borrowed(ray_steps), borrowed(status)
    tiles_across = (width + tile_w - 1) // tile_w
    nx = data.shape[2]
    nxy = data.shape[1] * data.shape[2]
    oz, oy, ox = offset[0], offset[1], offset[2]
    gz, gy, gx = gshape[0], gshape[1], gshape[2]
    ntab = alpha_tab.shape[0]
    shift = oz * nxy + oy * nx + ox
    gx1, gy1, gz1 = float(gx - 1), float(gy - 1), float(gz - 1)
    adaptive = block > 0 and multiplier.shape == empty.shape
    while True:
        it = take(counter)
        if it >= order.shape[0]:
            break
        tile_id, row0, col0, cast = _open_tile(order[it], tiles_across, tile_h, tile_w, out)
        if not cast:
            continue
        taken = 0
        for p0 in range(0, tile_h * tile_w, LANES):
            # A group of LANES pixels. Each lane's ray is marched alone up to where its
            # samples run inside the volume; the lanes' runs are then taken together, as one
            # packet (vrlib._kernels.packets.inside_runs, the same arithmetic lane by lane),
            # and the lanes march on, until every ray has ended.
            for lane in range(LANES):
                status[lane] = DONE
                steps[K, lane] = 0
                steps[END, lane] = 0  # an idle lane of the packet
                r = row0 + (p0 + lane) // tile_w
                c = col0 + (p0 + lane) % tile_w
                if p0 + lane >= tile_h * tile_w:
                    continue
                hit, d, t_in, t_out, ax, ay, az, bx, by, bz, k, k_first, k_last, t_first, \
                    t_last = _pixel_start(r, c, camera, height, width, mask, box_lo, box_hi,
                                          vol_lo, vol_hi, exact, origin, inv, ds)
                if not hit:
                    continue
                status[lane] = MARCH
                rays[AX, lane], rays[AY, lane], rays[AZ, lane] = ax, ay, az
                rays[BX, lane], rays[BY, lane], rays[BZ, lane] = bx, by, bz
                rays[RED, lane] = rays[GREEN, lane] = rays[BLUE, lane] = rays[ALPHA, lane] = 0.0
                ray_state[_D0, lane], ray_state[_D1, lane], ray_state[_D2, lane] = d
                ray_state[_T_IN, lane], ray_state[_T_OUT, lane] = t_in, t_out
                ray_state[_T_FIRST, lane], ray_state[_T_LAST, lane] = t_first, t_last
                ray_state[_SPENT, lane] = 0.0  # the budget's share this ray has used
                # Samples before t_check lie in a block already found not empty: no check
                # needed (a sample that rounding puts in an empty block adds exactly nothing).
                ray_state[_T_CHECK, lane] = -math.inf if block > 0 else math.inf
                ray_state[_T_ENTER, lane] = 0.0
                ray_steps[_K, lane] = k
                ray_steps[_K_FIRST, lane], ray_steps[_K_LAST, lane] = k_first, k_last
                # The step multiplier of the block before t_check (entered at t_enter), and
                # where the ray's samples inside the volume end (-1: not found yet).
                ray_steps[_M_BLOCK, lane] = 1
                ray_steps[_INSIDE_END, lane] = -1
            while True:
                for lane in range(LANES):
                    if status[lane] != MARCH:
                        continue
                    d = (ray_state[_D0, lane], ray_state[_D1, lane], ray_state[_D2, lane])
                    t_in, t_out = ray_state[_T_IN, lane], ray_state[_T_OUT, lane]
                    t_first, t_last = ray_state[_T_FIRST, lane], ray_state[_T_LAST, lane]
                    spent, t_check = ray_state[_SPENT, lane], ray_state[_T_CHECK, lane]
                    t_enter = ray_state[_T_ENTER, lane]
                    ax, ay, az = rays[AX, lane], rays[AY, lane], rays[AZ, lane]
                    bx, by, bz = rays[BX, lane], rays[BY, lane], rays[BZ, lane]
                    acc_r, acc_g = rays[RED, lane], rays[GREEN, lane]
                    acc_b, acc_a = rays[BLUE, lane], rays[ALPHA, lane]
                    k, k_first, k_last = ray_steps[_K, lane], ray_steps[_K_FIRST, lane], \
                        ray_steps[_K_LAST, lane]
                    m_block, inside_end = ray_steps[_M_BLOCK, lane], ray_steps[_INSIDE_END, lane]
                    run = False
                    while True:
                        t = (k + 0.5) * ds
                        fraction = 1.0
                        if exact is not None and (k == k_first or k == k_last):
                            t, fraction = _cut_segment(k, ds, t_first, t_last)
                            if t < t_in:  # another brick's sample
                                k += 1
                                continue
                        if t >= t_out:
                            break
                        ux = ax + t * bx
                        uy = ay + t * by
                        uz = az + t * bz
                        if skipping is not None and t >= t_check:
                            k_next, t_check, spent = _skip(
                                k, ux, uy, uz, ax, ay, az, bx, by, bz, ds, False, empty,
                                clearance, block, fine_counts, bound, budget, spent, k_first,
                                k_last, t_first, t_last, adaptive)
                            if k_next > k:
                                k = k_next
                                continue
                            if adaptive:
                                m_block = _block_bound(multiplier, block, ux, uy, uz)
                                t_enter = _entry(ax, ay, az, bx, by, bz, block, fine_counts,
                                                 ux, uy, uz)
                        if skipping is not None and m_block > 1:
                            # Adaptive steps: one sample, at its middle, for an aligned run of
                            # m segments inside this block (vrlib.adaptive bounds the change).
                            k0, m = _long_segment(k, m_block, ds, t_enter, t_check, k_first,
                                                  k_last)
                            if m > 1:
                                k = k0 + m - 1  # the last of the run: k + 1 follows it
                                t = (k0 + 0.5 * m) * ds
                                if t < t_in:  # another brick's sample
                                    k += 1
                                    continue
                                if t >= t_out:
                                    break
                                ux = ax + t * bx
                                uy = ay + t * by
                                uz = az + t * bz
                                fraction = float(m)
                        if (packets is not None and m_block == 1 and k != k_first and k != k_last
                                and _inside(k, ds, ax, ay, az, bx, by, bz, gx1, gy1, gz1, t_in,
                                            t_out)):
                            # A run of samples inside the volume, up to the next skip check
                            # (the samples inside form one interval per ray: its end, found
                            # once, serves every run): taken with the other lanes' runs.
                            if inside_end < 0:
                                inside_end = _inside_end(k, ds, ax, ay, az, bx, by, bz, gx1,
                                                         gy1, gz1, t_in, t_out, k_last)
                            steps[K, lane] = k
                            steps[END, lane] = _before(t_check, ds, k, inside_end)
                            run = True
                            break
                        # The two common filters unrolled, the others through the general
                        # loop.
                        if filtering is None or fkind == TENT:
                            value = trilinear(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ux, uy, uz)
                        elif fkind == CUBIC:
                            value = tricubic(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ux, uy, uz,
                                             fp0, fp1, fp2)
                        elif ntaps == 4:
                            value = separable4(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ux, uy, uz,
                                               fkind, fp0, fp1, fp2, radius)
                        else:
                            value = reconstruct(data, offset, gshape, ux, uy, uz, fkind, fp0,
                                                fp1, fp2, radius, ntaps, wx, wy, wz)
                        taken += 1
                        k += 1
                        # Classify: segment opacity 1 - exp(-density ds) (eq 1.4) and colour
                        # E alpha (eq 1.9), from the table.
                        i, w = lookup((value - tstart) * tinv, ntab)
                        alpha = entry(alpha_tab, i, w)
                        if not alpha > 0.0:
                            continue  # a transparent segment adds exactly nothing
                        if ((colour is None or not colour)
                                and (lighting is None or not by_gradient)):
                            cr = cg = cb = alpha  # white emission, no shading: colour = opacity
                        elif lighting is not None and (shade or by_gradient):
                            if filtering is None:
                                gx_, gy_, gz_ = tent_gradient(data, offset, gshape, ux, uy, uz)
                            else:
                                gx_, gy_, gz_ = gradient(data, offset, gshape, ux, uy, uz,
                                                         fkind, fp0, fp1, fp2, radius, ntaps,
                                                         wx, wy, wz, dx, dy, dz)
                            if headlight:
                                lx, ly, lz = -d[0], -d[1], -d[2]
                            else:
                                lx, ly, lz = light[0], light[1], light[2]
                            alpha, cr, cg, cb = classify_by_gradient(
                                alpha, i, w, emit_tab, gx_ * inv[0], gy_ * inv[1],
                                gz_ * inv[2], by_gradient, ramp_x, ramp_y, shade, lx, ly, lz,
                                d[0], d[1], d[2], ka, kd, ks, shininess)
                            if not alpha > 0.0:
                                continue
                        else:
                            cr = entry_channel(color_tab, i, w, 0)
                            cg = entry_channel(color_tab, i, w, 1)
                            cb = entry_channel(color_tab, i, w, 2)
                        if (exact is not None or skipping is not None) and fraction != 1.0:
                            # A segment cut by the volume's face, or a long one.
                            alpha, cr, cg, cb = _cut_to(fraction, alpha, cr, cg, cb)
                        acc_r, acc_g, acc_b, acc_a = _over(acc_r, acc_g, acc_b, acc_a, cr, cg,
                                                           cb, alpha)
                        if acc_a >= threshold:
                            break
                    if run:  # the lane waits for the packet where it stands
                        status[lane] = RUN
                        rays[RED, lane], rays[GREEN, lane] = acc_r, acc_g
                        rays[BLUE, lane], rays[ALPHA, lane] = acc_b, acc_a
                        ray_state[_SPENT, lane], ray_state[_T_CHECK, lane] = spent, t_check
                        ray_state[_T_ENTER, lane] = t_enter
                        ray_steps[_K, lane], ray_steps[_M_BLOCK, lane] = k, m_block
                        ray_steps[_INSIDE_END, lane] = inside_end
                        continue
                    status[lane] = DONE
                    _put_pixel(out, row0 + (p0 + lane) // tile_w, col0 + (p0 + lane) % tile_w,
                               acc_r, acc_g, acc_b, acc_a)
                if packets is None:
                    break  # a kernel without packets: every lane has marched to its end
                waiting = False
                for lane in range(LANES):
                    waiting = waiting or status[lane] == RUN
                if not waiting:
                    break
                inside_runs(flat, nx, nxy, shift, alpha_tab, color_tab, colour, ds, tstart,
                            tinv, threshold, rays, steps)
                for lane in range(LANES):
                    if status[lane] != RUN:
                        continue
                    taken += steps[K, lane] - ray_steps[_K, lane]
                    ray_steps[_K, lane] = steps[K, lane]
                    steps[K, lane] = 0
                    steps[END, lane] = 0
                    status[lane] = MARCH
                    if rays[ALPHA, lane] >= threshold:
                        status[lane] = DONE
                        _put_pixel(out, row0 + (p0 + lane) // tile_w,
                                   col0 + (p0 + lane) % tile_w, rays[RED, lane],
                                   rays[GREEN, lane], rays[BLUE, lane], rays[ALPHA, lane])
        samples[tile_id] = taken


@jit
def raycast_quick(data, offset, gshape, origin, spacing, box_lo, box_hi, vol_lo, vol_hi, exact,
                  camera, height, width, ds, tstart, tinv, alpha_tab, color_tab, threshold,
                  mask, tile_h, tile_w, order, counter, out, samples, colour):
    """:func:`raycast` for a quick start (:data:`vrlib.raycast.QUICK_START_SAMPLES`): the tent
    filter, unlit, nothing skipped, each ray marched alone to its end. The smallest kernel,
    for a first render's wait: it compiles in about two thirds of the time of
    :func:`raycast` compiled for the same render without packets (docs/kernel.md), and gives
    its image bit for bit (the same arithmetic, sample by sample, as :func:`raycast`'s
    scalar loop and its packets). It takes those of :func:`raycast`'s arguments that it
    reads, by the same names (:func:`vrlib.raycast._quick_arguments`). ``exact`` None
    compiles it without the cut segments' code (lattice ends), ``colour`` None without the
    colour table (white emission: colour equals opacity). A ray's set-up and its samples
    are calls to helpers compiled apart (:func:`_pixel_start_apart`,
    :func:`_trilinear_apart`): inline, the compile took as long or longer."""
    data, origin, camera = borrowed(data), borrowed(origin), borrowed(camera)
    alpha_tab, color_tab = borrowed(alpha_tab), borrowed(color_tab)
    mask, box_lo, box_hi, vol_lo, vol_hi, out, order, counter, samples = _tile_views(
        mask, box_lo, box_hi, vol_lo, vol_hi, out, order, counter, samples)
    flat = data.reshape(-1)
    inv = (1.0 / spacing[0], 1.0 / spacing[1], 1.0 / spacing[2])
    tiles_across = (width + tile_w - 1) // tile_w
    nx = data.shape[2]
    nxy = data.shape[1] * data.shape[2]
    oz, oy, ox = offset[0], offset[1], offset[2]
    gz, gy, gx = gshape[0], gshape[1], gshape[2]
    ntab = alpha_tab.shape[0]
    while True:
        it = take(counter)
        if it >= order.shape[0]:
            break
        tile_id, row0, col0, cast = _open_tile(order[it], tiles_across, tile_h, tile_w, out)
        if not cast:
            continue
        taken = 0
        for p in range(tile_h * tile_w):
            r = row0 + p // tile_w
            c = col0 + p % tile_w
            hit, d, t_in, t_out, ax, ay, az, bx, by, bz, k, k_first, k_last, t_first, \
                t_last = _pixel_start_apart(r, c, camera, height, width, mask, box_lo, box_hi,
                                            vol_lo, vol_hi, exact, origin, inv, ds)
            if not hit:
                continue
            acc_r = acc_g = acc_b = acc_a = 0.0
            while True:
                t = (k + 0.5) * ds
                fraction = 1.0
                if exact is not None and (k == k_first or k == k_last):
                    t, fraction = _cut_segment(k, ds, t_first, t_last)
                    if t < t_in:  # another brick's sample
                        k += 1
                        continue
                if t >= t_out:
                    break
                value = _trilinear_apart(flat, nx, nxy, oz, oy, ox, gz, gy, gx, ax + t * bx,
                                         ay + t * by, az + t * bz)
                taken += 1
                k += 1
                # Classify (eqs 1.4 and 1.9, from the table), as raycast does.
                i, w = lookup((value - tstart) * tinv, ntab)
                alpha = entry(alpha_tab, i, w)
                if not alpha > 0.0:
                    continue  # a transparent segment adds exactly nothing
                if colour is None or not colour:
                    cr = cg = cb = alpha  # white emission: colour = opacity
                else:
                    cr = entry_channel(color_tab, i, w, 0)
                    cg = entry_channel(color_tab, i, w, 1)
                    cb = entry_channel(color_tab, i, w, 2)
                if exact is not None and fraction != 1.0:  # a segment cut by a face
                    alpha, cr, cg, cb = _cut_to(fraction, alpha, cr, cg, cb)
                acc_r, acc_g, acc_b, acc_a = _over(acc_r, acc_g, acc_b, acc_a, cr, cg, cb, alpha)
                if acc_a >= threshold:
                    break
            _put_pixel(out, r, c, acc_r, acc_g, acc_b, acc_a)
        samples[tile_id] = taken
