"""Image error metrics.

Every metric takes two images of the same shape: :class:`vrlib.Image` objects (compared on all
four premultiplied RGBA channels) or plain arrays (compared as given), and returns a float.

The thesis judged images with a heuristic metric of its own whose definition is not at hand;
:func:`csf_error` is this package's documented stand-in (see its docstring), reported beside
the standard metrics so that a conclusion can be checked for dependence on the choice.
"""

from __future__ import annotations

import numpy as np

from vrlib import validate
from vrlib.image import Image

__all__ = ["rmse", "max_abs_error", "psnr", "ssim", "csf_error", "METRICS"]


def _pair(a, b):
    arrays = []
    for name, value in (("a", a), ("b", b)):
        if isinstance(value, Image):
            value = value.rgba
        arrays.append(validate.finite_array(name, value))
    a, b = arrays
    if a.shape != b.shape:
        raise ValueError(f"images must have the same shape, got {a.shape} and {b.shape}")
    if a.size == 0:
        raise ValueError("images must not be empty")
    return a, b


def rmse(a, b):
    """Root-mean-square difference.

    Examples
    --------
    >>> rmse(np.zeros((2, 2)), np.full((2, 2), 0.5))
    0.5
    """
    a, b = _pair(a, b)
    return float(np.sqrt(np.mean((a - b) ** 2)))


def max_abs_error(a, b):
    """Largest absolute difference.

    Examples
    --------
    >>> max_abs_error(np.array([0.0, 1.0]), np.array([0.25, 0.5]))
    0.5
    """
    a, b = _pair(a, b)
    return float(np.max(np.abs(a - b)))


def psnr(a, b, *, data_range=1.0):
    """Peak signal-to-noise ratio in dB, ``20 log10(data_range / rmse)`` (inf if equal).

    Examples
    --------
    >>> round(psnr(np.zeros(4), np.full(4, 0.1)), 6)
    20.0
    """
    peak = validate.positive_number("data_range", data_range)
    err = rmse(a, b)
    if err == 0.0:
        return float("inf")
    return float(20.0 * np.log10(peak / err))


def ssim(a, b, *, data_range=1.0):
    """Structural similarity (scikit-image; 1 for identical images).

    2-D arrays are compared as grey images; 3-D arrays as images with channels in the last
    axis. Both sides must be at least 7 x 7 pixels (the default SSIM window).

    Examples
    --------
    >>> x = np.linspace(0, 1, 64).reshape(8, 8)
    >>> ssim(x, x)
    1.0
    """
    a, b = _pair(a, b)
    peak = validate.positive_number("data_range", data_range)
    if a.ndim not in (2, 3):
        raise ValueError(f"ssim needs 2-D images or 3-D (H, W, C) images, got shape {a.shape}")
    if min(a.shape[:2]) < 7:
        raise ValueError(f"ssim needs images of at least 7 x 7 pixels, got {a.shape[:2]}")
    channel_axis = -1 if a.ndim == 3 else None
    from skimage.metrics import structural_similarity  # slow to import: on first use

    return float(structural_similarity(a, b, data_range=peak, channel_axis=channel_axis))


def _csf(cycles_per_degree):
    """Mannos-Sakrison contrast sensitivity, flattened to its peak below the peak frequency."""
    f = np.asarray(cycles_per_degree, dtype=np.float64)
    peak_f = 8.0
    f = np.maximum(f, peak_f)
    s = 2.6 * (0.0192 + 0.114 * f) * np.exp(-((0.114 * f) ** 1.1))
    peak = 2.6 * (0.0192 + 0.114 * peak_f) * np.exp(-((0.114 * peak_f) ** 1.1))
    return s / peak


def csf_error(a, b, *, pixels_per_degree=32.0):
    """Perceptually weighted RMS difference: the package's heuristic image metric.

    The difference image (each channel separately) is filtered in the frequency domain by a
    contrast sensitivity function, and the RMS of the result is returned. The CSF is Mannos and
    Sakrison's (1974), ``A(f) = 2.6 (0.0192 + 0.114 f) exp(-(0.114 f)^1.1)`` with ``f`` in
    cycles per degree of visual angle, normalised to 1 at its peak (8 cycles/degree) and held
    at 1 below it, so that smooth errors count fully while fine, barely visible ripple counts
    less. ``pixels_per_degree`` fixes the viewing geometry (32: a 512-pixel image seen at
    about 16 degrees, a screen at arm's length).

    Examples
    --------
    >>> flat = np.zeros((16, 16)); bias = np.full((16, 16), 0.1)
    >>> round(csf_error(flat, bias), 12)      # uniform errors are fully visible
    0.1
    >>> checker = 0.1 * (np.indices((16, 16)).sum(axis=0) % 2)
    >>> csf_error(flat, checker) < rmse(flat, checker)   # pixel-scale ripple is damped
    True
    """
    a, b = _pair(a, b)
    ppd = validate.positive_number("pixels_per_degree", pixels_per_degree)
    if a.ndim not in (2, 3):
        raise ValueError(f"csf_error needs 2-D or (H, W, C) images, got shape {a.shape}")
    diff = a - b
    if diff.ndim == 2:
        diff = diff[..., None]
    fy = np.fft.fftfreq(diff.shape[0])[:, None]
    fx = np.fft.fftfreq(diff.shape[1])[None, :]
    weight = _csf(np.hypot(fx, fy) * ppd)
    spectrum = np.fft.fft2(diff, axes=(0, 1)) * weight[..., None]
    filtered = np.fft.ifft2(spectrum, axes=(0, 1)).real
    return float(np.sqrt(np.mean(filtered**2)))


#: Metric functions by name; lower is better for all but ``psnr`` and ``ssim``.
METRICS = {
    "rmse": rmse,
    "max": max_abs_error,
    "psnr": psnr,
    "ssim": ssim,
    "csf": csf_error,
}
