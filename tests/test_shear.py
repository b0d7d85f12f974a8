"""Volume shearing: three-pass, two-pass and shear-warp against their twins and the truth."""

import numba
import numpy as np
import pytest
from naive import (
    exact_blob_image,
    image_mass,
    random_orbits,
    shear_naive,
    shearwarp_naive,
)

import data_gen
import vrlib
from vrlib import Glow, LookupTransfer, View, Volume, metrics, render
from vrlib.shear import plan_shear
from vrlib.shearwarp import warp

TABLE = LookupTransfer([0.0, 3.0, 1.0, 5.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])
FILTERS = ["box", "trilinear", "catmull-rom", "gaussian", "omoms"]
METHODS = ["shear3", "shear2", "shearwarp"]


def small_volume():
    return data_gen.make_field("random-blobs", count=4, seed=2).sample((5, 6, 7))


LIT = LookupTransfer([0.0, 3.0, 1.0, 5.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]],
                     shading=vrlib.Phong(specular=0.4, light=[0.0, 0.6, 0.8]),
                     gradient_opacity=vrlib.GradientOpacity([0.0, 2.0], [0.2, 1.0]))
TRANSFERS = {"glow": Glow(3.0), "table": TABLE, "lit-table": LIT,
             "headlight": Glow(3.0, shading=vrlib.Phong()),
             "gradient-opacity": Glow(3.0, gradient_opacity=vrlib.GradientOpacity([0.0, 1.0],
                                                                                  [0.0, 1.0]))}


@pytest.mark.parametrize("filt", FILTERS)
@pytest.mark.parametrize("transfer", TRANSFERS.values(), ids=TRANSFERS.keys())
@pytest.mark.parametrize("method", ["shear3", "shear2"])
def test_passes_match_naive_twin(filt, transfer, method):
    """The pass and compositing kernels follow the plan by the book. The intermediate volumes
    are float32: measured differences up to 8e-7, hence the 2e-6 bound. Shading and gradient
    opacity: the samples' central differences go through the same passes as the values, and
    each sample is classified by its resampled gradient, as the twin does."""
    vol = small_volume()
    view = View.orbit(azimuth=33, elevation=-21, size=(7, 9))
    fast = render(vol, view, method=method, filter=filt, transfer=transfer, step=0.6,
                  early_termination=1.0)
    slow = shear_naive(vol, view, vrlib.make_filter(filt), transfer, 0.6,
                       3 if method == "shear3" else 2)
    np.testing.assert_allclose(fast.rgba, slow, atol=2e-6)
    assert fast.alpha.max() > 0.02


@pytest.mark.parametrize("method", ["shear3", "shear2"])
@pytest.mark.parametrize("filt, azimuth, elevation", [("trilinear", 33, -21),
                                                      ("catmull-rom", 200, 40)])
@pytest.mark.parametrize("transfer", ["glow", "lit-table"])
def test_exact_ends_match_naive_twin(method, filt, transfer, azimuth, elevation):
    """``segment_ends="exact"`` in the shear methods: a depth sample (three passes) or a slice
    (two) stands for its segment of the ray cut to the stretch inside the volume; a cut
    segment counts its part inside, at its middle resampled by pass 3 (three passes) or by the
    nearest slice sample inside on the ray (two). The twins cut every segment in order, pixel
    by pixel; the renderers composite the cut parts in front of and behind the whole ones."""
    vol = small_volume()
    view = View.orbit(azimuth=azimuth, elevation=elevation, size=(7, 9))
    fast = render(vol, view, method=method, filter=filt, transfer=TRANSFERS[transfer],
                  step=0.6, early_termination=1.0, segment_ends="exact")
    slow = shear_naive(vol, view, vrlib.make_filter(filt), TRANSFERS[transfer], 0.6,
                       3 if method == "shear3" else 2, segment_ends="exact")
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    lattice = render(vol, view, method=method, filter=filt, transfer=TRANSFERS[transfer],
                     step=0.6, early_termination=1.0)
    assert np.abs(fast.rgba - lattice.rgba).max() > 1e-4  # the cut segments were counted


@pytest.mark.parametrize("azimuth, elevation", [
    (100, -35),
    # Two more views in make test-all only (CI's five minutes).
    pytest.param(200, 40, marks=pytest.mark.slow), pytest.param(30, 20, marks=pytest.mark.slow)])
