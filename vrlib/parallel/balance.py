"""Load balance of the object partition: how bricks are cut and dealt to ranks.

* ``"even"``: equal bricks, one per rank;
* ``"interleaved"``: ``k`` small bricks per rank, dealt round-robin;
* ``"work"``, the package's new method: a coarse map of which blocks of the volume are visible
  under the transfer function is summed over the ranks (one allreduce of a few kilobytes), and
  the k-d tree is re-cut so that each side of every split holds visible volume in proportion to
  its ranks. Ray samples per unit volume are the same everywhere in an orthographic view, so
  visible volume is the work of a ray caster that skips empty space, whatever the view, and
  each rank keeps one convex brick (binary swap still applies).
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from vrlib.arguments import check_transfer
from vrlib.filters import make_filter
from vrlib.parallel.decompose import split
from vrlib.parallel.sources import ghost
from vrlib.skipping import BLOCK, brick_empty_blocks

__all__ = ["BALANCE", "visible_cells", "work_split", "visible_work"]

#: Ways to cut and deal the bricks.
BALANCE = ("even", "interleaved", "work")


def visible_cells(data, first, lo, hi, shape, *, filter="trilinear", transfer=None):
    """Cells of the brick ``[lo, hi)`` that lie in blocks which can show, per global block of
    :data:`vrlib.skipping.BLOCK` cells: one rank's share of the work map that the work-sized
    split sums over the ranks.

    ``data`` holds the samples from global index ``first`` (z, y, x) on, covering the brick
    and the filter's margin; ``shape`` is the volume's sample shape. For a whole volume pass
    ``first = lo = (0, 0, 0)`` and ``hi`` its cells: the serial twin of the summed map.

    Examples
    --------
    >>> from vrlib import LookupTransfer
    >>> data = np.zeros((17, 17, 17)); data[12, 12, 12] = 1.0
    >>> ramp = LookupTransfer([0.0, 0.0, 1.0], value_range=(0.0, 1.0))  # 0 up to 0.5
    >>> visible_cells(data, (0, 0, 0), (0, 0, 0), (16, 16, 16), data.shape,
    ...               transfer=ramp).tolist()
    [[[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 512.0]]]
    """
    filt = make_filter(filter)
    transfer = check_transfer(transfer)
    cells = tuple(n - 1 for n in shape)
    empty = brick_empty_blocks(data, first, lo, hi, cells, filt, transfer)
    work = np.zeros(empty.shape)
    for index in np.argwhere(~empty):
        share = [min((i + 1) * BLOCK, h) - max(i * BLOCK, low)
                 for i, low, h in zip(index, lo, hi, strict=True)]
        work[tuple(index)] = math.prod(share)
    return work


def work_split(block_work, cells, parts, *, splitter=split):
    """The work-sized k-d split: ``parts`` bricks of ``cells`` (z, y, x), each side of every
    cut holding visible volume (``block_work``, per block) in proportion to its bricks. A
    small floor (1% of the densest block's per-cell weight) keeps empty regions from being
    free, since rays still cross them. ``splitter(cells, parts, weights=...)`` cuts the tree:
    :func:`vrlib.parallel.decompose.split`, or a compositor's own
    (:meth:`vrlib.parallel.composite.Compositor.split`, radix-k's groups).

    Examples
    --------
    >>> work = np.zeros((2, 2, 2)); work[1, 1, 1] = 512.0     # all in one corner block
    >>> [b.hi for b in work_split(work, (16, 16, 16), 2).bricks]   # the cut moves to it
    [(12, 16, 16), (16, 16, 16)]
    """
    per_cell = block_work / BLOCK**3
    weights = per_cell.repeat(BLOCK, 0).repeat(BLOCK, 1).repeat(BLOCK, 2)
    weights = weights[: cells[0], : cells[1], : cells[2]]
    weights = weights + 0.01 * max(float(weights.max()), 1e-300)
    return splitter(cells, parts, weights=weights)


def visible_work(comm, lattice, read, tree, filt, transfer, sent):
    """The work map summed over the ranks (one allreduce): each rank reads its brick of
    ``tree`` (with ``read``, :func:`vrlib.parallel.sources.open_source`) and counts its visible
    cells; the bytes it sends go to ``sent["balance"]``."""
    brick = tree.bricks[comm.Get_rank()]
    region = brick.samples(ghost(filt), lattice.shape)
    work = visible_cells(read(region), [a for a, _ in region], brick.lo, brick.hi,
                         lattice.shape, filter=filt, transfer=transfer)
    total = np.empty_like(work)
    comm.Allreduce(work, total, op=MPI.SUM)
    if comm.Get_size() > 1:
        sent["balance"] += work.nbytes
    return total
