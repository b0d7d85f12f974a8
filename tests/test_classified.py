"""Classification by gradient magnitude, and the classified (VolPack-style) shear-warp.

The classified renderer is checked against its naive twin (``naive.classified_naive``: no runs,
no skipping, dense bilinear mixing per slice), which proves that run-length encoding, skip
links over opaque pixels and the segment walk change nothing; against ray casting of the same
transfer function, which bounds what pre-classification costs; and for thread independence.
"""

import numpy as np
import pytest
from naive import classified_naive, random_orbits

import data_gen
import vrlib
from vrlib.classified import NORMAL_BINS, decode_normals, encode_normals


@pytest.fixture(scope="module")
def blobs():
    """A small anisotropic sparse volume: runs of every length, zeros between them."""
    field = data_gen.make_field("random-blobs", count=3, seed=2, sigma=(0.15, 0.25))
    return field.sample((11, 13, 9))


TRANSFERS = {
    "glow": vrlib.Glow(4.0),
    "shaded": vrlib.Glow(4.0, shading=vrlib.Phong(specular=0.4)),
    "colour": vrlib.LookupTransfer([0, 2, 8], color=[[1, 0, 0], [0, 1, 0], [0.2, 0.3, 1]]),
    "colour, shaded, by gradient": vrlib.LookupTransfer(
        [0, 2, 8], color=[[1, 0, 0], [0, 1, 0], [0.2, 0.3, 1]], shading=vrlib.Phong(),
        gradient_opacity=vrlib.GradientOpacity([0.5, 3.0], [0.0, 1.0])),
}
#: Every kind of volume the compositing compiles for (grey or coloured, shaded or not); the
#: coloured unshaded one compiles once more (2.5 s a kind), so make test-all checks it.
KINDS = [pytest.param(name, marks=pytest.mark.slow) if name == "colour" else name
         for name in TRANSFERS]
VIEWS = random_orbits(4, seed=3, size=14) + [vrlib.View.orbit(size=14),
                                              vrlib.View.orbit(azimuth=90, elevation=90,
                                                               size=14)]


@pytest.mark.parametrize("name", KINDS)
def test_classified_equals_its_naive_twin(blobs, name):
    """Every view, including axis-aligned ones (voxels hit exactly, one weight zero)."""
    transfer = TRANSFERS[name]
    scene = vrlib.classify(blobs, transfer)
    for view in VIEWS:
        got = scene.render(view, early_termination=1.0).rgba
        np.testing.assert_allclose(got, classified_naive(blobs, transfer, view),
                                   rtol=0, atol=1e-12)


def test_early_termination_and_min_opacity_follow_the_twin(blobs):
    """A pixel stops at the first sample that takes it to the threshold; voxels at or below
    ``min_opacity`` (over one spacing) are dropped. Dense enough that both act."""
    transfer = vrlib.Glow(40.0, shading=vrlib.Phong())
    for min_opacity in (0.0, 0.3):
        scene = vrlib.classify(blobs, transfer, min_opacity=min_opacity)
        for view in VIEWS[:3]:
            got = scene.render(view, early_termination=0.9)
            want = classified_naive(blobs, transfer, view, early_termination=0.9,
                                    min_opacity=min_opacity)
            np.testing.assert_allclose(got.rgba, want, rtol=0, atol=1e-12)
            assert got.alpha.max() > 0.9
    stored = next(iter(scene.stored_voxels.values()))
    assert 0 < stored < np.count_nonzero(blobs.data > 0)


def test_nothing_visible_renders_a_blank_image():
    """An all-transparent classification (VolPack 1.0b3 does not return from rendering one)."""
    view = VIEWS[0]
    for volume, low in ((vrlib.Volume(np.zeros((5, 6, 7))), 0.0),
                        (vrlib.Volume(np.ones((5, 6, 7))), 0.99)):
        scene = vrlib.classify(volume, vrlib.Glow(1.0, shading=vrlib.Phong()), min_opacity=low)
        image = scene.render(view)
        assert image.shape == view.shape and not image.rgba.any()
        assert set(scene.stored_voxels.values()) == {0}


def test_images_do_not_depend_on_the_thread_count(blobs):
    scene = vrlib.classify(blobs, TRANSFERS["colour, shaded, by gradient"])
    view = VIEWS[0]
    one = scene.render(view, threads=1)
    two = scene.render(view, threads=2)
    assert np.array_equal(one.rgba, two.rgba)
    assert one.stats.samples == two.stats.samples > 0


@pytest.mark.parametrize("name", KINDS)
def test_classified_is_close_to_ray_casting_the_same_transfer(name):
    """Pre-classification mixes voxels' colours and extinctions, not values; on a smooth field
    at 40^3 the image stays within 5e-3 rms of a fine ray cast of the same transfer function
    (measured: 3e-4 unshaded, about 2e-3 with gradients at axis-aligned views, where the
    central-difference normals differ most from the ray caster's trilinear ones)."""
    volume = data_gen.make_field("gaussian-blob", sigma=0.3).sample(40)
    transfer = TRANSFERS[name]
    scene = vrlib.classify(volume, transfer)
    for view in (vrlib.View.orbit(azimuth=20, elevation=10, size=40), vrlib.View.orbit(size=40)):
        ray = vrlib.render(volume, view, transfer=transfer, step=0.25, early_termination=1.0)
        got = scene.render(view, early_termination=1.0)
        assert vrlib.metrics.rmse(got.rgba, ray.rgba) < 5e-3
        assert ray.alpha.max() > 0.3


