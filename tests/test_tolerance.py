"""Rendering to a tolerance: the promise kept against the exact image of the reconstructed
field, what is chosen, and what is refused."""

import numpy as np
import pytest

import data_gen
import vrlib
from vrlib import Glow, LookupTransfer, View, metrics, render, render_reference


def steep(volume):
    """A narrow opacity peak, 3% of the value range wide: what point sampling aliases."""
    grid = np.linspace(0.0, 1.0, 1001)
    return LookupTransfer(40.0 * np.clip(1.0 - np.abs(grid - 0.6) / 0.015, 0.0, None),
                          value_range=volume.value_range)


@pytest.mark.parametrize("scene", ["marschner-lobb", "steep", "floor"])
@pytest.mark.parametrize("tolerance", [1e-2, 1e-3])
def test_the_promise_is_kept(scene, tolerance):
    """rmse against the exact image of the field the filter reconstructs is at most the
    tolerance, and the estimate the render reports is within a factor of 3 of it (the
    chapter on time against error measures 45 cases; these are the quick ones)."""
    vol = data_gen.make_field("marschner-lobb").sample(25)
    transfer = Glow(1.0)
    if scene == "steep":
        transfer = steep(vol)
    elif scene == "floor":
        blob = data_gen.make_field("gaussian-blob", sigma=0.25).sample(25)
        vol = vrlib.Volume(blob.data + 0.3, blob.extent)
    view = View.orbit(azimuth=30, elevation=20, size=40)
    exact = render_reference(vrlib.ReconstructedField(vol), view, transfer=transfer, tol=1e-8)
    img = render(vol, view, transfer=transfer, tolerance=tolerance)
    error = metrics.rmse(img, exact)
    assert error <= tolerance
    choices = img.stats.choices
    assert choices["estimate"] <= tolerance
    assert error <= 3.0 * choices["estimate"]
    assert choices["method"] == "raycast" and choices["segment_ends"] == "exact"


@pytest.mark.parametrize("coherent, uncorrelated", [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0),
                                                     (0.3, 1.0)])
@pytest.mark.parametrize("order", [1.0, 1.5, 2.0])
def test_the_finest_pilots_error_is_estimated_from_three_images(coherent, uncorrelated,
                                                                order):
    """Three images at steps h, h/2, h/4 whose errors hold a pattern that shrinks by 2^-p a
    halving (Richardson's model) and noise of the same order that changes its pattern: the
    estimate of the finest image's rms error, from the differences alone, is within 10% of
    it. Without noise it is Richardson's ``d / (2^p - 1)``; with noise alone Richardson's
    overestimates it, 2.2 times at order 1 and 1.4 at order 2 (so for aliased images it
    chose steps half as long as they needed at order 1)."""
    from vrlib.tolerance import finest_error

    rng = np.random.default_rng(7)
    truth, pattern = rng.random(200_000), rng.standard_normal(200_000)
    r = 2.0**-order
    images = [truth + 0.05 * r**k * (coherent * pattern + uncorrelated
                                      * rng.standard_normal(truth.size)) for k in range(3)]
    d0, d1 = images[0] - images[1], images[1] - images[2]
    rms = [float(np.sqrt(np.mean(d * d))) for d in (d0, d1)]
    estimate, kept = finest_error(*rms, float(np.mean(d0 * d1)), order)
    error = metrics.rmse(images[2], truth)
    assert abs(estimate - error) <= 0.1 * error
    richardson = rms[1] / (2.0**order - 1.0)
    assert richardson >= 0.95 * error
    assert abs(kept - 0.05 * coherent * r**2) <= 0.1 * error  # the part keeping its pattern
    if not uncorrelated:
        assert abs(estimate - richardson) <= 0.02 * richardson
    if not coherent:
        assert richardson > 1.3 * estimate