def test_exact_ends_bring_the_shear_methods_closer_to_the_exact_image(azimuth, elevation):
    """On Marschner-Lobb at 17^3 (live at every face), 24^2, one sample per voxel: the rmse
    against the exact image of the trilinear field. Measured: shear3 1.2e-2 to 1.4e-2 with
    lattice ends, 5.3e-4 to 1.3e-3 exact; shear2 9.2e-3 to 1.3e-2 against 8.5e-4 to 2.3e-3.
    Not shear-warp: there the warp's bilinear interpolation of the intermediate image, at the
    slices' resolution, errs by about 7e-3 here whatever the ends (1.01e-2 lattice and
    1.03e-2 exact at 4 planes per slice from (100, -35)); its exact ends are checked by their
    convergence (:func:`test_shearwarp_exact_ends_converge_at_second_order`)."""
    vol = data_gen.make_field("marschner-lobb").sample(17)
    view = View.orbit(azimuth=azimuth, elevation=elevation, size=24)
    exact = vrlib.render_reference(vrlib.ReconstructedField(vol), view, transfer=Glow(1.0))
    for method, factor in [("shear3", 8.0), ("shear2", 3.5)]:
        errors = {ends: metrics.rmse(render(vol, view, method=method, step=1.0,
                                            early_termination=1.0, segment_ends=ends), exact)
                  for ends in ("lattice", "exact")}
        assert errors["exact"] * factor < errors["lattice"], (method, errors)


@pytest.mark.parametrize("filt", FILTERS)
@pytest.mark.parametrize("transfer", [Glow(3.0), TABLE], ids=["glow", "table"])
@pytest.mark.parametrize("azimuth, elevation", [(33, -21), (120, 50), (-60, 10)])
def test_shearwarp_matches_naive_twin(filt, transfer, azimuth, elevation):
    vol = small_volume()
    view = View.orbit(azimuth=azimuth, elevation=elevation, size=(7, 9))
    fast = render(vol, view, method="shearwarp", filter=filt, transfer=transfer,
                  early_termination=1.0)
    slow = shearwarp_naive(vol, view, vrlib.make_filter(filt), transfer)
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)


@pytest.mark.parametrize("filt", ["trilinear", "catmull-rom", "gaussian"])
@pytest.mark.parametrize("transfer", [LIT, Glow(3.0, gradient_opacity=vrlib.GradientOpacity(
    [0.0, 1.0], [0.0, 1.0]))], ids=["lit-table", "gradient-opacity"])
@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
def test_shearwarp_with_gradients_matches_naive_twin(filt, transfer, projection):
    """Shear-warp classifies each sample by its gradient too (the slices' central differences,
    resampled with the same 2-D weights); a perspective view shades each intermediate pixel's
    samples along that pixel's own ray."""
    vol = small_volume()
    view = View.orbit(azimuth=120, elevation=50, size=(7, 9), projection=projection,
                      distance=4.0 if projection == "perspective" else None)
    fast = render(vol, view, method="shearwarp", filter=filt, transfer=transfer,
                  early_termination=1.0)
    slow = shearwarp_naive(vol, view, vrlib.make_filter(filt), transfer)
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    assert fast.alpha.max() > 0.02


@pytest.mark.parametrize("planes, filt", [(2, "trilinear"), (3, "catmull-rom"), (2, "omoms")])
@pytest.mark.parametrize("transfer", ["table", "lit-table"])
@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
def test_shearwarp_planes_match_naive_twin(planes, filt, transfer, projection):
    """Sample planes between the slices (``planes_per_slice``): each interpolates the two
    slices about it at the same in-slice point, gradients too, each a segment of ``1 /
    planes`` of the path between slices (the twin follows each ray through the planes)."""
    vol = small_volume()
    view = View.orbit(azimuth=-60, elevation=10, size=(7, 9), projection=projection,
                      distance=4.0 if projection == "perspective" else None)
    fast = render(vol, view, method="shearwarp", filter=filt, transfer=TRANSFERS[transfer],
                  early_termination=1.0, planes_per_slice=planes)
    slow = shearwarp_naive(vol, view, vrlib.make_filter(filt), TRANSFERS[transfer],
                           planes=planes)
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    assert fast.alpha.max() > 0.02
    single = render(vol, view, method="shearwarp", filter=filt, transfer=TRANSFERS[transfer],
                    early_termination=1.0)
    assert not np.allclose(fast.rgba, single.rgba, atol=1e-4)  # the planes were sampled


