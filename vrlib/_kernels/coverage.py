"""The pixels whose rays can meet a block that is not empty (the kernel behind
:func:`vrlib.skipping.footprint_mask`): each block's projected bounding rectangle, one pixel
wider all round, painted as a union.

Each rectangle is marked at its four corners (+1 at its first and stop corners, -1 at the
other two); the running sums along rows, then down columns, count the rectangles over each
pixel. One pass over the blocks and one over the rectangles' bounding box, where NumPy took
some thirty calls of 10-150 microseconds each (a render of a sparse scene spent 0.7 ms in them
per frame, 256^3 -> 512^2).
"""

from __future__ import annotations

import math

from vrlib._kernels._jit import jit
from vrlib._kernels.camera import project


@jit
def cover(camera, empty, block, last, origin, spacing, marks, mask):
    """Set ``mask[row, col]`` (``height x width``, False on entry) where a ray can meet one
    of the blocks that ``empty`` (z, y, x: one entry per block of ``block`` cells a side)
    says are not empty; a corner's sample index is clipped to ``last``, the lattice's last
    index x, y, z, and the lattice's sample 0 lies at world ``origin`` with ``spacing``.
    ``marks`` is scratch of the mask's shape, int32 zeros. Returns False, leaving ``mask``
    as it is, when a block reaches behind a perspective eye (every pixel may then see it).
    The grid is read here rather than listed in NumPy first (``argwhere`` cost a 512^2
    render 0.1 ms)."""
    height, width = mask.shape
    lo_r, lo_c, hi_r, hi_c = height, width, 0, 0
    ny, nx = empty.shape[1], empty.shape[2]
    blocks = empty.reshape(-1)
    for n in range(blocks.size):
        if blocks[n]:
            continue
        bz, by, bx = n // (ny * nx), n // nx % ny, n % nx
        r0 = c0 = math.inf
        r1 = c1 = -math.inf
        for corner in range(8):
            i = min((bx + (corner >> 2 & 1)) * block, last[0])
            j = min((by + (corner >> 1 & 1)) * block, last[1])
            k = min((bz + (corner & 1)) * block, last[2])
            row, col, depth = project(camera, height, width, origin[0] + i * spacing[0],
                                      origin[1] + j * spacing[1], origin[2] + k * spacing[2])
            if not (depth > 0.0 and math.isfinite(row) and math.isfinite(col)):
                return False
            r0, r1 = min(r0, row), max(r1, row)
            c0, c1 = min(c0, col), max(c1, col)
        # Pixels [first, stop) on each axis: one pixel wider all round.
        first_r = min(max(math.floor(r0) - 1, 0), height)
        stop_r = min(max(math.floor(r1) + 2, 0), height)
        first_c = min(max(math.floor(c0) - 1, 0), width)
        stop_c = min(max(math.floor(c1) + 2, 0), width)
        if first_r >= stop_r or first_c >= stop_c:
            continue
        lo_r, hi_r = min(lo_r, first_r), max(hi_r, stop_r)
        lo_c, hi_c = min(lo_c, first_c), max(hi_c, stop_c)
        marks[first_r, first_c] += 1
        if stop_c < width:
            marks[first_r, stop_c] -= 1
        if stop_r < height:
            marks[stop_r, first_c] -= 1
            if stop_c < width:
                marks[stop_r, stop_c] += 1
    # The running sums, in the rectangles' bounding box only (the count above a row is the
    # sum the row before left in marks).
    for r in range(lo_r, hi_r):
        run = 0
        for c in range(lo_c, hi_c):
            run += marks[r, c]
            total = run + marks[r - 1, c] if r > lo_r else run
            marks[r, c] = total
            mask[r, c] = total > 0
    return True
