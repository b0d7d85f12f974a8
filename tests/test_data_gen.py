"""Analytic fields (exact values, closed forms) and the volume loaders."""


import numpy as np
import pytest
from scipy import integrate

import data_gen
from data_gen import make_field

FIELD_SPECS = [
    ("gaussian-blob", {"center": (0.1, -0.2, 0.3), "sigma": 0.25, "amplitude": 2.0}),
    ("random-blobs", {"count": 3, "seed": 7}),
    ("marschner-lobb", {}),
    ("smooth-sphere", {"radius": 0.5, "width": 0.1}),
    ("grating", {"frequency": 3.0, "direction": (1, 2, 2)}),
    ("step-edge", {"normal": (0, 1, 1), "offset": 0.1}),
]


def quad_line(field, origin, direction, t0, t1):
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    value, _ = integrate.quad(lambda t: float(field(np.asarray(origin) + t * d)), t0, t1,
                              epsabs=1e-12, epsrel=1e-12, limit=400)
    return value


@pytest.mark.parametrize("name, params", FIELD_SPECS, ids=[s[0] for s in FIELD_SPECS])
def test_sample_puts_exact_values_on_the_lattice(name, params):
    field = make_field(name, **params)
    vol = field.sample((5, 6, 7))
    k, j, i = 3, 2, 5
    point = vol.index_to_world([i, j, k])
    assert vol.data[k, j, i] == pytest.approx(float(field(point)), abs=1e-15)
    np.testing.assert_array_equal(vol.extent, field.bounds)


CLOSED_FORMS = [s for s in FIELD_SPECS if s[0] not in ("marschner-lobb", "smooth-sphere")]


@pytest.mark.parametrize("name, params", CLOSED_FORMS, ids=[s[0] for s in CLOSED_FORMS])
def test_line_integrals_match_quadrature(name, params):
    field = make_field(name, **params)
    rng = np.random.default_rng(1)
    for _ in range(5):
        origin = rng.uniform(-1, 1, 3)
        direction = rng.normal(size=3)
        exact = float(field.line_integral(origin, direction, -0.7, 1.9))
        assert exact == pytest.approx(quad_line(field, origin, direction, -0.7, 1.9), abs=1e-9)


def test_blob_closed_forms():
    """The rendering model (docs/model.md): line integral A s sqrt(2 pi) exp(-r^2 / 2 s^2),
    total mass A (2 pi)^(3/2) s^3."""
    blob = make_field("gaussian-blob", center=(0.2, 0.0, 0.0), sigma=0.3, amplitude=1.5)
    r = 0.35
    line = blob.line_integral([0.2 + r, 0.0, -10.0], [0, 0, 1])
    assert line == pytest.approx(1.5 * 0.3 * np.sqrt(2 * np.pi) * np.exp(-(r**2) / 0.18))
    assert blob.integral() == pytest.approx(1.5 * (2 * np.pi) ** 1.5 * 0.3**3)
    box = [[-1, 1], [-0.5, 1], [-1, 0.2]]
    numeric, _ = integrate.tplquad(
        lambda z, y, x: float(blob([x, y, z])), -1, 1, -0.5, 1, -1, 0.2, epsabs=1e-10
    )
    assert blob.integral(box) == pytest.approx(numeric, rel=1e-8)


@pytest.mark.parametrize("name", ["gaussian-blob", "random-blobs", "marschner-lobb",
                                  "smooth-sphere", "grating"])
def test_gradients_match_finite_differences(name):
    params = {"count": 3} if name == "random-blobs" else {}
    field = make_field(name, **params)
    pts = np.random.default_rng(2).uniform(-0.9, 0.9, (20, 3))
    h = 1e-6
    fd = np.stack([(field(pts + h * e) - field(pts - h * e)) / (2 * h) for e in np.eye(3)], -1)
    np.testing.assert_allclose(field.gradient(pts), fd, atol=1e-5)


