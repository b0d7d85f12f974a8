"""Adaptive steps (vrlib.adaptive): long segments where the classified field changes slowly,
checked against the by-the-book twin, across bricks and threads, and against their bound."""

import numba
import numpy as np
import pytest
from naive import raycast_naive

import data_gen
import vrlib
from vrlib import Glow, LookupTransfer, Phong, View, render
from vrlib.adaptive import block_differences, gradient_bounds, step_multipliers
from vrlib.raycast import brightest, cast_rays
from vrlib.skipping import clearance
from vrlib.value_bounds import reconstructed_range

TABLE = LookupTransfer([0.0, 3.0, 0.5, 4.0], color=[[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])


def _grid(vol, seed):
    """Random multipliers (1, 2, 4, 8) per block, 1 in the blocks past the far faces."""
    counts = [-(-(n - 1) // 8) for n in vol.shape]
    multiplier = np.random.default_rng(seed).choice([1, 2, 4, 8], size=counts)
    for axis, n in enumerate(vol.shape):
        if (n - 1) % 8:
            multiplier[(slice(None),) * axis + (-1,)] = 1
    return multiplier


def _cast(vol, view, filt, transfer, step, multiplier, *, ends="lattice", data=None,
          first=0, box=None):
    """cast_rays over all of ``vol`` (or the brick ``data`` from z = ``first``, its own
    ``box``) with the given multipliers and no empty block."""
    empty = np.zeros(multiplier.shape, dtype=bool)
    ext = vol.extent
    rgba, taken = cast_rays(
        vol.data if data is None else data, offset=(first, 0, 0), global_shape=vol.shape,
        origin=vol.origin, spacing=vol.spacing,
        box=(ext[:, 0], ext[:, 1]) if box is None else box, view=view, filt=filt,
        transfer=transfer, ds=step * vol.spacing.min(),
        value_range=reconstructed_range(vol, filt), early_termination=1.0,
        skip=(empty, clearance(empty), 8, np.ones(view.shape, dtype=bool)),
        exact_ends=ends == "exact", multiplier=multiplier)
    return rgba, taken


# One combination of each choice runs in make test, every combination in make test-all.
TWIN_CASES = [pytest.param(ends, projection, filt, transfer, id=f"{ends}-{projection}-{filt}-"
                           f"{name}", marks=() if (ends, projection, filt, name) in {
                               ("lattice", "orthographic", "trilinear", "glow"),
                               ("exact", "perspective", "catmull-rom", "table")}
                           else pytest.mark.slow)
              for ends in ("lattice", "exact") for projection in ("orthographic", "perspective")
              for filt in ("trilinear", "catmull-rom")
              for name, transfer in (("glow", Glow(3.0)), ("table", TABLE))]


@pytest.mark.parametrize(("ends", "projection", "filt", "transfer"), TWIN_CASES)
def test_long_segments_match_naive_twin(ends, projection, filt, transfer):
    """The kernel's long segments (aligned runs of 2, 4 or 8 steps inside one block, sampled
    at their middle) equal the twin's, for random multipliers on a volume of 3x2x3 blocks."""
    vol = data_gen.make_field("marschner-lobb").sample((21, 17, 20))
    view = View.orbit(azimuth=33, elevation=-21, size=(9, 11), projection=projection)
    multiplier = _grid(vol, 7)
    filt = vrlib.make_filter(filt)
    fast, taken = _cast(vol, view, filt, transfer, 0.37, multiplier, ends=ends)
    slow = raycast_naive(vol, view, filt, transfer, 0.37, ends, multiplier=multiplier)
    np.testing.assert_allclose(fast, slow, atol=1e-6)
    plain, all_taken = _cast(vol, view, filt, transfer, 0.37, np.ones_like(multiplier),
                             ends=ends)
    assert taken < 0.8 * all_taken  # long segments were taken
    assert np.abs(fast - plain).max() > 1e-4  # and they change the image


def test_bricks_take_the_same_long_segments():
    """Two bricks cut at z = 10 (inside a block: long segments straddle the cut) compose to
    the whole volume's image: each long segment is taken once, by the brick that holds its
    sample."""
    vol = data_gen.make_field("marschner-lobb").sample((25, 21, 22))
    view = View.orbit(azimuth=-70, elevation=25, size=30)
    filt = vrlib.make_filter("catmull-rom")
    multiplier = _grid(vol, 3)
    whole, _ = _cast(vol, view, filt, Glow(1.0), 0.41, multiplier)
    split, ghost = 10, 2
    ext = vol.extent
    z_cut = ext[2, 0] + split * vol.spacing[2]
    parts = []
    for first, stop, (z_lo, z_hi) in [(0, split + ghost + 1, (ext[2, 0], z_cut)),
                                      (split - ghost, vol.shape[0], (z_cut, ext[2, 1]))]:
        rgba, _ = _cast(vol, view, filt, Glow(1.0), 0.41, multiplier,
                        data=np.ascontiguousarray(vol.data[first:stop]), first=first,
                        box=([ext[0, 0], ext[1, 0], z_lo], [ext[0, 1], ext[1, 1], z_hi]))
        parts.append(rgba)
    composited = vrlib.compositing.over(parts[1], parts[0])
    np.testing.assert_allclose(composited, whole, atol=1e-14)


@pytest.mark.parametrize("scene", ["blob", "tails", "marschner-lobb", "blobs-table"])
@pytest.mark.parametrize("budget", [1e-2, 1e-3])
def test_image_moves_within_the_step_budget(scene, budget):
    """No channel of any pixel moves by more than ``step_budget`` from the image at the base
    step (early termination off, so that only the steps differ).

    Measured (64^3 and 48^3, 96^2, step 0.5): the bound is loose by 10^3 to 10^5 (largest
    change at budget 1e-1 / 1e-2 / 1e-3: blob 5.1e-5 / 1.6e-6 / 1.2e-7, random blobs with a
    table 4.3e-6 / 1.4e-7 / 3.2e-10), so the saving is small: samples 0.73 / 0.95 / 0.99 of
    the base step's on the blob, 0.94 / 0.95 / 0.98 on the random blobs, none on
    Marschner-Lobb and on the wide blob (sigma 0.5, Glow(4)) below 1e-1. The test asserts the
    bound and that the blob does take long segments."""
    fields = {"blob": ("gaussian-blob", {"sigma": 0.3}, 64, Glow(1.0)),
              "tails": ("gaussian-blob", {"sigma": 0.5}, 48, Glow(4.0)),
              "marschner-lobb": ("marschner-lobb", {}, 48, Glow(1.0)),
              "blobs-table": ("random-blobs", {}, 48, TABLE)}
    name, params, n, transfer = fields[scene]
    vol = data_gen.make_field(name, **params).sample(n)
    view = View.orbit(azimuth=25, elevation=30, size=96)
    base = render(vol, view, transfer=transfer, early_termination=1.0)
    adaptive = render(vol, view, transfer=transfer, early_termination=1.0, step_budget=budget)
    assert np.abs(adaptive.rgba - base.rgba).max() <= budget
    if scene == "blob" and budget == 1e-2:
        assert adaptive.stats.samples < base.stats.samples


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="a single CPU")
def test_adaptive_steps_bit_identical_for_one_and_two_threads(monkeypatch):
    monkeypatch.setattr(vrlib.raycast, "ONE_THREAD_SAMPLES", 0)  # small renders on two too
    vol = data_gen.make_field("gaussian-blob", sigma=0.4).sample(33)
    view = View.orbit(azimuth=20, elevation=35, size=70)
    one = render(vol, view, threads=1, step_budget=1e-2)
    two = render(vol, view, threads=2, step_budget=1e-2)
    assert np.array_equal(one.rgba, two.rgba)
    assert one.stats.samples == two.stats.samples


def test_bounds_hold_on_random_rays():
    """The per-block gradient bound holds for the filter's own gradient at random points
    (the reconstruction's derivative through the kernel's weights)."""
    vol = data_gen.make_field("marschner-lobb").sample(17)
    for name in ("trilinear", "catmull-rom", "gaussian"):
        filt = vrlib.make_filter(name)
        bound = gradient_bounds(vol, filt)
        rng = np.random.default_rng(1)
        points = rng.uniform(vol.extent[:, 0], vol.extent[:, 1], size=(400, 3))
        grad = vrlib.reconstruct(vol, points, filter=filt, derivative=True)
        index = np.clip(np.floor(vol.world_to_index(points) / 8).astype(int), 0,
                        np.array(bound.shape[::-1]) - 1)
        assert np.all(np.linalg.norm(grad, axis=1)
                      <= bound[index[:, 2], index[:, 1], index[:, 0]] * (1 + 1e-9))


def test_differences_are_cached_and_multipliers_are_powers_of_two():
    vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(33)
    assert block_differences(vol) is block_differences(vol)
    m = step_multipliers(vol, vrlib.make_filter("trilinear"), Glow(1.0), 0.03, 1e-1,
                         value_range=(0.0, 1.0), brightest=brightest(Glow(1.0), (0.0, 1.0)))
    assert set(np.unique(m)) <= {1, 2, 4, 8} and m.max() > 1


@pytest.mark.parametrize(("options", "message"), [
    ({"step_budget": -1.0}, "step_budget"),
    ({"step_budget": float("nan")}, "step_budget"),
    ({"step_budget": 1e-2, "classification": "preintegrated"}, "classification='point'"),
    ({"step_budget": 1e-2, "transfer": Glow(1.0, shading=Phong())}, "shading"),
    ({"step_budget": 1e-2, "empty_space_skipping": False}, "empty_space_skipping=True"),
])
def test_step_budget_refusals(options, message):
    vol = data_gen.make_field("gaussian-blob").sample(9)
    with pytest.raises(ValueError, match=message):
        render(vol, View.orbit(size=8), **options)
