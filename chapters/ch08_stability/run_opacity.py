"""Opacity at its extremes.

1. Segment models: ``1 - exp(-x)`` computed as ``-expm1(-x)`` (vrlib), naively as
   ``1 - exp(-x)`` in float32 and float64, the linear model ``min(1, x)`` and the 1024-entry
   table, against extended precision, for optical depths ``x`` from 1e-10 to 100.
2. Opacity correction ``1 - (1 - alpha)^r`` as alpha -> 1 and as the step ratio r -> 0:
   vrlib's ``-expm1(r log1p(-alpha))`` against the naive power, checked for NaN, values outside
   [0, 1] and monotonicity in r.
3. Glow scale from 1e-6 to 1e6 per world unit: every method renders a Gaussian blob whose
   image is known in closed form; the image must be finite with alpha in [0, 1], and its error
   is recorded relative to the brightest exact pixel.

Writes ``build/results/ch08_stability/opacity.json``.
"""

import numpy as np

import data_gen
import vrlib
from chapters.ch08_stability._exact import glow_image
from chapters.common import progress, result_path, write_json
from vrlib.compositing import correct_opacity, segment_alpha

DEPTHS = np.logspace(-10, 2, 241)
SCALES = np.logspace(-6, 6, 13)
METHODS = list(vrlib.METHODS)


def segment_models():
    exact = -np.expm1(-DEPTHS.astype(np.longdouble))
    out = {"depth": DEPTHS.tolist()}
    candidates = {
        "vrlib exact (expm1)": segment_alpha(DEPTHS, 1.0),
        "naive 1 - exp(-x), float64": 1.0 - np.exp(-DEPTHS),
        "naive 1 - exp(-x), float32": (np.float32(1) - np.exp(-DEPTHS.astype(np.float32))),
        "linear min(1, x)": segment_alpha(DEPTHS, 1.0, model="linear"),
        "table (1024 entries)": segment_alpha(DEPTHS, 1.0, model="table"),
    }
    for name, value in candidates.items():
        value = np.asarray(value, dtype=np.longdouble)
        out[name] = {"absolute": np.abs(value - exact).astype(float).tolist(),
                     "relative": (np.abs(value - exact) / exact).astype(float).tolist()}
    return out


def corrections():
    ratios = np.logspace(-12, 0, 121)
    rows = []
    for k in range(1, 17):
        alpha = 1.0 - 10.0**-k
        ours = np.array([correct_opacity(alpha, r, 1.0).item() for r in ratios])
        naive = 1.0 - (1.0 - alpha) ** ratios
        a = np.longdouble(alpha)
        exact = -np.expm1(ratios.astype(np.longdouble) * np.log1p(-a))
        rows.append({
            "alpha": alpha, "one_minus_alpha": 10.0**-k,
            "finite": bool(np.all(np.isfinite(ours))),
            "in_range": bool(np.all((ours >= 0) & (ours <= 1))),
            "monotone": bool(np.all(np.diff(ours) >= 0)),
            "max_relative_error": float(np.max(np.abs(ours - exact) / exact)),
            "naive_max_relative_error": float(np.max(np.abs(naive - exact) / exact)),
        })
    edge = correct_opacity(np.array([0.0, 1.0]), 1e-12, 1.0)
    return {"rows": rows, "alpha_0_and_1": edge.tolist()}


def glow_sweep():
    field = data_gen.make_field("gaussian-blob", sigma=0.3, center=(0.05, -0.1, 0.08))
    vol = field.sample(48)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=64)
    rows = []
    for scale in progress(SCALES, "glow scales"):
        exact = glow_image(field, view, scale)
        for method in METHODS:
            img = vrlib.render(vol, view, method=method, filter="catmull-rom",
                               transfer=vrlib.Glow(float(scale)), step=0.5)
            alpha = img.alpha
            rows.append({
                "scale": float(scale), "method": method,
                "finite": bool(np.all(np.isfinite(img.rgba))),
                "in_range": bool(alpha.min() >= 0.0 and alpha.max() <= 1.0),
                "relative_error": float(np.abs(alpha - exact).max() / exact.max()),
                "exact_max": float(exact.max()),
            })
    return rows


def growth_scale(glow, factor=2.0):
    """The smallest glow scale at which some method's error exceeds `factor` times its error
    at the smallest scale (where the error is the reconstruction error alone)."""
    smallest = min(row["scale"] for row in glow)
    floor = {row["method"]: row["relative_error"] for row in glow if row["scale"] == smallest}
    grown = [row["scale"] for row in glow
             if row["relative_error"] > factor * floor[row["method"]]]
    return min(grown) if grown else None


def main():
    glow = glow_sweep()
    write_json(result_path(__file__, "opacity.json"), {
        "segment_models": segment_models(), "corrections": corrections(),
        "glow": glow, "glow_growth_scale": growth_scale(glow)})


if __name__ == "__main__":
    main()