@pytest.mark.parametrize("planes, filt", [(1, "trilinear"), (2, "catmull-rom")])
@pytest.mark.parametrize("transfer", ["glow", "lit-table"])
@pytest.mark.parametrize("projection, azimuth, elevation", [
    ("orthographic", -60, 10), ("orthographic", 200, 40), ("perspective", 33, -21),
    ("perspective", 200, 40)])
def test_shearwarp_exact_ends_match_naive_twin(planes, filt, transfer, projection, azimuth,
                                               elevation):
    """``segment_ends="exact"``: where a ray enters or leaves through a side face, the
    segment that the face cuts counts its part inside, sampled at that part's middle (the
    twin cuts every plane's segment to the ray's stretch inside, in order; the renderer
    composites the cut parts in front of and behind the whole ones). The perspective view
    from (200, 40) has rays that meet the front slice exactly on its edge."""
    vol = small_volume()
    view = View.orbit(azimuth=azimuth, elevation=elevation, size=(7, 9), projection=projection,
                      distance=4.0 if projection == "perspective" else None)
    fast = render(vol, view, method="shearwarp", filter=filt, transfer=TRANSFERS[transfer],
                  early_termination=1.0, planes_per_slice=planes, segment_ends="exact")
    slow = shearwarp_naive(vol, view, vrlib.make_filter(filt), TRANSFERS[transfer],
                           planes=planes, segment_ends="exact")
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    lattice = render(vol, view, method="shearwarp", filter=filt, transfer=TRANSFERS[transfer],
                     early_termination=1.0, planes_per_slice=planes)
    assert np.abs(fast.rgba - lattice.rgba).max() > 2e-6  # the cut segments were counted


@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
def test_shearwarp_exact_ends_converge_at_second_order(projection):
    """On Marschner-Lobb, live at every face, the image's change as the planes per slice
    double falls about twice each doubling with lattice ends (the segments the side faces cut
    count whole: first order) and about four times with exact ends. Measured (17^3, 24^2):
    lattice 2.1 to 2.4 over the first two doublings, exact 3.8 to 4.4, and the first change
    12 to 15 times smaller."""
    vol = data_gen.make_field("marschner-lobb").sample(17)
    view = View.orbit(azimuth=100, elevation=-35, size=24, projection=projection,
                      distance=3.0 if projection == "perspective" else None)
    changes = {}
    for ends in ("lattice", "exact"):
        images = [render(vol, view, method="shearwarp", planes_per_slice=m,
                         early_termination=1.0, segment_ends=ends) for m in (1, 2, 4)]
        changes[ends] = [metrics.rmse(a, b) for a, b in zip(images, images[1:], strict=False)]
    assert changes["lattice"][0] / changes["lattice"][1] < 2.8
    assert changes["exact"][0] / changes["exact"][1] > 3.2
    assert changes["exact"][1] / changes["exact"][0] < 1.0
    assert changes["exact"][0] < changes["lattice"][0] / 5.0


@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
def test_shearwarp_planes_converge_at_second_order_inside(projection):
    """On a field that vanishes at the volume's faces, the image's change as the planes per
    slice double falls about four times each doubling (the error along rays is of second
    order in the planes' spacing; the warp's own error is the same for every count and
    cancels in the differences). Measured: 3.4 to 4.9 over the first two doublings."""
    vol = data_gen.make_field("gaussian-blob").sample(17)
    view = View.orbit(azimuth=100, elevation=-35, size=24, projection=projection,
                      distance=3.0 if projection == "perspective" else None)
    images = [render(vol, view, method="shearwarp", planes_per_slice=m,
                     early_termination=1.0) for m in (1, 2, 4)]
    changes = [metrics.rmse(a, b) for a, b in zip(images, images[1:], strict=False)]
    assert changes[0] / changes[1] > 3.0
    assert changes[1] > 0.0


