"""Precision: float32 against float64, where each enters.

1. Accumulation along a ray. Front-to-back compositing (eqs 1.7-1.8) of ``n`` segments, up to
   4096, with small opacities, in float32, in float32 with compensated sums (Kahan for the
   colour, and the transparency kept as a compensated sum of ``log(1 - alpha)``), and in float64,
   against the same sums in extended precision (``numpy.longdouble``).
2. Intermediate volumes. The shear methods store their resampled volumes as float32 by default;
   the same renders with float64 intermediates, and both against the reference renderer.
3. Volume storage. Every method on the same volume stored as float32 and as float64.

Writes ``build/results/ch08_stability/precision.json``.
"""

import numpy as np

import data_gen
import vrlib
from chapters.common import by_profile, progress, result_path, write_json

LENGTHS = [16, 64, 256, 1024, 4096]
ALPHAS = [1e-4, 1e-3, 1e-2]
RAYS = by_profile(2000, 20000)
SIZES = by_profile([32, 64, 128], [64, 128, 256])
METHODS = list(vrlib.METHODS)


def accumulate(alpha, dtype, compensated=False):
    """Front-to-back over ``alpha[:, i]`` (emission 1, so colour = alpha premultiplied)."""
    a = alpha.astype(dtype)
    colour = np.zeros(a.shape[0], dtype)
    if not compensated:
        transparency = np.ones(a.shape[0], dtype)
        for i in range(a.shape[1]):
            colour = colour + transparency * a[:, i]
            transparency = transparency * (dtype(1) - a[:, i])
        return colour
    carry = np.zeros(a.shape[0], dtype)          # Kahan compensation of the colour sum
    log_t = np.zeros(a.shape[0], dtype)          # log transparency, itself compensated
    log_carry = np.zeros(a.shape[0], dtype)
    for i in range(a.shape[1]):
        term = np.exp(log_t) * a[:, i] - carry
        total = colour + term
        carry = (total - colour) - term
        colour = total
        step = np.log1p(-a[:, i]) - log_carry
        new = log_t + step
        log_carry = (new - log_t) - step
        log_t = new
    return colour


def accumulation():
    rng = np.random.default_rng(8)
    rows = []
    for n in progress(LENGTHS, "ray lengths"):
        for mean in ALPHAS:
            alpha = rng.uniform(0.0, 2.0 * mean, (RAYS, n))
            exact = accumulate(alpha, np.longdouble)
            row = {"samples": n, "mean_alpha": mean, "optical_depth": float(n * mean)}
            for name, dtype, comp in (("float32", np.float32, False),
                                      ("float32 compensated", np.float32, True),
                                      ("float64", np.float64, False)):
                err = np.abs(accumulate(alpha, dtype, comp).astype(np.longdouble) - exact)
                row[name] = float(err.max())
            rows.append(row)
    return rows


def intermediates():
    field = data_gen.make_field("marschner-lobb")
    rows = []
    for n in progress(SIZES, "intermediate volumes"):
        vol = field.sample(n)
        view = vrlib.View.orbit(azimuth=30, elevation=20, size=int(1.5 * n))
        ref = vrlib.render_reference(field, view, transfer=vrlib.Glow(1.0))
        for method in ("shear3", "shear2"):
            images = {p: vrlib.render(vol, view, method=method, filter="catmull-rom",
                                      intermediate=p) for p in ("float32", "float64")}
            rows.append({"N": n, "method": method,
                         "difference": float(np.abs(images["float32"].rgba
                                                    - images["float64"].rgba).max()),
                         "rmse_float32": vrlib.metrics.rmse(images["float32"], ref),
                         "rmse_float64": vrlib.metrics.rmse(images["float64"], ref),
                         "bytes_float32": images["float32"].stats.bytes,
                         "bytes_float64": images["float64"].stats.bytes})
    return rows


def storage():
    field = data_gen.make_field("marschner-lobb")
    n = SIZES[1]
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=int(1.5 * n))
    ref = vrlib.render_reference(field, view, transfer=vrlib.Glow(1.0))
    vol64 = field.sample(n)
    vol32 = field.sample(n, dtype=np.float32)
    rows = []
    for method in progress(METHODS, "storage"):
        a = vrlib.render(vol32, view, method=method, filter="catmull-rom")
        b = vrlib.render(vol64, view, method=method, filter="catmull-rom")
        rows.append({"method": method, "difference": float(np.abs(a.rgba - b.rgba).max()),
                     "rmse_float32": vrlib.metrics.rmse(a, ref),
                     "rmse_float64": vrlib.metrics.rmse(b, ref)})
    return {"N": n, "rows": rows}


def main():
    write_json(result_path(__file__, "precision.json"), {
        "accumulation": accumulation(), "intermediates": intermediates(),
        "storage": storage(), "rays": RAYS,
        "longdouble_eps": float(np.finfo(np.longdouble).eps)})


if __name__ == "__main__":
    main()