@pytest.mark.parametrize("case", ["confirmed", "refused"])
def test_a_longer_step_is_taken_only_when_a_pilot_confirms_it(case):
    """Where the pilots' differences do not point the same way, the longer step the split
    error allows is rendered as one more pilot and taken only if that pilot bears it out.
    Marschner-Lobb in perspective at 1e-3: confirmed, and the promise kept. Six sparse blobs
    at 1e-4: the longer step (1.15 voxels, off the lattice the pilots' steps sit on) misses
    the tolerance by 1.8 times, so it is refused and Richardson's step (0.99) taken."""
    if case == "confirmed":
        vol = data_gen.make_field("marschner-lobb").sample(41)
        transfer, tolerance = Glow(1.0), 1e-3
        view = View.orbit(azimuth=-60, elevation=35, projection="perspective", size=48)
    else:
        vol = data_gen.make_field("random-blobs", count=6, seed=4, sigma=(0.06, 0.1)).sample(64)
        transfer, tolerance = Glow(8.0), 1e-4
        view = View.orbit(azimuth=30, elevation=20, size=64)
    exact = render_reference(vrlib.ReconstructedField(vol), view, transfer=transfer, tol=1e-8)
    img = render(vol, view, transfer=transfer, tolerance=tolerance)
    choices = img.stats.choices
    checked = choices["pilot"]["checked"]
    assert checked is not None
    assert metrics.rmse(img, exact) <= tolerance
    if case == "confirmed":
        assert choices["step"] == checked
    else:
        assert choices["step"] < checked
        longer = render(vol, view, transfer=transfer, step=checked, segment_ends="exact",
                        early_termination=choices["early_termination"])
        assert metrics.rmse(longer, exact) > tolerance


@pytest.mark.parametrize("filt, n, size, orbit, tolerance, models_step", [
    ("trilinear", 17, 32, {}, 1e-3, 2.0),
    ("catmull-rom", 25, 40, {"azimuth": 30, "elevation": 20}, 3e-3, 1.64)])
def test_a_step_the_coarser_pilot_contradicts_is_not_taken(filt, n, size, orbit, tolerance,
                                                           models_step):
    """The error model extrapolates from the finest pilots; where a coarser pilot measured
    more error than the model gives at its step, steps up to it are not taken on the model's
    word. Marschner-Lobb at 17^3 seen along an axis: the steps of 1 and 1/2 voxel give the
    same image (the trilinear field is linear along the rays between lattice planes), so the
    model saw no error and took 2 voxels, whose error is 6.5 times the tolerance; at 25^3
    with Catmull-Rom within 3e-3, 1.64 voxels missed by 1.6 times."""
    vol = data_gen.make_field("marschner-lobb").sample(n)
    view = View.orbit(size=size, **orbit)
    field = vrlib.ReconstructedField(vol, filter=filt)
    exact = render_reference(field, view, transfer=Glow(1.0), tol=1e-8)
    img = render(vol, view, filter=filt, tolerance=tolerance)
    assert metrics.rmse(img, exact) <= tolerance
    pilot = img.stats.choices["pilot"]
    assert img.stats.choices["step"] in pilot["steps"]  # a pilot's own step
    # the step the model alone gave: it misses the tolerance
    longer = render(vol, view, filter=filt, step=models_step, segment_ends="exact",
                    early_termination=img.stats.choices["early_termination"])
    assert metrics.rmse(longer, exact) > tolerance


def test_the_samples_phase_is_checked_on_views_along_the_lattice():
    """Seen along the lattice every ray samples it at the same phase, and the pilots can agree
    while all miss a narrow peak between their samples. The same view half a step back
    samples the other phase; the step is halved until what that changes fits the tolerance.
    Seen along a diagonal, the pilots' own step misses the tolerance (1.96 times)."""
    vol = data_gen.make_field("marschner-lobb").sample(25)
    transfer, tolerance = steep(vol), 1e-3
    view = View.orbit(size=40, azimuth=45.0)
    exact = render_reference(vrlib.ReconstructedField(vol), view, transfer=transfer, tol=1e-8)
    img = render(vol, view, transfer=transfer, tolerance=tolerance)
    assert metrics.rmse(img, exact) <= tolerance
    phase = img.stats.choices["pilot"]["phase"]
    assert len(phase) >= 2 and img.stats.choices["step"] == phase[-1][0] < phase[0][0]
    pilots_step = render(vol, view, transfer=transfer, step=phase[0][0], segment_ends="exact",
                         early_termination=img.stats.choices["early_termination"])
    assert metrics.rmse(pilots_step, exact) > tolerance