def test_normal_codes_round_trip_within_their_bins():
    """96^2 octahedral bins: a median error under a degree, at most 2.6 degrees (bins that
    straddle the octahedron's folds; measured 0.86 and 2.50)."""
    rng = np.random.default_rng(0)
    g = rng.normal(size=(20000, 3)) * rng.uniform(0.01, 100.0, size=(20000, 1))
    decoded = decode_normals()[encode_normals(g)]
    unit = g / np.linalg.norm(g, axis=1, keepdims=True)
    angle = np.degrees(np.arccos(np.clip(np.sum(decoded * unit, axis=1), -1, 1)))
    assert np.median(angle) < 1.0 and angle.max() < 2.6
    assert encode_normals(np.zeros((1, 3)))[0] == NORMAL_BINS**2
    assert np.all(decode_normals()[-1] == 0.0)


def test_shading_per_frame_replaces_the_transfer_functions(blobs):
    """A light that moves with the eye, as VolPack's: the same image as classifying again."""
    light = vrlib.Phong(specular=0.3, light=[0.0, 0.6, 0.8])
    moved = vrlib.classify(blobs, vrlib.Glow(4.0, shading=vrlib.Phong())).render(
        VIEWS[1], shading=light)
    again = vrlib.classify(blobs, vrlib.Glow(4.0, shading=light)).render(VIEWS[1])
    assert np.array_equal(moved.rgba, again.rgba)


def test_classified_refuses_what_it_cannot_do(blobs):
    scene = vrlib.classify(blobs, vrlib.Glow(1.0))
    perspective = vrlib.View.orbit(projection="perspective", size=8)
    with pytest.raises(ValueError, match="orthographic"):
        scene.render(perspective)
    with pytest.raises(ValueError, match="classified with shading"):
        scene.render(VIEWS[0], shading=vrlib.Phong())
    with pytest.raises(ValueError, match="early_termination"):
        scene.render(VIEWS[0], early_termination=0.0)
    with pytest.raises(ValueError, match="threads"):
        scene.render(VIEWS[0], threads=0)
    with pytest.raises(TypeError, match="shading must be"):
        vrlib.classify(blobs, vrlib.Glow(1.0, shading=vrlib.Phong())).render(VIEWS[0],
                                                                            shading="phong")
    with pytest.raises(ValueError, match="min_opacity"):
        vrlib.classify(blobs, min_opacity=1.0)
    with pytest.raises(TypeError, match="volume must be"):
        vrlib.classify(blobs.data)
    with pytest.raises(TypeError, match="transfer"):
        vrlib.classify(blobs, "glow")


# Classification by gradient magnitude in the other renderers.

def test_gradient_opacity_checks_its_points():
    with pytest.raises(ValueError, match="increasing"):
        vrlib.GradientOpacity([2.0, 1.0], [0.0, 1.0])
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        vrlib.GradientOpacity([0.0, 1.0], [0.0, 2.0])
    with pytest.raises(ValueError, match="same length"):
        vrlib.GradientOpacity([0.0, 1.0, 2.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="finite"):
        vrlib.GradientOpacity([0.0, np.nan], [0.0, 1.0])
    with pytest.raises(TypeError, match="gradient_opacity must be"):
        vrlib.Glow(1.0, gradient_opacity=(0.0, 1.0))


def test_ray_casting_by_gradient_converges_to_the_reference():
    """Density times g(|grad F|), integrated by the reference renderer from the field's exact
    gradient: the Catmull-Rom ray cast at 48^3 agrees to 1e-4 rms (measured 1e-5), trilinear to
    2e-3 (measured 8e-4); unshaded and shaded."""
    field = data_gen.make_field("gaussian-blob", sigma=0.3)
    volume = field.sample(48)
    view = vrlib.View.orbit(azimuth=20, elevation=10, size=24)
    ramp = vrlib.GradientOpacity([0.5, 2.0], [0.0, 1.0])
    for shading in (None, vrlib.Phong()):
        transfer = vrlib.Glow(3.0, shading=shading, gradient_opacity=ramp)
        ref = vrlib.render_reference(field, view, transfer=transfer, tol=1e-6)
        plain = vrlib.render_reference(field, view, transfer=vrlib.Glow(3.0, shading=shading))
        assert vrlib.metrics.rmse(ref.rgba, plain.rgba) > 0.03  # the ramp matters here
        for filt, bound in (("catmull-rom", 1e-4), ("trilinear", 2e-3)):
            img = vrlib.render(volume, view, transfer=transfer, filter=filt, step=0.25)
            assert vrlib.metrics.rmse(img.rgba, ref.rgba) < bound


def test_a_ramp_of_ones_changes_nothing():
    volume = data_gen.make_field("gaussian-blob", sigma=0.3).sample(20)
    view = vrlib.View.orbit(azimuth=30, size=16)
    ones = vrlib.GradientOpacity([0.0, 1.0], [1.0, 1.0])
    for shading in (None, vrlib.Phong()):
        base = vrlib.render(volume, view, transfer=vrlib.Glow(2.0, shading=shading))
        same = vrlib.render(volume, view, transfer=vrlib.Glow(2.0, shading=shading,
                                                              gradient_opacity=ones))
        assert np.array_equal(base.rgba, same.rgba)


SHADED = vrlib.Glow(3.0, shading=vrlib.Phong(specular=0.3, light=[0.0, 0.6, 0.8]),
                    gradient_opacity=vrlib.GradientOpacity([0.0, 2.0], [0.3, 1.0]))


@pytest.fixture(scope="module")
def shaded_reference():
    """A smooth blob, shaded and classified by gradient magnitude: the reference renderer's
    image (the exact field's gradient), its view and the field."""
    field = data_gen.make_field("gaussian-blob", sigma=0.35)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=32)
    return field, view, vrlib.render_reference(field, view, transfer=SHADED, tol=1e-4)


