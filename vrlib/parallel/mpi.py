"""Parallel ray casting with MPI: object and image partitions, sort-last compositing.

Every function takes the communicator first and never creates one. Each rank generates (from
an analytic field) or reads (from a ``.npy`` file, memory-mapped) only the samples it needs,
renders on the global ray lattice (:func:`vrlib.raycast.cast_rays`), so that bricks join
without seams, and counts every byte it sends.

Object partition (:func:`render_object`): the volume is cut into bricks by a k-d tree; each
rank ray-casts its bricks into full-screen local images, and the images are composited in the
tree's front-to-back order by

* **direct send**: each rank owns one screen tile and receives, from every rank, the part of
  each local image that falls on it (only the bounding rectangle of what was drawn);
* **binary swap** (Ma et al. 1994): ``log2 P`` rounds in which pairs swap halves of their
  current screen region (again only what was drawn). Rank counts that are not powers of two
  fold pairs of k-d siblings together first.

Image partition (:func:`render_image`): each rank owns a screen tile; the volume stays in
bricks, and every rank sends each tile owner the box of its samples that the tile's rays can
read (counted as voxel traffic).

Load balance (``balance=``): ``"even"`` (equal bricks), ``"interleaved"`` (``k`` small bricks
per rank, dealt round-robin) and ``"work"``, the package's new method: a coarse map of which
blocks of the volume are visible under the transfer function is summed over the ranks (one
allreduce of a few kilobytes), and the k-d tree is re-cut so that each side of every split
holds visible volume in proportion to its ranks. Ray samples per unit volume are the same
everywhere in an orthographic view, so visible volume is the work of a ray caster that skips
empty space, whatever the view, and each rank keeps one convex brick (binary swap still
applies).

A rank that raises ends the frame on every rank at the next stage boundary: the others raise
:class:`RankFailed` naming it, so ``mpiexec`` returns within seconds instead of hanging.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from vrlib import _validate
from vrlib.compositing import over
from vrlib.filters import make_filter
from vrlib.image import Image, RenderStats
from vrlib.parallel.decompose import interleaved_owners, screen_tiles, split
from vrlib.parallel.traffic import swap_halves, swap_slots
from vrlib.raycast import BLOCK, cast_rays, coarsen, footprint_mask, taps_per_axis
from vrlib.skipping import filter_margin, lattice_sums
from vrlib.transfer import Glow, TransferFunction
from vrlib.view import View

__all__ = ["render_object", "render_image", "RankFailed", "Frame", "visible_cells",
           "work_split", "COMPOSITING", "BALANCE"]

COMPOSITING = ("direct-send", "binary-swap")
BALANCE = ("even", "interleaved", "work")
#: Header bytes counted for each rectangle sent (four int64 pixel bounds).
HEADER = 32


class RankFailed(RuntimeError):
    """Another rank raised during a distributed render.

    Examples
    --------
    >>> error = RankFailed(2, "reading its bricks", "OSError: disk gone")
    >>> str(error), error.rank
    ('rank 2 failed while reading its bricks: OSError: disk gone', 2)
    """

    def __init__(self, rank, stage, message):
        super().__init__(f"rank {rank} failed while {stage}: {message}")
        self.rank = rank
        self.stage = stage


class _Stage:
    """Ends a stage on every rank together: if any rank raised inside it, the rank that
    raised re-raises its own error and the others raise :class:`RankFailed` naming it."""

    def __init__(self, comm, name):
        self.comm, self.name = comm, name

    def __enter__(self):
        return self

    def __exit__(self, kind, value, traceback):
        if kind is not None and not issubclass(kind, Exception):
            return False
        report = None if value is None else (self.comm.Get_rank(),
                                             f"{kind.__name__}: {value}")
        failed = [r for r in self.comm.allgather(report) if r is not None]
        if not failed or value is not None:
            return False
        raise RankFailed(failed[0][0], self.name, failed[0][1])


@dataclass
class Frame:
    """One distributed frame.

    ``image`` is the composited :class:`vrlib.Image` on the root rank (None elsewhere);
    ``ranks`` (root only) one dict per rank: bricks, samples, seconds rendering and
    compositing, and bytes sent per phase (``balance``, ``voxels``, ``composite``,
    ``gather``).

    Examples
    --------
    >>> frame = Frame(None, [{"samples": 30, "bytes": {"composite": 8}},
    ...                      {"samples": 10, "bytes": {"composite": 4}}])
    >>> frame.imbalance(), frame.bytes_sent("composite").tolist()
    (1.5, [8.0, 4.0])
    """

    image: Image | None
    ranks: list = field(default_factory=list)

    def bytes_sent(self, phase=None):
        """Bytes each rank sent (in one phase, or in all)."""
        return np.array([sum(r["bytes"].values()) if phase is None else r["bytes"][phase]
                         for r in self.ranks], dtype=float)

    def imbalance(self, key="samples"):
        """Max over mean across ranks of ``key`` (1 is perfect balance)."""
        work = np.array([r[key] for r in self.ranks], dtype=float)
        return float(work.max() / work.mean()) if work.mean() > 0 else 1.0


# ---------------------------------------------------------------- the data each rank needs


@dataclass(frozen=True)
class _Lattice:
    """The global sample lattice: shape (z, y, x), origin and spacing (x, y, z)."""

    shape: tuple
    origin: np.ndarray
    spacing: np.ndarray

    @property
    def cells(self):
        return tuple(n - 1 for n in self.shape)

    def box(self, lo, hi):
        """World box (x, y, z arrays) of cells ``[lo, hi)``."""
        return (self.origin + np.array(lo[::-1]) * self.spacing,
                self.origin + np.array(hi[::-1]) * self.spacing)


def _source(source, shape, extent):
    """The lattice and a reader ``read(region) -> ndarray`` of a field or a ``.npy`` file."""
    if isinstance(source, str | Path):
        path = Path(source)
        if path.suffix != ".npy" or not path.is_file():
            raise ValueError(f"source must be an analytic field or an existing .npy file, got "
                             f"{str(path)!r}")
        array = np.load(path, mmap_mode="r")
        if array.ndim != 3 or min(array.shape) < 2:
            raise ValueError(f"source {path.name} must hold a 3-D array with at least 2 "
                             f"samples per axis, got shape {array.shape}")
        if shape is not None and tuple(shape) != array.shape:
            raise ValueError(f"shape {tuple(shape)} does not match the file's {array.shape}")
        shape = array.shape
        ext = np.array([[-1.0, 1.0]] * 3) if extent is None else np.asarray(extent, float)

        def read(region):
            block = np.array(array[tuple(slice(a, b) for a, b in region)], dtype=np.float64)
            if not np.all(np.isfinite(block)):
                raise ValueError(f"source {path.name} holds NaN or infinite samples")
            return block
    elif callable(getattr(source, "sample_region", None)):
        if shape is None:
            raise ValueError("shape is required for an analytic field (samples per axis)")
        if isinstance(shape, int | np.integer):
            shape = (int(shape),) * 3
        shape = tuple(_validate.positive_int("shape", n, minimum=2) for n in shape)
        ext = np.asarray(source.bounds if extent is None else extent, float)

        def read(region):
            return source.sample_region(shape, region, extent=ext)
    else:
        raise TypeError(f"source must be an analytic field (data_gen.make_field) or a path to "
                        f".npy samples, got {type(source).__name__}")
    origin = ext[:, 0].copy()
    spacing = (ext[:, 1] - ext[:, 0]) / (np.array(shape[::-1]) - 1)
    return _Lattice(tuple(shape), origin, spacing), read


def _ghost(filt):
    """Samples beyond a brick's box that its ray samples can read."""
    return taps_per_axis(filt) // 2 + 1