@pytest.mark.parametrize("scene", ["blob", "floor"])
def test_longer_steps_are_taken_on_large_images_when_a_pilot_bears_them_out(scene,
                                                                           monkeypatch):
    """On an image with ``LONGER_PIXELS`` times the pilot's pixels, a step beyond the
    pilot's first (2 voxels) is taken when a pilot at that step keeps the error within the
    share; the promise still holds. (The ratio is lowered here so that a small image
    qualifies: the rule is about sizes, the check the same at any size.)"""
    monkeypatch.setattr(vrlib.tolerance, "LONGER_PIXELS", 4)
    vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(24)
    if scene == "floor":  # live at the faces: the doublings' differences are not negligible
        vol = vrlib.Volume(vol.data + 0.3, vol.extent)
    view = View.orbit(azimuth=30, elevation=20, size=64)
    img = render(vol, view, transfer=Glow(1.0), tolerance=1e-2)
    choices = img.stats.choices
    assert choices["step"] > 2.0
    tried = dict(choices["pilot"]["longer"])  # step: its pilot's difference from 2 voxels'
    share = vrlib.tolerance.STEP_SHARE * 1e-2
    assert choices["step"] in tried and tried[choices["step"]] <= share
    # A longer step tried and not taken differed more (it failed the bound this one met).
    assert all(difference > tried[choices["step"]]
               for step, difference in tried.items() if step > choices["step"])
    exact = render_reference(vrlib.ReconstructedField(vol), view, transfer=Glow(1.0),
                             tol=1e-8)
    assert metrics.rmse(img, exact) <= 1e-2 and choices["estimate"] <= 1e-2


def test_a_small_image_stays_within_the_pilots_first_step():
    """Below ``LONGER_PIXELS`` times the pilot's pixels no longer step is tried: one more
    pilot would cost more than a doubled step saves."""
    vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(24)
    choices = render(vol, View.orbit(size=64), transfer=Glow(1.0), tolerance=1e-2).stats.choices
    assert choices["step"] == 2.0 and choices["pilot"]["longer"] == []


def test_a_smaller_tolerance_takes_a_smaller_step():
    vol = data_gen.make_field("marschner-lobb").sample(25)
    view = View.orbit(azimuth=30, elevation=20, size=40)
    steps = [render(vol, view, tolerance=t).stats.choices["step"] for t in (1e-2, 1e-3, 1e-4)]
    assert steps[0] >= steps[1] > steps[2]


@pytest.mark.parametrize("size, pilot", [(40, (32, 32)), ((200, 160), (50, 40)),
                                         (512, (64, 64)), ((1024, 96), (64, 32))])
def test_the_pilot_takes_a_quarter_of_the_pixels_per_axis_from_32_to_64(size, pilot):
    """A pilot's rays sample the image's: a quarter of them per axis, at least 32 and at most
    64 a side (more cost much on a large image: rays far apart miss the cache)."""
    vol = data_gen.make_field("gaussian-blob").sample(12)
    img = render(vol, View.orbit(size=size), tolerance=1e-2)
    assert tuple(img.stats.choices["pilot"]["shape"]) == pilot


