"""View: orbit framing, basis, rays, projection and validation."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from vrlib import View

angles = st.floats(-720.0, 720.0)


@given(azimuth=angles, elevation=angles)
def test_orbit_basis_is_right_handed_and_orthonormal(azimuth, elevation):
    view = View.orbit(azimuth=azimuth, elevation=elevation, size=8)
    np.testing.assert_allclose(view.basis @ view.basis.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(np.cross(view.right, view.up), -view.forward, atol=1e-12)


@given(azimuth=angles, elevation=angles, perspective=st.booleans())
def test_every_orbit_sees_the_whole_cube(azimuth, elevation, perspective):
    """At zoom 1 every corner of [-1, 1]^3 projects inside the image."""
    projection = "perspective" if perspective else "orthographic"
    view = View.orbit(azimuth=azimuth, elevation=elevation, size=(30, 40), projection=projection)
    corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
    rows, cols, depth = view.project(corners).T
    assert np.all((rows >= 0) & (rows <= 30) & (cols >= 0) & (cols <= 40))
    assert np.all(depth > 0)


def test_orbit_directions():
    """Azimuth turns about z from +x; elevation lifts towards +z; the image up is world z."""
    v = View.orbit(azimuth=90, elevation=0, size=4)
    np.testing.assert_allclose(v.forward, [0, -1, 0], atol=1e-15)
    np.testing.assert_allclose(v.up, [0, 0, 1], atol=1e-15)
    top = View.orbit(azimuth=0, elevation=90, size=4)
    np.testing.assert_allclose(top.forward, [0, 0, -1], atol=1e-15)
    np.testing.assert_allclose(top.right, [0, 1, 0], atol=1e-15)


def test_orthographic_rays_and_projection_agree():
    view = View.orbit(azimuth=30, elevation=20, size=(5, 7))
    origins, directions = view.rays()
    assert origins.shape == directions.shape == (5, 7, 3)
    np.testing.assert_allclose(directions, np.broadcast_to(view.forward, (5, 7, 3)))
    # A point anywhere along a pixel's ray projects onto that pixel's centre.
    points = origins + 1.3 * directions
    proj = view.project(points)
    rows, cols = np.mgrid[0:5, 0:7] + 0.5
    np.testing.assert_allclose(proj[..., 0], rows, atol=1e-12)
    np.testing.assert_allclose(proj[..., 1], cols, atol=1e-12)
    np.testing.assert_allclose(proj[..., 2], 1.3, atol=1e-12)
    # Rays start on the plane tangent to the scene sphere.
    np.testing.assert_allclose((origins - view.center) @ view.forward, -view.radius)
    assert view.pixel_size == pytest.approx(2 * math.sqrt(3) / 5)


def test_perspective_rays_and_projection_agree():
    view = View.orbit(azimuth=-40, elevation=65, size=(6, 4), projection="perspective",
                      distance=5.0)
    origins, directions = view.rays()
    np.testing.assert_allclose(origins, np.broadcast_to(view.eye, origins.shape))
    np.testing.assert_allclose(np.linalg.norm(directions, axis=-1), 1.0)
    proj = view.project(origins + 3.0 * directions)
    rows, cols = np.mgrid[0:6, 0:4] + 0.5
    np.testing.assert_allclose(proj[..., 0], rows, atol=1e-12)
    np.testing.assert_allclose(proj[..., 1], cols, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(view.eye - view.center), 5.0)
    assert view.fov == pytest.approx(2 * math.degrees(math.asin(math.sqrt(3) / 5)))
    # Behind the eye: no image position.
    behind = view.project(view.eye - view.forward)
    assert np.isnan(behind[0]) and np.isnan(behind[1])


def test_zoom_and_framing():
    base = View.orbit(size=100)
    zoomed = View.orbit(size=100, zoom=2.0)
    assert zoomed.pixel_size == pytest.approx(base.pixel_size / 2)
    framed = View.orbit(size=100, center=(5, 5, 5), radius=0.5)
    np.testing.assert_allclose(framed.project([5, 5, 5])[:2], [50, 50])
    assert framed.pixel_size == pytest.approx(0.01)


def test_explicit_fov_allows_eye_inside():
    view = View.orbit(projection="perspective", distance=0.5, fov=90, size=8)
    assert view.fov == 90.0
    assert View.orbit(size=8).eye is None


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        ({"size": 0}, ValueError, "size must be an integer >= 1"),
        ({"size": 2.5}, TypeError, "size must be an integer"),
        ({"size": (4, 0)}, ValueError, r"size\[1\] \(width\) must be an integer >= 1"),
        ({"size": (1, 2, 3)}, ValueError, "size must be an int or a"),
        ({"size": 20000}, ValueError, "at most 16384"),
        ({"azimuth": math.nan}, ValueError, "azimuth must be finite"),
        ({"elevation": math.inf}, ValueError, "elevation must be finite"),
        ({"zoom": 0.0}, ValueError, "zoom must be > 0"),
        ({"radius": -1.0}, ValueError, "radius must be > 0"),
        ({"projection": "fisheye"}, ValueError, "unknown projection 'fisheye'; known:"),
        ({"fov": 30.0}, ValueError, "perspective projection only"),
        ({"projection": "perspective", "fov": 180.0}, ValueError, "fov must be < 180"),
        ({"projection": "perspective", "fov": 0.0}, ValueError, "fov must be > 0"),
        ({"projection": "perspective", "distance": 1.0}, ValueError,
         "inside the scene sphere .* give fov"),
        ({"projection": "perspective", "distance": 0.0}, ValueError, "distance must be > 0"),
        ({"center": (0, np.nan, 0)}, ValueError, "center must be finite"),
    ],
)
def test_bad_input(kwargs, error, message):
    with pytest.raises(error, match=message):
        View.orbit(**kwargs)


def test_degenerate_directions():
    with pytest.raises(ValueError, match="forward must be a non-zero vector"):
        View([0, 0, 0])
    with pytest.raises(ValueError, match="up .* is parallel to the view direction"):
        View([0, 0, 1], up=[0, 0, 2])
    with pytest.raises(ValueError, match="forward must have three components"):
        View([1, 0])
