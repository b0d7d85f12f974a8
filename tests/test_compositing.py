"""The over operator and segment models (eqs 1.4-1.9)."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from vrlib import compositing


@st.composite
def segments(draw, min_n=1, max_n=12):
    """Premultiplied RGBA segments: alpha in [0, 1], colour in [0, alpha] (white-ish emitters)."""
    n = draw(st.integers(min_n, max_n))
    alpha = draw(hnp.arrays(np.float64, n, elements=st.floats(0.0, 1.0)))
    scale = draw(hnp.arrays(np.float64, (n, 3), elements=st.floats(0.0, 1.0)))
    return np.concatenate([scale * alpha[:, None], alpha[:, None]], axis=1)


@given(segments())
def test_front_to_back_equals_back_to_front(segs):
    a = compositing.composite(segs, order="front-to-back")
    b = compositing.composite(segs, order="back-to-front")
    np.testing.assert_allclose(a, b, atol=1e-12)


@given(segments(min_n=3, max_n=3))
def test_over_is_associative(segs):
    a, b, c = segs
    left = compositing.over(compositing.over(a, b), c)
    right = compositing.over(a, compositing.over(b, c))
    np.testing.assert_allclose(left, right, atol=1e-12)


@given(segments(min_n=2), st.data())
def test_split_and_merge_equals_whole(segs, data):
    """Compositing sub-runs separately and merging them (as parallel compositing does) gives
    the whole-ray result."""
    cut = data.draw(st.integers(1, len(segs) - 1))
    front = compositing.composite(segs[:cut])
    back = compositing.composite(segs[cut:])
    np.testing.assert_allclose(compositing.over(front, back), compositing.composite(segs),
                               atol=1e-12)


@given(segments())
def test_alpha_stays_in_unit_interval(segs):
    out = compositing.composite(segs)
    assert 0.0 <= out[3] <= 1.0 + 1e-12
    assert np.all(out[:3] <= out[3] + 1e-12)


def test_segments_compose_like_one_long_segment():
    """Eq 1.4: n segments of length p/n with density w composite to 1 - exp(-w p)."""
    density, length, n = 2.5, 0.8, 16
    alpha = compositing.segment_alpha(density, length / n)
    segs = np.tile([alpha, alpha, alpha, alpha], (n, 1))
    out = compositing.composite(segs)
    assert out[3] == pytest.approx(1 - np.exp(-density * length), abs=1e-14)


def test_composite_broadcasts_over_pixels():
    segs = np.random.default_rng(0).uniform(0, 1, size=(5, 7, 6, 4))
    segs[..., :3] *= segs[..., 3:4]
    out = compositing.composite(segs)
    assert out.shape == (5, 7, 4)
    np.testing.assert_allclose(out[2, 3], compositing.composite(segs[2, 3]))


def test_segment_models_against_exact():
    x = np.linspace(0.0, 12.0, 2001)
    exact = compositing.segment_alpha(x, 1.0)
    linear = compositing.segment_alpha(x, 1.0, model="linear")
    table = compositing.segment_alpha(x, 1.0, model="table")
    np.testing.assert_allclose(exact, 1 - np.exp(-x), atol=1e-15)
    # min(1, x) over-estimates: its error is x - (1 - exp(-x)) <= x^2 / 2 for small x.
    small = x < 0.1
    assert np.all(linear[small] >= exact[small])
    assert np.all(linear[small] - exact[small] <= x[small] ** 2 / 2 + 1e-15)
    # Linear interpolation of a convex-down function on a 1024 grid over [0, 8]: error below
    # h^2/8 = 7.6e-6 inside the table, below exp(-8) = 3.4e-4 past it.
    inside = x <= 8.0
    assert np.max(np.abs(table - exact)[inside]) < 8e-6
    assert np.max(np.abs(table - exact)) < 3.4e-4


def test_opacity_correction():
    a = np.array([0.0, 0.3, 0.9, 1.0])
    np.testing.assert_allclose(compositing.correct_opacity(a, 1.0, 1.0), a, atol=1e-15)
    half = compositing.correct_opacity(a, 0.5, 1.0)
    # Two half steps composite back to one full step.
    np.testing.assert_allclose(1 - (1 - half) ** 2, a, atol=1e-14)
    # Accurate for tiny opacities and tiny ratios (no cancellation).
    tiny = compositing.correct_opacity(1e-12, 1e-6, 1.0)
    assert tiny == pytest.approx(1e-18, rel=1e-9)
    assert compositing.correct_opacity(1.0, 1e-9, 1.0) == 1.0


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: compositing.over([1, 2, 3], [0, 0, 0, 0]), "front must have RGBA"),
        (lambda: compositing.composite([0.1, 0.1, 0.1, 0.1]), r"shape \(\.\.\., n, 4\)"),
        (lambda: compositing.composite([[0, 0, 0, 0]], order="sideways"), "unknown order"),
        (lambda: compositing.segment_alpha(1.0, 1.0, model="cubic"), "unknown model 'cubic'"),
        (lambda: compositing.correct_opacity(1.5, 1.0, 1.0), r"alpha must lie in \[0, 1\]"),
        (lambda: compositing.correct_opacity(np.nan, 1.0, 1.0), "alpha must hold only finite"),
        (lambda: compositing.correct_opacity(0.5, 0.0, 1.0), "step must be > 0"),
        (lambda: compositing.correct_opacity(0.5, 1.0, -1.0), "reference_step must be > 0"),
    ],
)
def test_bad_input(call, message):
    with pytest.raises(ValueError, match=message):
        call()