@pytest.mark.parametrize("filt", ["trilinear", "catmull-rom"])
@pytest.mark.parametrize("azimuth, elevation, distance", [(33, -21, 2.5), (200, 40, 4.0),
                                                          (-60, 80, 9.0)])
def test_perspective_shearwarp_matches_naive_twin(filt, azimuth, elevation, distance):
    """Perspective: per-slice scale, per-ray segment length (the twin follows each ray)."""
    vol = small_volume()
    view = View.orbit(azimuth=azimuth, elevation=elevation, size=(9, 7),
                      projection="perspective", distance=distance)
    fast = render(vol, view, method="shearwarp", filter=filt, transfer=Glow(3.0),
                  early_termination=1.0)
    slow = shearwarp_naive(vol, view, vrlib.make_filter(filt), Glow(3.0))
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    assert fast.alpha.max() > 0.02


def test_perspective_shaded_shearwarp_is_close_to_the_ray_casters():
    """Perspective shading (each intermediate pixel's own ray) against the ray caster at a
    quarter-voxel step: six blobs 48^3 -> 96^2 under a shaded colour table, four views.
    Measured rmse of premultiplied RGBA, 2026-11-26: 4.5e-3 to 5.2e-3 (orthographic
    shear-warp 3.2e-3 to 4.8e-3; the ray caster at one voxel 0.7e-3 to 1.7e-3: shear-warp
    samples once per slice and warps). The bound is 2x the measured worst case."""
    vol = data_gen.make_field("random-blobs", count=6, seed=7).sample(48)
    lit = vrlib.colormap("viridis", [(0, 0), (0.2, 0), (1, 0.6)], volume=vol,
                         shading=vrlib.Phong(specular=0.3))
    for azimuth, elevation in [(35, 25), (0, 0), (120, -40), (-70, 60)]:
        view = View.orbit(azimuth=azimuth, elevation=elevation, size=96,
                          projection="perspective")
        reference = render(vol, view, transfer=lit, step=0.25)
        image = render(vol, view, method="shearwarp", transfer=lit)
        assert vrlib.metrics.rmse(image, reference) < 1.05e-2
        assert reference.alpha.max() > 0.9


def test_perspective_shearwarp_against_reference():
    """A smooth blob seen from close by: shear-warp's perspective image stays as close to the
    reference as the perspective ray caster's at one sample per slice."""
    field = data_gen.make_field("gaussian-blob", sigma=0.3)
    vol = field.sample(64)
    view = View.orbit(azimuth=25, elevation=15, size=64, projection="perspective",
                      distance=3.5)
    ref = vrlib.render_reference(field, view, transfer=Glow(2.0), tol=1e-6).alpha
    warp = render(vol, view, method="shearwarp", transfer=Glow(2.0)).alpha
    ray = render(vol, view, method="raycast", transfer=Glow(2.0), step=1.0).alpha
    assert metrics.rmse(warp, ref) < 2.0 * metrics.rmse(ray, ref) + 1e-3
    assert metrics.rmse(warp, ref) < 0.01 * ref.max()


@pytest.mark.parametrize("method, options", [
    *((m, {}) for m in METHODS),
    ("shearwarp", {"planes_per_slice": 3, "segment_ends": "exact"})])
def test_bit_identical_for_one_and_two_threads(method, options):
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba sees a single CPU: nothing to compare")
    vol = data_gen.make_field("marschner-lobb").sample(24)
    view = View.orbit(azimuth=20, elevation=35, size=50)
    one = render(vol, view, method=method, filter="catmull-rom", threads=1, **options)
    two = render(vol, view, method=method, filter="catmull-rom", threads=2, **options)
    assert np.array_equal(one.rgba, two.rgba)