def test_marschner_lobb_uses_the_2d_radius():
    """rho depends on x, y only through r = sqrt(x^2 + y^2) (public code often wrongly uses
    the 3-D radius), and ranges over [0, 1]."""
    ml = make_field("marschner-lobb")
    a = ml([0.3, 0.4, 0.25])
    b = ml([0.5, 0.0, 0.25])
    assert a == pytest.approx(b, abs=1e-15)
    c = ml([0.5, 0.0, 0.0])
    expected = (1 + 0.25 * (1 + np.cos(2 * np.pi * 6 * np.cos(np.pi * 0.5 / 2)))) / 2.5
    assert c == pytest.approx(expected, abs=1e-15)
    values = ml.sample(41).data
    assert values.min() >= 0.0 and values.max() <= 1.0


def test_random_blobs_are_reproducible():
    a = make_field("random-blobs", count=5, seed=3).sample(8).data
    b = make_field("random-blobs", count=5, seed=3).sample(8).data
    c = make_field("random-blobs", count=5, seed=4).sample(8).data
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_sampling_in_chunks_matches_direct(monkeypatch):
    field = make_field("marschner-lobb")
    whole = field.sample((9, 10, 11)).data
    monkeypatch.setattr("data_gen.fields._CHUNK", 7)  # one z plane per chunk
    np.testing.assert_array_equal(field.sample((9, 10, 11)).data, whole)
    small = field.sample(4, extent=[[0, 1], [0, 1], [0, 1]], dtype=np.float32)
    assert small.dtype == np.float32 and small.origin.tolist() == [0, 0, 0]


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda: make_field("sphere"), ValueError, "unknown field .sphere.; known: .gaussian"),
        (lambda: make_field("gaussian-blob", width=1), TypeError, "bad parameters for field"),
        (lambda: make_field("gaussian-blob", sigma=0), ValueError, "sigma must be > 0"),
        (lambda: make_field("grating", direction=(0, 0, 0)), ValueError, "non-zero vector"),
        (lambda: make_field("blobs", blobs=[]), ValueError, "at least one blob"),
        (lambda: make_field("marschner-lobb").sample(1), ValueError, "integer >= 2"),
        (lambda: make_field("marschner-lobb").sample((4, 4)), ValueError, r"\(nz, ny, nx\)"),
        (lambda: make_field("marschner-lobb").sample(4, dtype=np.int16), ValueError,
         "float32 or float64"),
        (lambda: make_field("marschner-lobb")(np.zeros((3, 2))), ValueError, "last axis"),
        (lambda: make_field("grating").line_integral([0, 0, 0], [1, 0, 0]), ValueError,
         "needs finite t0 and t1"),
        (lambda: make_field("gaussian-blob").line_integral([0, 0, 0], [0, 0, 0]), ValueError,
         "non-zero"),
        (lambda: make_field("smooth-sphere").line_integral([0, 0, 0], [1, 0, 0]),
         NotImplementedError, "no closed-form line integral"),
    ],
)
def test_bad_input(call, error, message):
    with pytest.raises(error, match=message):
        call()


# -- loaders ---------------------------------------------------------------------------------


def test_mni_template_is_a_real_mri_volume():
    vol = data_gen.load("mni152")
    assert vol.shape == (95, 117, 99)  # [z, y, x] of the 2 mm template
    lo, hi = vol.value_range
    assert lo >= 0.0 and hi > 0.5
    assert np.count_nonzero(vol.data) > vol.data.size // 4


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda p: data_gen.load(p / "missing.npy"), FileNotFoundError, "no volume file"),
        (lambda p: data_gen.load_raw(p / "v.raw", (4, 5, 7), "uint16"), ValueError,
         "raw file holds 240 bytes, but shape"),
        (lambda p: data_gen.load_raw(p / "v.raw", (4, 5, 6), "uint16", byteorder="middle"),
         ValueError, "unknown byteorder"),
        (lambda p: data_gen.load_npy(p / "flat.npy"), ValueError, "must be 3-dimensional"),
        (lambda p: data_gen.load_mni_template(resolution=3), ValueError, "resolution must be"),
    ],
)
def test_loader_errors(tmp_path, call, error, message):
    np.zeros((4, 5, 6), np.uint16).tofile(tmp_path / "v.raw")
    (tmp_path / "v.tiff").write_bytes(b"")
    np.save(tmp_path / "flat.npy", np.zeros((3, 3)))
    with pytest.raises(error, match=message):
        call(tmp_path)
