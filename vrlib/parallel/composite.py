"""Sort-last compositing: how ranks' local images become one, in one registry.

Each compositor is one entry of :data:`COMPOSITORS`, with the two faces the package needs:

* ``composite(comm, held, tree, order, view, sent)``: the real thing, over MPI. ``held`` is
  this rank's ``[(brick, rgba), ...]`` (full-screen local images), ``order`` the k-d tree's
  bricks front to back; returns this rank's finished screen rectangle and its pixels, and
  counts the bytes it sends in ``sent["composite"]``.
* ``messages(tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel, **options)``:
  the same frame's messages (:class:`~vrlib.parallel.traffic.Messages`), sized from the
  bricks' projected footprints, for the simulated network (:mod:`vrlib.parallel.network`).

Both count only what was drawn (the bounding rectangle of each local image's content), so the
simulation and the MPI renderer agree up to headers (``tests/test_parallel_mpi.py``).

* **direct send**: each rank owns one screen tile and receives, from every rank, the part of
  each local image that falls on it;
* **binary swap** (Ma et al. 1994): ``log2 P`` rounds in which pairs swap halves of their
  current screen region. Rank counts that are not powers of two fold pairs of k-d siblings
  together first. It needs one convex brick per rank.

A new compositor is a class here with those two methods and an entry in :data:`COMPOSITORS`;
the MPI renderer, its argument check and the chapters read the registry.
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from vrlib.compositing import over
from vrlib.parallel.decompose import screen_tiles
from vrlib.parallel.rects import (
    NOTHING,
    area,
    clip,
    content,
    intersect,
    is_empty,
    pixels,
    tile_overlaps,
    union,
)
from vrlib.parallel.traffic import Messages, footprint_rect

__all__ = ["COMPOSITORS", "Compositor", "DirectSend", "BinarySwap", "HEADER",
           "direct_send_messages", "binary_swap_messages", "swap_slots", "swap_halves",
           "gather_to_root"]

#: Header bytes counted for each rectangle sent (four int64 pixel bounds).
HEADER = 32


class Compositor:
    """A sort-last compositing algorithm (see the module docstring for its two methods)."""

    name: str
    #: True when each rank must hold exactly one convex brick.
    one_brick_per_rank: bool = False

    def composite(self, comm, held, tree, order, view, sent):
        raise NotImplementedError

    def messages(self, tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel=4,
                 **options):
        raise NotImplementedError

    def __repr__(self):
        return f"COMPOSITORS[{self.name!r}]"


# ---------------------------------------------------------------- direct send


class DirectSend(Compositor):
    """Direct send: every local image, cut by the screen tiles, goes to each tile's owner."""

    name = "direct-send"

    def composite(self, comm, held, tree, order, view, sent):
        position = {b: i for i, b in enumerate(order)}
        tiles = screen_tiles(view.height, view.width, comm.Get_size())
        return _direct_send(comm, [rgba for _, rgba in held],
                            [position[brick.index] for brick, _ in held], tiles, sent)

    def messages(self, tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel=4):
        return direct_send_messages(tree, owners, tiles, view, origin, spacing,
                                    bytes_per_pixel=bytes_per_pixel)[0]


def _direct_send(comm, images, keys, tiles, sent):
    """Send each local image's part on every tile to the tile's owner; composite the parts
    received in ``keys`` order (front to back). Returns this rank's tile rectangle and
    pixels."""
    size, rank = comm.Get_size(), comm.Get_rank()
    mine = tiles.rects(rank)[0]
    headers = [[] for _ in range(size)]
    payloads = [[] for _ in range(size)]
    for rgba, key in zip(images, keys, strict=True):
        drawn = content(rgba)
        for dest in range(size):
            part = clip(drawn, tiles.rects(dest)[0])
            if not is_empty(part):
                headers[dest].append((key, part))
                payloads[dest].append(pixels(rgba, part))
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