@pytest.mark.parametrize("method", METHODS)
def test_glow_blob_against_closed_form(method):
    """Gaussian blob at 64^3, 96^2, Glow(2), step 1, over five views including a steep one.
    Measured worst rmse (trilinear / Catmull-Rom): shear3 1.4e-4 / 3.5e-5, shear2 1.4e-4 /
    3.3e-5, shear-warp 3.0e-4 / 2.1e-4 (its intermediate image at voxel resolution and the
    bilinear warp blur the image once more)."""
    field = data_gen.make_field("gaussian-blob", sigma=0.3, center=(0.05, -0.1, 0.08))
    vol = field.sample(64)
    for azimuth, elevation in [(30, 20), (0, 0), (45, 0), (10, 80), (-120, -30)]:
        view = View.orbit(azimuth=azimuth, elevation=elevation, size=96)
        exact = exact_blob_image(field, view, 2.0)
        for filt in ("trilinear", "catmull-rom"):
            img = render(vol, view, method=method, filter=filt, transfer=Glow(2.0), step=1.0)
            assert metrics.rmse(img.alpha, exact) < (5e-4 if method == "shearwarp" else 2e-4)


@pytest.mark.parametrize("method", METHODS)
def test_mass_invariant_over_random_orbits(method):
    """The rendering model (docs/model.md), to 1%, 8 random orbits."""
    field = data_gen.make_field("gaussian-blob", sigma=0.25, center=(0.1, 0.0, -0.1))
    vol = field.sample(48)
    expected = 1.5 * field.integral(field.bounds)
    for view in random_orbits(8, seed=11, size=80):
        img = render(vol, view, method=method, transfer=Glow(1.5), step=1.0)
        assert image_mass(img, view) == pytest.approx(expected, rel=1e-2)


def test_two_pass_is_as_accurate_as_three_pass():
    """Dropping the third pass costs no accuracy: on Marschner-Lobb (41^3, Catmull-Rom, step 1)
    the two-pass image is as close to the reference as the three-pass one (measured rmse,
    three / two: 0.0058 / 0.0054, 0.0047 / 0.0042, 0.0059 / 0.0062 at the three views).

    The issue's stricter wording, that the two-pass image differs from the three-pass one by no
    more than the three-pass one differs from the reference, does not hold: their errors are
    of the same size and independent (the methods sample different points along each ray:
    slices against the ray lattice), so the two images differ by about sqrt(2) times either
    error (measured 0.0072, 0.0052, 0.0080). The test checks what is true: the two-pass error
    is within 10% of the three-pass error, and the two images differ by at most the sum of
    their errors.
    """
    field = data_gen.make_field("marschner-lobb")
    vol = field.sample(41)
    for azimuth, elevation in [(20, 30), (-70, 10), (140, -45)]:
        view = View.orbit(azimuth=azimuth, elevation=elevation, size=48)
        ref = vrlib.render_reference(field, view, tol=1e-5)
        three = render(vol, view, method="shear3", filter="catmull-rom", step=1.0)
        two = render(vol, view, method="shear2", filter="catmull-rom", step=1.0)
        e3, e2 = metrics.rmse(three, ref), metrics.rmse(two, ref)
        assert e2 < 1.1 * e3
        assert metrics.rmse(two, three) <= e2 + e3


def test_two_pass_resamples_fewer_samples():
    """At one sample per voxel along the rays, pass 3 resamples about a volume's worth of
    samples that the two-pass method never computes."""
    vol = data_gen.make_field("marschner-lobb").sample(32)
    view = View.orbit(azimuth=25, elevation=40, size=56)
    three = render(vol, view, method="shear3", step=1.0).stats
    two = render(vol, view, method="shear2", step=1.0).stats
    assert two.passes["pass1"] == three.passes["pass1"]
    assert two.passes["pass2"] == three.passes["pass2"]
    assert two.voxels < 0.75 * three.voxels


def test_shearwarp_run_skipping_and_termination():
    """Skipping rows' transparent ends (threshold 0) changes nothing; early termination
    changes no channel by more than 1 - threshold."""
    data = data_gen.make_field("random-blobs", count=3, seed=5, sigma=(0.05, 0.08)).sample(
        32).data.copy()
    data[data < 0.05] = 0.0
    vol = Volume(data)
    view = View.orbit(azimuth=40, elevation=25, size=40)
    skipped = render(vol, view, method="shearwarp", transfer=Glow(2.0))
    full = render(vol, view, method="shearwarp", transfer=Glow(2.0), empty_space_skipping=False)
    assert np.array_equal(skipped.rgba, full.rgba)
    assert skipped.stats.samples < 0.5 * full.stats.samples
    solid = data_gen.make_field("smooth-sphere", radius=0.7).sample(24)
    opaque = render(solid, view, method="shearwarp", transfer=Glow(40.0),
                    early_termination=1.0)
    for threshold in (0.9, 0.99):
        early = render(solid, view, method="shearwarp", transfer=Glow(40.0),
                       early_termination=threshold)
        assert np.abs(early.rgba - opaque.rgba).max() <= 1.0 - threshold + 1e-12
        assert early.stats.samples < opaque.stats.samples


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("azimuth, elevation", [(0, 0), (90, 0), (0, 90), (45, 0),
                                                (45, 35.264), (-135, -45)])
