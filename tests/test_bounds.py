"""The scale-space error bound (vrlib.bounds)."""

import itertools
import math

import numpy as np
import pytest

from vrlib import bounds

FILTERS = ["box", "pyramid", "catmull-rom", "mitchell", "bspline", ("gaussian", 0.6, 2.0)]


@pytest.mark.parametrize("filt", FILTERS)
@pytest.mark.parametrize("ratio", [0.4, 1.0, 2.5])
def test_fourier_bound_is_an_upper_bound(filt, ratio):
    """The bound drops phases only, so it can never fall below the measured worst case."""
    assert bounds.fourier_bound(filt, ratio) >= bounds.feature_error(filt, ratio) * (1 - 1e-6)
    assert (bounds.fourier_bound(filt, ratio, dims=3)
            >= bounds.feature_error(filt, ratio, dims=3) * (1 - 1e-6))


def test_tent_error_approaches_its_taylor_limit():
    """Linear interpolation of a curve with second derivative f'' errs by h^2 |f''| / 8 at
    most; at the Gaussian's peak |f''| = 1 / sigma^2."""
    for ratio in (4.0, 6.0):
        limit = 1.0 / (8.0 * ratio**2)
        assert bounds.feature_error("pyramid", ratio) == pytest.approx(limit, rel=0.01)


def test_orders_of_accuracy():
    """Tent and B-spline reproduce linears only (error ~ (h/sigma)^2); Catmull-Rom reproduces
    quadratics (error falls faster: ~ (h/sigma)^3)."""
    def order(filt):
        return math.log(bounds.feature_error(filt, 2.0) / bounds.feature_error(filt, 4.0), 2)

    assert order("pyramid") == pytest.approx(2.0, abs=0.15)
    assert order("bspline") == pytest.approx(2.0, abs=0.15)
    assert order("catmull-rom") > 2.8


def test_three_d_search_is_the_exact_worst_case_of_the_product():
    """The hull-vertex search equals a brute-force maximum over every triple of 1-D pairs
    (small search so that brute force is feasible)."""
    f, r = bounds.error_samples("catmull-rom", 0.8, offsets=3, per_sample=3)
    pairs = list(zip(f.ravel(), r.ravel(), strict=True))
    brute = max(abs(r1 * r2 * r3 - f1 * f2 * f3)
                for (f1, r1), (f2, r2), (f3, r3) in itertools.product(pairs, repeat=3))
    vertices = bounds._hull(np.column_stack([f.ravel(), r.ravel()]))
    products = bounds._hull(np.column_stack([
        np.multiply.outer(vertices[:, 0], vertices[:, 0]).ravel(),
        np.multiply.outer(vertices[:, 1], vertices[:, 1]).ravel()]))
    fast = np.abs(np.multiply.outer(products[:, 1], vertices[:, 1])
                  - np.multiply.outer(products[:, 0], vertices[:, 0])).max()
    assert fast == pytest.approx(brute, rel=1e-12)


@pytest.mark.parametrize("filt", ["pyramid", "catmull-rom", "bspline"])
def test_three_d_error_is_at_least_the_one_d_error_and_at_most_three_times(filt):
    """Two axes at the lattice point under the peak reproduce it (f = R = 1 for these
    filters at offset 0), so 3-D is at least 1-D; to first order the three axes' errors add."""
    for ratio in (0.7, 1.5, 3.0):
        one, three = bounds.feature_error(filt, ratio), bounds.feature_error(filt, ratio, dims=3)
        assert one * (1 - 1e-9) <= three <= (1 + one) ** 3 - 1


def test_required_ratio_brackets_the_target():
    ratio = bounds.required_ratio("mitchell", 0.05)
    assert bounds.feature_error("mitchell", ratio) <= 0.05
    assert bounds.feature_error("mitchell", ratio * 0.99) > 0.05


def test_required_ratio_is_infinite_under_a_floor():
    """A Gaussian truncated at 2 voxels with s = 0.8 ripples by ~3.6% whatever the feature."""
    assert math.isinf(bounds.required_ratio(("gaussian", 0.8, 2.0), 0.01))


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: bounds.feature_error("pyramid", 0.0), "ratio must be > 0"),
        (lambda: bounds.feature_error("pyramid", math.nan), "ratio must be"),
        (lambda: bounds.feature_error("pyramid", 1.0, dims=2), "dims must be 1 or 3"),
        (lambda: bounds.fourier_bound("nope", 1.0), "unknown filter 'nope'"),
        (lambda: bounds.required_ratio("pyramid", -0.1), "target must be > 0"),
    ],
)
def test_bad_input_is_named(call, message):
    with pytest.raises(ValueError, match=message):
        call()
