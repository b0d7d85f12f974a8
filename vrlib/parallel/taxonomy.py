"""The taxonomy of parallel volume-rendering partitions (thesis chapter 1, claim 4), as data.

A partition divides either the *image* (each node renders the rays of its screen regions and
needs the voxels behind them) or the *object* (each node renders its part of the volume and
sends image fragments to be composited). Object partitions cut the volume into slabs (one
axis), shafts (two) or blocks (three); image partitions cut the screen into tiles. Either kind
is contiguous (one region per node) or interleaved (many small regions dealt round-robin), and
static (the assignment is fixed) or dynamic (it follows the view or a work queue).

:func:`frame` builds one simulated frame's messages for every class, so that each row of the
taxonomy is counted, not only derived.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vrlib import validate

__all__ = ["Partition", "TAXONOMY", "communication", "frame"]

SPACES = ("image", "object")
LAYOUTS = ("contiguous", "interleaved")
SCHEDULES = ("static", "dynamic")


@dataclass(frozen=True)
class Partition:
    """One class of the taxonomy.

    Parameters
    ----------
    space : {"image", "object"}
    shape : {"tiles"} for image partitions; {"slabs", "shafts", "blocks"} for object ones
    layout : {"contiguous", "interleaved"}
    schedule : {"static", "dynamic"}

    Examples
    --------
    >>> Partition("object", "blocks").name
    'object / blocks / contiguous / static'
    >>> Partition("image", "slabs")
    Traceback (most recent call last):
    ...
    ValueError: shape must be one of 'tiles' for image partitions, got 'slabs'
    """

    space: str
    shape: str
    layout: str = "contiguous"
    schedule: str = "static"

    def __post_init__(self):
        validate.choice("space", self.space, SPACES)
        shapes = ("tiles",) if self.space == "image" else ("slabs", "shafts", "blocks")
        if self.shape not in shapes:
            allowed = ", ".join(repr(s) for s in shapes)
            raise ValueError(f"shape must be one of {allowed} for {self.space} partitions, "
                             f"got {self.shape!r}")
        validate.choice("layout", self.layout, LAYOUTS)
        validate.choice("schedule", self.schedule, SCHEDULES)

    @property
    def name(self):
        """The class as ``space / shape / layout / schedule``."""
        return f"{self.space} / {self.shape} / {self.layout} / {self.schedule}"


def communication(partition):
    """What one frame sends for a class, and how it grows (``W^2`` image, ``N^3`` voxels,
    ``P`` nodes, ``k`` regions per node, ``dtheta`` the turn per frame); the exact counts are
    :mod:`vrlib.parallel.model` and :mod:`vrlib.parallel.traffic`.

    Examples
    --------
    >>> communication(Partition("object", "blocks"))[1]
    'local image 1.5 W^2 / P^(2/3) per node, 1.5 W^2 P^(1/3) in total'
    """
    p = partition
    if p.space == "image":
        if p.schedule == "static":
            what = "voxels behind each tile, from the bricks that hold them"
            grows = "N^3 in total (nearly all remote), times (1 + 2r/t)^2 for filter borders"
            if p.layout == "interleaved":
                grows = "up to N^3 per node: every node's tiles see the whole volume"
        else:
            what = "voxels whose projection moves into another node's tile"
            grows = "N^3 dtheta (L/D) / (4 sqrt(P)) per node for square tiles"
            if p.layout == "interleaved":
                grows = "N^3 dtheta / (4 t) per node for tiles of t pixels: interleaving " \
                        "multiplies it by sqrt(P) W / t"
        return what, grows
    local = {"slabs": "W^2 / 2", "shafts": "W^2 / sqrt(P)", "blocks": "1.5 W^2 / P^(2/3)"}
    total = {"slabs": "P W^2 / 2", "shafts": "W^2 sqrt(P)", "blocks": "1.5 W^2 P^(1/3)"}
    what = "image fragments of each brick, to the nodes compositing their screen regions"
    grows = f"local image {local[p.shape]} per node, {total[p.shape]} in total"
    if p.layout == "interleaved":
        grows += "; k bricks per node multiply blocks' total by k^(1/3)"
    if p.schedule == "dynamic":
        grows += "; plus the bricks handed to another node when the work is re-balanced"
    return what, grows


#: Every class of the taxonomy (image tiles x 2 x 2, object shapes x 2 x 2).
TAXONOMY = tuple(
    Partition(space, shape, layout, schedule)
    for space, shapes in (("image", ("tiles",)), ("object", ("slabs", "shafts", "blocks")))
    for shape in shapes
    for layout in LAYOUTS
    for schedule in SCHEDULES
)


def frame(partition, nodes, samples, view, *, after=None, work=None, interleave=8,
          tiles_per_node=4, radius=2.0, pixel_bytes=4, voxel_bytes=1):
    """One simulated frame's messages for a class of the taxonomy: ``nodes`` nodes render a
    cube of ``samples^3`` samples over [-1, 1]^3 seen by ``view``.

    * object, static: bricks (a regular grid of slabs, shafts or blocks; ``interleave``
      bricks per node dealt round-robin when interleaved) composited by direct send onto
      contiguous screen tiles;
    * object, dynamic: the k-d tree is re-cut every frame to follow the work, ``work`` =
      ``(before, after)``, two maps of work per cell on a coarse lattice (a scene that moves):
      the frame composites the new bricks and moves every cell whose owner changed
      (:func:`~vrlib.parallel.traffic.migration`, counted on the coarse lattice, each of its
      cells standing for the samples it covers);
    * image, static: tiles (contiguous, or ``tiles_per_node`` square tiles per node dealt
      round-robin) receive every voxel their rays can read within ``radius`` samples from the
      bricks that hold them (:func:`~vrlib.parallel.traffic.image_static`);
    * image, dynamic: voxels live with the tile they project into and move when the view
      turns from ``view`` to ``after`` (:func:`~vrlib.parallel.traffic.image_dynamic`).

    Examples
    --------
    >>> from vrlib import View
    >>> view = View.orbit(azimuth=30, elevation=20, size=64)
    >>> static = frame(Partition("object", "blocks"), 8, 33, view)
    >>> interleaved = frame(Partition("object", "blocks", "interleaved"), 8, 33, view)
    >>> bool(interleaved.total > static.total)          # more, smaller bricks to composite
    True
    """
    from vrlib.parallel import decompose, traffic
    from vrlib.parallel.composite import COMPOSITORS

    p = partition
    nodes = validate.positive_int("nodes", nodes)
    cells = (samples - 1,) * 3
    origin, spacing = np.array([-1.0, -1.0, -1.0]), np.full(3, 2.0 / (samples - 1))
    width = view.width
    if p.space == "image":
        if p.layout == "contiguous":
            tiles = decompose.screen_tiles(view.height, width, nodes)
        else:
            tile = max(1, int(width / math.sqrt(tiles_per_node * nodes)))
            tiles = decompose.screen_tiles(view.height, width, nodes, layout="interleaved",
                                           tile=tile)
        if p.schedule == "static":
            tree = decompose.split(cells, nodes)
            return traffic.image_static(tree, np.arange(nodes), tiles, view, (samples,) * 3,
                                        origin, spacing, radius=radius,
                                        bytes_per_voxel=voxel_bytes)
        if after is None:
            raise ValueError("a dynamic image partition needs the next frame's view (after)")
        return traffic.image_dynamic(tiles, view, after, (samples,) * 3, origin, spacing,
                                     bytes_per_voxel=voxel_bytes)
    parts = nodes * (interleave if p.layout == "interleaved" else 1)
    owners = decompose.interleaved_owners(parts, nodes)
    tiles = decompose.screen_tiles(view.height, width, nodes)
    direct = COMPOSITORS["direct-send"]
    if p.schedule == "static":
        tree = decompose.split(cells, parts, shape=p.shape,
                               grid=decompose.grid_shape(parts, p.shape))
        return direct.messages(tree, owners, tiles, view, origin, spacing,
                               bytes_per_pixel=pixel_bytes)
    if work is None:
        raise ValueError("a dynamic object partition needs two work maps (work=(before, "
                         "after))")
    coarse = [decompose.split(np.shape(w), parts, shape=p.shape, weights=w) for w in work]
    per_cell = math.prod(cells) / math.prod(np.shape(work[0])) * voxel_bytes
    moved = traffic.migration(coarse[0].bricks, owners, coarse[1].bricks, owners,
                              bytes_per_cell=per_cell)
    return direct.messages(_scaled(coarse[1], cells), owners, tiles, view, origin, spacing,
                           bytes_per_pixel=pixel_bytes) + moved


def _scaled(tree, cells):
    """A k-d tree cut on a coarse lattice, its bricks scaled to ``cells``."""
    from vrlib.parallel.decompose import Brick, KdTree

    coarse = np.array([max(b.hi[a] for b in tree.bricks) for a in range(3)])

    def scale(index):
        return tuple(int(round(i * c / g)) for i, c, g in zip(index, cells, coarse,
                                                               strict=True))

    return KdTree(tuple(Brick(b.index, scale(b.lo), scale(b.hi)) for b in tree.bricks), None)
