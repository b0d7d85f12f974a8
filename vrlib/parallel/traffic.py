"""The messages of one frame, sized from a real partition and a real view.

Each function returns :class:`Messages` (source node, destination node, bytes), ready to be
routed on a :class:`~vrlib.parallel.network.Network`. Object partitions send image fragments:
a brick's local image is the pixels whose centres fall in the bounding rectangle of its
projected box (:func:`footprint_rect`, what a renderer that tracks its footprint would send),
and each compositor of :data:`vrlib.parallel.composite.COMPOSITORS` sizes its own frame from
them. Image partitions send voxels (here): a voxel goes to every screen tile whose rays can
read it, that is every tile within the filter's reach of its projection.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vrlib.parallel.rects import area

__all__ = ["Messages", "sum_messages", "footprint_rect", "gather", "image_static",
           "image_dynamic", "migration"]

#: Most voxels projected when counting an image partition's traffic; larger volumes are
#: counted on a sub-lattice whose every voxel stands for ``stride^3`` of them.
MAX_PROJECTED = 1 << 24


@dataclass(frozen=True)
class Messages:
    """One frame's messages; messages from a node to itself are dropped (they use no
    channel) and repeated pairs are merged.

    Examples
    --------
    >>> m = Messages.merged([0, 0, 1, 2], [1, 1, 1, 0], [3.0, 4.0, 9.0, 2.0], nodes=3)
    >>> m.src.tolist(), m.dst.tolist(), m.bytes.tolist(), m.sent_per_node(3).tolist()
    ([0, 2], [1, 0], [7.0, 2.0], [7.0, 0.0, 2.0])
    """

    src: np.ndarray
    dst: np.ndarray
    bytes: np.ndarray

    @classmethod
    def merged(cls, src, dst, size, nodes):
        src = np.asarray(src, dtype=np.int64).ravel()
        dst = np.asarray(dst, dtype=np.int64).ravel()
        size = np.asarray(size, dtype=np.float64).ravel()
        keep = (src != dst) & (size > 0)
        key, where = np.unique(src[keep] * nodes + dst[keep], return_inverse=True)
        total = np.bincount(where, size[keep], minlength=key.size)
        return cls(key // nodes, key % nodes, total)

    def __add__(self, other):
        return Messages(np.concatenate([self.src, other.src]),
                        np.concatenate([self.dst, other.dst]),
                        np.concatenate([self.bytes, other.bytes]))

    @property
    def total(self):
        """Bytes sent over the network in the frame."""
        return float(self.bytes.sum())

    def sent_per_node(self, nodes):
        """Bytes each node sends."""
        return np.bincount(self.src, self.bytes, minlength=nodes).astype(np.float64)


def sum_messages(rounds, nodes):
    """Several rounds' messages as one frame's (repeated pairs merged).

    Examples
    --------
    >>> a = Messages.merged([0], [1], [3.0], nodes=2)
    >>> sum_messages([a, a], 2).bytes.tolist()
    [6.0]
    """
    rounds = list(rounds)
    if not rounds:
        return Messages.merged([], [], [], nodes)
    return Messages.merged(np.concatenate([m.src for m in rounds]),
                           np.concatenate([m.dst for m in rounds]),
                           np.concatenate([m.bytes for m in rounds]), nodes)


def footprint_rect(view, lo, hi):
    """Pixels ``(r0, r1, c0, c1)`` whose centres lie in the bounding rectangle of the
    projected world box ``[lo, hi]`` (x, y, z), clipped to the image; empty when it misses.

    Examples
    --------
    >>> from vrlib import View
    >>> footprint_rect(View([0, 0, -1], up=[0, 1, 0], size=8, radius=1.0), [-1, -1, -1],
    ...                [0, 0, 1])
    (4, 8, 0, 4)
    """
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])], dtype=np.float64)
    p = view.project(corners)
    if not np.all(np.isfinite(p[:, :2])):
        return (0, view.height, 0, view.width)  # reaches behind the eye: the whole screen
    r0 = min(max(math.ceil(p[:, 0].min() - 0.5), 0), view.height)
    r1 = min(max(math.floor(p[:, 0].max() - 0.5) + 1, 0), view.height)
    c0 = min(max(math.ceil(p[:, 1].min() - 0.5), 0), view.width)
    c1 = min(max(math.floor(p[:, 1].max() - 0.5) + 1, 0), view.width)
    if r1 <= r0 or c1 <= c0:
        return (0, 0, 0, 0)
    return (r0, r1, c0, c1)


def gather(tiles_or_regions, nodes, *, root=0, bytes_per_pixel=4):
    """Every node's finished pixels to ``root`` (the display): ``tiles_or_regions`` is a
    :class:`~vrlib.parallel.decompose.ScreenTiles` or a list of ``(node, rect)``.

    Examples
    --------
    >>> from vrlib.parallel.decompose import screen_tiles
    >>> gather(screen_tiles(8, 8, 4), 4, bytes_per_pixel=1).sent_per_node(4).tolist()
    [0.0, 16.0, 16.0, 16.0]
    """
    if hasattr(tiles_or_regions, "owner"):
        t = tiles_or_regions
        h = np.diff(t.rows)[:, None] * np.diff(t.cols)[None, :]
        pixels = np.bincount(t.owner.ravel(), h.ravel().astype(float), minlength=nodes)
        src = np.arange(nodes)
    else:
        src = np.array([n for n, _ in tiles_or_regions])
        pixels = np.array([area(r) for _, r in tiles_or_regions], dtype=float)
    return Messages.merged(src, np.full(len(src), root), pixels * bytes_per_pixel, nodes)


def _sub_lattice(sample_shape):
    """Stride so that at most :data:`MAX_PROJECTED` voxels are projected."""
    count = math.prod(sample_shape)
    return max(1, math.ceil((count / MAX_PROJECTED) ** (1.0 / 3.0)))


def _owned_samples(brick, sample_shape, stride):
    """Global sample indices (per axis) a brick owns: its cells' lower corners, plus the
    volume's last sample on its upper faces."""
    axes = []
    for lo, hi, n in zip(brick.lo, brick.hi, sample_shape, strict=True):
        stop = n if hi == n - 1 else hi
        first = -(-lo // stride) * stride
        axes.append(np.arange(first, stop, stride))
    return axes


def _project_samples(view, axes, origin, spacing):
    """Image coordinates and depths of the lattice points ``axes`` (z, y, x index arrays)."""
    z, y, x = np.meshgrid(*axes, indexing="ij")
    points = np.stack([x, y, z], axis=-1).reshape(-1, 3) * np.asarray(spacing) + origin
    return view.project(points)


def _reach_pixels(view, depth, reach):
    """Filter reach ``reach`` (world units) in pixels at each ``depth``."""
    if not view.is_perspective:
        return np.full(depth.shape, reach / view.pixel_size)
    return reach * view.distance / (view.pixel_size * np.maximum(depth, 1e-12))


def _tile_range(bounds, x, rho):
    """First and last tile (by ``bounds``) with a pixel centre within ``rho`` of ``x``; the
    first exceeds the last when there is none."""
    first = np.maximum(np.searchsorted(bounds, x - rho + 0.5, side="left") - 1, 0)
    last = np.minimum(np.searchsorted(bounds, x + rho - 0.5, side="right") - 1,
                      len(bounds) - 2)
    return first, last


def image_static(tree, owners, tiles, view, sample_shape, origin, spacing, *, radius=1.0,
                 bytes_per_voxel=1):
    """Image partition, data fixed in bricks: each tile owner receives every voxel its rays
    can read (within ``radius`` samples of a point on one of its rays) from the bricks'
    owners.

    Voxels are counted by projecting them; volumes of more than :data:`MAX_PROJECTED` samples
    are counted on a regular sub-lattice, each sample standing for ``stride^3``.

    Examples
    --------
    >>> from vrlib import View
    >>> from vrlib.parallel.decompose import screen_tiles, split
    >>> view = View([0, 0, -1], up=[0, 1, 0], size=8, radius=1.0)
    >>> tree = split((4, 4, 4), 2, shape="shafts")          # lower and upper halves in y
    >>> msgs = image_static(tree, [0, 1], screen_tiles(8, 8, 2), view, (5, 5, 5),
    ...                     (-1, -1, -1), (0.5, 0.5, 0.5), radius=0.1)
    >>> msgs.sent_per_node(2).tolist()      # voxels each brick sends the other's tile
    [5.0, 10.0]
    """
    stride = _sub_lattice(sample_shape)
    reach = radius * float(np.linalg.norm(spacing))
    nodes = max(int(np.max(owners)) + 1, tiles.nodes)
    src, dst, size = [], [], []
    for brick in tree.bricks:
        axes = _owned_samples(brick, sample_shape, stride)
        if any(a.size == 0 for a in axes):
            continue
        p = _project_samples(view, axes, origin, spacing)
        rho = _reach_pixels(view, p[:, 2], reach)
        # Tiles with a pixel centre within the reach: first tile i whose last centre
        # rows[i + 1] - 0.5 >= r - rho, last tile whose first centre rows[i] + 0.5 <= r + rho.
        i0, i1 = _tile_range(tiles.rows, p[:, 0], rho)
        j0, j1 = _tile_range(tiles.cols, p[:, 1], rho)
        seen = (i0 <= i1) & (j0 <= j1)
        voxel = np.arange(p.shape[0])
        keys = []
        for di in range(int((i1 - i0).max(initial=0)) + 1):
            for dj in range(int((j1 - j0).max(initial=0)) + 1):
                hit = seen & (i0 + di <= i1) & (j0 + dj <= j1)
                who = tiles.owner[(i0 + di)[hit], (j0 + dj)[hit]]
                keys.append(voxel[hit] * nodes + who)
        # A voxel that two tiles of one node need travels once.
        who = np.unique(np.concatenate(keys)) % nodes
        src.append(np.full(nodes, owners[brick.index]))
        dst.append(np.arange(nodes))
        size.append(np.bincount(who, minlength=nodes) * float(stride**3 * bytes_per_voxel))
    return Messages.merged(np.concatenate(src), np.concatenate(dst), np.concatenate(size),
                           nodes)


def image_dynamic(tiles, before, after, sample_shape, origin, spacing, *, bytes_per_voxel=1):
    """Image partition, data migrating with the view: each voxel lives on the owner of the
    tile its centre projects into (off-screen voxels: the nearest edge tile), and moves when
    the view changes from ``before`` to ``after``. (Filter borders are left out: the voxels
    near a tile's edge that both nodes need.)

    Examples
    --------
    >>> from vrlib import View
    >>> from vrlib.parallel.decompose import screen_tiles
    >>> a, b = View.orbit(azimuth=0, size=8), View.orbit(azimuth=180, size=8)
    >>> image_dynamic(screen_tiles(8, 8, 2), a, b, (5, 5, 5), (-1, -1, -1),
    ...               (0.5, 0.5, 0.5)).total       # a half turn swaps left and right
    105.0
    """
    stride = _sub_lattice(sample_shape)
    nodes = tiles.nodes
    src, dst, size = [], [], []
    for z0 in range(0, sample_shape[0], 16 * stride):
        axes = [np.arange(z0, min(z0 + 16 * stride, sample_shape[0]), stride),
                np.arange(0, sample_shape[1], stride), np.arange(0, sample_shape[2], stride)]
        owner = []
        for view in (before, after):
            p = _project_samples(view, axes, origin, spacing)
            i = np.clip(np.searchsorted(tiles.rows, p[:, 0], side="right") - 1, 0,
                        len(tiles.rows) - 2)
            j = np.clip(np.searchsorted(tiles.cols, p[:, 1], side="right") - 1, 0,
                        len(tiles.cols) - 2)
            owner.append(tiles.owner[i, j])
        src.append(owner[0])
        dst.append(owner[1])
        size.append(np.full(owner[0].size, float(stride**3 * bytes_per_voxel)))
    return Messages.merged(np.concatenate(src), np.concatenate(dst), np.concatenate(size),
                           nodes)


def migration(before, before_owners, after, after_owners, *, bytes_per_cell=1.0):
    """An object partition re-cut between frames: every cell whose brick changes owner moves,
    from the owner of the brick that held it to the owner of the brick that holds it now.
    ``before`` and ``after`` are lists of :class:`~vrlib.parallel.decompose.Brick` tiling the
    same box of cells (counted cell by cell, so the box should be at most a few ten million
    cells: a coarse lattice whose cells stand for many samples, ``bytes_per_cell`` each).

    Examples
    --------
    >>> from vrlib.parallel.decompose import split
    >>> a, b = split((8, 8, 8), 2), split((8, 8, 8), 2, weights=np.ones((8, 8, 8)) *
    ...                                  (np.arange(8) < 2)[:, None, None] + 0.01)
    >>> [x.hi[0] for x in a.bricks], [x.hi[0] for x in b.bricks]   # the cut moves 4 -> 1
    ([4, 8], [1, 8])
    >>> migration(a.bricks, [0, 1], b.bricks, [0, 1]).bytes.tolist()  # 3 slices of 64 cells
    [192.0]
    """
    cells = tuple(max(b.hi[a] for b in before) for a in range(3))
    owners = []
    for bricks, owner in ((before, before_owners), (after, after_owners)):
        label = np.empty(cells, dtype=np.int64)
        for brick, node in zip(bricks, owner, strict=True):
            label[brick.lo[0]:brick.hi[0], brick.lo[1]:brick.hi[1],
                  brick.lo[2]:brick.hi[2]] = node
        owners.append(label)
    nodes = int(max(np.max(before_owners), np.max(after_owners))) + 1
    moved = owners[0] != owners[1]
    pairs = np.bincount(owners[0][moved] * nodes + owners[1][moved], minlength=nodes * nodes)
    key = np.flatnonzero(pairs)
    return Messages(key // nodes, key % nodes, pairs[key] * float(bytes_per_cell))
