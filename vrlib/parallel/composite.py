"""Sort-last compositing: how ranks' local images become one, in one registry.

A compositor is a sequence of *rounds*; in each, a rank sends rectangles of pixels to some
ranks and receives rectangles from others. Each entry of :data:`COMPOSITORS` has the faces the
package needs, built on the same schedule (which rank sends which screen region to which, in
which round):

* ``composite(exchange, held, tree, owners, order, view)``: the real thing, over MPI
  (:class:`~vrlib.parallel.exchange.Exchange`). ``held`` is this rank's
  ``[(brick, rgba), ...]`` (full-screen local images), ``owners`` the rank of each brick,
  ``order`` the k-d tree's bricks front to back; returns this rank's finished screen rectangle
  and its pixels.
* ``rounds(tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel)``: the same frame's
  messages round by round (:class:`~vrlib.parallel.traffic.Messages`), sized from the bricks'
  projected footprints, for the simulated network (:mod:`vrlib.parallel.network`);
  ``messages(...)`` sums them.
* ``split(cells, ranks, weights=None)``: the k-d tree of one brick per rank whose subtrees
  match the compositor's groups.

Both faces send only what was drawn (the bounding rectangle of each image's content within the
region sent), so the simulation bounds every message the MPI renderer sends
(``tests/test_parallel_mpi.py`` checks them pair by pair).

* **direct send**: each rank owns one screen tile and receives, from every rank, the part of
  each local image that falls on it: one round of ``P - 1`` messages per rank;
* **binary swap** (Ma et al. 1994): ``log2 P`` rounds in which pairs swap halves of their
  current screen region. Rank counts that are not powers of two fold pairs of k-d siblings
  together first (those ranks then idle). It needs one convex brick per rank;
* **radix-k** (Peterka et al. 2009): ``P = k_1 k_2 ... k_m``; in round ``i`` groups of
  ``k_i`` ranks split their current region into ``k_i`` pieces and each gathers one piece from
  the others. ``k = 2`` every round is binary swap, one round of ``k = P`` is direct send onto
  strips, and any rank count works with every rank busy to the end (a prime count is one
  round). The default factorisation takes factors of at most 8 (IceT's default ``k``).

A new compositor is a class here with those methods and an entry in :data:`COMPOSITORS`; the
MPI renderer, its argument check, the network simulation and the chapters read the registry.
"""

from __future__ import annotations

import math

import numpy as np

from vrlib import validate
from vrlib.compositing import over
from vrlib.parallel.decompose import screen_tiles, split
from vrlib.parallel.exchange import HEADER
from vrlib.parallel.rects import (
    NOTHING,
    area,
    clip,
    content,
    intersect,
    is_empty,
    tile_overlaps,
    union,
)
from vrlib.parallel.traffic import Messages, footprint_rect, sum_messages

__all__ = ["COMPOSITORS", "Compositor", "DirectSend", "BinarySwap", "RadixK", "HEADER",
           "direct_send_messages", "binary_swap_rounds", "binary_swap_messages",
           "radix_k_rounds", "radix_k_messages", "swap_slots",
           "swap_halves", "split_region", "radix_factors", "compositor", "gather_to_root"]


class Compositor:
    """A sort-last compositing algorithm (see the module docstring for its methods)."""

    name: str
    #: True when each rank must hold exactly one convex brick.
    one_brick_per_rank: bool = False

    def split(self, cells, ranks, weights=None):
        """The k-d tree of ``ranks`` bricks this compositor composites, brick ``i`` on rank
        ``i``."""
        return split(cells, ranks, weights=weights)

    def composite(self, exchange, held, tree, owners, order, view):
        """Composite this rank's local images with the others' over MPI (the rounds of
        ``exchange``); returns this rank's finished screen rectangle and its pixels."""
        raise NotImplementedError

    def rounds(self, tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel=4):
        """The same frame's messages, one :class:`~vrlib.parallel.traffic.Messages` per
        round, sized from the bricks' projected footprints."""
        raise NotImplementedError

    def messages(self, tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel=4,
                 **options):
        """All of a frame's messages (the rounds' summed)."""
        return sum_messages(self.rounds(tree, owners, tiles, view, origin, spacing,
                                        bytes_per_pixel=bytes_per_pixel, **options),
                            _nodes(owners, tiles))

    def __repr__(self):
        return f"COMPOSITORS[{self.name!r}]"


def _nodes(owners, tiles):
    return max(int(np.max(owners)) + 1, 0 if tiles is None else tiles.nodes)


