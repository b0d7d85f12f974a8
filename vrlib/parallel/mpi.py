"""Parallel ray casting with MPI: object and image partitions, sort-last compositing.

Every function takes the communicator first and never creates one. Each rank generates (from
an analytic field) or reads (from a ``.npy`` file, memory-mapped) only the samples it needs
(:mod:`vrlib.parallel.sources`), renders on the global ray lattice
(:func:`vrlib.raycast.cast_rays`), so that bricks join without seams, and counts every byte
it sends.

Object partition (:func:`render_object`): the volume is cut into bricks by a k-d tree
(balanced as :mod:`vrlib.parallel.balance` says); each rank ray-casts its bricks into
full-screen local images, and the images are composited in the tree's front-to-back order by
a compositor of :data:`vrlib.parallel.composite.COMPOSITORS` (direct send, binary swap).

Image partition (:func:`render_image`): each rank owns a screen tile; the volume stays in
bricks, and every rank sends each tile owner the box of its samples that the tile's rays can
read (counted as voxel traffic).

A rank that raises ends the frame on every rank at the next stage boundary
(:mod:`vrlib.parallel.stage`): the others raise :class:`RankFailed` naming it.
"""

from __future__ import annotations

import math
import resource
import time
from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI

from vrlib import validate
from vrlib.arguments import render_arguments
from vrlib.image import Image, RenderStats
from vrlib.parallel import rects
from vrlib.parallel.balance import BALANCE, visible_cells, visible_work, work_split
from vrlib.parallel.composite import COMPOSITORS, HEADER, RadixK, compositor, gather_to_root
from vrlib.parallel.decompose import interleaved_owners, screen_tiles, split
from vrlib.parallel.exchange import Exchange
from vrlib.parallel.sources import RawFile, ghost, global_value_range, open_source
from vrlib.parallel.stage import RankFailed, Stage
from vrlib.raycast import cast_rays, segment_options
from vrlib.skipping import BLOCK, brick_empty_blocks, clearance, footprint_mask

__all__ = ["render_object", "render_image", "RankFailed", "Frame", "visible_cells",
           "work_split", "COMPOSITORS", "RadixK", "RawFile", "BALANCE", "HEADER"]


@dataclass
class Frame:
    """One distributed frame.

    ``image`` is the composited :class:`vrlib.Image` on the root rank (None elsewhere);
    ``ranks`` (root only) one dict per rank: bricks, samples, seconds rendering and
    compositing, bytes sent per phase (``balance``, ``voxels``, ``composite``,
    ``gather``), the process's peak resident memory (``peak_rss``, bytes), and (object
    partition) ``messages``, one ``[round, destination, pixels]`` per rectangle the rank sent
    while compositing.

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


def _cast(data, first, brick_lo, brick_hi, lattice, view, filt, transfer, ds, value_range,
          pixels=None, exact_ends=False, preintegrated=False, reach=0):
    """Ray-cast one brick's samples; ``pixels`` restricts the rays to a mask.

    A pre-integrated segment whose middle lies in the brick reads values up to half a step
    beyond it: ``reach`` cells each side, which the brick's ghost samples hold, count in its
    empty blocks too, so that it skips exactly what the serial render skips."""
    near = [max(0, a - reach) for a in brick_lo], [min(n, b + reach) for b, n in
                                                  zip(brick_hi, lattice.cells, strict=True)]
    empty = brick_empty_blocks(data, first, *near, lattice.cells, filt, transfer)
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
                     early_termination=1.0,
                     # Only non-empty blocks sampled: the work-sized split balances them.
                     skip=(empty, clearance(empty, through=False), BLOCK, mask),
                     exact_ends=exact_ends, preintegrated=preintegrated)


def _peak_rss():
    """This process's peak resident memory so far, bytes (Linux reports kilobytes)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _root(root, size):
    root = validate.positive_int("root", root, minimum=0)
    if root >= size:
        raise ValueError(f"root must be a rank of the communicator, 0..{size - 1}, got {root}")
    return root


