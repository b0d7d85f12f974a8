"""The prefilter of generalized interpolation (vrlib.prefilter): poles, exactness, boundary
rule, scipy agreement, numerical range."""

import math
import os

import numpy as np
import pytest
from naive import interpolation_matrix
from scipy import ndimage

import data_gen
import vrlib
from vrlib import prefilter
from vrlib.filters import make_filter

PREFILTERED = ["cardinal-bspline", "omoms"]


def test_poles_are_the_roots_of_the_sampled_kernels():
    """The published poles: sqrt(3) - 2 for the cubic B-spline (Unser 1999), (sqrt(105) -
    13) / 8 for cubic O-MOMS (from its sampled kernel (4 z + 13 + 4 / z) / 21)."""
    assert make_filter("cardinal-bspline").poles[0] == pytest.approx(math.sqrt(3) - 2, abs=1e-15)
    assert make_filter("omoms").poles[0] == pytest.approx((math.sqrt(105) - 13) / 8, abs=1e-15)
    assert make_filter("catmull-rom").poles == () and not make_filter("bspline").prefiltered


@pytest.mark.parametrize("name", PREFILTERED)
@pytest.mark.parametrize("n", [2, 3, 4, 17, 80])
def test_recursion_solves_the_boundary_system(name, n):
    """The recursion's coefficients solve the interpolation system with the half-sample
    symmetric boundary (the naive twin's matrix), to rounding, for short and long lines."""
    filt = make_filter(name)
    f = np.random.default_rng(n).normal(size=n)
    c = prefilter.coefficients(f, filt.poles)
    a = interpolation_matrix(filt, n)
    np.testing.assert_allclose(a @ c, f, atol=1e-13)
    np.testing.assert_allclose(c, np.linalg.solve(a, f), atol=1e-12)


def test_cardinal_coefficients_equal_scipys_spline_filter():
    """scipy.ndimage.spline_filter(order=3, mode="reflect") computes the same coefficients
    (its start of the causal recursion is truncated, exact to about 1e-14 from 20 samples)."""
    data = np.random.default_rng(3).random((24, 21, 20))
    ours = prefilter.coefficients(data, make_filter("cardinal-bspline").poles)
    np.testing.assert_allclose(ours, ndimage.spline_filter(data, order=3, mode="reflect"),
                               atol=1e-12)


@pytest.mark.parametrize("scale", [1e300, 1e-300, 1e-310])
def test_huge_and_tiny_values_scale_exactly(scale):
    """The recursion is linear: scaled samples give scaled coefficients, with no overflow at
    1e300 and none of the relative precision lost at 1e-300 (1e-310 is subnormal: only its
    absolute precision, 1e-323, is kept)."""
    f = np.random.default_rng(0).random((5, 4, 3))
    pole = make_filter("omoms").poles
    c = prefilter.coefficients(f, pole)
    scaled = prefilter.coefficients(f * scale, pole)
    assert np.all(np.isfinite(scaled))
    tol = 1e-14 if scale > 1e-300 else 1e-10
    np.testing.assert_allclose(scaled / scale, c, rtol=tol, atol=tol)


def test_step_edge_rings_and_the_ringing_decays_at_the_pole_rate():
    """A step's coefficients overshoot (the interpolating spline rings), and the overshoot
    falls by |p| per sample away from the edge."""
    f = np.r_[np.zeros(20), np.ones(20)]
    for name in PREFILTERED:
        p = make_filter(name).poles[0]
        c = prefilter.coefficients(f, [p])
        beyond = c[20:30] - 1.0
        assert beyond[0] > 0.0 and c[19] < 0.0
        np.testing.assert_allclose(beyond[1:] / beyond[:-1], p, rtol=1e-9)


