"""The roofline's micro-kernels do the work they claim (their speed is measured in
``benchmarks/bench_roofline.py``, never here)."""

import numba
import numpy as np
import pytest
from naive import reconstruct_naive

from vrlib import Volume, make_filter, roofline
from vrlib._kernels import roofline as kernels


def rays_and_brick(dtype, count=5):
    rng = np.random.default_rng(3)
    brick = rng.uniform(-1.0, 1.0, (roofline.BRICK,) * 3).astype(dtype)
    direction = np.array([0.36, 0.48, 0.8])
    return brick, roofline._rays(count, direction), direction


def points_along(starts, direction):
    steps = np.arange(roofline.STEPS)[None, :, None]
    return starts[:, None, :] + steps * direction  # (rays, steps, 3)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_trilinear_rays_sum_the_trilinear_samples(dtype):
    """Each ray's sum equals the sum of the naive reconstruction at its sample points (the
    rays never leave the brick, so no clamping is involved)."""
    brick, starts, direction = rays_and_brick(dtype)
    out = np.empty(len(starts))
    kernels.sample_rays(brick, starts, direction, roofline.STEPS, False, 0.0, 0.5, out)
    points = points_along(starts, direction)
    assert points.min() >= 1.0 and points.max() <= roofline.BRICK - 3.0
    expected = reconstruct_naive(Volume(brick.astype(np.float64)), make_filter("trilinear"),
                                 points.reshape(-1, 3)).reshape(points.shape[:2]).sum(axis=1)
    np.testing.assert_allclose(out, expected, rtol=1e-5 if dtype == np.float32 else 1e-12,
                               atol=1e-5)


def test_tricubic_rays_sum_the_catmull_rom_samples():
    brick, starts, direction = rays_and_brick(np.float32)
    out = np.empty(len(starts))
    kernels.sample_rays(brick, starts, direction, roofline.STEPS, True, 0.0, 0.5, out)
    points = points_along(starts, direction)
    expected = reconstruct_naive(Volume(brick.astype(np.float64)), make_filter("catmull-rom"),
                                 points.reshape(-1, 3)).reshape(points.shape[:2]).sum(axis=1)
    np.testing.assert_allclose(out, expected, rtol=1e-5, atol=1e-5)


def test_triad_and_measure():
    """The triad computes b + s c; measure reports every ceiling and restores the thread
    count it changed."""
    a, b, c = np.zeros(10), np.arange(10.0), np.ones(10)
    kernels.triad(a, b, c, 2.0)
    np.testing.assert_array_equal(a, np.arange(10.0) + 2.0)
    before = numba.get_num_threads()
    limits = roofline.measure(threads=1, repeats=1, elements=1 << 12, rays=64)
    assert numba.get_num_threads() == before and limits["threads"] == 1
    assert all(limits[k] > 0 for k in limits)
    with pytest.raises(ValueError, match="repeats must be an integer >= 1"):
        roofline.measure(repeats=0)
