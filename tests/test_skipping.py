"""Empty-space skipping: the emptiness test is conservative for every filter."""

import numpy as np
import pytest
from naive import reconstruct_naive

import data_gen
from vrlib import Glow, LookupTransfer, View, Volume, make_filter, render
from vrlib.skipping import (
    chessboard_distance,
    clearance,
    empty_blocks,
    footprint_mask,
    skip_grid,
)
from vrlib.value_bounds import lattice_sums


def test_lattice_sums_of_known_filters():
    """Partition-of-unity filters sum to 1; only filters with negative lobes have sum |w| > 1;
    Catmull-Rom's 1-D sum |w| peaks at 1.25 (at half a sample: two lobes of -1/16)."""
    for name in ["box", "trilinear", "bspline"]:
        s_min, s_max, a_max = lattice_sums(make_filter(name))
        assert s_min == pytest.approx(1.0) and s_max == pytest.approx(1.0)
        assert a_max == pytest.approx(1.0)
    s_min, s_max, a_max = lattice_sums(make_filter("catmull-rom"))
    assert a_max == pytest.approx(1.25**3, rel=1e-6)
    g_min, g_max, g_abs = lattice_sums(make_filter("gaussian", sigma=0.5))
    assert g_min < 1.0 < g_max and g_abs == pytest.approx(g_max)


def test_filter_margin():
    margins = [make_filter(f).margin for f in ["box", "trilinear", "catmull-rom"]]
    assert margins == [0, 0, 1]
    assert make_filter("gaussian", sigma=0.5, radius=2.5).margin == 2


@pytest.mark.parametrize("filt", ["box", "trilinear", "catmull-rom", "mitchell", "gaussian",
                                  ("gaussian", 0.5, 2.5)], ids=str)
@pytest.mark.parametrize("transfer", [Glow(1.0), LookupTransfer([0.0, 0.0, 1.0],
                                                                value_range=(-1.0, 1.0))],
                         ids=["glow", "table-from-0"])
def test_empty_blocks_are_really_empty(filt, transfer):
    """At random points inside every block marked empty, the reconstruction has zero
    density; overshoot of the cubics near a bright voxel keeps neighbouring blocks marked."""
    rng = np.random.default_rng(0)
    data = np.zeros((17, 17, 17))
    data[rng.integers(0, 17, 6), rng.integers(0, 17, 6), rng.integers(0, 17, 6)] = 1.0
    data[8, 8, 8] = -0.5  # a negative voxel: cubic overshoot around it must not fool the test
    vol = Volume(data)
    f = make_filter(filt)
    empty = empty_blocks(vol, f, transfer, block=4)
    assert 0 < empty.sum() < empty.size
    for idx in np.argwhere(empty):
        pts = (idx[::-1] + rng.uniform(0, 1, (20, 3))) * 4  # index coords inside the block
        values = reconstruct_naive(vol, f, np.minimum(pts, 16))
        assert np.all(transfer.opacity_density(values) == 0.0)


def test_vectorised_max_density_matches_scalar():
    rng = np.random.default_rng(4)
    tf = LookupTransfer(rng.uniform(0, 3, 37) * (rng.uniform(0, 1, 37) > 0.5),
                        value_range=(-1.0, 2.0))
    lo = rng.uniform(-2, 3, 500)
    hi = lo + rng.exponential(0.3, 500)
    many = tf.max_density(lo, hi)
    one = np.array([tf.max_density(a, b) for a, b in zip(lo, hi, strict=True)])
    np.testing.assert_array_equal(many, one)
    for a, b, m in zip(lo[:50], hi[:50], many[:50], strict=True):
        assert m == pytest.approx(tf.opacity_density(np.linspace(a, b, 20001)).max(), abs=1e-3)


