"""Claim 1 (thesis abstract and chapter 1): "a separable cubic filter reconstructs more
accurately than a pyramid (trilinear) filter or a Gaussian filter", backed by "an analytic
scale-space bound on error as a function of feature size and sampling density" and by "an
image-based heuristic metric against reference images".

The checks below are what the package found to be true (chapters ch02 and ch03): the claim
holds for an interpolating cubic (Catmull-Rom; Mitchell, nearly interpolating, beats the tent
and the Gaussian as well) and fails for the cubic B-spline, which the thesis's wording would
also cover.
"""

import numpy as np
import pytest

from vrlib import bounds

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


def _image_errors(field, n, scale, methods, size=48):
    import vrlib

    view = vrlib.View.orbit(azimuth=30, elevation=25, size=size)
    ref = vrlib.render_reference(field, view, transfer=vrlib.Glow(scale), tol=1e-6).alpha
    volume = field.sample(n)
    return {(m, f): vrlib.metrics.rmse(vrlib.render(volume, view, method=m, filter=f,
                                                    transfer=vrlib.Glow(scale),
                                                    early_termination=1.0).alpha, ref)
            for m in methods for f in ("catmull-rom", "pyramid", "gaussian", "bspline")}


@pytest.mark.claim(1, "supports")
@pytest.mark.parametrize("method", ["raycast", "shear3", "shear2", "shearwarp"])
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