def direct_send_messages(tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel=4):
    """Direct send: each brick's local image, cut by the screen tiles, goes to each tile's
    owner.

    Returns
    -------
    messages : Messages
    local_pixels : ndarray
        Pixels of each brick's local image (its footprint rectangle).

    Examples
    --------
    >>> from vrlib import View
    >>> from vrlib.parallel.decompose import screen_tiles, split
    >>> view = View([0, 0, -1], up=[0, 1, 0], size=8, radius=1.0)   # looking down z
    >>> tree = split((4, 4, 4), 2, shape="shafts")          # lower and upper halves in y
    >>> tiles = screen_tiles(8, 8, 2)                       # left and right halves
    >>> msgs, local = direct_send_messages(tree, [0, 1], tiles, view, (-1, -1, -1),
    ...                                  (0.5, 0.5, 0.5), bytes_per_pixel=1)
    >>> local.tolist(), msgs.sent_per_node(2).tolist()     # half of each goes across
    ([32.0, 32.0], [16.0, 16.0])
    """
    nodes = max(int(np.max(owners)) + 1, tiles.nodes)
    src, dst, size, local = [], [], [], []
    for brick in tree.bricks:
        rect = footprint_rect(view, *brick.world_box(origin, spacing))
        local.append(area(rect))
        who, overlap = tile_overlaps(tiles, rect)
        src.append(np.full(who.size, owners[brick.index]))
        dst.append(who)
        size.append(overlap * bytes_per_pixel)
    return (Messages.merged(np.concatenate(src), np.concatenate(dst), np.concatenate(size),
                            nodes), np.array(local, dtype=np.float64))


# ---------------------------------------------------------------- binary swap


class BinarySwap(Compositor):
    """Binary swap over the k-d tree's bricks, brick ``i`` on rank ``i``."""

    name = "binary-swap"
    one_brick_per_rank = True

    def composite(self, comm, held, tree, order, view, sent):
        rect, full = _binary_swap(comm, tree, held[0][1], order, sent)
        return rect, (pixels(full, rect) if not is_empty(rect) else None)

    def messages(self, tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel=4,
                 bounded=True):
        if not np.array_equal(owners, np.arange(len(tree))):
            raise ValueError("binary swap takes brick i on node i (owners 0, 1, ...)")
        return binary_swap_messages(tree, view, origin, spacing,
                                    bytes_per_pixel=bytes_per_pixel, bounded=bounded)


def _exchange(comm, partner, rgba, rect_out, sent):
    """Send the pixels ``rect_out`` of ``rgba`` to ``partner`` and receive the pixels it
    sends (the rectangle it names first); returns (rect, pixels) received."""
    theirs = comm.sendrecv(rect_out, dest=partner, source=partner)
    sent["composite"] += HEADER
    buf = np.empty((max(theirs[1] - theirs[0], 0), max(theirs[3] - theirs[2], 0), 4))
    out = pixels(rgba, rect_out) if not is_empty(rect_out) else np.empty((0, 0, 4))
    comm.Sendrecv(out, dest=partner, recvbuf=buf, source=partner)
    sent["composite"] += out.nbytes
    return theirs, buf


def _merge(rgba, rect, buf, mine_in_front):
    """Composite received pixels into ``rgba`` at ``rect``."""
    if is_empty(rect):
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
                _exchange(comm, first, rgba, content(rgba), sent)
                return NOTHING, rgba
            if rank == first:
                theirs, buf = _exchange(comm, second, rgba, NOTHING, sent)
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
        theirs, buf = _exchange(comm, partner, rgba, content(rgba, give), sent)
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


def swap_slots(tree):
    """Binary swap's slots: the subtrees at depth ``floor(log2 P)`` of the k-d tree, each one
    brick or two (a pair folded together before the swap), left to right.

    Examples
    --------
    >>> from vrlib.parallel.decompose import split
    >>> swap_slots(split((8, 8, 8), 3))           # brick 0 alone, bricks 1 and 2 folded
    [0, (1, 4, 1, 2)]
    """
    depth = int(math.floor(math.log2(len(tree))))
    slots = []

    def visit(node, level):
        if level == depth or not isinstance(node, tuple):
            slots.append(node)
            return
        visit(node[2], level + 1)
        visit(node[3], level + 1)

    visit(tree.node, 0)
    if len(slots) != 1 << depth:
        raise ValueError("binary swap needs a k-d tree from vrlib.parallel.decompose.split "
                         "(a perfect tree over its first floor(log2 P) levels)")
    return slots