def _composite_in_order(region, pieces):
    """Pixels of ``region`` from ``pieces`` ``[(key, rect, rgba_of_rect), ...]`` composited
    front to back by ``key`` (the visibility order)."""
    out = np.zeros((region[1] - region[0], region[3] - region[2], 4))
    for _key, rect, buf in sorted(pieces, key=lambda piece: piece[0]):
        if buf is None:
            continue
        r0, r1 = rect[0] - region[0], rect[1] - region[0]
        c0, c1 = rect[2] - region[2], rect[3] - region[2]
        out[r0:r1, c0:c1] = over(out[r0:r1, c0:c1], buf)
    return out


def _merge_in_order(target, region, mine, pieces):
    """Composite received ``pieces`` ``[(key, rect, pixels), ...]`` into ``target``, the
    pixels of ``region`` this rank holds (visibility key ``mine``), in place: the pieces
    behind it under it, nearest first, and the pieces in front of it over it, nearest first,
    one over operation per piece on its own rectangle."""
    behind = sorted((p for p in pieces if p[0] > mine), key=lambda p: p[0])
    front = sorted((p for p in pieces if p[0] < mine), key=lambda p: -p[0])
    for pieces_, mine_in_front in ((behind, True), (front, False)):
        for _key, rect, buf in pieces_:
            if buf is None:
                continue
            part = target[rect[0] - region[0]:rect[1] - region[0],
                          rect[2] - region[2]:rect[3] - region[2]]
            part[...] = over(part, buf) if mine_in_front else over(buf, part)


def _own(rgba, rect):
    """This rank's own pixels of ``rect``, as a piece (None when it drew nothing there)."""
    drawn = content(rgba, rect)
    if is_empty(drawn):
        return NOTHING, None
    return drawn, rgba[drawn[0]:drawn[1], drawn[2]:drawn[3]]


# ---------------------------------------------------------------- direct send


class DirectSend(Compositor):
    """Direct send: every local image, cut by the screen tiles, goes to each tile's owner.
    Takes any number of bricks per rank."""

    name = "direct-send"

    def composite(self, exchange, held, tree, owners, order, view):
        rank, size = exchange.rank, exchange.size
        position = {b: i for i, b in enumerate(order)}
        tiles = screen_tiles(view.height, view.width, size)
        mine = tiles.rects(rank)[0]
        sends, pieces = [], []
        for brick, rgba in sorted(held, key=lambda item: item[0].index):
            drawn = content(rgba)
            for dest in range(size):
                if dest != rank:
                    sends.append((dest, clip(drawn, tiles.rects(dest)[0]), rgba))
            if len(held) > 1:
                pieces.append((position[brick.index], *_own(rgba, mine)))
        # Each source sends its bricks in index order.
        sources = [(int(owners[b]), b) for b in range(len(tree)) if owners[b] != rank]
        sources.sort()
        received = exchange.swap(0, sends, [s for s, _ in sources])
        received = [(position[b], rect, buf) for (_, b), (rect, buf) in zip(sources, received,
                                                                              strict=True)]
        if len(held) == 1:  # composite into this rank's own image, in place
            brick, rgba = held[0]
            target = rgba[mine[0]:mine[1], mine[2]:mine[3]]
            _merge_in_order(target, mine, position[brick.index], received)
            return mine, np.ascontiguousarray(target)
        return mine, _composite_in_order(mine, pieces + received)

    def rounds(self, tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel=4):
        return [direct_send_messages(tree, owners, tiles, view, origin, spacing,
                                     bytes_per_pixel=bytes_per_pixel)[0]]


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

    def composite(self, exchange, held, tree, owners, order, view):
        rank = exchange.rank
        rgba = held[0][1]
        full = (0, rgba.shape[0], 0, rgba.shape[1])
        position = {brick: i for i, brick in enumerate(order)}
        slots = swap_slots(tree)
        leaders = []
        for slot in slots:
            if not isinstance(slot, tuple):
                leaders.append(slot)
                continue
            first, second = slot[2], slot[3]
            if rank == second:  # fold: hand everything to the sibling and stop
                exchange.swap(0, [(first, content(rgba), rgba)], [])
                return NOTHING, None
            if rank == first:
                ((rect, buf),) = exchange.swap(0, [], [second])
                _merge_in_order(rgba, full, position[first], [(position[second], rect, buf)])
            leaders.append(first)
        s = leaders.index(rank)
        region = full
        for r in range(int(math.log2(len(slots)))):
            partner_slot = s ^ (1 << r)
            partner = leaders[partner_slot]
            keep, give = swap_halves(region, s < partner_slot)
            ((rect, buf),) = exchange.swap(1 + r, [(partner, content(rgba, give), rgba)],
                                           [partner])
            # The group whose bricks come first in the visibility order is in front.
            group = 1 << (r + 1)
            _merge_in_order(rgba, full,
                            min(position[b] for b in _group(tree, slots, s, group)),
                            [(min(position[b] for b in _group(tree, slots, partner_slot,
                                                              group)), rect, buf)])
            region = keep
        return region, np.ascontiguousarray(rgba[region[0]:region[1], region[2]:region[3]])

    def rounds(self, tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel=4,
               bounded=True):
        if not np.array_equal(owners, np.arange(len(tree))):
            raise ValueError("binary swap takes brick i on node i (owners 0, 1, ...)")
        return binary_swap_rounds(tree, view, origin, spacing,
                                  bytes_per_pixel=bytes_per_pixel, bounded=bounded)


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


