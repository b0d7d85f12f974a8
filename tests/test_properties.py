"""Property-based stress tests (hypothesis) over random volumes, views, filters and steps.

For every method: the image is finite, alpha stays in [0, 1] and colour is non-negative;
empty-space skipping never changes the image; one and two threads give the same image, bit for
bit. For compositing: front-to-back equals back-to-front. ``make test`` runs a bounded number of
examples per property; ``make test-all`` (HYPOTHESIS_PROFILE=thorough) many more.
"""

import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import vrlib
from vrlib.compositing import composite

# The drawn volumes include empty ones (all zeros) on purpose: their images must be finite
# too. The warning that such an image is empty is checked in test_formats.
pytestmark = pytest.mark.filterwarnings("ignore::vrlib.arguments.EmptyImageWarning")

METHODS = list(vrlib.METHODS)
# Every filter in make test-all; in make test the two most used (each filter compiles its own
# kernels, and the property tests alone would pay a minute of make test's budget for them;
# the per-filter naive twins cover every filter there).
FILTERS = (list(vrlib.filters.STANDARD) if os.environ.get("HYPOTHESIS_PROFILE") == "thorough"
           else ["trilinear", "catmull-rom"])
#: Examples per rendering property: bounded in ``make test``, many more in ``make test-all``.
RENDERS = settings(max_examples=300 if os.environ.get("HYPOTHESIS_PROFILE") == "thorough"
                   else 12)


@st.composite
def volumes(draw):
    shape = tuple(draw(st.integers(2, 9)) for _ in range(3))
    kind = draw(st.sampled_from(["uniform", "sparse", "huge", "tiny", "constant"]))
    seed = draw(st.integers(0, 2**16))
    rng = np.random.default_rng(seed)
    data = rng.uniform(0.0, 1.0, shape)
    if kind == "sparse":
        data[data < 0.8] = 0.0
    elif kind == "huge":
        data *= 1e12
    elif kind == "tiny":
        data *= 1e-12
    elif kind == "constant":
        data[...] = data.flat[0]
    sides = [draw(st.floats(0.01, 100.0)) for _ in range(3)]
    extent = [[-s / 2, s / 2] for s in sides]
    return vrlib.Volume(data, extent=extent), kind


@st.composite
def views(draw, volume):
    azimuth = draw(st.floats(-180.0, 180.0))
    elevation = draw(st.floats(-90.0, 90.0))
    size = draw(st.integers(4, 20))
    return vrlib.View.orbit(azimuth=azimuth, elevation=elevation, size=size,
                            radius=volume.bounding_radius, center=volume.center)


def glow_for(volume, kind):
    """A glow scale that gives moderate opacity whatever the magnitudes and extent."""
    peak = max(abs(v) for v in volume.value_range) or 1.0
    size = float(np.max(volume.extent[:, 1] - volume.extent[:, 0]))
    return vrlib.Glow(2.0 / (peak * size))


def check(img):
    rgba = img.rgba
    assert np.all(np.isfinite(rgba))
    assert rgba[..., 3].min() >= 0.0 and rgba[..., 3].max() <= 1.0
    assert rgba[..., :3].min() >= 0.0


@RENDERS
@given(data=st.data(), method=st.sampled_from(METHODS), filt=st.sampled_from(FILTERS),
       step=st.floats(0.2, 3.0))
def test_every_image_is_finite_and_in_range(data, method, filt, step):
    volume, kind = data.draw(volumes())
    view = data.draw(views(volume))
    check(vrlib.render(volume, view, method=method, filter=filt, step=step,
                       transfer=glow_for(volume, kind)))


@pytest.mark.slow  # tests/test_skipping.py checks the same in make test, case by case
@RENDERS
@given(data=st.data(), method=st.sampled_from(["raycast", "shearwarp"]),
       filt=st.sampled_from(FILTERS), threshold=st.floats(0.1, 0.9))
def test_empty_space_skipping_never_changes_the_image(data, method, filt, threshold):
    volume, _ = data.draw(volumes())
    view = data.draw(views(volume))
    lo, hi = volume.value_range
    if hi <= lo:
        hi = lo + 1.0
    cut = lo + threshold * (hi - lo)
    density = np.where(np.linspace(lo, hi, 65) > cut, 8.0 / (hi - lo), 0.0)
    size = float(np.max(volume.extent[:, 1] - volume.extent[:, 0]))
    transfer = vrlib.LookupTransfer(density / size, value_range=(lo, hi))
    on = vrlib.render(volume, view, method=method, filter=filt, transfer=transfer,
                      empty_space_skipping=True, early_termination=1.0)
    off = vrlib.render(volume, view, method=method, filter=filt, transfer=transfer,
                       empty_space_skipping=False, early_termination=1.0)
    np.testing.assert_array_equal(on.rgba, off.rgba)


@RENDERS
@given(data=st.data(), method=st.sampled_from(METHODS), filt=st.sampled_from(FILTERS))
def test_one_and_two_threads_give_the_same_image(data, method, filt):
    volume, kind = data.draw(volumes())
    view = data.draw(views(volume))
    images = [vrlib.render(volume, view, method=method, filter=filt, threads=t,
                           transfer=glow_for(volume, kind)).rgba for t in (1, 2)]
    np.testing.assert_array_equal(images[0], images[1])


@given(alpha=arrays(np.float64, st.tuples(st.integers(1, 5), st.integers(1, 40)),
                    elements=st.floats(0.0, 1.0)),
       colour=st.floats(0.0, 1.0))
def test_front_to_back_equals_back_to_front(alpha, colour):
    """Premultiplied segments (colour <= alpha) composited either way agree to rounding."""
    samples = np.stack([alpha * colour] * 3 + [alpha], axis=-1)
    front = composite(samples)
    back = composite(samples, order="back-to-front")
    np.testing.assert_allclose(front, back, rtol=1e-12, atol=1e-14)
    assert np.all((front[..., 3] >= 0.0) & (front[..., 3] <= 1.0 + 1e-15))


@RENDERS
@given(data=st.data(), projection_distance=st.floats(1.2, 10.0))
def test_perspective_images_are_finite_and_in_range(data, projection_distance):
    volume, kind = data.draw(volumes())
    azimuth = data.draw(st.floats(-180.0, 180.0))
    elevation = data.draw(st.floats(-89.0, 89.0))
    view = vrlib.View.orbit(azimuth=azimuth, elevation=elevation, size=12,
                            projection="perspective", radius=volume.bounding_radius,
                            center=volume.center,
                            distance=projection_distance * volume.bounding_radius)
    for method in ("raycast", "shearwarp", "splat"):
        try:
            img = vrlib.render(volume, view, method=method, transfer=glow_for(volume, kind))
        except ValueError as error:  # an eye inside a slab the method needs outside
            assert "eye" in str(error)
            continue
        check(img)
