"""Kernel of the maximum- and average-intensity projections (:mod:`vrlib.projection`)."""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from vrlib._kernels._jit import borrowed, parallel_jit
from vrlib._kernels.camera import pixel_ray, ray_box
from vrlib._kernels.filters import TENT
from vrlib._kernels.sampling import reconstruct, tap_scratch, trilinear

#: Blend codes: the largest reconstructed value along a ray, or their mean.
MAXIMUM, AVERAGE = 0, 1


@parallel_jit
def project(data, gshape, origin, spacing, box_lo, box_hi, camera, height, width, ds, fkind,
            fp0, fp1, fp2, radius, ntaps, blend, value, hit, samples, exact):
    """``value[row, col]``: the largest (``blend = MAXIMUM``) or mean (``AVERAGE``) value
    reconstructed at the samples ``t = (k + 1/2) ds`` of the pixel's ray inside the box, the
    same positions the ray caster samples; ``hit`` says whether the ray took any sample,
    ``samples[row]`` counts them. With ``exact`` segment ends, as the ray caster's: sample
    ``k`` stands for ``[k ds, (k + 1) ds)``, and where the box's faces cut that segment the
    sample lies at the middle of its part inside and the mean weighs it by that part's
    length. Rows run in parallel, each pixel on its own: the image does not depend on the
    thread count."""
    inv0, inv1, inv2 = 1.0 / spacing[0], 1.0 / spacing[1], 1.0 / spacing[2]
    offset = np.zeros(3, dtype=np.int64)
    # Borrowed views (no reference counts) for the call per sample: counting references to
    # each array at every call took three quarters of a projection's time.
    data, gshape = borrowed(data), borrowed(gshape)
    flat = data.reshape(-1)
    nx, nxy = data.shape[2], data.shape[1] * data.shape[2]
    gz, gy, gx = gshape[0], gshape[1], gshape[2]
    for r in prange(height):
        wx, wy, wz, _, _, _ = tap_scratch()
        taken = 0
        for c in range(width):
            o, d = pixel_ray(camera, height, width, r, c)
            t_in, t_out = ray_box(o, d, box_lo, box_hi)
            t_in = max(t_in, 0.0)
            best = -math.inf
            total = 0.0
            weights = 0.0
            count = 0
            k = math.floor(t_in / ds) if exact else math.ceil(t_in / ds - 0.5)
            while t_out > t_in:
                t = (k + 0.5) * ds
                part = 1.0
                if exact and (k * ds < t_in or (k + 1) * ds > t_out):  # a cut segment
                    a, b = max(k * ds, t_in), min((k + 1) * ds, t_out)
                    if not b > a:
                        if a >= t_out:
                            break
                        k += 1
                        continue
                    t, part = 0.5 * (a + b), (b - a) / ds
                elif t >= t_out:
                    break
                ux = (o[0] + t * d[0] - origin[0]) * inv0
                uy = (o[1] + t * d[1] - origin[1]) * inv1
                uz = (o[2] + t * d[2] - origin[2]) * inv2
                if fkind == TENT:  # the ray caster's own unrolled trilinear
                    v = trilinear(flat, nx, nxy, 0, 0, 0, gz, gy, gx, ux, uy, uz)
                else:
                    v = reconstruct(data, borrowed(offset), gshape, ux, uy, uz, fkind, fp0,
                                    fp1, fp2, radius, ntaps, borrowed(wx), borrowed(wy),
                                    borrowed(wz))
                best = max(best, v)
                total += v * part if exact else v
                weights += part
                count += 1
                k += 1
            hit[r, c] = count > 0
            if count == 0:
                value[r, c] = 0.0
            elif blend == MAXIMUM:
                value[r, c] = best
            else:
                value[r, c] = total / weights if exact else total / count
            taken += count
        samples[r] = taken