def binary_swap_rounds(tree, view, origin, spacing, *, bytes_per_pixel=4, bounded=True):
    """Binary swap (Ma et al. 1994) on the k-d tree's bricks, brick ``i`` on node ``i``: the
    messages of each round, the fold first (empty when ``P`` is a power of two).

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
    >>> rounds = binary_swap_rounds(split((8, 8, 8), 4), view, (-1, -1, -1),
    ...                             (0.25, 0.25, 0.25), bytes_per_pixel=1, bounded=False)
    >>> [m.sent_per_node(4).tolist() for m in rounds]     # no fold; 128 then 64 pixels each
    [[0.0, 0.0, 0.0, 0.0], [128.0, 128.0, 128.0, 128.0], [64.0, 64.0, 64.0, 64.0]]
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
    out = [Messages.merged(src, dst, size, nodes)]
    region = [full] * len(slots)
    for r in range(int(math.log2(len(slots)))):
        src, dst, size = [], [], []
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
        out.append(Messages.merged(src, dst, size, nodes))
    return out


def binary_swap_messages(tree, view, origin, spacing, *, bytes_per_pixel=4, bounded=True):
    """All of binary swap's messages (:func:`binary_swap_rounds` summed).

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
    return sum_messages(binary_swap_rounds(tree, view, origin, spacing,
                                           bytes_per_pixel=bytes_per_pixel, bounded=bounded),
                        len(tree))


# ---------------------------------------------------------------- radix-k


def radix_factors(ranks, target=8):
    """Radix-k's default factorisation of ``ranks``: its prime factors, smallest first, each
    multiplied into the previous factor while that stays at most ``target``.

    Examples
    --------
    >>> radix_factors(12), radix_factors(64), radix_factors(7), radix_factors(8, target=2)
    ([4, 3], [8, 8], [7], [2, 2, 2])
    >>> radix_factors(4096), radix_factors(1)
    ([8, 8, 8, 8], [])
    """
    n = validate.positive_int("ranks", ranks)
    target = validate.positive_int("target", target, minimum=2)
    primes, f = [], 2
    while f * f <= n:
        while n % f == 0:
            primes.append(f)
            n //= f
        f += 1
    if n > 1:
        primes.append(n)
    factors = []
    for p in primes:
        if factors and factors[-1] * p <= target:
            factors[-1] *= p
        else:
            factors.append(p)
    return factors