@pytest.mark.parametrize("filt", ["trilinear", "catmull-rom"])
@pytest.mark.parametrize("method, options", [("raycast", {}), ("splat", {"mode": "direct"}),
                                             ("shear3", {}), ("shear2", {}),
                                             ("shearwarp", {})])
def test_every_method_converges_to_the_shaded_reference(method, options, filt,
                                                         shaded_reference):
    """Every method takes shading and gradient opacity (sheet splatting excepted, above) and
    converges to the reference on a smooth blob sampled at 64^3. Measured rmse, trilinear /
    Catmull-Rom: raycast 1.9e-4 / 1.5e-5 (the filter's own derivative), splat (direct, each
    voxel shaded) 3.8e-4 / 2.1e-4, shear3 3.2e-4 / 1.4e-4, shear2 2.6e-4 / 1.5e-4, shear-warp
    4.5e-4 / 3.3e-4 (the samples' central differences, resampled); the same image unshaded
    is 0.10 away."""
    field, view, reference = shaded_reference
    image = vrlib.render(field.sample(64), view, method=method, filter=filt, transfer=SHADED,
                         **options)
    assert vrlib.metrics.rmse(image, reference) < 1e-3
    if method == "splat":
        unshaded = vrlib.render(field.sample(64), view, method=method, filter=filt,
                                transfer=vrlib.Glow(3.0), **options)
        assert vrlib.metrics.rmse(unshaded, reference) > 0.05


@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
@pytest.mark.parametrize("filt", ["trilinear", "catmull-rom", "gaussian"])
def test_direct_splatting_classifies_and_shades_each_voxel(projection, filt):
    """Direct splatting with gradients follows the naive twin (each voxel classified by its own
    central-difference gradient and shaded as seen from the eye); the per-voxel values are
    float32, hence the 1e-6 bound."""
    from naive import splat_naive

    volume = data_gen.make_field("random-blobs", count=4, seed=2).sample((5, 6, 7))
    view = vrlib.View.orbit(azimuth=33, elevation=-21, size=(7, 9), projection=projection)
    transfer = vrlib.LookupTransfer(
        [0.0, 3.0, 1.0, 5.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]],
        shading=vrlib.Phong(specular=0.4, light=[0.0, 0.6, 0.8]),
        gradient_opacity=vrlib.GradientOpacity([0.0, 2.0], [0.2, 1.0]))
    fast = vrlib.render(volume, view, method="splat", mode="direct", filter=filt,
                        transfer=transfer, early_termination=1.0)
    slow = splat_naive(volume, view, vrlib.make_filter(filt), transfer, "direct")
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    assert fast.alpha.max() > 0.05


def test_segment_opacity_is_one_minus_exp():
    """The classified kernel's opacity of a segment of optical depth ``d``, ``1 - exp(-d)``
    (eq 1.4), inline (a table of powers of two and a polynomial; the Taylor series below
    0.02): within 3e-16 of it above 0.02 (libm's ``exp`` gives about 1e-16) and 1e-13 below,
    exactly 1 where float64 rounds it to 1, over the depths a sample can have."""
    from vrlib._kernels.classified import _opacity

    python = getattr(_opacity, "py_func", _opacity)  # the same function without the JIT
    rng = np.random.default_rng(0)
    deep = np.concatenate([np.linspace(0.02, 50.0, 20001), 0.02 + 45 * rng.random(20000)])
    faint = np.linspace(0.0, 0.02, 2001)[:-1]
    for depths, bound in ((deep, 3e-16), (faint, 1e-13)):
        got = np.array([python(d) for d in depths])
        assert np.max(np.abs(got + np.expm1(-depths))) <= bound
    assert [python(d) for d in (38.0, 44.0, 1e3)] == [1.0, 1.0, 1.0]
    assert _opacity(0.5) == python(0.5)  # compiled, the same arithmetic