@pytest.mark.parametrize("shape", [(1, 1, 9), (5, 7, 6), (16, 9, 12)])
@pytest.mark.parametrize("fraction", [0.3, 0.9, 0.999])
def test_chessboard_distance_is_scipys(shape, fraction):
    """The skip grid's distances (NumPy alone) are SciPy's chessboard distance transform's,
    sparse to dense grids, one with a single block that is not far."""
    from scipy.ndimage import distance_transform_cdt

    far = np.random.default_rng(len(shape) + int(1000 * fraction)).random(shape) < fraction
    far.flat[far.size // 3] = False
    expected = distance_transform_cdt(far, metric="chessboard")
    assert np.array_equal(chessboard_distance(far), expected)
    assert expected.max() >= 2 or fraction < 0.5


def test_chessboard_distance_refuses_a_grid_with_nothing_to_measure_from():
    """A grid that is far everywhere has no distance to measure: refused, not dilated for
    ever."""
    with pytest.raises(ValueError, match="far must be False somewhere"):
        chessboard_distance(np.ones((3, 4, 5), dtype=bool))


@pytest.mark.parametrize("through", [True, False])
@pytest.mark.parametrize("seed", range(4))
def test_clearance_is_how_far_a_ray_may_go_unchecked(seed, through):
    """A ray jumps (empty) or samples unchecked (not empty) across the cube of 2|d| - 1
    blocks around a block of clearance d. An empty block's cube must hold only empty blocks;
    a non-empty block's no deep empty block (one two or more blocks from any non-empty
    block: there a jump would pay; with ``through=False`` no empty block at all). And the
    cube must be as large as that allows: a block of the kind that stops it lies at distance
    |d|. Brute force on random grids, sparse to dense, and the grids of one kind only."""
    rng = np.random.default_rng(seed)
    empty = rng.random((5, 7, 6)) < (0.3, 0.7, 0.95, 0.99)[seed]
    reach = clearance(empty, through=through)
    index = np.indices(empty.shape).reshape(3, -1).T
    flat = empty.reshape(-1)
    full_at = index[~flat]
    away = np.array([np.abs(full_at - here).max(axis=1).min() if here_empty else 0
                     for here, here_empty in zip(index, flat, strict=True)])
    deep = away >= (2 if through else 1)
    for n, here in enumerate(index):
        distance = np.abs(index - here).max(axis=1)
        stops = ~flat if flat[n] else deep
        d = reach[tuple(here)]
        assert (d > 0) == flat[n]
        if stops.any():
            assert distance[stops].min() == abs(d)
        else:
            assert abs(d) == max(empty.shape)
    assert (clearance(np.ones((2, 3, 4), bool)) == 4).all()
    assert (clearance(np.zeros((2, 3, 4), bool)) == -4).all()


@pytest.mark.parametrize("projection, seed", [("orthographic", 0), ("orthographic", 1),
                                              ("perspective", 2), ("orthographic", 3)])
def test_footprint_mask_is_each_blocks_rectangle_painted(projection, seed):
    """The pixels whose rays may meet a non-empty block (the ray caster samples no other):
    the union of the blocks' projected corner rectangles, one pixel wider all round. Painted
    here block by block, and compared pixel for pixel with the mask built from marks and
    prefix sums, on random grids (sparse to nearly empty) and a zoomed, non-square view
    whose rectangles run off the image."""
    rng = np.random.default_rng(seed)
    volume = Volume(np.zeros((24, 40, 32)), spacing=(1.0, 0.5, 2.0))
    empty = rng.random((3, 5, 4)) < (0.5, 0.8, 0.9, 0.97)[seed]
    view = View.fit(volume, size=(37, 53), azimuth=25.0 * seed + 10.0, elevation=20.0 - 9 * seed,
                    projection=projection, zoom=2.5 if seed == 3 else 1.0)
    painted = np.zeros(view.shape, dtype=bool)
    for bz, by, bx in np.argwhere(~empty):
        corners = [[min((bx + i) * 8, 31), min((by + j) * 8, 39), min((bz + k) * 8, 23)]
                   for i in (0, 1) for j in (0, 1) for k in (0, 1)]
        rc = view.project(volume.origin + np.array(corners) * volume.spacing)[:, :2]
        r0, c0 = np.floor(rc.min(axis=0)).astype(int) - 1
        r1, c1 = np.floor(rc.max(axis=0)).astype(int) + 2
        painted[max(r0, 0):max(r1, 0), max(c0, 0):max(c1, 0)] = True
    np.testing.assert_array_equal(footprint_mask(view, volume, empty, 8), painted)


@pytest.mark.parametrize("method, options", [
    ("raycast", {}),
    ("raycast", {"classification": "preintegrated"}),
    ("raycast", {"skip_budget": 1e-3}),
    ("splat", {}),
    ("shear3", {}),
    ("shearwarp", {}),
])
def test_a_transfer_function_changed_in_place_is_not_served_from_a_cache(method, options):
    """What renders keep between calls (a volume's skip grid, a transfer function's
    segment and pre-integrated tables, splatting's culled voxels) is kept under the transfer
    function's settings (``cache_key``). A table changed in place after a render, so that
    other blocks show, must render as a new transfer function with those settings does: a
    grid or table kept under the old settings would leave the newly visible blobs' edges
    out."""
    vol = data_gen.make_field("random-blobs", count=3, seed=1).sample(24)
    view = View.orbit(size=24, azimuth=20.0, elevation=10.0)
    tf = LookupTransfer([0.0, 0.0, 4.0, 4.0], value_range=vol.value_range)
    before = render(vol, view, method=method, transfer=tf, **options)
    tf.density[:] = [0.0, 4.0, 0.0, 0.0]
    changed = render(vol, view, method=method, transfer=tf, **options)
    same = LookupTransfer(tf.density.copy(), value_range=vol.value_range)
    fresh = render(vol, view, method=method, transfer=same, **options)
    assert np.abs(fresh.rgba - before.rgba).max() > 0.05  # the change shows
    np.testing.assert_array_equal(changed.rgba, fresh.rgba)


class _ComparedGlow(Glow):
    """A user's subclass that defines ``==`` and so, in Python, no hash: no weak key."""

    def __eq__(self, other):
        return isinstance(other, _ComparedGlow) and other.scale == self.scale


class _UnpicklableGlow(Glow):
    """A user's subclass holding what pickle refuses: no settings key."""

    def __init__(self, scale):
        super().__init__(scale)
        self.note = lambda: None


@pytest.mark.parametrize("cls", [_ComparedGlow, _UnpicklableGlow])
@pytest.mark.parametrize("classification", ["point", "preintegrated"])
def test_a_transfer_function_that_cannot_be_kept_under_renders_as_its_settings(cls,
                                                                            classification):
    """Tables are kept with a transfer function under its settings, in a weak dictionary
    keyed by the object; a subclass that cannot be hashed or pickled keeps nothing and
    renders, twice, as the built-in function with its settings."""
    vol = data_gen.make_field("random-blobs", count=3, seed=1).sample(16)
    view = View.orbit(size=12, azimuth=20.0)
    want = render(vol, view, transfer=Glow(3.0), classification=classification)
    for _ in range(2):
        got = render(vol, view, transfer=cls(3.0), classification=classification)
        np.testing.assert_array_equal(got.rgba, want.rgba)


def test_the_skip_grid_is_kept_per_filter_and_transfer_function():
    """One grid per (filter, transfer function settings), built once: equal settings in a
    new object find it, another filter or scale builds its own, and the grid is read-only
    (a render cannot spoil it for the next)."""
    vol = data_gen.make_field("random-blobs", count=3, seed=1).sample(24)
    tent, cubic = make_filter("trilinear"), make_filter("catmull-rom")
    grid = skip_grid(vol, tent, Glow(1.0))
    assert skip_grid(vol, tent, Glow(1.0)) is grid
    assert skip_grid(vol, cubic, Glow(1.0)) is not grid
    assert skip_grid(vol, tent, Glow(2.0)) is not grid
    np.testing.assert_array_equal(grid.empty, empty_blocks(vol, tent, Glow(1.0)))
    np.testing.assert_array_equal(grid.clearance, clearance(grid.empty))
    with pytest.raises(ValueError):
        grid.empty[0, 0, 0] = True
