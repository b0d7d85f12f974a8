"""Rectangles of pixels ``(r0, r1, c0, c1)`` (rows ``r0 <= r < r1``, columns ``c0 <= c < c1``):
what compositing sends, and how they meet screen tiles. The real compositors
(:mod:`vrlib.parallel.composite`) and the simulated frames (:mod:`vrlib.parallel.traffic`)
measure pixels with these same functions.
"""

from __future__ import annotations

import numpy as np

__all__ = ["NOTHING", "area", "is_empty", "intersect", "clip", "union", "content",
           "pixels", "tile_overlaps"]

#: The empty rectangle.
NOTHING = (0, 0, 0, 0)


def area(rect):
    """Pixels in ``rect`` (0 when empty).

    Examples
    --------
    >>> area((0, 2, 1, 4)), area((3, 2, 0, 4))
    (6, 0)
    """
    r0, r1, c0, c1 = rect
    return max(r1 - r0, 0) * max(c1 - c0, 0)


def is_empty(rect):
    """True when ``rect`` holds no pixel."""
    return rect[1] <= rect[0] or rect[3] <= rect[2]


def intersect(a, b):
    """The overlap of two rectangles (possibly empty, not normalised)."""
    return (max(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), min(a[3], b[3]))


def clip(a, b):
    """The overlap of two rectangles, :data:`NOTHING` when they do not meet.

    Examples
    --------
    >>> clip((0, 4, 0, 4), (2, 6, 3, 9)), clip((0, 4, 0, 4), (5, 6, 0, 4))
    ((2, 4, 3, 4), (0, 0, 0, 0))
    """
    rect = intersect(a, b)
    return rect if not is_empty(rect) else NOTHING


def union(a, b):
    """The bounding rectangle of two rectangles (an empty one adds nothing)."""
    if area(a) == 0:
        return b
    if area(b) == 0:
        return a
    return (min(a[0], b[0]), max(a[1], b[1]), min(a[2], b[2]), max(a[3], b[3]))


def content(rgba, within=None):
    """Bounding rectangle of the non-zero pixels of ``rgba`` (inside ``within``).

    Examples
    --------
    >>> image = np.zeros((4, 4, 4)); image[1, 2, 3] = 0.5
    >>> content(image), content(image, (2, 4, 0, 4))
    ((1, 2, 2, 3), (0, 0, 0, 0))
    """
    r0, r1, c0, c1 = within if within is not None else (0, rgba.shape[0], 0, rgba.shape[1])
    drawn = np.any(rgba[r0:r1, c0:c1] != 0.0, axis=2)
    rows, cols = np.flatnonzero(drawn.any(axis=1)), np.flatnonzero(drawn.any(axis=0))
    if rows.size == 0:
        return NOTHING
    return (r0 + int(rows[0]), r0 + int(rows[-1]) + 1, c0 + int(cols[0]), c0 + int(cols[-1]) + 1)


def pixels(rgba, rect):
    """The pixels of ``rgba`` in ``rect``, contiguous (ready to send)."""
    return np.ascontiguousarray(rgba[rect[0]:rect[1], rect[2]:rect[3]])


def tile_overlaps(tiles, rect):
    """Owners and overlapping pixel counts of the screen tiles
    (:class:`~vrlib.parallel.decompose.ScreenTiles`) meeting ``rect``.

    Examples
    --------
    >>> from vrlib.parallel.decompose import screen_tiles
    >>> owners, counts = tile_overlaps(screen_tiles(8, 8, 2), (0, 2, 2, 6))
    >>> owners.tolist(), counts.tolist()
    ([0, 1], [4.0, 4.0])
    """
    r0, r1, c0, c1 = rect
    if r1 <= r0 or c1 <= c0:
        return np.zeros(0, np.int64), np.zeros(0)
    i0 = np.searchsorted(tiles.rows, r0, side="right") - 1
    i1 = np.searchsorted(tiles.rows, r1, side="left")
    j0 = np.searchsorted(tiles.cols, c0, side="right") - 1
    j1 = np.searchsorted(tiles.cols, c1, side="left")
    h = np.minimum(r1, tiles.rows[i0 + 1:i1 + 1]) - np.maximum(r0, tiles.rows[i0:i1])
    w = np.minimum(c1, tiles.cols[j0 + 1:j1 + 1]) - np.maximum(c0, tiles.cols[j0:j1])
    return tiles.owner[i0:i1, j0:j1].ravel(), np.outer(h, w).ravel().astype(np.float64)
