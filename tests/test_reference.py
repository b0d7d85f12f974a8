"""The reference renderer: exact where closed forms exist, convergent everywhere else."""

import numpy as np
import pytest

import data_gen
import vrlib
from vrlib import Glow, LookupTransfer, Phong, View, compositing, render_reference
from vrlib.reference import _clip_to_box


def closed_form(field, view, scale):
    o, d = view.rays()
    t0, t1 = _clip_to_box(o, d, field.bounds[:, 0], field.bounds[:, 1])
    return 1.0 - np.exp(-scale * field.line_integral(o, d, t0, t1))


@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
@pytest.mark.parametrize("name, params", [
    ("gaussian-blob", {"sigma": 0.3, "center": (0.2, -0.1, 0.3)}),
    ("random-blobs", {"count": 5, "seed": 3}),
    ("grating", {"frequency": 2.5, "direction": (1, 2, 0)}),
    ("step-edge", {"normal": (1, 1, 0), "offset": 0.1}),
])
def test_glow_matches_closed_form_to_1e6(projection, name, params):
    """The rendering model (docs/model.md): for a Gaussian blob under Glow the reference equals
    1 - exp(-k * line integral); the same holds for every field with a closed form (the step
    edge's jump is handled by splitting the quadrature there)."""
    field = data_gen.make_field(name, **params)
    view = View.orbit(azimuth=-35, elevation=25, size=40, projection=projection)
    img = render_reference(field, view, transfer=Glow(2.0), tol=1e-6)
    exact = closed_form(field, view, 2.0)
    assert np.abs(img.alpha - exact).max() < 1e-6
    np.testing.assert_allclose(img.rgba[..., 0], img.alpha, atol=1e-6)  # grey: E = 1


def test_tolerance_is_honoured_without_a_closed_form():
    """Marschner-Lobb has no closed form: a loose and a tight tolerance agree to the loose
    one."""
    field = data_gen.make_field("marschner-lobb")
    view = View.orbit(azimuth=10, elevation=50, size=24)
    loose = render_reference(field, view, tol=1e-4, segments=4)
    tight = render_reference(field, view, tol=1e-9, segments=16)
    assert np.abs(loose.rgba - tight.rgba).max() < 1e-4
    assert tight.stats.samples > loose.stats.samples


def test_coloured_transfer_against_fine_riemann_sum():
    """General transfer functions: compare with a brute-force composite of 40000 segments."""
    field = data_gen.make_field("random-blobs", count=3, seed=1)
    tf = LookupTransfer([0.0, 4.0, 1.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
                        value_range=(0.0, 1.0))
    view = View.orbit(azimuth=60, elevation=-10, size=6)
    img = render_reference(field, view, transfer=tf, tol=1e-8)
    o, d = view.rays()
    t0, t1 = _clip_to_box(o, d, -1.0, 1.0)
    n = 40000
    for r, c in [(2, 3), (3, 2), (1, 4)]:
        t = t0[r, c] + (np.arange(n) + 0.5) * (t1[r, c] - t0[r, c]) / n
        values = field(o[r, c] + t[:, None] * d[r, c])
        alpha = compositing.segment_alpha(tf.opacity_density(values), (t1[r, c] - t0[r, c]) / n)
        segs = np.concatenate([tf.emission(values) * alpha[:, None], alpha[:, None]], axis=1)
        np.testing.assert_allclose(img.rgba[r, c], compositing.composite(segs), atol=1e-6)


def test_shading_uses_the_field_gradient():
    field = data_gen.make_field("gaussian-blob", sigma=0.4)
    view = View.orbit(size=9)
    flat = render_reference(field, view, transfer=Glow(1.0))
    lit = render_reference(field, view, transfer=Glow(1.0, shading=Phong(ambient=0.0,
                                                                          diffuse=1.0)))
    np.testing.assert_allclose(lit.alpha, flat.alpha, atol=1e-12)
    # Seen head-on, the blob's edges face sideways: darker than its centre, relative to alpha.
    ratio = lit.rgba[..., 0] / np.maximum(lit.alpha, 1e-12)
    assert ratio[4, 4] > ratio[4, 1]


def test_rays_that_miss_and_partial_boxes():
    field = data_gen.make_field("gaussian-blob")
    with pytest.warns(vrlib.EmptyImageWarning, match="lies outside the view"):
        img = render_reference(field, View.orbit(size=6, center=(9, 9, 9), radius=0.5))
    assert np.array_equal(img.rgba, np.zeros((6, 6, 4)))
    sub = render_reference(field, View.orbit(size=6), extent=[[0, 1], [0, 1], [0, 1]])
    assert 0 < sub.alpha.max() < 1


@pytest.mark.parametrize("kwargs, error, message", [
    ({"tol": 0.0}, ValueError, "tol must be > 0"),
    ({"tol": np.nan}, ValueError, "tol must be finite"),
    ({"segments": 0}, ValueError, "segments must be an integer >= 1"),
    ({"transfer": "glow"}, TypeError, "transfer must be a vrlib transfer function"),
    ({"extent": [[1, 0], [0, 1], [0, 1]]}, ValueError, "extent along x is inverted"),
])
def test_bad_input(kwargs, error, message):
    with pytest.raises(error, match=message):
        render_reference(data_gen.make_field("gaussian-blob"), View.orbit(size=4), **kwargs)


def test_bad_field_or_view():
    with pytest.raises(TypeError, match="field must be an analytic data_gen field"):
        render_reference(np.zeros((4, 4, 4)), View.orbit(size=4))
    with pytest.raises(TypeError, match="view must be a vrlib.View"):
        render_reference(data_gen.make_field("gaussian-blob"), None)
