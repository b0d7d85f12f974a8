"""Claim 1 (thesis abstract and chapter 1): "a separable cubic filter reconstructs more
accurately than a pyramid (trilinear) filter or a Gaussian filter", backed by "an analytic
scale-space bound on error as a function of feature size and sampling density" and by "an
image-based heuristic metric against reference images".

The checks below are what the package found to be true (chapters ch02 and ch03): the claim
holds for an interpolating cubic (Catmull-Rom; Mitchell, nearly interpolating, beats the tent
and the Gaussian as well) and fails for the cubic B-spline, which the thesis's wording would
also cover. Beyond the thesis: the most accurate cubics are prefiltered ones (generalized
interpolation, Thevenaz, Blu and Unser 2000): the cubic B-spline on prefiltered coefficients
and the cubic O-MOMS beat Catmull-Rom in the error bound, at points and in images.
"""

import numpy as np
import pytest

import vrlib
from vrlib import bounds

PREFILTERED = ["cardinal-bspline", "omoms"]
RATIOS = [0.5, 0.75, 1.0, 1.5, 2.0, 3.0]
GAUSSIANS = [("gaussian", s, 2.0) for s in (0.5, 0.6, 0.7, 0.8)]


@pytest.mark.claim(1, "supports")
@pytest.mark.parametrize("dims", [1, 3])
def test_catmull_rom_has_the_lowest_worst_case_error_at_every_feature_size(dims):
    for ratio in RATIOS:
        cubic = bounds.feature_error("catmull-rom", ratio, dims=dims)
        for other in ["pyramid", "mitchell", "bspline", *GAUSSIANS]:
            assert cubic < bounds.feature_error(other, ratio, dims=dims), (other, ratio)


@pytest.mark.claim(1, "supports")
def test_catmull_rom_has_the_lowest_fourier_bound():
    """The analytic bound ranks the filters the same way as the measured worst case."""
    for ratio in RATIOS:
        cubic = bounds.fourier_bound("catmull-rom", ratio)
        for other in ["pyramid", "bspline", *GAUSSIANS]:
            assert cubic < bounds.fourier_bound(other, ratio), (other, ratio)


@pytest.mark.claim(1, "refutes")
def test_the_claim_fails_for_the_cubic_b_spline():
    """The B-spline is a separable cubic too, and it is less accurate than the pyramid filter
    at every feature size: it blurs (its response at Nyquist is 0.16 against the tent's
    0.41)."""
    errors = np.array([[bounds.feature_error(f, q) for q in RATIOS]
                       for f in ("bspline", "pyramid")])
    assert np.all(errors[0] > errors[1])


@pytest.mark.claim(1, "supports")
def test_a_truncated_gaussian_has_an_error_floor_the_cubic_does_not():
    """At sigma/h = 6 the cubic's error is below 2e-4 while the Gaussian of s = 0.8 (R = 2)
    stays above 1% from its ripple."""
    assert bounds.feature_error("catmull-rom", 6.0) < 2e-4
    assert bounds.feature_error(("gaussian", 0.8, 2.0), 6.0) > 0.01


@pytest.mark.claim(1, "beyond")
@pytest.mark.parametrize("dims", [1, 3])
def test_prefiltered_cubics_have_a_lower_worst_case_error_than_catmull_rom(dims):
    """At every feature size of the derived predictions (docs/derivations.md), measured and
    bounded, in 1-D and 3-D; O-MOMS lowest (ch02: at sigma/h = 1 in 1-D, 0.048 Catmull-Rom,
    0.020 cardinal B-spline, 0.012 O-MOMS)."""
    for ratio in RATIOS:
        cubic = bounds.feature_error("catmull-rom", ratio, dims=dims)
        spline, omoms = (bounds.feature_error(f, ratio, dims=dims) for f in PREFILTERED)
        assert omoms < spline < cubic, ratio
    if dims == 1:  # the bound ranks them alike (three sizes: each bound takes a second)
        for ratio in (0.75, 1.0, 2.0):
            assert max(bounds.fourier_bound(f, ratio) for f in PREFILTERED) < bounds.fourier_bound(
                "catmull-rom", ratio)


