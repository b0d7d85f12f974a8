"""Compositing: the over operator and segment opacity models.

Colours are premultiplied RGBA in the last axis. A ray is cut into segments, each with constant
opacity density ``Omega`` and emission ``E``; a segment of length ``p`` has transparency
``T = exp(-Omega p)`` (eq 1.4), opacity ``alpha = 1 - T`` and, with ``1/Omega`` folded into the
emission, premultiplied colour ``E * alpha`` (eq 1.9). Segments combine with the associative
over operator, front to back (eqs 1.7-1.8) or back to front (eq 1.6); associativity is what
parallel compositing relies on.
"""

from __future__ import annotations

import numpy as np

from vrlib import validate

__all__ = [
    "over",
    "composite",
    "segment_alpha",
    "correct_opacity",
    "SEGMENT_MODELS",
    "ORDERS",
    "SEGMENT_ENDS",
]

#: How the segments that the volume's faces cut are counted (``segment_ends``, every method
#: that integrates along rays): ``"lattice"``, each sample standing for its whole segment, or
#: ``"exact"``, only the part inside the volume.
SEGMENT_ENDS = ("lattice", "exact")

#: Segment opacity models accepted by :func:`segment_alpha`.
SEGMENT_MODELS = ("exact", "linear", "table")
#: Compositing orders accepted by :func:`composite`.
ORDERS = ("front-to-back", "back-to-front")

# The "table" model: 1 - exp(-x) tabulated on [0, _TABLE_MAX] and linearly interpolated.
_TABLE_MAX = 8.0


def _rgba(name, value):
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 0 or arr.shape[-1] != 4:
        raise ValueError(f"{name} must have RGBA in its last axis (size 4), got shape {arr.shape}")
    return arr


def over(front, back):
    """Composite premultiplied RGBA ``front`` over ``back`` (eqs 1.7-1.8).

    ``out = front + (1 - alpha_front) * back`` for every channel, alpha included.

    Examples
    --------
    >>> over([0.5, 0.0, 0.0, 0.5], [0.0, 0.4, 0.0, 0.4]).tolist()
    [0.5, 0.2, 0.0, 0.7]
    """
    front = _rgba("front", front)
    back = _rgba("back", back)
    return front + (1.0 - front[..., 3:4]) * back


def composite(samples, *, order="front-to-back"):
    """Composite a sequence of premultiplied RGBA segments, listed nearest first.

    Parameters
    ----------
    samples : array_like, shape (..., n, 4)
        Segments along the second-to-last axis, the one nearest the viewer first.
    order : {"front-to-back", "back-to-front"}
        Accumulation order: front to back keeps the running opacity (eqs 1.7-1.8) and is what
        early ray termination needs; back to front needs no opacity (eq 1.6). Both give the
        same result.

    Returns
    -------
    ndarray, shape (..., 4)

    Examples
    --------
    >>> segs = [[0.2, 0.2, 0.2, 0.2], [0.5, 0.5, 0.5, 0.5]]
    >>> composite(segs).tolist()
    [0.6, 0.6, 0.6, 0.6]
    >>> composite(segs, order="back-to-front").tolist()
    [0.6, 0.6, 0.6, 0.6]
    """
    samples = _rgba("samples", samples)
    if samples.ndim < 2:
        raise ValueError(f"samples must have shape (..., n, 4), got {samples.shape}")
    validate.choice("order", order, ORDERS)
    n = samples.shape[-2]
    acc = np.zeros(samples.shape[:-2] + (4,))
    if order == "front-to-back":
        for i in range(n):
            acc = acc + (1.0 - acc[..., 3:4]) * samples[..., i, :]  # eqs 1.7-1.8
    else:
        for i in range(n - 1, -1, -1):
            seg = samples[..., i, :]
            acc = seg + (1.0 - seg[..., 3:4]) * acc  # eq 1.6
    return acc


def segment_alpha(density, length, *, model="exact"):
    """Opacity of a segment of constant opacity density (eq 1.4: ``alpha = 1 - exp(-x)``).

    Parameters
    ----------
    density : array_like
        Opacity density per world unit (>= 0).
    length : float or array_like
        Segment length in world units (>= 0).
    model : {"exact", "linear", "table"}
        ``"exact"``: ``1 - exp(-x)`` with ``x = density * length``; ``"linear"``: the
        first-order approximation ``min(1, x)``; ``"table"``: ``1 - exp(-x)`` looked up in a
        1024-entry table over ``x`` in [0, 8] with linear interpolation (``x`` past 8 takes the
        last entry, an error below 3.4e-4).

    Examples
    --------
    >>> segment_alpha(np.array([0.0, 1.0, 10.0]), 0.5, model="linear").tolist()
    [0.0, 0.5, 1.0]
    >>> round(float(segment_alpha(1.0, 1.0)), 6)
    0.632121
    """
    validate.choice("model", model, SEGMENT_MODELS)
    x = np.asarray(density, dtype=np.float64) * np.asarray(length, dtype=np.float64)
    if model == "exact":
        return -np.expm1(-x)
    if model == "linear":
        return np.minimum(1.0, x)
    grid = np.linspace(0.0, _TABLE_MAX, 1024)
    return np.interp(x, grid, -np.expm1(-grid))


def correct_opacity(alpha, step, reference_step):
    """Opacity of a sample taken at spacing ``step`` from one defined at ``reference_step``.

    ``alpha' = 1 - (1 - alpha)^(step / reference_step)``, computed as
    ``-expm1(r * log1p(-alpha))`` so that it stays accurate as ``alpha -> 0`` and as the ratio
    ``r`` shrinks. ``alpha = 1`` stays 1.

    Examples
    --------
    >>> correct_opacity(0.75, 0.5, 1.0).item()
    0.5
    """
    a = validate.finite_array("alpha", alpha)
    if np.any((a < 0.0) | (a > 1.0)):
        raise ValueError("alpha must lie in [0, 1]")
    ratio = validate.positive_number("step", step) / validate.positive_number(
        "reference_step", reference_step
    )
    with np.errstate(divide="ignore"):
        return -np.expm1(ratio * np.log1p(-a))
