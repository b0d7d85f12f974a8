"""Splitting the work: bricks of the volume (object partitions) and regions of the screen (image
partitions).

Bricks are boxes of lattice *cells*: a volume of ``n`` samples per axis has ``n - 1`` cells, and
a brick owning cells ``[lo, hi)`` renders the ray samples that fall in its world box. Every
brick comes from a k-d tree (a regular grid is the tree that splits at the grid lines), so a
front-to-back order of the bricks for any view follows from the tree: at each split, the side
facing the viewer first. That order is what compositing needs, and it is the same for every
pixel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vrlib import validate

__all__ = ["Brick", "KdTree", "grid_shape", "split", "ScreenTiles", "screen_tiles",
           "interleaved_owners", "SHAPES"]

#: Which axes (z, y, x order) each object-partition shape may cut.
SHAPES = {"slabs": (0,), "shafts": (1, 2), "blocks": (0, 1, 2)}


@dataclass(frozen=True)
class Brick:
    """Cells ``[lo, hi)`` (z, y, x) of the global lattice, and the brick's place in the
    k-d tree (``index``, in the tree's left-to-right order).

    Examples
    --------
    >>> b = Brick(0, (0, 0, 0), (4, 8, 8))
    >>> b.cells, b.samples(1, (17, 17, 17))
    ((4, 8, 8), ((0, 6), (0, 10), (0, 10)))
    """

    index: int
    lo: tuple
    hi: tuple

    @property
    def cells(self):
        """Cells per axis (z, y, x)."""
        return tuple(h - lo for lo, h in zip(self.lo, self.hi, strict=True))

    def samples(self, ghost, sample_shape):
        """Sample index ranges ``(start, stop)`` per axis (z, y, x) a brick needs: its cells'
        corners plus ``ghost`` samples each side, clipped to the volume."""
        return tuple((max(0, lo - ghost), min(n, h + 1 + ghost))
                     for lo, h, n in zip(self.lo, self.hi, sample_shape, strict=True))

    def world_box(self, origin, spacing):
        """The brick's world box ``(lo, hi)`` as (x, y, z) arrays."""
        lo = np.asarray(origin, float) + np.array(self.lo[::-1]) * np.asarray(spacing, float)
        hi = np.asarray(origin, float) + np.array(self.hi[::-1]) * np.asarray(spacing, float)
        return lo, hi


@dataclass(frozen=True)
class KdTree:
    """A k-d split of a box of cells into bricks.

    ``node`` is a nested tuple: a leaf is a brick index, an inner node
    ``(axis, position, left, right)`` with ``left`` holding the cells below ``position``.

    Examples
    --------
    >>> from vrlib import View
    >>> tree = split((8, 8, 8), 2)                     # cut along z at cell 4
    >>> up = View.orbit(elevation=-60, size=8)         # looking up: low z is nearer
    >>> tree.order(up, origin=(-1, -1, -1), spacing=(0.25, 0.25, 0.25))
    [0, 1]
    """

    bricks: tuple
    node: object

    def __len__(self):
        return len(self.bricks)

    def order(self, view, origin, spacing):
        """Brick indices front to back for ``view`` (valid for every pixel).

        At each split the half nearer the viewer comes first: the half the eye lies in
        (perspective), or the half ``forward`` points away from (orthographic).
        """
        forward = view.forward
        eye = view.eye
        out = []

        def visit(node):
            if not isinstance(node, tuple):
                out.append(node)
                return
            axis, position, left, right = node
            world_axis = 2 - axis
            if not view.is_perspective:
                low_first = forward[world_axis] >= 0.0
            else:
                plane = origin[world_axis] + position * spacing[world_axis]
                low_first = eye[world_axis] < plane
            first, second = (left, right) if low_first else (right, left)
            visit(first)
            visit(second)

        visit(self.node)
        return out

    def leaves(self, node=None):
        """Brick indices under ``node`` (default the whole tree), left to right."""
        node = self.node if node is None else node
        if not isinstance(node, tuple):
            return [node]
        return self.leaves(node[2]) + self.leaves(node[3])


def grid_shape(parts, shape="blocks"):
    """Bricks per axis (z, y, x) that split a cube into ``parts`` slabs, shafts or blocks.

    Slabs cut z only, shafts cut y and x, blocks all three; the factors are as even as the
    count allows.

    Examples
    --------
    >>> grid_shape(64, "slabs"), grid_shape(64, "shafts"), grid_shape(64, "blocks")
    ((64, 1, 1), (1, 8, 8), (4, 4, 4))
    >>> grid_shape(8, "shafts")
    (1, 2, 4)
    """
    parts = validate.positive_int("parts", parts)
    axes = SHAPES[validate.choice("shape", shape, tuple(SHAPES))]
    best = None
    for factors in _factorisations(parts, len(axes)):
        spread = max(factors) / min(factors)
        if best is None or spread < best[0]:
            best = (spread, factors)
    counts = [1, 1, 1]
    for axis, count in zip(axes, sorted(best[1]), strict=True):
        counts[axis] = count
    return tuple(counts)


def _factorisations(n, k):
    if k == 1:
        yield (n,)
        return
    for first in range(1, n + 1):
        if n % first == 0:
            for rest in _factorisations(n // first, k - 1):
                yield (first, *rest)


def split(cells, parts, *, shape="blocks", weights=None, grid=None, groups=None):
    """Split a box of ``cells`` (z, y, x) into ``parts`` bricks by a k-d tree.

    Parameters
    ----------
    cells : (int, int, int)
        Cells per axis of the whole volume (samples - 1).
    parts : int
        Number of bricks.
    shape : {"slabs", "shafts", "blocks"}
        Which axes may be cut.
    weights : ndarray of shape ``cells``, optional
        Work per cell. Each split is placed so that the work on either side is in proportion
        to the bricks it will hold (the work-sized split of :mod:`vrlib.parallel.mpi`);
        default: split the cells themselves evenly.
    grid : (int, int, int), optional
        Cut a regular grid with this many bricks per axis instead (product ``parts``).
    groups : sequence of int, optional
        Factors ``k_1, k_2, ...`` of ``parts`` (radix-k's rounds): the tree is cut so that
        every block of ``k_1``, ``k_1 k_2``, ... consecutive bricks is a subtree, hence
        contiguous in every visibility order.

    Raises
    ------
    ValueError
        More bricks than cells along an axis (each brick needs at least one cell).

    Notes
    -----
    The tree halves the count at every level (``n`` into ``n // 2`` and ``n - n // 2``),
    cutting the longest allowed axis, so that its first ``floor(log2 parts)`` levels form a
    perfect binary tree: what binary-swap compositing needs. With ``groups`` a node of ``c``
    blocks halves the blocks instead (``c // 2`` of them on the left).

    Examples
    --------
    >>> tree = split((8, 8, 8), 4)
    >>> [(b.lo, b.hi) for b in tree.bricks][:2]
    [((0, 0, 0), (4, 4, 8)), ((0, 4, 0), (4, 8, 8))]
    >>> tree.node[:2]                  # the first cut: z at cell 4
    (0, 4)
    >>> six = split((8, 8, 8), 6, groups=[2, 3])     # pairs {0, 1}, {2, 3}, {4, 5}
    >>> six.leaves(six.node[2]), six.leaves(six.node[3][2]), six.leaves(six.node[3][3])
    ([0, 1], [2, 3], [4, 5])
    """
    cells = tuple(validate.positive_int("cells", c) for c in cells)
    parts = validate.positive_int("parts", parts)
    axes = SHAPES[validate.choice("shape", shape, tuple(SHAPES))]
    if weights is not None:
        weights = np.asarray(weights, dtype=np.float64)
        if weights.shape != cells:
            raise ValueError(f"weights must have shape {cells} (one per cell), got "
                             f"{weights.shape}")
        if not np.all(np.isfinite(weights)) or np.any(weights < 0):
            raise ValueError("weights must be finite and non-negative")
    if grid is not None:
        if math.prod(grid) != parts:
            raise ValueError(f"grid {tuple(grid)} holds {math.prod(grid)} bricks, not {parts}")
        axes = (0, 1, 2)
    if grid is not None and any(g > c for g, c in zip(grid, cells, strict=True)):
        raise ValueError(f"cannot cut {cells} cells into a {tuple(grid)} grid of {shape}: at "
                         "most one brick per cell along each axis; use fewer parts or a larger "
                         "volume")
    capacity = math.prod(cells[a] for a in axes) if grid is None else parts
    if parts > capacity:
        raise ValueError(
            f"cannot split {cells} cells into {parts} {shape} (at most {capacity}): use "
            "fewer parts or a larger volume"
        )
    blocks = None
    if groups is not None:
        groups = [validate.positive_int("groups", g) for g in groups]
        if math.prod(groups) != parts:
            raise ValueError(f"groups {tuple(groups)} multiply to {math.prod(groups)}, not "
                             f"the {parts} parts")
        blocks = [math.prod(groups[:i]) for i in range(len(groups))]
    bricks = []

    def left_count(n):
        if blocks is None:
            return n // 2
        # The largest block size under n that n is made of: halve the blocks.
        block = max(b for b in blocks if b < n and n % b == 0)
        return n // block // 2 * block

    def build(lo, hi, n, counts):
        if n == 1:
            bricks.append(Brick(len(bricks), tuple(lo), tuple(hi)))
            return len(bricks) - 1
        if counts is not None:
            axis = max(range(3), key=lambda a: (counts[a], -a))
            half = counts[axis] // 2
            left_n = n // counts[axis] * half
            position = lo[axis] + round((hi[axis] - lo[axis]) * half / counts[axis])
            sub_left, sub_right = list(counts), list(counts)
            sub_left[axis], sub_right[axis] = half, counts[axis] - half
        else:
            open_axes = [a for a in axes if hi[a] - lo[a] > 1]
            axis = max(open_axes, key=lambda a: (hi[a] - lo[a], -a))
            left_n = left_count(n)
            # Each side keeps enough cells for its bricks.
            across = math.prod(hi[a] - lo[a] for a in axes if a != axis)
            least = (-(-left_n // across), -(-(n - left_n) // across))
            if sum(least) > hi[axis] - lo[axis]:
                box = tuple(h - low for low, h in zip(lo, hi, strict=True))
                raise ValueError(f"cannot split {cells} cells into {parts} {shape}: a box of "
                                 f"{box} cells cannot hold {left_n} + {n - left_n} bricks of "
                                 "whole cells; use fewer parts or a larger volume")
            position = _cut(lo, hi, axis, left_n / n, weights, least)
            sub_left = sub_right = None
        left_hi, right_lo = list(hi), list(lo)
        left_hi[axis] = right_lo[axis] = position
        left = build(lo, left_hi, left_n, sub_left)
        right = build(right_lo, hi, n - left_n, sub_right)
        return (axis, position, left, right)

    node = build([0, 0, 0], list(cells), parts, None if grid is None else list(grid))
    return KdTree(tuple(bricks), node)


def _cut(lo, hi, axis, fraction, weights, least=(1, 1)):
    """Cell position along ``axis`` that leaves ``fraction`` of the work (or of the cells)
    below it, keeping at least ``least`` cells below and above."""
    first, last = lo[axis] + max(least[0], 1), hi[axis] - max(least[1], 1)
    if weights is None:
        return min(max(lo[axis] + round((hi[axis] - lo[axis]) * fraction), first), last)
    box = weights[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    other = tuple(a for a in range(3) if a != axis)
    profile = box.sum(axis=other)
    total = profile.sum()
    if total <= 0.0:
        return min(max(lo[axis] + round((hi[axis] - lo[axis]) * fraction), first), last)
    cumulative = np.concatenate([[0.0], np.cumsum(profile)])
    # The cut whose work below is nearest the target share.
    position = lo[axis] + int(np.argmin(np.abs(cumulative - fraction * total)))
    return min(max(position, first), last)


def interleaved_owners(bricks, ranks):
    """Owner of each of ``bricks`` bricks dealt round-robin to ``ranks`` ranks (``k`` bricks
    each when ``bricks = k * ranks``).

    Examples
    --------
    >>> interleaved_owners(8, 4).tolist()
    [0, 1, 2, 3, 0, 1, 2, 3]
    """
    bricks = validate.positive_int("bricks", bricks)
    ranks = validate.positive_int("ranks", ranks)
    if ranks > bricks:
        raise ValueError(f"{ranks} ranks for {bricks} bricks: every rank needs at least one "
                         "brick (use at most as many ranks as bricks)")
    return np.arange(bricks) % ranks


@dataclass(frozen=True)
class ScreenTiles:
    """A screen cut into a grid of rectangular tiles, each owned by one node.

    ``rows`` and ``cols`` are the tile boundaries (pixel indices, first 0, last the image
    size); ``owner[i, j]`` the node owning tile ``(i, j)``.

    Examples
    --------
    >>> tiles = screen_tiles(8, 8, 2)
    >>> tiles.rects(1), tiles.nodes
    ([(0, 8, 4, 8)], 2)
    """

    rows: np.ndarray
    cols: np.ndarray
    owner: np.ndarray

    @property
    def nodes(self):
        """Number of nodes the tiles are dealt to."""
        return int(self.owner.max()) + 1

    def rects(self, node):
        """Pixel rectangles ``(r0, r1, c0, c1)`` owned by ``node``."""
        return [(int(self.rows[i]), int(self.rows[i + 1]), int(self.cols[j]),
                 int(self.cols[j + 1])) for i, j in np.argwhere(self.owner == node)]


def screen_tiles(height, width, nodes, *, layout="contiguous", tile=16):
    """Deal a ``height x width`` screen to ``nodes`` nodes.

    ``"contiguous"``: one rectangle per node, in a grid as square as the count allows (rows
    of tiles top to bottom, row-major owners). ``"interleaved"``: square tiles of ``tile``
    pixels dealt round-robin in row order (each row shifted by one when it holds a multiple of
    the node count), so each node's tiles are spread over the whole screen.

    Examples
    --------
    >>> t = screen_tiles(8, 8, 4)
    >>> t.rows.tolist(), t.cols.tolist(), t.owner.tolist()
    ([0, 4, 8], [0, 4, 8], [[0, 1], [2, 3]])
    >>> screen_tiles(8, 8, 2, layout="interleaved", tile=4).owner.tolist()
    [[0, 1], [1, 0]]
    """
    height = validate.positive_int("height", height)
    width = validate.positive_int("width", width)
    nodes = validate.positive_int("nodes", nodes)
    layout = validate.choice("layout", layout, ("contiguous", "interleaved"))
    if layout == "contiguous":
        if nodes > height * width:
            raise ValueError(f"{nodes} nodes for a {height} x {width} screen: at most one "
                             "node per pixel")
        ty = max(f for f in range(1, nodes + 1) if nodes % f == 0 and f * f <= nodes)
        tx = nodes // ty
        if tx > width or ty > height:
            ty, tx = min(nodes, height), 1
            if nodes > height:
                raise ValueError(f"{nodes} nodes cannot tile a {height} x {width} screen")
        rows = np.round(np.linspace(0, height, ty + 1)).astype(int)
        cols = np.round(np.linspace(0, width, tx + 1)).astype(int)
        owner = np.arange(ty * tx).reshape(ty, tx)
    else:
        tile = validate.positive_int("tile", tile)
        rows = np.unique(np.minimum(np.arange(0, height + tile, tile), height))
        cols = np.unique(np.minimum(np.arange(0, width + tile, tile), width))
        i, j = np.meshgrid(np.arange(len(rows) - 1), np.arange(len(cols) - 1), indexing="ij")
        # Round-robin in row order; when a row holds a multiple of the node count, each row
        # shifts by one, so that no node's tiles line up in columns.
        columns = len(cols) - 1
        owner = (i * columns + j + (i if columns % nodes == 0 else 0)) % nodes
        if len(np.unique(owner)) < nodes:
            raise ValueError(f"{nodes} nodes for {owner.size} tiles of {tile} pixels: use "
                             "smaller tiles or fewer nodes")
    return ScreenTiles(rows, cols, owner)
