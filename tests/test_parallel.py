"""vrlib.parallel without MPI: partitions, routing, frame traffic and the analytic model."""

import math

import numpy as np
import pytest

from vrlib import View
from vrlib.parallel import composite, decompose, model, network, taxonomy, traffic

ORIGIN = np.array([-1.0, -1.0, -1.0])


def lattice(n):
    return ORIGIN, np.full(3, 2.0 / (n - 1))


# ---------------------------------------------------------------- decompositions


@pytest.mark.parametrize("parts", [1, 2, 3, 5, 6, 7, 8, 12])
@pytest.mark.parametrize("shape", ["slabs", "shafts", "blocks"])
def test_split_tiles_the_volume_exactly(parts, shape):
    """Every cell belongs to exactly one brick, and only the shape's axes are cut."""
    cells = (13, 14, 15)
    tree = decompose.split(cells, parts, shape=shape)
    count = np.zeros(cells, dtype=int)
    for b in tree.bricks:
        count[b.lo[0]:b.hi[0], b.lo[1]:b.hi[1], b.lo[2]:b.hi[2]] += 1
        for axis in set(range(3)) - set(decompose.SHAPES[shape]):
            assert (b.lo[axis], b.hi[axis]) == (0, cells[axis])
    assert len(tree) == parts and np.all(count == 1)
    assert sorted(tree.leaves()) == list(range(parts))


def test_weighted_split_balances_the_weights():
    """With all the weight in one corner, the split puts it evenly across bricks."""
    weights = np.zeros((32, 32, 32))
    weights[:8, :8, :8] = 1.0
    tree = decompose.split((32, 32, 32), 8, weights=weights)
    shares = [weights[b.lo[0]:b.hi[0], b.lo[1]:b.hi[1], b.lo[2]:b.hi[2]].sum()
              for b in tree.bricks]
    assert max(shares) / np.mean(shares) < 1.2
    even = decompose.split((32, 32, 32), 8)
    even_shares = [weights[b.lo[0]:b.hi[0], b.lo[1]:b.hi[1], b.lo[2]:b.hi[2]].sum()
                   for b in even.bricks]
    assert max(even_shares) / np.mean(even_shares) == 8.0


def test_split_refuses_more_parts_than_cells():
    with pytest.raises(ValueError, match="cannot split"):
        decompose.split((3, 3, 3), 4, shape="slabs")
    with pytest.raises(ValueError, match="weights must have shape"):
        decompose.split((4, 4, 4), 2, weights=np.ones((3, 3, 3)))


def test_grid_split_is_the_regular_grid():
    tree = decompose.split((8, 8, 8), 8, grid=(2, 2, 2))
    assert sorted((b.lo, b.hi) for b in tree.bricks)[0] == ((0, 0, 0), (4, 4, 4))
    assert all(b.cells == (4, 4, 4) for b in tree.bricks)


def ray_entries(tree, view, origin, spacing):
    """For each brick: where every (seventh) ray enters it (NaN if it misses)."""
    o, d = view.rays()
    o, d = o.reshape(-1, 3)[::7], d.reshape(-1, 3)[::7]
    for b in tree.bricks:
        lo, hi = b.world_box(origin, spacing)
        with np.errstate(divide="ignore", invalid="ignore"):
            t0, t1 = (lo - o) / d, (hi - o) / d
        t_in = np.nanmax(np.minimum(t0, t1), axis=1)
        t_out = np.nanmin(np.maximum(t0, t1), axis=1)
        yield b.index, np.where(t_out > t_in + 1e-9, t_in, np.nan)


@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
@pytest.mark.parametrize("azimuth,elevation", [(30, 20), (-120, -50), (200, 70), (0, 0)])
def test_tree_order_is_front_to_back_along_every_ray(projection, azimuth, elevation):
    """Two bricks one ray meets are ordered as the ray meets them."""
    n = 17
    origin, spacing = lattice(n)
    tree = decompose.split((n - 1,) * 3, 7)
    view = View.orbit(azimuth=azimuth, elevation=elevation, size=64, projection=projection)
    rank = {b: i for i, b in enumerate(tree.order(view, origin, spacing))}
    entries = list(ray_entries(tree, view, origin, spacing))
    for i, t_i in entries:
        for j, t_j in entries:
            both = np.isfinite(t_i) & np.isfinite(t_j) & (t_i < t_j - 1e-9)
            if both.any():
                assert rank[i] < rank[j], (i, j)