def split_region(region, k):
    """A screen ``region`` ``(r0, r1, c0, c1)`` cut into ``k`` strips across its longer side
    (piece ``j`` from ``j * length // k``); some are empty when the side is shorter than ``k``.

    Examples
    --------
    >>> split_region((0, 6, 0, 4), 3)
    [(0, 2, 0, 4), (2, 4, 0, 4), (4, 6, 0, 4)]
    >>> split_region((0, 2, 0, 7), 2)
    [(0, 2, 0, 3), (0, 2, 3, 7)]
    """
    r0, r1, c0, c1 = region
    rows = r1 - r0 >= c1 - c0
    start, length = (r0, r1 - r0) if rows else (c0, c1 - c0)
    cuts = [start + j * length // k for j in range(k + 1)]
    if rows:
        return [(cuts[j], cuts[j + 1], c0, c1) for j in range(k)]
    return [(r0, r1, cuts[j], cuts[j + 1]) for j in range(k)]


def _members(rank, stride, k):
    """Radix-k: this rank's digit and its group of ``k`` ranks in the round of ``stride``."""
    digit = (rank // stride) % k
    return digit, [rank + (j - digit) * stride for j in range(k)]


class RadixK(Compositor):
    """Radix-k over the k-d tree's bricks, brick ``i`` on rank ``i``.

    Parameters
    ----------
    factors : sequence of int, optional
        ``k`` of each round, first round first; their product must be the rank count.
        Default: :func:`radix_factors` with ``target``.
    target : int
        Largest factor the default factorisation makes (IceT's default is 8).

    Examples
    --------
    >>> RadixK().factors_for(24), RadixK([2, 3, 4]).factors_for(24)
    ([8, 3], [2, 3, 4])
    >>> RadixK([2, 3]).factors_for(8)
    Traceback (most recent call last):
    ...
    ValueError: radix-k factors (2, 3) multiply to 6, not the 8 ranks
    """

    name = "radix-k"
    one_brick_per_rank = True

    def __init__(self, factors=None, *, target=8):
        self.target = validate.positive_int("target", target, minimum=2)
        self.factors = None if factors is None else tuple(
            validate.positive_int("factors", f, minimum=2) for f in factors)

    def factors_for(self, ranks):
        """The factorisation used for ``ranks`` ranks."""
        if self.factors is None:
            return radix_factors(ranks, self.target)
        if math.prod(self.factors) != ranks:
            raise ValueError(f"radix-k factors {self.factors} multiply to "
                             f"{math.prod(self.factors)}, not the {ranks} ranks")
        return list(self.factors)

    def split(self, cells, ranks, weights=None):
        return split(cells, ranks, weights=weights, groups=self.factors_for(ranks))

    def composite(self, exchange, held, tree, owners, order, view):
        rank = exchange.rank
        rgba = held[0][1]
        position = {b: i for i, b in enumerate(order)}
        region, stride = (0, rgba.shape[0], 0, rgba.shape[1]), 1

        def key(member):
            # A member's image holds the block of ``stride`` bricks its group has merged, a
            # subtree of the k-d tree, so contiguous in the visibility order.
            first = member // stride * stride
            return min(position[b] for b in range(first, first + stride))

        for round, k in enumerate(self.factors_for(exchange.size)):
            digit, members = _members(rank, stride, k)
            pieces = split_region(region, k)
            others = [m for j, m in enumerate(members) if j != digit]
            received = exchange.swap(
                round, [(m, content(rgba, pieces[j]), rgba) for j, m in enumerate(members)
                        if j != digit], others)
            region = pieces[digit]
            _merge_in_order(rgba[region[0]:region[1], region[2]:region[3]], region, key(rank),
                            [(key(m), rect, buf) for m, (rect, buf) in zip(others, received,
                                                                            strict=True)])
            stride *= k
        return region, np.ascontiguousarray(rgba[region[0]:region[1], region[2]:region[3]])

    def rounds(self, tree, owners, tiles, view, origin, spacing, *, bytes_per_pixel=4,
               bounded=True):
        if not np.array_equal(owners, np.arange(len(tree))):
            raise ValueError("radix-k takes brick i on node i (owners 0, 1, ...)")
        return radix_k_rounds(tree, view, origin, spacing, self.factors_for(len(tree)),
                              bytes_per_pixel=bytes_per_pixel, bounded=bounded)

    def __repr__(self):
        if self.factors is None and self.target == 8:
            return "COMPOSITORS['radix-k']"
        return f"RadixK({list(self.factors) if self.factors else None}, target={self.target})"


def radix_k_rounds(tree, view, origin, spacing, factors, *, bytes_per_pixel=4, bounded=True):
    """Radix-k (Peterka et al. 2009) on the k-d tree's bricks, brick ``i`` on node ``i``: the
    messages of each round. Node ``s`` sends each member of its group the part of that
    member's piece inside the bounding rectangle of what its own group has merged so far
    (vectorised over the nodes, so thousands of nodes and large ``k`` route in a moment);
    without ``bounded`` the whole piece (the classic count, ``W^2 (1 - 1/P)`` per node).

    Examples
    --------
    >>> from vrlib import View
    >>> from vrlib.parallel.decompose import split
    >>> view = View.orbit(size=12)
    >>> rounds = radix_k_rounds(split((6, 6, 6), 6, groups=[2, 3]), view, (-1, -1, -1),
    ...                         (1 / 3, 1 / 3, 1 / 3), [2, 3], bytes_per_pixel=1)
    >>> rounds[0].src.tolist(), rounds[0].dst.tolist()  # pairs (node 1 sends nothing)
    ([0, 2, 3, 4, 5], [1, 3, 2, 5, 4])
    >>> sorted(rounds[1].dst[rounds[1].src == 1].tolist())   # then triples {1, 3, 5}
    [3, 5]
    """
    nodes = len(tree)
    if math.prod(factors) != nodes:
        raise ValueError(f"radix-k factors {tuple(factors)} multiply to {math.prod(factors)}, "
                         f"not the {nodes} nodes")
    empty = np.array([np.inf, -np.inf, np.inf, -np.inf])
    full = (0, view.height, 0, view.width)
    held = np.array([empty if is_empty(r) else r for r in
                     (footprint_rect(view, *b.world_box(origin, spacing)) if bounded else full
                      for b in tree.bricks)], dtype=float).reshape(nodes, 4)
    region = np.tile(np.array([0, view.height, 0, view.width], dtype=np.int64), (nodes, 1))
    node = np.arange(nodes)
    out, stride = [], 1
    for k in factors:
        digit = (node // stride) % k
        r0, r1, c0, c1 = region.T
        rows = r1 - r0 >= c1 - c0
        start = np.where(rows, r0, c0)
        length = np.where(rows, r1 - r0, c1 - c0)
        src, dst, size = [], [], []
        merged = np.tile(empty, (nodes, 1))
        kept = region.copy()
        for j in range(k):
            a, b = start + j * length // k, start + (j + 1) * length // k
            piece = np.where(rows[:, None], np.stack([a, b, c0, c1], 1),
                             np.stack([r0, r1, a, b], 1))
            member = node + (j - digit) * stride
            # What s sends member j: piece j inside what s holds.
            h = np.clip(np.minimum(piece[:, 1], held[:, 1]) - np.maximum(piece[:, 0],
                                                                         held[:, 0]), 0, None)
            w = np.clip(np.minimum(piece[:, 3], held[:, 3]) - np.maximum(piece[:, 2],
                                                                         held[:, 2]), 0, None)
            send = j != digit
            src.append(node[send])
            dst.append(member[send])
            size.append((h * w)[send] * bytes_per_pixel)
            kept[digit == j] = piece[digit == j]
            other = held[member]
            merged = np.stack([np.minimum(merged[:, 0], other[:, 0]),
                               np.maximum(merged[:, 1], other[:, 1]),
                               np.minimum(merged[:, 2], other[:, 2]),
                               np.maximum(merged[:, 3], other[:, 3])], 1)
        out.append(Messages.merged(np.concatenate(src), np.concatenate(dst),
                                   np.concatenate(size), nodes))
        held, region, stride = merged, kept, stride * k
    return out


def radix_k_messages(tree, view, origin, spacing, factors, *, bytes_per_pixel=4,
                     bounded=True):
    """All of radix-k's messages (:func:`radix_k_rounds` summed)."""
    return sum_messages(radix_k_rounds(tree, view, origin, spacing, factors,
                                       bytes_per_pixel=bytes_per_pixel, bounded=bounded),
                        len(tree))


#: Compositors by name.
COMPOSITORS = {c.name: c for c in (DirectSend(), BinarySwap(), RadixK())}


def compositor(spec):
    """A compositor from a name of :data:`COMPOSITORS`, ``"radix-k:AxB..."`` (radix-k with
    the factors ``A``, ``B``, ... round by round), or a :class:`Compositor` itself.

    Examples
    --------
    >>> compositor("binary-swap"), compositor("radix-k:2x3").factors
    (COMPOSITORS['binary-swap'], (2, 3))
    """
    if isinstance(spec, Compositor):
        return spec
    name, _, factors = str(spec).partition(":")
    if factors and name == "radix-k":
        try:
            return RadixK([int(f) for f in factors.split("x")])
        except ValueError:
            pass  # not integers: fall through to the message naming the allowed values
    if factors or name not in COMPOSITORS:
        allowed = ", ".join(repr(n) for n in COMPOSITORS)
        raise ValueError(f"unknown compositing {spec!r}: use one of {allowed}, "
                         "'radix-k:AxB...' or a Compositor")
    return COMPOSITORS[name]


# ---------------------------------------------------------------- the finished image


def gather_to_root(comm, parts, shape, root, sent):
    """Each rank's finished rectangles ``[(rect, pixels), ...]`` to ``root``; the full image
    there (None elsewhere)."""
    parts = [(rect, buf) for rect, buf in parts if not is_empty(rect)]
    if comm.Get_rank() != root:
        sent["gather"] += sum(HEADER + buf.nbytes for _, buf in parts)
    gathered = comm.gather(parts, root=root)
    if comm.Get_rank() != root:
        return None
    out = np.zeros(shape + (4,))
    for rank_parts in gathered:
        for rect, buf in rank_parts:
            out[rect[0]:rect[1], rect[2]:rect[3]] = buf
    return out
