"""Image output and the error metrics."""

import os

import numpy as np
import png  # pypng: an independent decoder for our PNG writer
import pytest

from vrlib import Image, metrics


def gradient_image(h=16, w=12):
    alpha = np.linspace(0.0, 1.0, h * w).reshape(h, w)
    rgba = np.stack([0.5 * alpha, alpha, 0.25 * alpha, alpha], axis=-1)
    return Image(rgba)


def read_png(path):
    width, height, rows, info = png.Reader(bytes=path.read_bytes()).read()
    planes = info["planes"]
    return np.array([np.asarray(row) for row in rows]).reshape(height, width, planes)


def test_png_round_trip_8_and_16_bit(tmp_path):
    img = gradient_image()
    for bits, top in [(8, 255), (16, 65535)]:
        path = tmp_path / f"out{bits}.png"
        img.save(path, bits=bits)
        back = read_png(path)
        assert back.shape == (16, 12, 3)
        np.testing.assert_allclose(back / top, img.composited(), atol=0.5 / top + 1e-12)


def test_png_with_straight_alpha(tmp_path):
    img = gradient_image()
    path = tmp_path / "rgba.png"
    img.save(path, bits=16, background=None)
    back = read_png(path) / 65535
    assert back.shape == (16, 12, 4)
    np.testing.assert_allclose(back[..., 3], img.alpha, atol=1e-5)
    visible = img.alpha > 0.05
    np.testing.assert_allclose(back[..., 1][visible], 1.0, atol=1e-4)


def test_npy_round_trip(tmp_path):
    img = gradient_image()
    img.save(tmp_path / "img.npy")
    np.testing.assert_array_equal(np.load(tmp_path / "img.npy"), img.rgba)


def test_save_is_atomic(tmp_path, monkeypatch):
    """A writer that fails mid-way leaves the previous file in place and no temporary."""
    path = tmp_path / "img.png"
    gradient_image().save(path)
    before = path.read_bytes()

    def broken_bytes():
        raise OSError("disk full")

    monkeypatch.setattr("vrlib.image.encode_png", lambda pixels: broken_bytes())
    with pytest.raises(OSError, match="disk full"):
        gradient_image().save(path)
    assert path.read_bytes() == before
    assert os.listdir(tmp_path) == ["img.png"]


@pytest.mark.parametrize(
    "rgba, message",
    [
        (np.zeros((4, 4, 3)), r"shape \(height, width, 4\)"),
        (np.zeros((4, 4)), "rgba must be 3-dimensional"),
        (np.full((2, 2, 4), np.nan), "only finite values"),
        (np.full((2, 2, 4), 1.5), r"alpha must lie in \[0, 1\]"),
    ],
)
def test_image_rejects_bad_arrays(rgba, message):
    with pytest.raises(ValueError, match=message):
        Image(rgba)


def test_save_rejects_bad_arguments(tmp_path):
    img = gradient_image()
    with pytest.raises(ValueError, match=r"must end in \.png or \.npy"):
        img.save(tmp_path / "img.jpg")
    with pytest.raises(ValueError, match="bits must be 8 or 16"):
        img.save(tmp_path / "img.png", bits=12)
    assert not any(tmp_path.iterdir())


def test_metrics_basic_values():
    a = np.zeros((8, 8))
    b = np.full((8, 8), 0.2)
    assert metrics.rmse(a, b) == pytest.approx(0.2)
    assert metrics.max_abs_error(a, b) == pytest.approx(0.2)
    assert metrics.psnr(a, b) == pytest.approx(20 * np.log10(1 / 0.2))
    assert metrics.psnr(a, a) == np.inf
    assert metrics.ssim(b, b) == pytest.approx(1.0)
    assert metrics.csf_error(a, b) == pytest.approx(0.2)


def test_metrics_take_images():
    img = gradient_image()
    other = Image(img.rgba * 0.9)
    assert metrics.rmse(img, other) == pytest.approx(metrics.rmse(img.rgba, other.rgba))
    assert metrics.ssim(img, other) < 1.0


def test_metric_ordering_on_noise():
    """More noise scores worse on every metric."""
    rng = np.random.default_rng(0)
    clean = np.tile(np.linspace(0, 1, 32), (32, 1))
    small = clean + rng.normal(0, 0.01, clean.shape)
    large = clean + rng.normal(0, 0.05, clean.shape)
    assert metrics.rmse(clean, small) < metrics.rmse(clean, large)
    assert metrics.psnr(clean, small) > metrics.psnr(clean, large)
    assert metrics.ssim(clean, small) > metrics.ssim(clean, large)
    assert metrics.csf_error(clean, small) < metrics.csf_error(clean, large)


def test_csf_discounts_fine_ripple_not_smooth_error():
    """Equal RMS: a pixel-scale checkerboard counts less than a smooth ripple of error.

    The checkerboard's one frequency is sqrt(2)/2 cycles per pixel, 22.6 cycles/degree at 32
    pixels per degree, where the Mannos-Sakrison CSF is 0.40 of its peak; the smooth ripple (one
    cycle per image, 0.5 cycles/degree) is on the flat part held at 1.
    """
    n = 64
    checker = 0.1 * (2 * (np.indices((n, n)).sum(axis=0) % 2) - 1)
    ramp = 0.1 * np.sin(2 * np.pi * np.arange(n) / n)[None, :].repeat(n, 0) * np.sqrt(2)
    zero = np.zeros((n, n))
    assert metrics.rmse(zero, checker) == pytest.approx(metrics.rmse(zero, ramp), rel=1e-9)
    def csf(f):
        return 2.6 * (0.0192 + 0.114 * f) * np.exp(-((0.114 * f) ** 1.1))

    expected = 0.1 * csf(32 * np.sqrt(2) / 2) / csf(8.0)
    assert metrics.csf_error(zero, checker) == pytest.approx(expected, rel=1e-9)
    assert metrics.csf_error(zero, ramp) == pytest.approx(0.1, rel=1e-9)


@pytest.mark.parametrize("name", sorted(metrics.METRICS))
def test_metrics_reject_bad_input(name):
    metric = metrics.METRICS[name]
    with pytest.raises(ValueError, match="same shape"):
        metric(np.zeros((8, 8)), np.zeros((8, 9)))
    with pytest.raises(ValueError, match="only finite"):
        metric(np.zeros((8, 8)), np.full((8, 8), np.nan))


def test_metric_specific_errors():
    with pytest.raises(ValueError, match="at least 7 x 7"):
        metrics.ssim(np.zeros((4, 4)), np.zeros((4, 4)))
    with pytest.raises(ValueError, match="data_range must be > 0"):
        metrics.psnr(np.zeros(4), np.ones(4), data_range=0)
    with pytest.raises(ValueError, match="pixels_per_degree must be > 0"):
        metrics.csf_error(np.zeros((4, 4)), np.ones((4, 4)), pixels_per_degree=-1)
    with pytest.raises(ValueError, match="must not be empty"):
        metrics.rmse(np.zeros(0), np.zeros(0))


def test_an_image_shows_itself_in_a_notebook():
    """Jupyter calls _repr_png_: the PNG that save() writes, composited over black."""
    import io

    import imageio.v3 as iio

    rgba = np.zeros((3, 4, 4))
    rgba[1, 2] = (0.25, 0.5, 0.0, 0.5)
    data = Image(rgba)._repr_png_()
    pixels = iio.imread(io.BytesIO(data))
    assert pixels.shape == (3, 4, 3) and pixels[1, 2].tolist() == [64, 128, 0]