def test_screen_tiles_cover_the_screen_once():
    for layout in ("contiguous", "interleaved"):
        tiles = decompose.screen_tiles(50, 70, 6, layout=layout, tile=8)
        area = np.zeros((50, 70), dtype=int)
        for node in range(6):
            for r0, r1, c0, c1 in tiles.rects(node):
                area[r0:r1, c0:c1] += 1
        assert np.all(area == 1)
    with pytest.raises(ValueError, match="unknown layout"):
        decompose.screen_tiles(8, 8, 2, layout="random")


# ---------------------------------------------------------------- routing


def walk(net, s, d):
    """Channels a message crosses, hop by hop (the routing rule written out plainly)."""
    x, y = s % net.columns, s // net.columns
    tx, ty = d % net.columns, d // net.columns
    hops = []
    for axis, length in ((0, net.columns), (1, net.rows)):
        here, there = (x, tx) if axis == 0 else (y, ty)
        ahead, behind = (there - here) % length, (here - there) % length
        forward = ahead <= behind if net.torus else there > here
        while here != there:
            if forward:
                hops.append((axis, +1, here, y if axis == 0 else tx))
                here = (here + 1) % length
            else:
                here = (here - 1) % length
                hops.append((axis, -1, here, y if axis == 0 else tx))
        if axis == 0:
            x = here
    return hops


@pytest.mark.parametrize("torus", [False, True])
@pytest.mark.parametrize("columns,rows", [(4, 4), (5, 3), (1, 6), (8, 2)])
def test_routing_matches_a_hop_by_hop_walk(torus, columns, rows):
    net = network.Network(columns, rows, torus=torus)
    rng = np.random.default_rng(3)
    src = rng.integers(0, net.nodes, 300)
    dst = rng.integers(0, net.nodes, 300)
    size = rng.uniform(1, 10, 300)
    load = net.route(src, dst, size)
    expected = {"east": np.zeros_like(load.east), "west": np.zeros_like(load.west),
                "north": np.zeros_like(load.north), "south": np.zeros_like(load.south)}
    for s, d, b in zip(src, dst, size, strict=True):
        for axis, sign, link, lane in walk(net, s, d):
            name = {(0, 1): "east", (0, -1): "west", (1, 1): "north", (1, -1): "south"}
            expected[name[(axis, sign)]][lane, link] += b
    for name, array in expected.items():
        np.testing.assert_allclose(getattr(load, name), array, atol=1e-9)
    # Bytes on channels = bytes x hops.
    assert load.total == pytest.approx(float((size * net.hops(src, dst)).sum()))


def test_routing_a_frame_of_4096_nodes():
    """A frame of a million messages on 64 x 64 nodes routes (the issue asks for seconds)."""
    net = network.Network.square(4096, torus=True)
    rng = np.random.default_rng(0)
    src, dst = rng.integers(0, 4096, (2, 1_000_000))
    load = net.route(src, dst, np.ones(src.size))
    assert load.total == pytest.approx(float(net.hops(src, dst).sum()))


def test_bad_messages_are_refused():
    net = network.Network(2, 2)
    with pytest.raises(ValueError, match="dst must name nodes 0..3"):
        net.route([0], [4], [1.0])
    with pytest.raises(ValueError, match="one entry per message"):
        net.route([0, 1], [1], [1.0])
    with pytest.raises(ValueError, match="finite and non-negative"):
        net.route([0], [1], [np.nan])


# ---------------------------------------------------------------- traffic and model