def test_axis_aligned_tied_and_flipping_views(method, azimuth, elevation):
    """Views along an axis, exactly between axes (where the principal axis flips between
    nearby frames): the image a hair to either side differs only by the method's own error."""
    vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(32)
    images = [render(vol, View.orbit(azimuth=azimuth + da, elevation=elevation + de, size=40),
                     method=method, step=1.0)
              for da, de in [(0, 0), (1e-6, -1e-6), (-1e-6, 1e-6)]]
    for img in images:
        assert np.all(np.isfinite(img.rgba))
    assert metrics.max_abs_error(images[1], images[2]) < 5e-3


def test_plan_avoids_bottlenecks():
    """The third pass runs along the axis most parallel to the view; the scale factors of the
    first two passes stay away from zero for every view."""
    vol = Volume(np.zeros((8, 8, 8)))
    for view in random_orbits(40, seed=3, size=16):
        plan = plan_shear(vol, view, 0.1)
        assert plan.order[2] == int(np.argmax(np.abs(view.forward)))
        assert min(abs(plan.a), abs(plan.e)) > 0.4 / view.pixel_size * vol.spacing[0]


@pytest.mark.parametrize(
    "method, kwargs, error, message",
    [
        ("shear3", {}, ValueError, "orthographic only"),
        ("shear2", {}, ValueError, "orthographic only"),
    ],
)
def test_perspective_is_refused_clearly(method, kwargs, error, message):
    view = View.orbit(size=8, projection="perspective")
    with pytest.raises(error, match=message):
        render(small_volume(), view, method=method, **kwargs)


def test_perspective_shearwarp_refuses_an_eye_inside_the_slab():
    """Rays from an eye between the front and back slices would run along the slices."""
    view = View.orbit(azimuth=10, elevation=5, size=8, projection="perspective",
                      distance=0.8, fov=90)
    with pytest.raises(ValueError, match="eye outside the volume's slab along its principal "
                                         "axis x"):
        render(small_volume(), view, method="shearwarp")


@pytest.mark.parametrize(
    "method, kwargs, error, message",
    [
        ("shearwarp", {"min_opacity": 1.0}, ValueError, "min_opacity must be < 1"),
        ("shearwarp", {"min_opacity": -0.1}, ValueError, "min_opacity must be >= 0"),
        ("shearwarp", {"segment_ends": "middle"}, ValueError, "segment_ends"),
        ("shear3", {"segment_ends": "middle"}, ValueError, "segment_ends"),
        ("shear2", {"segment_ends": 1}, ValueError, "segment_ends"),
        ("shearwarp", {"planes_per_slice": 0}, ValueError, "planes_per_slice must be an "
                                                            "integer >= 1"),
        ("shearwarp", {"planes_per_slice": 65}, ValueError, "planes_per_slice must be an "
                                                             "integer from 1 to 64"),
        ("shearwarp", {"planes_per_slice": 1.5}, TypeError, "planes_per_slice must be an "
                                                             "integer"),
        ("shearwarp", {"planes_per_slice": True}, TypeError, "planes_per_slice must be an "
                                                              "integer"),
        ("shear3", {"min_opacity": 0.1}, TypeError, "method 'shear3' takes no option"),
        ("shear2", {"filter": ("gaussian", 0.5, 6.0)}, ValueError, "radius 6 is out of range"),
    ],
)
def test_bad_input(method, kwargs, error, message):
    with pytest.raises(error, match=message):
        render(small_volume(), View.orbit(size=8), method=method, **kwargs)