@pytest.mark.slow
@pytest.mark.parametrize("azimuth", [0.0, 3.0])
@pytest.mark.parametrize("size", [136, 152])
def test_the_promise_holds_wherever_the_pilots_rays_fall_on_the_lattice(size, azimuth):
    """A pilot's rays are a coarser grid than the image's, and where they fall on the
    lattice decides what they see of a narrow peak: on chapter 11's Marschner-Lobb 41^3
    under it (views along and near the lattice), pilots of 20, 22 and 24 pixels a side broke
    the promise by up to 6.8 times, while every size from 28 to 48 held, the closest at 0.83
    of the tolerance (docs/kernel.md, the twenty-ninth session). These images take pilots of
    34 and 38 pixels, the package's rule; forced to 20 to 24 pixels, these same cases miss
    by up to 7.9 times."""
    vol = data_gen.make_field("marschner-lobb").sample(41)
    transfer = steep(vol)
    view = View.orbit(size=size, azimuth=azimuth)
    exact = render_reference(vrlib.ReconstructedField(vol), view, transfer=transfer, tol=1e-6)
    for tolerance in (1e-2, 1e-3):
        img = render(vol, view, transfer=transfer, tolerance=tolerance)
        assert img.stats.choices["pilot"]["shape"] == [size // 4] * 2
        assert metrics.rmse(img, exact) <= tolerance


def test_method_auto_is_ray_casting():
    vol = data_gen.make_field("gaussian-blob").sample(12)
    view = View.orbit(size=16)
    img = render(vol, view, method="auto", tolerance=1e-3)
    assert img.stats.choices["method"] == "raycast"
    assert np.array_equal(render(vol, view, method="auto").rgba, render(vol, view).rgba)


def test_without_a_tolerance_nothing_changes():
    """tolerance=None renders with the given settings, bit for bit as a render without it."""
    vol = data_gen.make_field("marschner-lobb").sample(17)
    view = View.orbit(size=24)
    plain = render(vol, view, step=0.5, early_termination=0.999)
    assert np.array_equal(render(vol, view, tolerance=None).rgba, plain.rgba)
    assert plain.stats.choices is None


@pytest.mark.parametrize("options, message", [
    ({"method": "splat"}, "ray casting only"),
    ({"step": 0.5}, "chooses step"),
    ({"early_termination": 0.9}, "chooses early_termination"),
    ({"classification": "point"}, "chooses classification"),
    ({"blend": "maximum"}, "emission-absorption"),
    ({"tolerance": 0.0}, "tolerance"),
    ({"tolerance": 1.5}, "tolerance"),
    ({"tolerance": float("nan")}, "tolerance"),
])
def test_what_a_tolerance_refuses(options, message):
    vol = data_gen.make_field("gaussian-blob").sample(12)
    arguments = {"tolerance": 1e-3, **options}
    with pytest.raises(ValueError, match=message):
        render(vol, View.orbit(size=8), **arguments)


def test_an_unreachable_tolerance_is_refused_with_what_is_reachable():
    """A narrow peak on a coarse volume at 1e-7: the step it needs lies below 1/256 voxel,
    and the error there is named instead of an image returned."""
    vol = data_gen.make_field("marschner-lobb").sample(13)
    with pytest.raises(ValueError, match=r"out of reach .* at least"):
        render(vol, View.orbit(size=16), transfer=steep(vol), tolerance=1e-7)


def test_a_memo_shared_between_renders_changes_no_image():
    """The pilot's renders share what does not depend on the step (``memo``: the footprint
    of the volume's skip grid, the kernel's plan); each image equals the one rendered
    without it, for several steps and two views in turn, and the plan is built once per
    view. The phase check's view, the last one moved back along its direction, keeps both:
    its rays lie on the same lines (a perspective view moved back does not: its own)."""
    from vrlib.filters import make_filter
    from vrlib.raycast import render_raycast

    vol = data_gen.make_field("random-blobs", count=4, seed=2, sigma=(0.06, 0.1)).sample(33)
    views = [View.orbit(azimuth=a, elevation=20, size=24).fitted(vol.extent) for a in (30, 70)]
    ramp = LookupTransfer(np.clip(np.linspace(-4.0, 16.0, 101), 0.0, None))  # empty blocks
    options = dict(filt=make_filter("trilinear"), transfer=ramp, early_termination=1.0,
                   empty_space_skipping=True, segment_ends="exact")
    memo, plans = {}, []
    for view in views:
        for step in (2.0, 1.0, 0.5):
            shared = render_raycast(vol, view, step=step, memo=memo, **options)
            alone = render_raycast(vol, view, step=step, **options)
            assert np.array_equal(shared.rgba, alone.rgba)
            assert shared.alpha.max() > 0.2
            plans.append(memo["ray plan"][1])
    assert [len({id(plan) for plan in plans[n:n + 3]}) for n in (0, 3)] == [1, 1]
    assert plans[0] is not plans[3]
    assert memo["grid"][1].empty.any() and memo["mask"][0][0] is views[-1]
    assert memo["mask"][1].any() and not memo["mask"][1].all()
    mask = memo["mask"][1]
    for back in (0.25, 0.75):
        moved = views[-1].moved_back(back * float(vol.spacing.min()))
        shared = render_raycast(vol, moved, step=1.0, memo=memo, **options)
        assert np.array_equal(shared.rgba, render_raycast(vol, moved, step=1.0, **options).rgba)
        assert memo["ray plan"][1] is plans[-1] and memo["mask"][1] is mask
    eye = View.orbit(azimuth=30, elevation=20, size=24,
                     projection="perspective").fitted(vol.extent)
    assert eye.moved_back(0.1).lines is not eye