def test_classic_binary_swap_sends_w2_one_minus_one_over_p():
    """Full-screen binary swap: each node sends W^2 (1 - 1/P) pixels (docs/derivations.md)."""
    origin, spacing = lattice(33)
    view = View.orbit(azimuth=30, elevation=20, size=64)
    for parts in (2, 4, 8, 16):
        tree = decompose.split((32, 32, 32), parts)
        msgs = composite.binary_swap_messages(tree, view, origin, spacing, bounded=False)
        per_node = msgs.sent_per_node(parts)
        np.testing.assert_allclose(per_node, 64 * 64 * 4 * (1 - 1 / parts))
        assert model.binary_swap_frame(parts, 64, 64)[0] == per_node[0]
        bounded = composite.binary_swap_messages(tree, view, origin, spacing).total
        assert bounded < msgs.total


@pytest.mark.parametrize("parts", [2, 4, 8, 16, 64])
def test_radix_k_with_k_two_is_binary_swap(parts):
    """Radix-k with k = 2 in every round cuts the same k-d tree and sends exactly binary
    swap's messages, round by round."""
    origin, spacing = lattice(33)
    view = View.orbit(azimuth=30, elevation=20, size=64)
    radix = composite.RadixK(target=2)
    tree = radix.split((32, 32, 32), parts)
    assert tree == decompose.split((32, 32, 32), parts)
    swap = composite.binary_swap_rounds(tree, view, origin, spacing)[1:]  # no fold
    for a, b in zip(radix.rounds(tree, np.arange(parts), None, view, origin, spacing), swap,
                    strict=True):
        assert (a.src.tolist(), a.dst.tolist(), a.bytes.tolist()) == \
            (b.src.tolist(), b.dst.tolist(), b.bytes.tolist())


@pytest.mark.parametrize("parts", [1, 2, 3, 6, 7, 12, 30, 64, 96, 4096])
@pytest.mark.parametrize("target", [2, 3, 8, 64])
def test_radix_factors_multiply_to_the_count(parts, target):
    """The default factorisation multiplies to the rank count, each factor at most the target
    unless a prime exceeds it, and no two neighbouring factors could be merged."""
    factors = composite.radix_factors(parts, target)
    assert math.prod(factors) == parts
    for f in factors:
        assert f <= target or all(f % p for p in range(2, math.isqrt(f) + 1))


@pytest.mark.parametrize("groups", [[2, 3], [3, 2], [2, 2, 3], [5], [3, 4]])
def test_grouped_split_makes_every_group_a_subtree(groups):
    """Every block of k_1, k_1 k_2, ... consecutive bricks is one subtree of the k-d tree, so
    that radix-k's groups are contiguous in every visibility order."""
    parts = math.prod(groups)
    tree = decompose.split((24, 24, 24), parts, groups=groups)
    subtrees = set()

    def visit(node):
        leaves = tuple(tree.leaves(node))
        subtrees.add(leaves)
        if isinstance(node, tuple):
            visit(node[2])
            visit(node[3])

    visit(tree.node)
    size = 1
    for k in groups:
        size *= k
        for start in range(0, parts, size):
            assert tuple(range(start, start + size)) in subtrees
    for view in (View.orbit(azimuth=a, elevation=e, size=8) for a, e in [(30, 20), (-100, 60)]):
        order = tree.order(view, *lattice(25))
        for block in (b for b in subtrees if len(b) > 1):
            where = sorted(order.index(i) for i in block)
            assert where == list(range(where[0], where[0] + len(block)))


def test_radix_k_sends_the_classic_count_with_full_regions():
    """Sending whole pieces, each node sends (1 - 1/P) of the image over radix-k's rounds,
    whatever the factorisation (as binary swap does); bounded rectangles send less."""
    origin, spacing = lattice(33)
    view = View.orbit(azimuth=30, elevation=20, size=60)
    for factors in ([2, 3], [6], [3, 2, 2], [4, 3]):
        parts = math.prod(factors)
        tree = decompose.split((32, 32, 32), parts, groups=factors)
        full = composite.radix_k_messages(tree, view, origin, spacing, factors,
                                          bytes_per_pixel=1, bounded=False)
        np.testing.assert_allclose(full.sent_per_node(parts), 60 * 60 * (1 - 1 / parts))
        assert composite.radix_k_messages(tree, view, origin, spacing, factors).total < \
            4 * full.total


