"""Transfer functions: Glow, lookup tables, shading, and their kernel twins."""

import numpy as np
import pytest

from vrlib import Glow, LookupTransfer, Phong
from vrlib.transfer import range_maximum

VALUES = np.linspace(-0.5, 2.5, 61)


def test_glow_is_the_study_function():
    """Eq 1.9 with O the identity (scaled) and S = 1."""
    glow = Glow(3.0)
    np.testing.assert_allclose(glow.opacity_density(VALUES), 3.0 * np.maximum(VALUES, 0))
    np.testing.assert_array_equal(glow.emission(VALUES), np.ones((61, 3)))
    assert glow.max_density(-2.0, -1.0) == 0.0
    assert glow.max_density(-1.0, 0.5) == 1.5


def make_table():
    rng = np.random.default_rng(3)
    return LookupTransfer(rng.uniform(0, 5, 9), rng.uniform(0, 1, (9, 3)),
                          value_range=(0.0, 2.0))


@pytest.mark.parametrize("tf", [Glow(2.0), make_table()], ids=["glow", "table"])
def test_segment_table_interpolates_to_the_exact_model(tf):
    """The kernels' table of segment opacity and colour, linearly interpolated, is within
    1e-8 of 1 - exp(-density ds) and 1e-6 of E alpha (measured 1.1e-8 for this steep colour
    table) at any value up to the bound it was built for (renderers pass a bound on every value
    the filter can reconstruct)."""
    ds = 0.05
    start, inv, alpha, premult, emit = tf.segment_table(ds, -0.7, 2.4)
    values = np.linspace(-1.0, 2.4, 4001)
    pos = np.clip((values - start) * inv, 0, alpha.size - 1)
    grid = np.arange(alpha.size)
    exact_alpha = -np.expm1(-tf.opacity_density(values) * ds)
    np.testing.assert_allclose(np.interp(pos, grid, alpha), exact_alpha, atol=1e-8)
    for ch in range(3):
        np.testing.assert_allclose(np.interp(pos, grid, premult[:, ch]),
                                   tf.emission(values)[:, ch] * exact_alpha, atol=1e-6)
        np.testing.assert_allclose(np.interp(pos, grid, emit[:, ch]), tf.emission(values)[:, ch],
                                   atol=1e-12)


def test_table_interpolates_and_clamps():
    tf = LookupTransfer([0.0, 2.0, 1.0], [[0, 0, 0], [1, 0, 0], [0, 0, 1]],
                        value_range=(1.0, 3.0))
    np.testing.assert_allclose(tf.opacity_density([0.0, 1.5, 2.0, 2.5, 9.0]),
                               [0.0, 1.0, 2.0, 1.5, 1.0])
    np.testing.assert_allclose(tf.emission([2.5]), [[0.5, 0, 0.5]])


def test_table_max_density_bounds_every_value_in_range():
    tf = make_table()
    rng = np.random.default_rng(0)
    for _ in range(200):
        lo, hi = np.sort(rng.uniform(-1, 3, 2))
        inside = np.linspace(lo, hi, 501)
        bound = tf.max_density(lo, hi)
        assert bound >= tf.opacity_density(inside).max() - 1e-12
        assert bound == pytest.approx(tf.opacity_density(inside).max(), abs=0.05)


@pytest.mark.parametrize("count", [1, 2, 4, 5, 40])
def test_range_maximum_is_each_intervals_maximum(count):
    """A few intervals are read one by one, more from the sparse table: both give each
    interval's maximum exactly."""
    rng = np.random.default_rng(count)
    values = rng.random(257)
    first = rng.integers(0, 256, count)
    last = first + 1 + rng.integers(0, 257 - first)
    expected = [values[a:b].max() for a, b in zip(first, last, strict=True)]
    assert range_maximum(values, first, last).tolist() == expected


def test_from_alpha_matches_vtk_opacity_units():
    """VTK's scalar opacity is alpha per unit distance; density -ln(1 - a)/d reproduces it."""
    tf = LookupTransfer.from_alpha([0.0, 0.5], unit_distance=0.25)
    alpha_over_unit = 1 - np.exp(-tf.opacity_density([1.0]) * 0.25)
    np.testing.assert_allclose(alpha_over_unit, [0.5])


