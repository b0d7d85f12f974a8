"""The roofline's micro-kernels do the work they claim (their speed is measured in
``benchmarks/bench_roofline.py``, never here)."""

import numba
import numpy as np
import pytest
from naive import reconstruct_naive

from vrlib import Volume, make_filter, roofline
from vrlib._kernels import roofline as kernels
from vrlib._kernels.packets import LANES, trilinear_packet


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


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_packets_sum_what_the_scalar_rays_sum(dtype):
    """Eight rays a packet, sampled in vector form (gathers), sum the same samples as the
    scalar loop: bit for bit in float64 (the same operations lane by lane), within float32
    rounding for float32 samples (widened before their differences, not after). A packet
    that read a corner at the wrong offset, or mixed two lanes, would miss by far more."""
    brick, starts, direction = rays_and_brick(dtype, count=3 * LANES)
    scalar, packed = np.empty(len(starts)), np.empty(len(starts))
    kernels.sample_rays(brick, starts, direction, roofline.STEPS, False, 0.0, 0.5, scalar)
    kernels.sample_packets(brick, starts, direction, roofline.STEPS, packed)
    if dtype == np.float64:
        np.testing.assert_array_equal(packed, scalar)
    else:
        np.testing.assert_allclose(packed, scalar, rtol=0, atol=1e-6)
    one_packet = numba.njit(lambda *args: trilinear_packet(*args))  # compiled code only
    lanes = one_packet(brick.reshape(-1), brick.shape[2], brick.shape[1] * brick.shape[2],
                       *(tuple(float(v) for v in starts[:LANES, axis]) for axis in range(3)))
    expected = reconstruct_naive(Volume(brick.astype(np.float64)), make_filter("trilinear"),
                                 starts[:LANES])
    np.testing.assert_allclose(lanes, expected, rtol=0, atol=1e-6)


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


def test_footprints_sum_the_footprint_table():
    """Each footprint pixel adds the table's value at the pixel's offset from the centre."""
    from vrlib.footprint import footprint
    from vrlib.view import View

    fp = footprint("catmull-rom", (1.0, 1.0, 1.0), View.orbit(azimuth=30, elevation=20).basis)
    px = 0.8
    centres = np.array([[20.3, 21.7], [30.5, 18.25]])
    sheets = np.zeros((1, 64, 64))
    drawn = kernels.draw_footprints(fp.table, fp.extent, fp.extent_v, px, centres, sheets)
    rows, cols = np.mgrid[0:64, 0:64]
    expected = sum(fp((cols + 0.5 - c) * px, (r - rows - 0.5) * px) for r, c in centres)
    np.testing.assert_allclose(sheets[0], expected, atol=1e-12)
    # Pixels drawn: those within the table's reach (columns and rows).
    count = 0
    for r, c in centres:
        count += int(((np.abs(rows + 0.5 - r) * px <= fp.extent_v)
                      & (np.abs(cols + 0.5 - c) * px <= fp.extent)).sum())
    assert drawn == count > 0


@pytest.mark.parametrize("filt, ntaps", [("trilinear", 2), ("catmull-rom", 4)])
def test_resampled_lines_and_slices_match_the_filter(filt, ntaps):
    """Lines resampled with per-output weights equal the naive 1-D reconstruction; slices
    equal the separable 2-D sum with shared weights."""
    rng = np.random.default_rng(5)
    lines = rng.uniform(-1.0, 1.0, (3, 40)).astype(np.float32)
    out = np.empty((5, 30), np.float32)
    kernels.resample_lines(lines, 1.07, 2.3, ntaps, 0.0, 0.5, out)
    k = make_filter(filt)
    for n in range(5):
        pos = np.arange(30) / 1.07 + 2.3
        taps = np.arange(40)
        expected = (k(pos[:, None] - taps[None, :]) * lines[n % 3][None, :]).sum(axis=1)
        np.testing.assert_allclose(out[n], expected, rtol=1e-5, atol=1e-6)
    slices = rng.uniform(-1.0, 1.0, (2, 12, 12))
    offsets = np.arange(ntaps) - (ntaps // 2 - 1)
    wi, wj = k(0.3 - offsets), k(0.6 - offsets)
    planes = np.empty((3, 8, 8))
    kernels.resample_slices(slices, ntaps, wi, wj, planes)
    for n in range(3):
        s = slices[n % 2]
        expected = sum(wj[b] * wi[a] * s[b:b + 8, a:a + 8] for b in range(ntaps)
                       for a in range(ntaps))
        np.testing.assert_allclose(planes[n], expected, rtol=1e-12)


def test_ray_caster_ladder_kernels_do_the_renderers_work():
    """The ladder's kernel samples the same points as the ceiling's (to rounding: positions from
    the lattice, not incremental), and with classification composites the table's opacities
    front to back."""
    brick, starts, direction = rays_and_brick(np.float64)
    ceiling, plain, composited = (np.empty(len(starts)) for _ in range(3))
    table = np.linspace(0.0, 0.2, 11)
    kernels.sample_rays(brick, starts, direction, roofline.STEPS, False, 0.0, 0.5, ceiling)
    kernels.march_rays(brick, starts, direction, roofline.STEPS, False, -1.0, 5.0, table, plain)
    kernels.march_rays(brick, starts, direction, roofline.STEPS, True, -1.0, 5.0, table,
                       composited)
    np.testing.assert_allclose(plain, ceiling, rtol=1e-12)
    points = points_along(starts, direction)
    values = reconstruct_naive(Volume(brick), make_filter("trilinear"),
                               points.reshape(-1, 3)).reshape(points.shape[:2])
    alpha = np.interp((values + 1.0) * 5.0, np.arange(11), table)
    expected = 1.0 - np.prod(1.0 - alpha, axis=1)
    np.testing.assert_allclose(composited, expected, rtol=1e-12)
    ladder = roofline.ray_caster_ladder(threads=1, repeats=1, rays=64)
    assert list(ladder) == ["ceiling", "renderer sampling", "with classification and compositing"]
    assert all(rate > 0 for rate in ladder.values())