def test_direct_send_matches_the_bounding_rectangle_model():
    """Simulated direct-send bytes against the model's bounding rectangles for the same view,
    within 5%: pixel rounding at rectangle edges, and the model keeps ``1/P`` of each local
    image on its own node, where the simulation keeps what falls on the node's own tile
    (measured: blocks and shafts within 2%, 16 slabs 3%)."""
    n = 129
    origin, spacing = lattice(n)
    view = View.orbit(azimuth=30, elevation=20, size=512)
    for parts, shape in [(64, "blocks"), (64, "shafts"), (16, "slabs")]:
        grid = decompose.grid_shape(parts, shape)
        tree = decompose.split((n - 1,) * 3, parts, grid=grid)
        msgs, local = composite.direct_send_messages(tree, np.arange(parts),
                                                     decompose.screen_tiles(512, 512, parts),
                                                     view, origin, spacing)
        _, total = model.object_frame(grid, side=2.0, pixel=view.pixel_size, view=view)
        assert msgs.total == pytest.approx(total, rel=0.05)


def test_cauchy_mean_area_against_many_views():
    """The mean projected area over directions is a quarter of the surface (Cauchy)."""
    rng = np.random.default_rng(1)
    d = rng.normal(size=(20000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    sides = (0.5, 1.0, 2.0)
    mean = np.mean([model.projected_area(sides, v) for v in d])
    assert mean == pytest.approx(model.projected_area(sides), rel=0.01)


def test_image_static_traffic_is_nearly_the_whole_volume():
    """Each tile owner receives the voxels behind its tile from the other nodes: the total
    is N^3 (1 - 1/P) times the border factor, to 15%."""
    n, parts, size = 65, 16, 256
    origin, spacing = lattice(n)
    view = View.orbit(azimuth=10, elevation=5, size=size)
    tree = decompose.split((n - 1,) * 3, parts)
    tiles = decompose.screen_tiles(size, size, parts)
    msgs = traffic.image_static(tree, np.arange(parts), tiles, view, (n,) * 3, origin,
                                spacing, radius=1.0)
    # Only voxels that project inside the image count: the volume fills part of the screen.
    reach = float(np.linalg.norm(spacing)) / view.pixel_size
    _, total = model.image_static_frame(parts, n**3, tile=size / 4, reach=reach)
    assert msgs.total == pytest.approx(total, rel=0.15)


def test_image_dynamic_traffic_against_the_model():
    n, parts, size = 65, 16, 256
    origin, spacing = lattice(n)
    before = View.orbit(azimuth=0, elevation=0, size=size, zoom=math.sqrt(3))
    after = View.orbit(azimuth=2, elevation=0, size=size, zoom=math.sqrt(3))
    tiles = decompose.screen_tiles(size, size, parts)
    msgs = traffic.image_dynamic(tiles, before, after, (n,) * 3, origin, spacing)
    _, total = model.image_dynamic_frame(parts, n**3, dtheta=math.radians(2), depth=2.0,
                                         tile_width=size / 4, pixel=before.pixel_size)
    assert msgs.total == pytest.approx(total, rel=0.25)


def test_mean_hops_against_routing():
    rng = np.random.default_rng(2)
    for torus in (False, True):
        net = network.Network.square(64, torus=torus)
        src, dst = rng.integers(0, 64, (2, 200000))
        assert net.hops(src, dst).mean() == pytest.approx(model.mean_hops(64, torus=torus),
                                                          rel=0.01)


def test_taxonomy_lists_every_class_with_its_communication():
    assert len(taxonomy.TAXONOMY) == 16
    for p in taxonomy.TAXONOMY:
        what, grows = taxonomy.communication(p)
        assert what and grows
    assert "voxels" in taxonomy.communication(taxonomy.Partition("image", "tiles"))[0]
    assert "fragments" in taxonomy.communication(taxonomy.Partition("object", "blocks"))[0]
    with pytest.raises(ValueError, match="unknown layout"):
        taxonomy.Partition("object", "blocks", layout="striped")