@pytest.mark.claim(1, "beyond")
def test_prefiltered_cubics_reconstruct_points_more_accurately_than_catmull_rom():
    """RMS error of vrlib.reconstruct against the Marschner-Lobb field sampled at 41^3, at
    random points inside the central 80% of the box (nearer the faces every filter meets the
    boundary rule, which no filter can make exact for a field that does not vanish there):
    about 0.6x Catmull-Rom's for the cardinal B-spline and 0.5x for O-MOMS."""
    import data_gen

    field = data_gen.make_field("marschner-lobb")
    volume = field.sample(41)
    points = np.random.default_rng(0).uniform(-0.8, 0.8, (20000, 3))
    truth = field(points)
    rms = {f: float(np.sqrt(np.mean((vrlib.reconstruct(volume, points, filter=f) - truth) ** 2)))
           for f in ["catmull-rom", *PREFILTERED]}
    assert rms["omoms"] < rms["cardinal-bspline"] < 0.75 * rms["catmull-rom"]


def _image_errors(field, n, scale, methods, size=48, filters=("catmull-rom", "pyramid",
                                                                 "gaussian", "bspline")):
    view = vrlib.View.orbit(azimuth=30, elevation=25, size=size)
    ref = vrlib.render_reference(field, view, transfer=vrlib.Glow(scale), tol=1e-6).alpha
    volume = field.sample(n)
    return {(m, f): vrlib.metrics.rmse(vrlib.render(volume, view, method=m, filter=f,
                                                    transfer=vrlib.Glow(scale),
                                                    early_termination=1.0).alpha, ref)
            for m in methods for f in filters}


@pytest.mark.claim(1, "supports")
@pytest.mark.parametrize("method", ["raycast", pytest.param("shear3", marks=pytest.mark.slow),
                                    "shear2", "shearwarp"])
def test_catmull_rom_images_are_closest_to_the_reference(method):
    """Image part of claim 1 (chapter ch03): on Marschner-Lobb at 41^3 and on a blob of about
    1.2 samples at 24^3, the Catmull-Rom image has a lower rmse than the pyramid's, the
    Gaussian's and the B-spline's, for ray casting and the three shear methods."""
    import data_gen

    for field, n, scale in [(data_gen.make_field("marschner-lobb"), 41, 1.0),
                            (data_gen.make_field("gaussian-blob", sigma=0.08), 24, 8.0)]:
        errors = _image_errors(field, n, scale, [method])
        for other in ("pyramid", "gaussian", "bspline"):
            assert errors[method, "catmull-rom"] < errors[method, other], (field, other)


@pytest.mark.claim(1, "supports")
def test_splatting_ranks_the_filters_alike_on_fields_that_vanish_at_the_faces():
    """Splatting's kernels reach past the volume's faces (where the reference stops), which
    adds the same rim error for every filter on fields that do not vanish there; on a blob the
    cubic is again the most accurate."""
    import data_gen

    errors = _image_errors(data_gen.make_field("gaussian-blob", sigma=0.08), 24, 8.0, ["splat"])
    for other in ("pyramid", "gaussian", "bspline"):
        assert errors["splat", "catmull-rom"] < errors["splat", other]


@pytest.mark.claim(1, "beyond")
@pytest.mark.parametrize("method", ["raycast", "shear3"])
def test_prefiltered_cubic_images_are_closer_to_the_reference_than_catmull_roms(method):
    """The fields and views of the image test above: both prefiltered cubics give a lower
    image rmse than Catmull-Rom (ch03 shows every method; splatting's rim error on
    Marschner-Lobb swamps the filters' difference until issue 17's clipping)."""
    import data_gen

    for field, n, scale in [(data_gen.make_field("marschner-lobb"), 41, 1.0),
                            (data_gen.make_field("gaussian-blob", sigma=0.08), 24, 8.0)]:
        errors = _image_errors(field, n, scale, [method], filters=["catmull-rom", *PREFILTERED])
        for prefiltered in PREFILTERED:
            assert errors[method, prefiltered] < errors[method, "catmull-rom"], (field,
                                                                                  prefiltered)