def test_phong_factor():
    shade = Phong(ambient=0.2, diffuse=0.6, specular=0.5, shininess=4.0)
    view_dir = np.array([0.0, 0.0, 1.0])
    grads = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 3.0]])
    np.testing.assert_allclose(shade.factor(grads, view_dir), [0.8, 0.2, 0.8, 0.8])
    np.testing.assert_allclose(shade.highlight(grads, view_dir), [0.5, 0.0, 0.5, 0.5])
    lit_side = Phong(ambient=0.0, diffuse=1.0, light=(1, 0, 0))
    np.testing.assert_allclose(lit_side.factor(grads, view_dir), [0.0, 1.0, 1.0, 0.0])


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda: Glow(0.0), ValueError, "scale must be > 0"),
        (lambda: Glow(np.nan), ValueError, "scale must be finite"),
        (lambda: Glow(1.0, shading="phong"), TypeError, "shading must be a vrlib.Phong"),
        (lambda: LookupTransfer([1.0]), ValueError, "at least 2 entries"),
        (lambda: LookupTransfer([[1.0, 2.0]]), ValueError, "density must be 1-dimensional"),
        (lambda: LookupTransfer([1.0, -1.0]), ValueError, "must be >= 0"),
        (lambda: LookupTransfer([1.0, np.nan]), ValueError, "only finite values"),
        (lambda: LookupTransfer([1.0, 2.0], [[1, 1, 1]]), ValueError,
         r"color table must have shape \(2, 3\)"),
        (lambda: LookupTransfer([1.0, 2.0], [[1, 1], [1, 1]]), ValueError,
         r"shape \(2, 3\) to match"),
        (lambda: LookupTransfer([1.0, 2.0], value_range=(1.0, 1.0)), ValueError,
         "value_range must be increasing"),
        (lambda: LookupTransfer.from_alpha([0.0, 1.0]), ValueError, r"alpha entries .* \[0, 1\)"),
        (lambda: Phong(ambient=-0.1), ValueError, "ambient must be >= 0"),
        (lambda: Phong(shininess=0.0), ValueError, "shininess must be > 0"),
        (lambda: Phong(light=(0, 0, 0)), ValueError, "light must be a non-zero vector"),
    ],
)
def test_bad_input(call, error, message):
    with pytest.raises(error, match=message):
        call()


def _head():
    """A stand-in for a scan: a ball of tissue (values near 100) in faint noise."""
    rng = np.random.default_rng(5)
    z, y, x = np.mgrid[-1:1:24j, -1:1:24j, -1:1:24j]
    data = np.where(x * x + y * y + z * z < 0.6, 90.0 + 20.0 * rng.random((24,) * 3),
                    5.0 * rng.random((24,) * 3))
    return data


def test_one_default_transfer_for_python_and_the_command_line(tmp_path):
    """Real data rendered without a transfer function shows its inside (the ramp fitted to
    its histogram), as the command line's default does; the analytic fields' samples keep
    the thesis's Glow(1.0). Glow(1.0) on such data is the white silhouette the default
    used to give."""
    import argparse

    import data_gen
    import vrlib
    from vrlib.cli import make_transfer

    volume = vrlib.Volume(_head())
    view = vrlib.View.orbit(azimuth=20, size=24)
    shown = vrlib.render(volume, view)
    np.testing.assert_array_equal(
        shown.rgba, vrlib.render(volume, view, transfer=vrlib.auto_transfer(volume)).rgba)
    glow = vrlib.render(volume, view, transfer=Glow(1.0)).alpha
    covered = glow > 0.5
    assert (glow[covered] > 0.99).mean() > 0.5  # measured 0.65: a silhouette
    assert (shown.alpha[covered] > 0.99).mean() < 0.1  # measured 0
    assert np.ptp(shown.composited()[covered]) > 0.5  # measured 0.89
    # The command line builds the same function for a file.
    np.save(tmp_path / "head.npy", _head())
    loaded = data_gen.load(tmp_path / "head.npy")
    options = argparse.Namespace(shade=False, cmap=None, labels=False, transfer=None,
                                 opacity=None, clim=None)
    cli = make_transfer(options, field=None)(loaded)
    values = np.linspace(*loaded.value_range, 101)
    default = vrlib.default_transfer(loaded)
    np.testing.assert_array_equal(cli.opacity_density(values), default.opacity_density(values))
    np.testing.assert_array_equal(cli.emission(values), default.emission(values))
    # Fields keep Glow(1.0), in render and in classify.
    blob = data_gen.make_field("gaussian-blob", sigma=0.4).sample(12)
    assert repr(vrlib.default_transfer(blob)) == "Glow(1)"
    np.testing.assert_array_equal(vrlib.render(blob, view).rgba,
                                  vrlib.render(blob, view, transfer=Glow(1.0)).rgba)
    assert repr(vrlib.classify(blob).transfer) == "Glow(1)"
    assert vrlib.classify(volume).transfer is vrlib.default_transfer(volume)
    with pytest.raises(TypeError, match="transfer must be None or a vrlib transfer function"):
        vrlib.Volume(_head(), transfer="glow")
