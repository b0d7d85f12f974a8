"""A 2-D mesh or torus network: route every message of a frame and count bytes per channel.

Nodes sit on an ``X x Y`` grid, node ``r`` at column ``r % X``, row ``r // X``. A channel is
one direction of one link between neighbours (a torus adds the wrap-around links). Messages
follow dimension-order routing: along the row to the destination's column, then along that
column; on a torus each leg takes the shorter way round (east or north on a tie). Loads are
accumulated with difference arrays, so a frame of millions of messages on thousands of nodes
routes in well under a second.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vrlib import validate

__all__ = ["Network", "ChannelLoad", "mesh_shape"]


def mesh_shape(nodes):
    """Columns and rows ``(X, Y)`` of the squarest grid of ``nodes`` nodes (``X >= Y``).

    Examples
    --------
    >>> mesh_shape(64), mesh_shape(128), mesh_shape(6)
    ((8, 8), (16, 8), (3, 2))
    """
    nodes = validate.positive_int("nodes", nodes)
    y = max(f for f in range(1, math.isqrt(nodes) + 1) if nodes % f == 0)
    return nodes // y, y


@dataclass(frozen=True)
class ChannelLoad:
    """Bytes on every channel after routing a frame.

    ``east[y, x]``: link from column ``x`` to ``x + 1`` (mod X on a torus) in row ``y``;
    ``west[y, x]``: the reverse direction of the same link; ``north[x, y]`` and ``south[x, y]``
    likewise along column ``x``. Links a mesh does not have hold zero and are left out of the
    statistics.

    Examples
    --------
    >>> load = Network(3, 1).route([0, 2], [2, 0], [5.0, 1.0])
    >>> load.max, load.mean, load.total
    (5.0, 3.0, 12.0)
    """

    east: np.ndarray
    west: np.ndarray
    north: np.ndarray
    south: np.ndarray
    torus: bool

    def channels(self):
        """Loads of the channels the network has, as one flat array."""
        x_links = self.east.shape[1] if self.torus else self.east.shape[1] - 1
        y_links = self.north.shape[1] if self.torus else self.north.shape[1] - 1
        if self.east.shape[1] == 1:
            x_links = 0
        if self.north.shape[1] == 1:
            y_links = 0
        return np.concatenate([self.east[:, :x_links].ravel(), self.west[:, :x_links].ravel(),
                               self.north[:, :y_links].ravel(),
                               self.south[:, :y_links].ravel()])

    @property
    def max(self):
        """Busiest channel's bytes."""
        ch = self.channels()
        return float(ch.max()) if ch.size else 0.0

    @property
    def mean(self):
        """Mean bytes per channel."""
        ch = self.channels()
        return float(ch.mean()) if ch.size else 0.0

    @property
    def total(self):
        """Bytes summed over channels (each message counted once per hop)."""
        return float(self.channels().sum())

    def bisection(self):
        """Mean bytes per channel across the cut between columns ``X/2 - 1`` and ``X/2``
        (both directions; the wrap-around cut too on a torus)."""
        cols = self.east.shape[1]
        if cols < 2:
            return 0.0
        cut = [cols // 2 - 1]
        if self.torus and cols > 2:
            cut.append(cols - 1)
        loads = np.concatenate([self.east[:, cut].ravel(), self.west[:, cut].ravel()])
        return float(loads.mean())


class Network:
    """A ``columns x rows`` mesh or torus.

    Parameters
    ----------
    columns, rows : int
        Grid size; ``Network.square(P)`` picks the squarest grid for ``P`` nodes.
    torus : bool
        Add wrap-around links.

    Examples
    --------
    >>> net = Network(4, 1)
    >>> load = net.route([0], [3], [10.0])
    >>> load.east[0].tolist(), net.hops([0], [3]).tolist()
    ([10.0, 10.0, 10.0, 0.0], [3])
    >>> Network(4, 1, torus=True).route([0], [3], [10.0]).west[0].tolist()
    [0.0, 0.0, 0.0, 10.0]
    """

    def __init__(self, columns, rows, *, torus=False):
        self.columns = validate.positive_int("columns", columns)
        self.rows = validate.positive_int("rows", rows)
        self.torus = bool(torus)

    @classmethod
    def square(cls, nodes, *, torus=False):
        """The squarest grid of ``nodes`` nodes."""
        return cls(*mesh_shape(nodes), torus=torus)

    @property
    def nodes(self):
        """Number of nodes."""
        return self.columns * self.rows

    def __repr__(self):
        kind = "torus" if self.torus else "mesh"
        return f"Network({self.columns} x {self.rows} {kind})"

    def _check(self, src, dst, size):
        src = np.asarray(src, dtype=np.int64).ravel()
        dst = np.asarray(dst, dtype=np.int64).ravel()
        size = np.asarray(size, dtype=np.float64).ravel()
        if not (src.shape == dst.shape == size.shape):
            raise ValueError(f"src, dst and bytes must have one entry per message; got "
                             f"{src.size}, {dst.size} and {size.size}")
        for name, nodes in (("src", src), ("dst", dst)):
            if nodes.size and (nodes.min() < 0 or nodes.max() >= self.nodes):
                raise ValueError(f"{name} must name nodes 0..{self.nodes - 1}")
        if not np.all(np.isfinite(size)) or np.any(size < 0):
            raise ValueError("bytes must be finite and non-negative")
        return src, dst, size

    def _leg(self, length, lanes, start, end, lane, size):
        """Loads ``(forward, backward)`` of one routing leg on ``lanes`` rings (torus) or lines
        (mesh) of ``length`` nodes."""
        forward = np.zeros((lanes, length + 1))
        backward = np.zeros((lanes, length + 1))
        ahead, behind = (end - start) % length, (start - end) % length
        go_forward = ahead <= behind if self.torus else end > start
        moving = end != start
        # Forward: links start .. end - 1 (mod length); link x carries x -> x + 1.
        f = moving & go_forward
        _add_ring(forward, lane[f], start[f], ahead[f], size[f], length)
        # Backward: links end .. start - 1 (mod length); link x carries x + 1 -> x.
        b = moving & ~go_forward
        _add_ring(backward, lane[b], end[b], behind[b], size[b], length)
        return (np.cumsum(forward, axis=1)[:, :length], np.cumsum(backward, axis=1)[:, :length])

    def route(self, src, dst, size):
        """Route messages ``src[i] -> dst[i]`` of ``size[i]`` bytes; return the
        :class:`ChannelLoad`."""
        src, dst, size = self._check(src, dst, size)
        sx, sy = src % self.columns, src // self.columns
        dx, dy = dst % self.columns, dst // self.columns
        # Along the source's row to the target's column, then along that column.
        east, west = self._leg(self.columns, self.rows, sx, dx, sy, size)
        north, south = self._leg(self.rows, self.columns, sy, dy, dx, size)
        return ChannelLoad(east, west, north, south, self.torus)

    def hops(self, src, dst):
        """Links each message crosses under dimension-order routing."""
        src = np.asarray(src, dtype=np.int64)
        dst = np.asarray(dst, dtype=np.int64)
        ddx = np.abs(src % self.columns - dst % self.columns)
        ddy = np.abs(src // self.columns - dst // self.columns)
        if self.torus:
            ddx = np.minimum(ddx, self.columns - ddx)
            ddy = np.minimum(ddy, self.rows - ddy)
        return ddx + ddy


def _add_ring(diff, lane, start, steps, size, length):
    """Add ``size`` to links ``start .. start + steps - 1`` (mod ``length``) of each lane,
    as a difference array (an interval that wraps is split in two)."""
    stop = start + steps
    wrap = stop > length
    row = lane * diff.shape[1]
    index = np.concatenate([row + start, row + np.where(wrap, length, stop),
                            row[wrap], row[wrap] + stop[wrap] - length])
    weight = np.concatenate([size, -size, size[wrap], -size[wrap]])
    diff += np.bincount(index, weight, minlength=diff.size).reshape(diff.shape)
