"""The taxonomy of parallel volume-rendering partitions (thesis chapter 1, claim 4), as data.

A partition divides either the *image* (each node renders the rays of its screen regions and
needs the voxels behind them) or the *object* (each node renders its part of the volume and
sends image fragments to be composited). Object partitions cut the volume into slabs (one
axis), shafts (two) or blocks (three); image partitions cut the screen into tiles. Either kind
is contiguous (one region per node) or interleaved (many small regions dealt round-robin), and
static (the assignment is fixed) or dynamic (it follows the view or a work queue).
"""

from __future__ import annotations

from dataclasses import dataclass

from vrlib import validate

__all__ = ["Partition", "TAXONOMY", "communication"]

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
