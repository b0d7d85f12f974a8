"""vrlib.reconstruct: the reconstructed field at world points, checked against scipy's
map_coordinates (an implementation this package did not write) and against exact fields."""

import numpy as np
import pytest
from scipy import ndimage

import vrlib
from vrlib.filters import STANDARD

EXTENT = [[-1.0, 2.0], [0.0, 1.5], [-0.5, 0.5]]


def volume_and_points(shape=(14, 17, 20), count=400, seed=0):
    """A random volume on an anisotropic box, and random points inside it (world and index)."""
    rng = np.random.default_rng(seed)
    vol = vrlib.Volume(rng.random(shape), extent=EXTENT)
    index = rng.uniform(0.0, 1.0, (count, 3)) * (np.array(shape[::-1]) - 1)
    return vol, vol.index_to_world(index), index


def scipy_at(vol, index, **kw):
    return ndimage.map_coordinates(np.asarray(vol.data), index[:, ::-1].T, **kw)


def test_trilinear_equals_map_coordinates_order_1():
    vol, pts, index = volume_and_points()
    np.testing.assert_allclose(vrlib.reconstruct(vol, pts), scipy_at(vol, index, order=1),
                               atol=1e-13)


def test_cardinal_bspline_equals_map_coordinates_order_3():
    """Everywhere inside the box with scipy's mode="reflect" (vrlib's boundary rule); with
    mode="mirror" only away from the faces, where the two rules' coefficients agree to
    |p|^d (|p| = 0.268, d = 10 samples: 2e-6 times the data's scale)."""
    vol, pts, index = volume_and_points(shape=(32, 30, 28), count=2000)
    ours = vrlib.reconstruct(vol, pts, filter="cardinal-bspline")
    np.testing.assert_allclose(ours, scipy_at(vol, index, order=3, mode="reflect"), atol=1e-11)
    inner = np.all((index >= 10) & (index <= np.array(vol.shape[::-1]) - 11), axis=1)
    assert inner.sum() > 5
    np.testing.assert_allclose(ours[inner], scipy_at(vol, index[inner], order=3, mode="mirror"),
                               atol=1e-5)


@pytest.mark.parametrize("name", ["cardinal-bspline", "omoms", "catmull-rom", "pyramid"])
def test_interpolating_reconstructions_pass_through_every_sample(name):
    """At lattice points, faces and corners included, for volumes of 2, 3 and 7 samples."""
    for shape in [(2, 2, 2), (3, 2, 3), (7, 3, 2)]:
        data = np.random.default_rng(len(shape)).random(shape)
        vol = vrlib.Volume(data, extent=EXTENT)
        k, j, i = np.meshgrid(*[np.arange(s) for s in shape], indexing="ij")
        index = np.column_stack([i.ravel(), j.ravel(), k.ravel()]).astype(float)
        got = vrlib.reconstruct(vol, vol.index_to_world(index), filter=name)
        np.testing.assert_allclose(got, data.ravel(), atol=1e-12)


@pytest.mark.parametrize("name,degree", [("cardinal-bspline", 3), ("omoms", 3),
                                         ("catmull-rom", 2), ("pyramid", 1)])
def test_polynomials_up_to_the_filters_order_are_reconstructed_exactly(name, degree):
    """Approximation order 4 for the prefiltered cubics (they reproduce cubics), 3 for
    Catmull-Rom, 2 for the tent (Thevenaz et al. 2000), away from the faces (the boundary
    rule is not polynomial)."""
    n = 48
    x = np.arange(n, dtype=float)
    line = 0.3 * x**degree - x ** max(degree - 1, 0) + 2.0
    data = np.broadcast_to(line, (n, n, n)).copy()
    vol = vrlib.Volume(data, extent=[[0.0, n - 1.0]] * 3)
    u = np.linspace(20.0, 27.0, 57)  # |p|^20 < 1e-9: the faces' influence is below rounding
    pts = np.column_stack([u, np.full_like(u, 11.3), np.full_like(u, 12.7)])
    got = vrlib.reconstruct(vol, pts, filter=name)
    np.testing.assert_allclose(got, 0.3 * u**degree - u ** max(degree - 1, 0) + 2.0,
                               rtol=1e-9)


