"""Closed-form images for the stability chapter."""

import numpy as np


def chords(view, lo, hi):
    """Entry and exit ray parameters ``(t0, t1)`` of every pixel's ray through the box
    ``[lo, hi]`` (``t1 == t0`` when it misses), and the rays."""
    o, d = view.rays()
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (np.asarray(lo) - o) / d, (np.asarray(hi) - o) / d
    t0 = np.nanmax(np.minimum(ta, tb), axis=-1)
    t1 = np.nanmin(np.maximum(ta, tb), axis=-1)
    if view.eye is not None:
        t0 = np.maximum(t0, 0.0)
    return t0, np.maximum(t1, t0), o, d


def glow_image(field, view, scale, extent=None):
    """Glow image ``1 - exp(-k * line integral)`` of a field with an exact line integral
    (docs/model.md), each ray clipped to ``extent`` (default the field's box)."""
    box = field.bounds if extent is None else np.asarray(extent, float)
    t0, t1, o, d = chords(view, box[:, 0], box[:, 1])
    return -np.expm1(-scale * field.line_integral(o, d, t0, t1))


def constant_image(value, view, scale, extent):
    """Glow image of a constant volume: ``1 - exp(-k c chord)``."""
    box = np.asarray(extent, float)
    t0, t1, _, _ = chords(view, box[:, 0], box[:, 1])
    return -np.expm1(-scale * value * (t1 - t0))