def _warp_by_numpy(inter, m, shape, grey):
    """The affine warp's documented arithmetic on whole arrays: bilinear in ``inter`` at
    ``(x, y) = (m00 c + m01 r + m02, m10 c + m11 r + m12)``, clipped to [0, 1], transparent
    outside or where all four neighbours are."""
    n_j, n_i = inter.shape[:2]
    rows, cols = np.meshgrid(np.arange(shape[0]), np.arange(shape[1]), indexing="ij")
    x = m[0, 0] * cols + (m[0, 1] * rows + m[0, 2])
    y = m[1, 0] * cols + (m[1, 1] * rows + m[1, 2])
    inside = (x >= 0.0) & (y >= 0.0) & (x <= n_i - 1) & (y <= n_j - 1)
    i = np.minimum(np.where(inside, x, 0.0).astype(int), n_i - 2)
    j = np.minimum(np.where(inside, y, 0.0).astype(int), n_j - 2)
    tx, ty = x - i, y - j
    if inter.shape[2] == 2:  # grey: red and opacity alone
        inter = inter[..., [0, 0, 0, 1]]
    corners = [inter[j, i], inter[j, i + 1], inter[j + 1, i], inter[j + 1, i + 1]]
    top = (1 - tx)[..., None] * corners[0] + tx[..., None] * corners[1]
    bottom = (1 - tx)[..., None] * corners[2] + tx[..., None] * corners[3]
    value = np.minimum(np.maximum((1 - ty)[..., None] * top + ty[..., None] * bottom, 0.0), 1.0)
    if grey:
        value[..., 1] = value[..., 2] = value[..., 0]
    clear = np.all([c[..., 3] == 0.0 for c in corners], axis=0)
    value[~inside | clear] = 0.0
    return value


@pytest.mark.parametrize("grey, channels", [(True, 4), (True, 2), (False, 4)])
@pytest.mark.parametrize("seed", range(3))
def test_affine_warp_is_its_arithmetic_bit_for_bit(grey, channels, seed):
    """The affine warp takes eight pixels at once in vector form (each pixel's neighbours
    loaded a row at a time and transposed across the eight, one store of the eight pixels)
    and the rest of a row one at a time: both must be the documented arithmetic exactly.
    Random intermediate images (values outside [0, 1] to clip, transparent patches, grey or
    coloured), rotated, scaled and shifted maps, rows whose pixels fall inside, across and
    outside the image, grey images also as red and opacity alone (the classified
    renderer's); compared bit for bit with numpy's whole-array arithmetic."""
    rng = np.random.default_rng(seed)
    inter = rng.random((37, 45, 4)) * 1.4 - 0.2
    inter[rng.random((37, 45)) < 0.3] = 0.0
    inter[:5] = 0.0  # a transparent margin: the box the warp visits is smaller
    if grey:
        inter[..., 1] = inter[..., 2] = inter[..., 0]
    if channels == 2:
        inter = np.ascontiguousarray(inter[..., [0, 3]])
    angle, scale = rng.uniform(0, 2 * np.pi), rng.uniform(0.6, 1.5)
    m = np.array([[scale * np.cos(angle), -scale * np.sin(angle), 0.0],
                  [scale * np.sin(angle), scale * np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    # The image's centre to the intermediate image's, give or take a few pixels.
    m[:2, 2] = [22.0, 18.0] - m[:2, :2] @ [30.0, 26.0] + rng.uniform(-8, 8, 2)
    out = np.full((53, 61, 4), np.nan)
    warp(inter, m, out, grey)
    expected = _warp_by_numpy(inter, m, out.shape[:2], grey)
    assert (expected[..., 3] > 0).sum() > 100  # the test sees pixels, not only margins
    np.testing.assert_array_equal(out, expected)


@pytest.mark.parametrize("shape, grey", [((1, 5, 4), False), ((5, 1, 2), True),
                                         ((5, 5, 2), False), ((5, 5, 3), True)])
def test_warp_refuses_an_intermediate_image_it_cannot_read(shape, grey):
    """The vector warp reads a pixel's two neighbours along a row as one block of channels
    (a lane outside the image reads the first cell): fewer than 2 rows or columns, or a
    layout of channels it does not know, would be read out of bounds, so it says so."""
    with pytest.raises(ValueError, match="inter must be a"):
        warp(np.zeros(shape), np.eye(3), np.empty((4, 4, 4)), grey)