def test_coefficient_volume_is_cached_counted_and_flushes_what_it_cannot_store():
    """Built once per volume and filter (0 s the second time); coefficients below the storage
    type's resolution of the largest sample are exact zeros, so a sparse volume stays sparse."""
    data = np.zeros((40, 8, 8), dtype=np.float32)
    data[:3] = 1.0
    vol = vrlib.Volume(data)
    coeffs, seconds = prefilter.coefficient_volume(vol, make_filter("cardinal-bspline"))
    assert seconds > 0.0 and coeffs.dtype == np.float32
    assert prefilter.coefficient_volume(vol, make_filter("cardinal-bspline"))[0] is coeffs
    assert prefilter.coefficient_volume(vol, make_filter("cardinal-bspline"))[1] == 0.0
    assert np.all(coeffs.data[20:] == 0.0) and np.all(coeffs.data[:4] != 0.0)
    with pytest.raises(ValueError, match="takes no prefilter"):
        prefilter.coefficient_volume(vol, make_filter("catmull-rom"))
    with pytest.raises(ValueError, match="poles must lie in"):
        prefilter.coefficients([1.0, 2.0], [0.5])
    with pytest.raises(ValueError, match="differences overflow; rescale them"):
        vrlib.Volume(np.tile([0.0, 1.7e308], (2, 2, 1)))  # refused before any prefilter


@pytest.mark.parametrize("name", PREFILTERED)
def test_effective_response_is_the_cardinal_kernels_fourier_transform(name):
    """The reconstruction of a unit impulse is the cardinal kernel; its numerical Fourier
    transform is ``effective_response`` (the kernel's response over the sampled kernel's)."""
    filt = make_filter(name)
    n = 101
    c = prefilter.coefficients(np.eye(1, n, n // 2)[0], filt.poles)
    x = np.linspace(-40.0, 40.0, 32001)
    k = np.arange(n) - n // 2
    cardinal = (c[None, :] * filt(x[:, None] - k[None, :])).sum(axis=1)
    omega = np.linspace(0.0, 2.5 * np.pi, 11)
    numeric = (cardinal[None, :] * np.cos(omega[:, None] * x[None, :])).sum(axis=1) * (x[1] - x[0])
    np.testing.assert_allclose(filt.effective_response(omega), numeric, atol=1e-6)


def test_every_method_counts_what_its_prefilter_costs():
    """The coefficients a method needs from the volume are computed once and kept; the shear
    methods also prefilter their intermediate lines on every frame (ch04 times both)."""
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=12)
    for method in vrlib.METHODS:
        vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample((9, 10, 11))
        first, later = (vrlib.render(vol, view, method=method, filter="cardinal-bspline")
                        for _ in range(2))
        assert first.stats.prefilter["samples"] >= vol.data.size, method
        assert first.stats.prefilter["operations"] == (
            prefilter.OPERATIONS_PER_VOXEL * first.stats.prefilter["samples"]
            * (1 if method in ("shear3", "shear2") else (2 if method == "shearwarp" else 3)))
        assert 0.0 < first.stats.prefilter["kept_seconds"] <= first.stats.prefilter["seconds"]
        assert later.stats.prefilter["kept_seconds"] == 0.0
        per_frame = later.stats.prefilter["samples"]
        assert (per_frame > 0) == (method in ("shear3", "shear2")), method
        assert later.stats.prefilter["cached"] == (per_frame == 0)
        assert per_frame < first.stats.prefilter["samples"]
        assert vrlib.render(vol, view, method=method).stats.prefilter is None


def test_python_threads_take_turns_in_the_parallel_kernels():
    """numba's workqueue threading layer (its fallback without TBB or OpenMP, and the
    Makefile's) aborts the whole process when two Python threads run parallel regions at once;
    vrlib's parallel kernels are launched one at a time
    (:data:`vrlib._kernels._jit.PARALLEL_LAUNCH`), so four threads prefiltering at once finish,
    each with the serial answer. Without the lock this process aborts within its first
    rounds."""
    import subprocess
    import sys

    code = """
import threading
import numpy as np
from vrlib.prefilter import coefficients
rng = np.random.default_rng(0)
data = [rng.random((12, 10, 14)) for _ in range(4)]
pole = [3.0 ** 0.5 - 2.0]
expected = [coefficients(d, pole) for d in data]
wrong = []
def work(i):
    for _ in range(200):
        if not np.array_equal(coefficients(data[i], pole), expected[i]):
            wrong.append(i)
threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
for t in threads:
    t.start()
for t in threads:
    t.join()
print("wrong", len(wrong))
"""
    env = {**os.environ, "NUMBA_THREADING_LAYER": "workqueue"}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=300, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "wrong 0" in done.stdout