def _value_range(comm, lows, highs, filt):
    """Bounds of every reconstructable value, the same on every rank: the global min and max
    of the samples, then the filter's overshoot (as
    :func:`vrlib.raycast.reconstructed_range`)."""
    lo = comm.allreduce(min(lows, default=math.inf), op=MPI.MIN)
    hi = comm.allreduce(max(highs, default=-math.inf), op=MPI.MAX)
    s_min, s_max, a_max = lattice_sums(filt)
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    return (min(centre * s_min, centre * s_max) - a_max * half,
            max(centre * s_min, centre * s_max) + a_max * half)


def _empty_blocks(data, first, lo, hi, cells, filt, transfer):
    """Empty-space grid (global blocks of :data:`BLOCK` cells) for the samples a brick takes:
    a block is marked empty when nothing in its part of the brick (plus the filter's margin)
    can show; blocks outside the brick are marked empty, since the brick takes no samples
    there."""
    empty = np.ones([-(-c // BLOCK) for c in cells], dtype=bool)
    margin = filter_margin(filt)
    s_min, s_max, a_max = lattice_sums(filt)
    b0 = [lo[a] // BLOCK for a in range(3)]
    b1 = [-(-hi[a] // BLOCK) for a in range(3)]
    for bz in range(b0[0], b1[0]):
        for by in range(b0[1], b1[1]):
            for bx in range(b0[2], b1[2]):
                index = (bz, by, bx)
                part = []
                for a in range(3):
                    c0 = max(index[a] * BLOCK, lo[a]) - margin
                    c1 = min((index[a] + 1) * BLOCK, hi[a]) + 1 + margin
                    part.append(slice(max(c0 - first[a], 0), max(c1 - first[a], 0)))
                values = data[tuple(part)]
                v_lo, v_hi = float(values.min()), float(values.max())
                centre, half = 0.5 * (v_lo + v_hi), 0.5 * (v_hi - v_lo)
                low = min(centre * s_min, centre * s_max) - a_max * half
                high = max(centre * s_min, centre * s_max) + a_max * half
                empty[index] = transfer.max_density(low, high) <= 0.0
    return empty


def _cast(data, first, brick_lo, brick_hi, lattice, view, filt, transfer, ds, value_range,
          pixels=None):
    """Ray-cast one brick's samples; ``pixels`` restricts the rays to a mask."""
    empty = _empty_blocks(data, first, brick_lo, brick_hi, lattice.cells, filt, transfer)
    mask = footprint_mask(view, lattice, empty, BLOCK) if not empty.all() else \
        np.zeros(view.shape, dtype=bool)
    if pixels is not None:
        mask &= pixels
    if not mask.any():
        return np.zeros(view.shape + (4,)), 0
    box = lattice.box(brick_lo, brick_hi)
    return cast_rays(data, offset=tuple(first), global_shape=lattice.shape,
                     origin=lattice.origin, spacing=lattice.spacing, box=box, view=view,
                     filt=filt, transfer=transfer, ds=ds, value_range=value_range,
                     early_termination=1.0, skip=(empty, coarsen(empty), BLOCK, mask))


# ---------------------------------------------------------------- rectangles of pixels


def _content(rgba, within=None):
    """Bounding rectangle ``(r0, r1, c0, c1)`` of the non-zero pixels (inside ``within``)."""
    r0, r1, c0, c1 = within if within is not None else (0, rgba.shape[0], 0, rgba.shape[1])
    drawn = np.any(rgba[r0:r1, c0:c1] != 0.0, axis=2)
    rows, cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
    if rows.size == 0:
        return (0, 0, 0, 0)
    return (r0 + int(rows[0]), r0 + int(rows[-1]) + 1, c0 + int(cols[0]), c0 + int(cols[-1]) + 1)


def _clip(a, b):
    rect = (max(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), min(a[3], b[3]))
    return rect if rect[1] > rect[0] and rect[3] > rect[2] else (0, 0, 0, 0)


def _empty(rect):
    return rect[1] <= rect[0] or rect[3] <= rect[2]


def _pixels(rgba, rect):
    return np.ascontiguousarray(rgba[rect[0]:rect[1], rect[2]:rect[3]])


# ---------------------------------------------------------------- compositing


def _direct_send(comm, images, keys, tiles, sent):
    """Send each local image's part on every tile to the tile's owner; composite the parts
    received in ``keys`` order (front to back). Returns this rank's tile rectangle and
    pixels."""
    size, rank = comm.Get_size(), comm.Get_rank()
    mine = tiles.rects(rank)[0]
    headers = [[] for _ in range(size)]
    payloads = [[] for _ in range(size)]
    for rgba, key in zip(images, keys, strict=True):
        drawn = _content(rgba)
        for dest in range(size):
            part = _clip(drawn, tiles.rects(dest)[0])
            if not _empty(part):
                headers[dest].append((key, part))
                payloads[dest].append(_pixels(rgba, part))
    incoming = comm.alltoall(headers)
    sent["composite"] += HEADER * sum(len(h) for d, h in enumerate(headers) if d != rank)
    requests, received = [], []
    for dest in range(size):
        if dest == rank:
            continue
        for buf in payloads[dest]:
            requests.append(comm.Isend(buf, dest=dest, tag=7))
            sent["composite"] += buf.nbytes
    for source in range(size):
        if source == rank:
            received += [(key, part, buf) for (key, part), buf in zip(headers[rank],
                                                                        payloads[rank],
                                                                        strict=True)]
            continue
        for key, part in incoming[source]:
            buf = np.empty((part[1] - part[0], part[3] - part[2], 4))
            comm.Recv(buf, source=source, tag=7)
            received.append((key, part, buf))
    MPI.Request.Waitall(requests)
    tile = np.zeros((mine[1] - mine[0], mine[3] - mine[2], 4))
    for _key, part, buf in sorted(received, key=lambda item: item[0]):
        r0, r1 = part[0] - mine[0], part[1] - mine[0]
        c0, c1 = part[2] - mine[2], part[3] - mine[2]
        tile[r0:r1, c0:c1] = over(tile[r0:r1, c0:c1], buf)
    return mine, tile


def _exchange(comm, partner, rgba, rect_out, sent):
    """Send the pixels ``rect_out`` of ``rgba`` to ``partner`` and receive the pixels it
    sends (the rectangle it names first); returns (rect, pixels) received."""
    theirs = comm.sendrecv(rect_out, dest=partner, source=partner)
    sent["composite"] += HEADER
    buf = np.empty((max(theirs[1] - theirs[0], 0), max(theirs[3] - theirs[2], 0), 4))
    out = _pixels(rgba, rect_out) if not _empty(rect_out) else np.empty((0, 0, 4))
    comm.Sendrecv(out, dest=partner, recvbuf=buf, source=partner)
    sent["composite"] += out.nbytes
    return theirs, buf


def _merge(rgba, rect, buf, mine_in_front):
    """Composite received pixels into ``rgba`` at ``rect``."""
    if _empty(rect):
        return
    region = rgba[rect[0]:rect[1], rect[2]:rect[3]]
    region[...] = over(region, buf) if mine_in_front else over(buf, region)


def _binary_swap(comm, tree, rgba, order, sent):
    """Binary swap over the tree's slots (brick ``i`` on rank ``i``). Returns this rank's
    final screen rectangle (empty on ranks folded away) and the full-size image holding it."""
    rank = comm.Get_rank()
    height, width = rgba.shape[:2]
    position = {brick: i for i, brick in enumerate(order)}
    slots = swap_slots(tree)
    leaders = []
    for slot in slots:
        if isinstance(slot, tuple):
            first, second = slot[2], slot[3]
            if rank == second:  # fold: hand everything to the sibling and stop
                _exchange(comm, first, rgba, _content(rgba), sent)
                return (0, 0, 0, 0), rgba
            if rank == first:
                theirs, buf = _exchange(comm, second, rgba, (0, 0, 0, 0), sent)
                _merge(rgba, theirs, buf, position[first] < position[second])
            leaders.append(first)
        else:
            leaders.append(slot)
    s = leaders.index(rank)
    region = (0, height, 0, width)
    for r in range(int(math.log2(len(slots)))):
        partner_slot = s ^ (1 << r)
        partner = leaders[partner_slot]
        keep, give = swap_halves(region, s < partner_slot)
        theirs, buf = _exchange(comm, partner, rgba, _content(rgba, give), sent)
        # The group whose bricks come first in the visibility order is in front.
        group = 1 << (r + 1)
        mine_front = min(position[b] for b in _group(tree, slots, s, group)) < \
            min(position[b] for b in _group(tree, slots, partner_slot, group))
        _merge(rgba, theirs, buf, mine_front)
        region = keep
    return region, rgba


def _group(tree, slots, slot, size):
    """Bricks of the ``size // 2`` slots that share ``slot``'s group below a round."""
    half = size // 2
    start = (slot // half) * half
    bricks = []
    for s in slots[start:start + half]:
        bricks += tree.leaves(s)
    return bricks


def _gather(comm, rect, pixels, shape, root, sent):
    """Each rank's finished rectangle to ``root``; the full image there."""
    payload = (rect, pixels if not _empty(rect) else None)
    if comm.Get_rank() != root and not _empty(rect):
        sent["gather"] += HEADER + pixels.nbytes
    parts = comm.gather(payload, root=root)
    if comm.Get_rank() != root:
        return None
    out = np.zeros(shape + (4,))
    for part, buf in parts:
        if not _empty(part):
            out[part[0]:part[1], part[2]:part[3]] = buf
    return out


# ---------------------------------------------------------------- the renderers


def _root(root, size):
    root = _validate.positive_int("root", root, minimum=0)
    if root >= size:
        raise ValueError(f"root must be a rank of the communicator, 0..{size - 1}, got {root}")
    return root


def _check(view, filter, transfer, step, compositing=None, balance=None,
           bricks_per_rank=1):
    if not isinstance(view, View):
        raise TypeError(f"view must be a vrlib.View, got {type(view).__name__}")
    filt = make_filter(filter)
    transfer = Glow(1.0) if transfer is None else transfer
    if not isinstance(transfer, TransferFunction):
        raise TypeError(f"transfer must be a vrlib transfer function, got {transfer!r}")
    if transfer.shading is not None:
        raise ValueError("the parallel renderers take unshaded transfer functions "
                         "(shading=None)")
    step = _validate.positive_number("step", step)
    if compositing is not None:
        _validate.choice("compositing", compositing, COMPOSITING)
    if balance is not None:
        _validate.choice("balance", balance, BALANCE)
        _validate.positive_int("bricks_per_rank", bricks_per_rank)
        if balance == "interleaved" and compositing == "binary-swap":
            raise ValueError("binary-swap compositing needs one convex brick per rank: use "
                             "balance='even' or 'work', or compositing='direct-send'")
    return filt, transfer, step


def visible_cells(data, first, lo, hi, shape, *, filter="trilinear", transfer=None):
    """Cells of the brick ``[lo, hi)`` that lie in blocks which can show, per global block of
    :data:`vrlib.raycast.BLOCK` cells: one rank's share of the work map that the work-sized
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
    transfer = Glow(1.0) if transfer is None else transfer
    cells = tuple(n - 1 for n in shape)
    empty = _empty_blocks(data, first, lo, hi, cells, filt, transfer)
    work = np.zeros(empty.shape)
    for index in np.argwhere(~empty):
        share = [min((i + 1) * BLOCK, h) - max(i * BLOCK, low)
                 for i, low, h in zip(index, lo, hi, strict=True)]
        work[tuple(index)] = math.prod(share)
    return work


def work_split(block_work, cells, parts):
    """The work-sized k-d split: ``parts`` bricks of ``cells`` (z, y, x), each side of every
    cut holding visible volume (``block_work``, per block) in proportion to its bricks. A
    small floor (1% of the densest block's per-cell weight) keeps empty regions from being
    free, since rays still cross them.

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
    return split(cells, parts, weights=weights)


def _visible_work(comm, lattice, read, tree, rank, filt, transfer, sent):
    """The work map summed over the ranks (one allreduce)."""
    brick = tree.bricks[rank]
    region = brick.samples(_ghost(filt), lattice.shape)
    work = visible_cells(read(region), [a for a, _ in region], brick.lo, brick.hi,
                         lattice.shape, filter=filt, transfer=transfer)
    total = np.empty_like(work)
    comm.Allreduce(work, total, op=MPI.SUM)
    if comm.Get_size() > 1:
        sent["balance"] += work.nbytes
    return total


def render_object(comm, source, view, *, shape=None, extent=None, filter="trilinear",
                  transfer=None, step=0.5, compositing="binary-swap", balance="even",
                  bricks_per_rank=4, root=0):
    """Render ``source`` with an object partition over the ranks of ``comm``.

    Parameters
    ----------
    comm : mpi4py.MPI.Comm
    source : data_gen field or path to a ``.npy`` file
        A field is sampled on the lattice ``shape`` over ``extent`` (default its bounds), each
        rank evaluating only its brick and ghost samples; a file is memory-mapped and each
        rank reads only its brick (``extent`` default [-1, 1]^3).
    view : vrlib.View
    shape : int or (int, int, int)
        Samples per axis (fields only).
    filter, transfer, step
        As :func:`vrlib.render` (ray casting; unshaded transfer functions). Early ray
        termination is off, so the image equals the serial render's with
        ``early_termination=1``.
    compositing : {"binary-swap", "direct-send"}
    balance : {"even", "interleaved", "work"}
        How bricks are cut and dealt (see the module's notes).
    bricks_per_rank : int
        Bricks per rank for ``"interleaved"``.
    root : int
        Rank that receives the image.

    Returns
    -------
    Frame

    Raises
    ------
    ValueError, TypeError
        Bad arguments (the same on every rank), or more ranks than the volume has cells to
        give along the cut axes.
    RankFailed
        Another rank raised.

    Examples
    --------
    Run under ``mpiexec -n P python script.py``; with one rank it is the serial render:

    >>> from mpi4py import MPI
    >>> import data_gen, vrlib
    >>> field = data_gen.make_field("gaussian-blob", sigma=0.4)
    >>> view = vrlib.View.orbit(azimuth=30, elevation=20, size=16)
    >>> frame = render_object(MPI.COMM_WORLD, field, view, shape=17)
    >>> serial = vrlib.render(field.sample(17), view, early_termination=1.0)
    >>> bool(abs(frame.image.rgba - serial.rgba).max() < 1e-12)
    True
    """
    size, rank = comm.Get_size(), comm.Get_rank()
    sent = {"balance": 0, "voxels": 0, "composite": 0, "gather": 0}
    with _Stage(comm, "checking the arguments"):
        filt, transfer, step = _check(view, filter, transfer, step, compositing,
                                      balance, bricks_per_rank)
        root = _root(root, size)
        lattice, read = _source(source, shape, extent)
        parts = size * bricks_per_rank if balance == "interleaved" else size
        tree = split(lattice.cells, parts)
        owners = interleaved_owners(parts, size) if balance == "interleaved" else \
            np.arange(size)
    ds = step * float(lattice.spacing.min())
    with _Stage(comm, "reading its bricks"):
        mine = [b for b in tree.bricks if owners[b.index] == rank]
        bricks = []
        for brick in mine:
            region = brick.samples(_ghost(filt), lattice.shape)
            bricks.append((brick, [a for a, _ in region], read(region)))
    value_range = _value_range(comm, [float(d.min()) for *_, d in bricks],
                               [float(d.max()) for *_, d in bricks], filt)
    if balance == "work":
        with _Stage(comm, "measuring its visible volume"):
            block_work = _visible_work(comm, lattice, read, tree, rank, filt, transfer, sent)
        tree = work_split(block_work, lattice.cells, size)
        with _Stage(comm, "reading its re-balanced brick"):
            brick = tree.bricks[rank]
            region = brick.samples(_ghost(filt), lattice.shape)
            bricks = [(brick, [a for a, _ in region], read(region))]
    with _Stage(comm, "rendering"):
        start = time.perf_counter()
        images, samples = [], 0
        for brick, first, data in bricks:
            rgba, taken = _cast(data, first, brick.lo, brick.hi, lattice, view, filt,
                                transfer, ds, value_range)
            images.append(rgba)
            samples += taken
        render_s = time.perf_counter() - start
    start = time.perf_counter()
    order = tree.order(view, lattice.origin, lattice.spacing)
    position = {b: i for i, b in enumerate(order)}
    if compositing == "direct-send":
        tiles = screen_tiles(view.height, view.width, size)
        rect, pixels = _direct_send(comm, images, [position[b.index] for b, *_ in bricks],
                                    tiles, sent)
    else:
        rect, full = _binary_swap(comm, tree, images[0], order, sent)
        pixels = _pixels(full, rect) if not _empty(rect) else None
    composite_s = time.perf_counter() - start
    rgba = _gather(comm, rect, pixels, view.shape, root, sent)
    stats = {"rank": rank, "bricks": len(bricks), "samples": int(samples),
             "render_s": render_s, "composite_s": composite_s, "bytes": sent}
    ranks = comm.gather(stats, root=root)
    if rank != root:
        return Frame(None)
    np.clip(rgba[..., 3], 0.0, 1.0, out=rgba[..., 3])
    total = sum(r["samples"] for r in ranks)
    image = Image(rgba, RenderStats(samples=total, operations=0,
                                    bytes=int(sum(sum(r["bytes"].values()) for r in ranks)),
                                    seconds=max(r["render_s"] + r["composite_s"]
                                                for r in ranks)))
    return Frame(image, ranks)


def _needed(view, lattice, region, tile, reach):
    """Index box (per axis ``(start, stop)``) of the samples in ``region`` that rays through
    the pixels of ``tile`` can read, or None."""
    axes = [np.arange(a, b) for a, b in region]
    z, y, x = np.meshgrid(*axes, indexing="ij")
    points = np.stack([x, y, z], axis=-1).reshape(-1, 3) * lattice.spacing + lattice.origin
    p = view.project(points)
    if view.eye is None:
        rho = np.full(p.shape[0], reach / view.pixel_size)
    else:
        unit = view.pixel_size / view.distance  # pixel width one unit from the eye
        slope = 1.0 + unit * math.hypot(view.height, view.width) / 2.0
        rho = reach * slope / (unit * np.maximum(p[:, 2] - reach, 1e-12))
    rho = rho * (1.0 + 1e-9) + 1e-9
    r0, r1, c0, c1 = tile
    hit = (p[:, 0] + rho >= r0 + 0.5) & (p[:, 0] - rho <= r1 - 0.5)
    hit &= (p[:, 1] + rho >= c0 + 0.5) & (p[:, 1] - rho <= c1 - 0.5)
    if view.eye is not None:
        hit |= ~np.isfinite(p[:, 0]) | (p[:, 2] - reach <= 0.0)
    if not hit.any():
        return None
    index = np.argwhere(hit.reshape(z.shape))
    return [(a + int(lo), a + int(hi) + 1) for a, lo, hi in
            zip([r[0] for r in region], index.min(axis=0), index.max(axis=0), strict=True)]


def render_image(comm, source, view, *, shape=None, extent=None, filter="trilinear",
                 transfer=None, step=0.5, root=0):
    """Render ``source`` with an image partition over the ranks of ``comm``.

    The volume stays where it is loaded, one brick per rank (no ghosts); each rank owns one
    screen tile and receives from every rank the box of samples its tile's rays can read
    (within the filter's reach of the tile), assembles them, and ray-casts its tile.
    Arguments as :func:`render_object`. Returns a :class:`Frame` whose ranks count the voxel
    traffic under ``bytes["voxels"]``.

    Examples
    --------
    >>> from mpi4py import MPI
    >>> import data_gen, vrlib
    >>> field = data_gen.make_field("marschner-lobb")
    >>> view = vrlib.View.orbit(azimuth=30, elevation=20, size=16)
    >>> frame = render_image(MPI.COMM_WORLD, field, view, shape=17, filter="catmull-rom")
    >>> frame.image.shape, frame.ranks[0]["bytes"]["voxels"]   # one rank: nothing to send
    ((16, 16), 0)
    """
    size, rank = comm.Get_size(), comm.Get_rank()
    sent = {"balance": 0, "voxels": 0, "composite": 0, "gather": 0}
    with _Stage(comm, "checking the arguments"):
        filt, transfer, step = _check(view, filter, transfer, step)
        root = _root(root, size)
        lattice, read = _source(source, shape, extent)
        tree = split(lattice.cells, size)
        tiles = screen_tiles(view.height, view.width, size)
    ds = step * float(lattice.spacing.min())
    with _Stage(comm, "reading its brick"):
        brick = tree.bricks[rank]
        region = [(lo, n if hi == n - 1 else hi)
                  for lo, hi, n in zip(brick.lo, brick.hi, lattice.shape, strict=True)]
        data = read(region)
    value_range = _value_range(comm, [float(data.min())], [float(data.max())], filt)
    with _Stage(comm, "finding the voxels each tile needs"):
        reach = filt.radius * float(np.linalg.norm(lattice.spacing))
        boxes = [_needed(view, lattice, region, tiles.rects(d)[0], reach) for d in range(size)]
    incoming = comm.alltoall(boxes)
    sent["voxels"] += HEADER * (size - 1)
    requests = []
    for dest, box in enumerate(boxes):
        if box is not None and dest != rank:
            part = np.ascontiguousarray(data[tuple(slice(a - r[0], b - r[0])
                                                   for (a, b), r in zip(box, region,
                                                                        strict=True))])
            requests.append(comm.Isend(part, dest=dest, tag=11))
            sent["voxels"] += part.nbytes
    pieces = []
    for source_rank, box in enumerate(incoming):
        if box is None:
            continue
        if source_rank == rank:
            buf = data[tuple(slice(a - r[0], b - r[0]) for (a, b), r in zip(box, region,
                                                                             strict=True))]
        else:
            buf = np.empty([b - a for a, b in box])
            comm.Recv(buf, source=source_rank, tag=11)
        pieces.append((box, buf))
    MPI.Request.Waitall(requests)
    with _Stage(comm, "rendering its tile"):
        start = time.perf_counter()
        tile = tiles.rects(rank)[0]
        samples = 0
        pixels = np.zeros((tile[1] - tile[0], tile[3] - tile[2], 4))
        if pieces:
            lo = [min(box[a][0] for box, _ in pieces) for a in range(3)]
            hi = [max(box[a][1] for box, _ in pieces) for a in range(3)]
            # Samples nobody sent are NaN: a ray that read one would show it.
            local = np.full([h - a for a, h in zip(lo, hi, strict=True)], np.nan)
            for box, buf in pieces:
                local[tuple(slice(a - o, b - o) for (a, b), o in zip(box, lo,
                                                                     strict=True))] = buf
            mask = np.zeros(view.shape, dtype=bool)
            mask[tile[0]:tile[1], tile[2]:tile[3]] = True
            skip_grid = np.zeros([-(-c // BLOCK) for c in lattice.cells], dtype=bool)
            rgba, samples = cast_rays(
                local, offset=tuple(lo), global_shape=lattice.shape, origin=lattice.origin,
                spacing=lattice.spacing, box=lattice.box((0, 0, 0), lattice.cells), view=view,
                filt=filt, transfer=transfer, ds=ds, value_range=value_range,
                early_termination=1.0, skip=(skip_grid, coarsen(skip_grid), BLOCK, mask))
            pixels = _pixels(rgba, tile)
        render_s = time.perf_counter() - start
    rgba = _gather(comm, tile, pixels, view.shape, root, sent)
    stats = {"rank": rank, "bricks": 1, "samples": int(samples), "render_s": render_s,
             "composite_s": 0.0, "bytes": sent}
    ranks = comm.gather(stats, root=root)
    if rank != root:
        return Frame(None)
    np.clip(rgba[..., 3], 0.0, 1.0, out=rgba[..., 3])
    image = Image(rgba, RenderStats(samples=sum(r["samples"] for r in ranks), operations=0,
                                    bytes=int(sum(sum(r["bytes"].values()) for r in ranks)),
                                    seconds=max(r["render_s"] for r in ranks)))
    return Frame(image, ranks)