@pytest.mark.parametrize("name", [n for n in STANDARD if n != "box"])
def test_gradient_is_the_derivative_of_the_value(name):
    """derivative=True gives the world-space gradient: central differences of the values
    (where the filter is differentiable), on an anisotropic lattice."""
    vol, pts, _ = volume_and_points(count=50, seed=2)
    pts = pts * 0.6 + 0.4 * vol.center  # stay clear of the faces
    h = 1e-6
    grad = vrlib.reconstruct(vol, pts, filter=name, derivative=True)
    assert grad.shape == (50, 3)
    for axis in range(3):
        step = np.zeros(3)
        step[axis] = h
        diff = (vrlib.reconstruct(vol, pts + step, filter=name)
                - vrlib.reconstruct(vol, pts - step, filter=name)) / (2 * h)
        # Kinks (box edges, the tent's and O-MOMS's at the lattice) are where they differ.
        close = np.isclose(grad[:, axis], diff, rtol=1e-5, atol=1e-5)
        assert close.mean() > 0.95


def test_box_gradient_is_the_samples_gradient_at_the_nearest_sample():
    """The box filter's derivative is zero: its gradient is numpy.gradient of the samples
    (world units, one-sided on the faces) at the sample it takes, faces included."""
    vol, pts, _ = volume_and_points(count=50, seed=3)
    grad = vrlib.reconstruct(vol, pts, filter="box", derivative=True)
    index = np.clip(np.floor(vol.world_to_index(pts) + 0.5).astype(int), 0,
                    np.array(vol.shape[::-1]) - 1)
    hx, hy, hz = vol.spacing
    expected = [np.gradient(vol.data, h, axis=a) for h, a in ((hx, 2), (hy, 1), (hz, 0))]
    ix, iy, iz = index.T
    np.testing.assert_allclose(grad, np.stack([g[iz, iy, ix] for g in expected], axis=1),
                               rtol=1e-12, atol=1e-12)
    assert np.abs(grad).max() > 0.0


def test_outside_points_are_nan_and_bad_input_is_refused():
    vol, _, _ = volume_and_points(shape=(4, 5, 6))
    pts = np.array([[-1.0, 0.0, -0.5], [2.0 + 1e-12, 1.5, 0.5], [2.1, 1.0, 0.0],
                    [0.0, -0.01, 0.0]])
    out = vrlib.reconstruct(vol, pts, filter="omoms")
    assert np.isfinite(out[:2]).all() and np.isnan(out[2:]).all()
    assert np.isnan(vrlib.reconstruct(vol, pts, derivative=True)[2:]).all()
    assert vrlib.reconstruct(vol, np.zeros((0, 3))).shape == (0,)
    with pytest.raises(ValueError, match=r"points must have shape \(n, 3\)"):
        vrlib.reconstruct(vol, np.zeros(3))
    with pytest.raises(ValueError, match="points must hold only finite values"):
        vrlib.reconstruct(vol, [[0.0, np.nan, 0.0]])
    with pytest.raises(TypeError, match="points must hold real numbers"):
        vrlib.reconstruct(vol, [["a", "b", "c"]])
    with pytest.raises(ValueError, match="unknown filter 'cubic'; known: .*'omoms'"):
        vrlib.reconstruct(vol, np.zeros((1, 3)), filter="cubic")
    with pytest.raises(TypeError, match="derivative must be True or False"):
        vrlib.reconstruct(vol, np.zeros((1, 3)), derivative="yes")
    with pytest.raises(TypeError, match="volume must be a vrlib.Volume"):
        vrlib.reconstruct(np.zeros((3, 3, 3)), np.zeros((1, 3)))