def swap_halves(region, lower):
    """One binary-swap round's split of a screen ``region`` ``(r0, r1, c0, c1)`` across its
    longer side: ``(keep, give)``, the lower half kept by the partner with ``lower`` set.

    Examples
    --------
    >>> swap_halves((0, 8, 0, 4), True), swap_halves((0, 8, 0, 4), False)[0]
    (((0, 4, 0, 4), (4, 8, 0, 4)), (4, 8, 0, 4))
    """
    r0, r1, c0, c1 = region
    if r1 - r0 >= c1 - c0:
        mid = (r0 + r1) // 2
        halves = ((r0, mid, c0, c1), (mid, r1, c0, c1))
    else:
        mid = (c0 + c1) // 2
        halves = ((r0, r1, c0, mid), (r0, r1, mid, c1))
    return halves if lower else halves[::-1]


def binary_swap_messages(tree, view, origin, spacing, *, bytes_per_pixel=4, bounded=True):
    """Binary swap (Ma et al. 1994) on the k-d tree's bricks, brick ``i`` on node ``i``.

    Pairs folded into one slot first send the second brick's image to the first; then in
    round ``r`` slot ``s`` swaps halves of its current screen region with slot ``s ^ 2^r``.
    With ``bounded`` a node sends only the part of the half inside the bounding rectangle of
    what its group has rendered; otherwise the whole half (the classic count, ``W^2 (1 - 1/P)``
    per node).

    Examples
    --------
    >>> from vrlib import View
    >>> from vrlib.parallel.decompose import split
    >>> view = View.orbit(size=16)
    >>> m = binary_swap_messages(split((8, 8, 8), 4), view, (-1, -1, -1), (0.25, 0.25, 0.25),
    ...                 bytes_per_pixel=1, bounded=False)
    >>> m.sent_per_node(4).tolist()               # 16^2 x (1 - 1/4) each
    [192.0, 192.0, 192.0, 192.0]
    """
    slots = swap_slots(tree)
    full = (0, view.height, 0, view.width)
    rects = [footprint_rect(view, *b.world_box(origin, spacing)) for b in tree.bricks]
    nodes = len(tree)
    src, dst, size = [], [], []
    leader, held = [], []
    for slot in slots:
        if isinstance(slot, tuple):
            first, second = slot[2], slot[3]
            src.append(second)
            dst.append(first)
            size.append(area(rects[second] if bounded else full) * bytes_per_pixel)
            leader.append(first)
            held.append(union(rects[first], rects[second]))
        else:
            leader.append(slot)
            held.append(rects[slot])
    region = [full] * len(slots)
    for r in range(int(math.log2(len(slots)))):
        new_held = list(held)
        for s in range(len(slots)):
            partner = s ^ (1 << r)
            keep, give = swap_halves(region[s], s < partner)
            part = intersect(give, held[s]) if bounded else give
            src.append(leader[s])
            dst.append(leader[partner])
            size.append(area(part) * bytes_per_pixel)
            region[s] = keep
            new_held[s] = union(held[s], held[partner])
        held = new_held
    return Messages.merged(src, dst, size, nodes)


#: Compositors by name.
COMPOSITORS = {c.name: c for c in (DirectSend(), BinarySwap())}


# ---------------------------------------------------------------- the finished image


def gather_to_root(comm, rect, finished, shape, root, sent):
    """Each rank's finished rectangle to ``root``; the full image there."""
    payload = (rect, finished if not is_empty(rect) else None)
    if comm.Get_rank() != root and not is_empty(rect):
        sent["gather"] += HEADER + finished.nbytes
    parts = comm.gather(payload, root=root)
    if comm.Get_rank() != root:
        return None
    out = np.zeros(shape + (4,))
    for part, buf in parts:
        if not is_empty(part):
            out[part[0]:part[1], part[2]:part[3]] = buf
    return out
