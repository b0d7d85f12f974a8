"""NaN samples as holes (Volume(..., nan="transparent")): a hole contributes nothing and never
poisons its neighbours, for every method and every filter applied to the samples."""

import numpy as np
import pytest

import data_gen
import vrlib
from vrlib.value_bounds import reconstructed_range

N = 24
# The two filters most used run in make test; the others (each a kernel to compile per
# method) in make test-all.
SAMPLE_FILTERS = ["trilinear", "catmull-rom",
                  *(pytest.param(f, marks=pytest.mark.slow)
                    for f in ("box", "gaussian", "mitchell", "bspline"))]


def pocket_and_holes():
    """Marschner-Lobb with a zero-valued ball of radius 8 voxels (transparent under Glow), and
    the same volume with NaN holes in the ball's middle 2x2x2 samples."""
    data = data_gen.make_field("marschner-lobb").sample(N).data.copy()
    z, y, x = np.indices(data.shape)
    centre = (N - 1) / 2
    data[(x - centre) ** 2 + (y - centre) ** 2 + (z - centre) ** 2 <= 8.0**2] = 0.0
    holed = data.copy()
    middle = slice(N // 2 - 1, N // 2 + 1)
    holed[middle, middle, middle] = np.nan
    return vrlib.Volume(data), vrlib.Volume(holed, nan="transparent")


@pytest.mark.parametrize("method", sorted(vrlib.METHODS))
@pytest.mark.parametrize("filt", SAMPLE_FILTERS)
def test_a_hole_inside_a_transparent_pocket_changes_nothing(method, filt):
    """Everything a hole reaches is transparent, and everything else reconstructs from the
    finite samples: a hole in the middle of a pocket that is transparent anyway (wider than
    the hole plus twice the filter's reach) gives the pocket's image, for every method and
    filter. (A NaN that leaked, or a stand-in value that was blended in, would show.)"""
    pocket, holed = pocket_and_holes()
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=20)
    options = {"mode": "direct"} if method == "splat" and filt == "box" else {}
    want = vrlib.render(pocket, view, method=method, filter=filt, **options)
    got = vrlib.render(holed, view, method=method, filter=filt, **options)
    assert np.all(np.isfinite(got.rgba)) and want.alpha.max() > 0.3
    np.testing.assert_allclose(got.rgba, want.rgba, atol=2e-7)


def test_holes_hide_what_they_reach_and_nothing_else():
    """vrlib.reconstruct: points whose filter support gives a hole weight have no value
    (NaN); all others equal the reconstruction of the hole-free volume, whatever the hole
    held. With the box filter only the hole's own cell is lost."""
    pocket, holed = pocket_and_holes()
    rng = np.random.default_rng(1)
    points = rng.uniform(-1, 1, (4000, 3))
    for filt, reach in (("trilinear", 1.0), ("catmull-rom", 2.0), ("box", 0.5)):
        want = vrlib.reconstruct(pocket, points, filter=filt)
        got = vrlib.reconstruct(holed, points, filter=filt)
        index = holed.world_to_index(points)
        near = np.all(np.abs(index - (N / 2 - 0.5)) < 0.5 + reach, axis=1)
        assert np.isnan(got[near & (np.max(np.abs(index - (N / 2 - 0.5)), axis=1) < 0.5)]).all()
        np.testing.assert_array_equal(got[~near], want[~near])
        assert np.isnan(got).sum() <= near.sum() and np.isnan(got).any()


def test_shaded_ray_casting_and_classified_volumes_with_holes():
    """Shading with holes ray casts (its gradients come from the same taps as its values);
    classify and the methods that difference samples refuse shading, and classify draws a
    hole's voxel as empty."""
    pocket, holed = pocket_and_holes()
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=20)
    shaded = vrlib.Glow(1.0, shading=vrlib.Phong())
    np.testing.assert_allclose(vrlib.render(holed, view, transfer=shaded, filter="catmull-rom")
                               .rgba, vrlib.render(pocket, view, transfer=shaded,
                                                   filter="catmull-rom").rgba, atol=2e-7)
    with pytest.raises(ValueError, match="shading and gradient opacity are ray cast only"):
        vrlib.render(holed, view, method="splat", transfer=shaded)
    with pytest.raises(ValueError, match="shading and gradient opacity are ray cast only"):
        vrlib.classify(holed, shaded)
    np.testing.assert_allclose(vrlib.classify(holed).render(view).rgba,
                               vrlib.classify(pocket).render(view).rgba, atol=2e-7)


def test_hole_rules_and_errors():
    data = np.arange(27.0).reshape(3, 3, 3)
    data[1, 1, 1] = np.nan
    with pytest.raises(ValueError, match=r"found 1 NaN .*nan='transparent' makes NaN holes"):
        vrlib.Volume(data)
    vol = vrlib.Volume(data, nan="transparent")
    assert vol.value_range == (0.0, 26.0) and vol.holes.sum() == 1
    assert vol.data[1, 1, 1] == vol.hole_value > 1e20
    assert vrlib.Volume(np.arange(8.0).reshape(2, 2, 2)).holes is None
    data[0, 0, 0] = np.inf
    with pytest.raises(ValueError, match="found 2 NaN or infinite"):
        vrlib.Volume(data, nan="transparent")
    with pytest.raises(ValueError, match="all NaN"):
        vrlib.Volume(np.full((2, 2, 2), np.nan), nan="transparent")
    with pytest.raises(ValueError, match="unknown nan 'zero'"):
        vrlib.Volume(np.zeros((2, 2, 2)), nan="zero")
    with pytest.raises(ValueError, match="prefilters along whole lines"):
        vrlib.render(vol, vrlib.View.orbit(size=4), filter="cardinal-bspline")
    lo, hi = reconstructed_range(vol, vrlib.make_filter("catmull-rom"))
    assert lo < 0.0 < 26.0 < hi < 1e3


def test_automatic_and_label_transfer_functions_leave_holes_out():
    """The histogram ramp and the label table are built from the finite samples only: a
    volume with holes gets the ramp of its finite samples."""
    pocket, holed = pocket_and_holes()
    auto = vrlib.auto_transfer(holed)
    assert auto.value_range[1] <= holed.value_range[1]
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=12)
    assert vrlib.render(holed, view, transfer=auto).alpha.max() > 0.1
    labels = vrlib.Volume(np.where(np.isnan(holed.data) | (holed.data > 1e10), np.nan,
                                   np.round(pocket.data * 3)), nan="transparent")
    table = vrlib.label_transfer(labels)
    assert table.value_range == (-0.5, 3.5)
