"""The analytic model of a frame's communication (docs/derivations.md, derived there; tested here
against :mod:`vrlib.parallel.traffic` routed on :mod:`vrlib.parallel.network`).

Notation: a cube volume of side ``L`` world units with ``N^3`` samples, a ``W x W`` image of
``pixel`` world units per pixel, ``P`` nodes on an ``X x Y`` mesh or torus. A channel is one
direction of one link.
"""

from __future__ import annotations

import math

import numpy as np

from vrlib import validate
from vrlib.parallel.network import mesh_shape

__all__ = ["projected_area", "box_rect_area", "object_frame", "binary_swap_frame",
           "image_static_frame", "image_dynamic_frame", "channel_loads", "mean_hops"]


def projected_area(sides, direction=None):
    """Projected area of a box with ``sides`` (x, y, z): for a unit ``direction``
    ``|d_x| s_y s_z + |d_y| s_x s_z + |d_z| s_x s_y``; without one, the mean over all
    directions, a quarter of the surface area (Cauchy).

    Examples
    --------
    >>> projected_area((2, 2, 2)), projected_area((2, 2, 2), (0, 0, 1))
    (6.0, 4.0)
    """
    sx, sy, sz = (float(s) for s in sides)
    if direction is None:
        return 0.5 * (sx * sy + sy * sz + sx * sz)
    dx, dy, dz = np.abs(np.asarray(direction, float))
    return float(dx * sy * sz + dy * sx * sz + dz * sx * sy)


def box_rect_area(sides, right, up):
    """Area of the bounding rectangle of a box's orthographic projection onto the image axes
    ``right`` and ``up`` (what a renderer that sends bounding rectangles sends).

    Examples
    --------
    >>> r, u = [0.6, 0.8, 0.0], [0.0, 0.0, 1.0]
    >>> round(box_rect_area((1, 1, 1), r, u), 6)        # (0.6 + 0.8) x 1
    1.4
    """
    s = np.asarray(sides, float)
    return float((s @ np.abs(right)) * (s @ np.abs(up)))


def _brick_sides(side, grid):
    """Sides (x, y, z) of one brick of a cube of ``side`` cut into ``grid`` (z, y, x)."""
    return (side / grid[2], side / grid[1], side / grid[0])


def object_frame(grid, *, side, pixel, bytes_per_pixel=4, view=None):
    """Direct-send bytes per node and in total for an object partition into ``grid`` (z, y, x)
    bricks, one per node.

    Each node sends its local image, less the share that falls on its own tile (``1/P``).
    The local image is the mean projected area (``view`` None: Cauchy, the derived slab
    ``W^2 / 2``, shaft ``W^2 / sqrt(P)``, block ``1.5 W^2 / P^(2/3)`` when the image spans
    the volume), or the bounding rectangle of the box's projection for ``view``.

    Returns
    -------
    (per_node, total) : (float, float)
        Bytes.

    Examples
    --------
    >>> per_node, total = object_frame((4, 4, 4), side=2.0, pixel=2.0 / 512)
    >>> round(per_node / 4 / 512**2, 4)     # 1.5 / 64^(2/3) x (1 - 1/64) of the image
    0.0923
    """
    nodes = math.prod(grid)
    sides = _brick_sides(side, grid)
    if view is None:
        area = projected_area(sides)
    else:
        area = box_rect_area(sides, view.right, view.up)
    per_node = area / pixel**2 * bytes_per_pixel * (1.0 - 1.0 / nodes)
    return per_node, per_node * nodes


def binary_swap_frame(nodes, width, height, *, bytes_per_pixel=4):
    """Binary swap with full-screen images: ``W H (1 - 1/P)`` bytes per node.

    Examples
    --------
    >>> binary_swap_frame(4, 512, 512)[0] / (4 * 512 * 512)
    0.75
    """
    per_node = width * height * bytes_per_pixel * (1.0 - 1.0 / nodes)
    return per_node, per_node * nodes


def image_static_frame(nodes, samples, *, tile, reach=0.0, bytes_per_voxel=1):
    """An image partition with the data fixed in bricks: nearly every voxel a tile needs is on
    another node. A tile of ``tile`` pixels a side needs the voxels behind it and behind a
    border of ``reach`` pixels (the filter's reach), ``(1 + 2 reach / tile)^2`` of its share.

    Returns bytes ``(per_node, total)``.

    Examples
    --------
    >>> round(image_static_frame(64, 256**3, tile=64, reach=2)[1] / 256**3, 6)  # 1.0625^2 x 63/64
    1.111267
    """
    border = (1.0 + 2.0 * reach / tile) ** 2
    total = samples * border * (1.0 - 1.0 / nodes) * bytes_per_voxel
    return total / nodes, total


def image_dynamic_frame(nodes, samples, *, dtheta, depth, tile_width, pixel,
                        bytes_per_voxel=1):
    """An image partition whose data migrates with the view: a turn of ``dtheta`` radians
    about the image's vertical axis shifts a voxel at depth offset ``z`` by ``z dtheta``; with
    ``z`` uniform over a volume ``depth`` deep, the mean shift is ``depth dtheta / 4``, and a
    voxel changes tile with probability shift / ``tile_width`` (pixels). With the image
    spanning the volume (``tile_width = W / sqrt(P)``) this is the derived
    ``N^3 dtheta / (4 sqrt(P))`` per node.

    Returns bytes ``(per_node, total)``.

    Examples
    --------
    >>> import math
    >>> per_node, _ = image_dynamic_frame(64, 512**3, dtheta=math.radians(1), depth=2.0,
    ...                                   tile_width=64, pixel=2.0 / 512)
    >>> round(per_node / (512**3 / 64), 4)   # share of a node's voxels that move
    0.0349
    """
    shift = depth * abs(dtheta) / 4.0 / pixel
    per_node = samples / nodes * min(1.0, shift / tile_width) * bytes_per_voxel
    return per_node, per_node * nodes


def mean_hops(nodes, *, torus=False):
    """Mean links crossed by a message between two nodes drawn uniformly (with repetition) on
    the squarest grid, under dimension-order routing.

    Examples
    --------
    >>> mean_hops(64), mean_hops(64, torus=True)
    (5.25, 4.0)
    """
    total = 0.0
    for n in mesh_shape(nodes):
        d = np.abs(np.arange(n)[:, None] - np.arange(n)[None, :])
        if torus:
            d = np.minimum(d, n - d)
        total += float(d.mean())
    return total


def channel_loads(total, nodes, *, torus=False):
    """Model of the channel loads for ``total`` bytes sent between uniformly drawn nodes.

    Returns a dict: ``mean`` (total x mean hops / channels) and ``bisection`` (half the
    traffic crosses the middle cut, half of that each way, over its ``2 Y`` directed
    channels, ``4 Y`` on a torus). The derivation counts a link's two directions together, which
    doubles its figures against these.

    Examples
    --------
    >>> loads = channel_loads(1e6, 64)
    >>> loads["bisection"], round(loads["mean"])
    (31250.0, 23438)
    """
    validate.positive_int("nodes", nodes)
    x, y = mesh_shape(nodes)
    x_links = (x if torus else x - 1) if x > 1 else 0
    y_links = (y if torus else y - 1) if y > 1 else 0
    channels = 2 * x_links * y + 2 * y_links * x
    cut = (4 if torus and x > 2 else 2) * y
    channels = max(channels, 1)
    return {"mean": total * mean_hops(nodes, torus=torus) / channels,
            "bisection": total * 0.5 / cut if x > 1 else 0.0}