def _refuse_default_transfer(source, given):
    """A file rendered without a transfer function: the serial default
    (:func:`vrlib.default_transfer`) fits a ramp to the whole volume's histogram, which no
    rank holds, and Glow(1.0) would not show real data. Refuse rather than guess."""
    if not given and not callable(getattr(source, "sample_region", None)):
        raise ValueError("transfer is required for a file source: vrlib.render's default fits "
                         "a ramp to the whole volume's histogram, which no rank holds; pass "
                         "one, e.g. vrlib.colormap('gray', [(0, 0), (1, 0.25)], clim=(LOW, "
                         "HIGH)) or vrlib.auto_transfer(data_gen.load(path))")


def _check(view, filter, transfer, step, compositing=None, balance=None,
           bricks_per_rank=1):
    filt, transfer, step, _ = render_arguments(view, filter, transfer, step)
    if filt.prefiltered:
        raise ValueError(f"filter {filt.name!r} reconstructs prefiltered coefficients, and its "
                         "prefilter is a recursion along whole lines of the volume, while each "
                         "rank reads only its brick; use a filter applied to the samples "
                         "(e.g. 'catmull-rom'), or vrlib.render on one machine")
    if compositing is not None:
        compositing = compositor(compositing)
    if balance is not None:
        validate.choice("balance", balance, BALANCE)
        validate.positive_int("bricks_per_rank", bricks_per_rank)
        if balance == "interleaved" and compositing.one_brick_per_rank:
            raise ValueError(f"{compositing.name} compositing needs one convex brick per rank: "
                             "use balance='even' or 'work', or compositing='direct-send'")
    return filt, transfer, step, compositing


def render_object(comm, source, view, *, shape=None, extent=None, filter="trilinear",
                  transfer=None, step=0.5, compositing="binary-swap", balance="even",
                  bricks_per_rank=4, segment_ends=None, classification="point", root=0):
    """Render ``source`` with an object partition over the ranks of ``comm``.

    Parameters
    ----------
    comm : mpi4py.MPI.Comm
    source : data_gen field, path to a ``.npy`` or ``.nii`` file, or RawFile
        A field is sampled on the lattice ``shape`` over ``extent`` (default its bounds), each
        rank evaluating only its brick and ghost samples; a file is memory-mapped and each
        rank reads only its brick and ghost samples (``extent`` default: the box
        :func:`data_gen.load` gives the file; see :mod:`vrlib.parallel.sources`).
    view : vrlib.View
    shape : int or (int, int, int)
        Samples per axis (fields only).
    filter, transfer, step
        As :func:`vrlib.render` (ray casting; shading and gradient opacity included). Early ray
        termination is off, so the image equals the serial render's with
        ``early_termination=1``. ``transfer`` defaults to ``Glow(1.0)`` for a field, as its
        serial samples carry; a file needs one (the serial default fits the whole histogram).
    compositing : str or Compositor, default "binary-swap"
        A name from :data:`vrlib.parallel.composite.COMPOSITORS` ("binary-swap",
        "direct-send", "radix-k"), ``"radix-k:2x3"`` or ``RadixK([2, 3])`` (radix-k with the
        factors of the rank count given round by round); see
        :func:`vrlib.parallel.composite.compositor`.
    balance : {"even", "interleaved", "work"}
        How bricks are cut and dealt (see the module's notes).
    bricks_per_rank : int
        Bricks per rank for ``"interleaved"``.
    segment_ends, classification
        As :func:`vrlib.render`'s ray-casting options: the volume's outer faces cut the
        segments (``"exact"``), never a brick's; a pre-integrated segment belongs to the brick
        that holds its middle, which reads half a step past its box from ghost samples. The
        image equals the serial render's with the same options.
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
    transfer_given = transfer is not None
    with Stage(comm, "checking the arguments"):
        filt, transfer, step, compositor = _check(view, filter, transfer, step, compositing,
                                                  balance, bricks_per_rank)
        exact, preint = segment_options(segment_ends, classification)
        root = _root(root, size)
        lattice, read = open_source(source, shape, extent)
        _refuse_default_transfer(source, transfer_given)
        view = view.fitted(lattice.extent)
        if balance == "interleaved":
            tree = split(lattice.cells, size * bricks_per_rank)
        else:
            tree = compositor.split(lattice.cells, size)
        owners = interleaved_owners(len(tree), size)
    ds = step * float(lattice.spacing.min())
    # A pre-integrated segment's ends reach half a step past its brick's box.
    reach = math.ceil(0.5 * step) if preint else 0
    with Stage(comm, "reading its bricks"):
        mine = [b for b in tree.bricks if owners[b.index] == rank]
        bricks = []
        for brick in mine:
            region = brick.samples(ghost(filt) + reach, lattice.shape)
            bricks.append((brick, [a for a, _ in region], read(region)))
    value_range = global_value_range(comm, [float(d.min()) for *_, d in bricks],
                                     [float(d.max()) for *_, d in bricks], filt)
    if balance == "work":
        with Stage(comm, "measuring its visible volume"):
            block_work = visible_work(comm, lattice, read, tree, filt, transfer, sent)
        tree = work_split(block_work, lattice.cells, size, splitter=compositor.split)
        with Stage(comm, "reading its re-balanced brick"):
            brick = tree.bricks[rank]
            region = brick.samples(ghost(filt) + reach, lattice.shape)
            bricks = [(brick, [a for a, _ in region], read(region))]
    with Stage(comm, "rendering"):
        start = time.perf_counter()
        held, samples = [], 0  # (brick, its full-screen local image)
        for brick, first, data in bricks:
            rgba, taken = _cast(data, first, brick.lo, brick.hi, lattice, view, filt,
                                transfer, ds, value_range, exact_ends=exact,
                                preintegrated=preint, reach=reach)
            held.append((brick, rgba))
            samples += taken
        render_s = time.perf_counter() - start
    start = time.perf_counter()
    order = tree.order(view, lattice.origin, lattice.spacing)
    log = []  # [round, destination, pixels] per rectangle sent
    with Exchange(comm, compositor.name, sent, log) as exchange:
        rect, finished = compositor.composite(exchange, held, tree, owners, order, view)
    composite_s = time.perf_counter() - start
    rgba = gather_to_root(comm, [(rect, finished)], view.shape, root, sent)
    stats = {"rank": rank, "bricks": len(bricks), "samples": int(samples),
             "render_s": render_s, "composite_s": composite_s, "bytes": sent,
             "messages": log, "peak_rss": _peak_rss()}
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


def _needed(view, lattice, region, tiles, reach):
    """Index box (per axis ``(start, stop)``) of the samples in ``region`` that rays through
    the pixels of any of ``tiles`` (pixel rectangles) can read, or None."""
    axes = [np.arange(a, b) for a, b in region]
    z, y, x = np.meshgrid(*axes, indexing="ij")
    points = np.stack([x, y, z], axis=-1).reshape(-1, 3) * lattice.spacing + lattice.origin
    p = view.project(points)
    if not view.is_perspective:
        rho = np.full(p.shape[0], reach / view.pixel_size)
    else:
        unit = view.pixel_size / view.distance  # pixel width one unit from the eye
        slope = 1.0 + unit * math.hypot(view.height, view.width) / 2.0
        rho = reach * slope / (unit * np.maximum(p[:, 2] - reach, 1e-12))
    rho = rho * (1.0 + 1e-9) + 1e-9
    hit = np.zeros(p.shape[0], dtype=bool)
    for r0, r1, c0, c1 in tiles:
        hit |= ((p[:, 0] + rho >= r0 + 0.5) & (p[:, 0] - rho <= r1 - 0.5) &
                (p[:, 1] + rho >= c0 + 0.5) & (p[:, 1] - rho <= c1 - 0.5))
    if view.is_perspective:
        hit |= ~np.isfinite(p[:, 0]) | (p[:, 2] - reach <= 0.0)
    if not hit.any():
        return None
    index = np.argwhere(hit.reshape(z.shape))
    return [(a + int(lo), a + int(hi) + 1) for a, lo, hi in
            zip([r[0] for r in region], index.min(axis=0), index.max(axis=0), strict=True)]


def render_image(comm, source, view, *, shape=None, extent=None, filter="trilinear",
                 transfer=None, step=0.5, layout="contiguous", tile=16, segment_ends=None,
                 classification="point", root=0):
    """Render ``source`` with an image partition over the ranks of ``comm``.

    The volume stays where it is loaded, one brick per rank (no ghosts); each rank owns
    screen tiles and receives from every rank the box of samples its tiles' rays can read
    (within the filter's reach of a tile), assembles them, and ray-casts its tiles. With
    ``layout="contiguous"`` each rank owns one rectangle; with ``"interleaved"`` square tiles
    of ``tile`` pixels are dealt round-robin
    (:func:`vrlib.parallel.decompose.screen_tiles`), which spreads the work of a scene whose
    content is off-centre, at the price of receiving the samples behind the whole screen.
    Other arguments as :func:`render_object`. Returns a :class:`Frame` whose ranks count the
    voxel traffic under ``bytes["voxels"]``.

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
    transfer_given = transfer is not None
    with Stage(comm, "checking the arguments"):
        filt, transfer, step, _ = _check(view, filter, transfer, step)
        exact, preint = segment_options(segment_ends, classification)
        validate.choice("layout", layout, ("contiguous", "interleaved"))
        root = _root(root, size)
        lattice, read = open_source(source, shape, extent)
        _refuse_default_transfer(source, transfer_given)
        view = view.fitted(lattice.extent)
        tree = split(lattice.cells, size)
        tiles = screen_tiles(view.height, view.width, size, layout=layout, tile=tile)
    ds = step * float(lattice.spacing.min())
    with Stage(comm, "reading its brick"):
        brick = tree.bricks[rank]
        region = [(lo, n if hi == n - 1 else hi)
                  for lo, hi, n in zip(brick.lo, brick.hi, lattice.shape, strict=True)]
        data = read(region)
    value_range = global_value_range(comm, [float(data.min())], [float(data.max())], filt)
    with Stage(comm, "finding the voxels each tile needs"):
        reach = filt.radius * float(np.linalg.norm(lattice.spacing))
        boxes = [_needed(view, lattice, region, tiles.rects(d), reach) for d in range(size)]
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
            buf = np.empty([b - a for a, b in box], dtype=data.dtype)  # one file: one type
            comm.Recv(buf, source=source_rank, tag=11)
        pieces.append((box, buf))
    MPI.Request.Waitall(requests)
    with Stage(comm, "rendering its tiles"):
        start = time.perf_counter()
        mine = tiles.rects(rank)
        samples = 0
        rgba = np.zeros(view.shape + (4,))
        if pieces:
            lo = [min(box[a][0] for box, _ in pieces) for a in range(3)]
            hi = [max(box[a][1] for box, _ in pieces) for a in range(3)]
            # Samples nobody sent are NaN: a ray that read one would show it.
            local = np.full([h - a for a, h in zip(lo, hi, strict=True)], np.nan,
                            dtype=data.dtype)
            for box, buf in pieces:
                local[tuple(slice(a - o, b - o) for (a, b), o in zip(box, lo,
                                                                     strict=True))] = buf
            mask = np.zeros(view.shape, dtype=bool)
            for r0, r1, c0, c1 in mine:
                mask[r0:r1, c0:c1] = True
            skip_grid = np.zeros([-(-c // BLOCK) for c in lattice.cells], dtype=bool)
            rgba, samples = cast_rays(
                local, offset=tuple(lo), global_shape=lattice.shape, origin=lattice.origin,
                spacing=lattice.spacing, box=lattice.box((0, 0, 0), lattice.cells), view=view,
                filt=filt, transfer=transfer, ds=ds, value_range=value_range,
                early_termination=1.0,
                skip=(skip_grid, clearance(skip_grid, through=False), BLOCK, mask),
                exact_ends=exact, preintegrated=preint)
        render_s = time.perf_counter() - start
    rgba = gather_to_root(comm, [(r, rects.pixels(rgba, r)) for r in mine], view.shape, root,
                          sent)
    stats = {"rank": rank, "bricks": 1, "samples": int(samples), "render_s": render_s,
             "composite_s": 0.0, "bytes": sent, "peak_rss": _peak_rss()}
    ranks = comm.gather(stats, root=root)
    if rank != root:
        return Frame(None)
    np.clip(rgba[..., 3], 0.0, 1.0, out=rgba[..., 3])
    image = Image(rgba, RenderStats(samples=sum(r["samples"] for r in ranks), operations=0,
                                    bytes=int(sum(sum(r["bytes"].values()) for r in ranks)),
                                    seconds=max(r["render_s"] for r in ranks)))
    return Frame(image, ranks)
