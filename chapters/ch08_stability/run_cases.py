"""Stress cases: corners of the parameter space, each rendered by every method and judged.

Each case states what must hold; the verdict is measured. The default judgement of an image:
finite, alpha in [0, 1], colour non-negative, and (where an exact image is known) a largest
error within three times the same method's error on an ordinary oblique view (plus 1e-3),
so that a case fails only if the corner makes the method worse. A method may instead refuse a
case it does not support, if it does so with a ValueError whose message says why. Writes
``build/results/ch08_stability/cases.json``.
"""

import math

import numpy as np

import data_gen
import vrlib
from chapters.ch08_stability._exact import constant_image, glow_image
from chapters.common import progress, result_path, write_json
from vrlib.value_bounds import lattice_sums

METHODS = list(vrlib.METHODS)
N, SIZE, SCALE = 32, 48, 2.0
BLOB = data_gen.make_field("gaussian-blob", sigma=0.3, center=(0.05, -0.1, 0.08))
CASES = []


def case(group, name, expectation):
    def register(fn):
        CASES.append((group, name, expectation, fn))
        return fn
    return register


def sane(img):
    rgba = img.rgba
    return bool(np.all(np.isfinite(rgba)) and rgba[..., 3].min() >= 0.0
                and rgba[..., 3].max() <= 1.0 and rgba[..., :3].min() >= 0.0)


def attempt(method, volume, view, **kw):
    """Render, or the refusal message if the method raises ValueError."""
    kw.setdefault("filter", "catmull-rom")
    kw.setdefault("transfer", vrlib.Glow(SCALE))
    try:
        return vrlib.render(volume, view, method=method, **kw), None
    except ValueError as error:
        return None, str(error)


BASELINE = {}


def baseline(method, field=BLOB):
    """Largest error on the ordinary oblique view of ``field`` sampled at 32^3 over its box
    (the yardstick of the judgement)."""
    key = f"{method} {field!r}"
    if key not in BASELINE:
        view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE)
        img, _ = attempt(method, field.sample(N), view)
        BASELINE[key] = float(np.abs(img.alpha - glow_image(field, view, SCALE)).max())
    return BASELINE[key]


def judge_views(views, *, volume=None, field=BLOB, extent=None, refusable=()):
    """Every method on each view against the exact blob image."""
    volume = field.sample(N) if volume is None else volume
    out = {}
    for method in METHODS:
        worst, refusal, ok = 0.0, None, True
        for view in views:
            img, refusal = attempt(method, volume, view)
            if img is None:
                ok &= method in refusable and refusal is not None
                continue
            error = float(np.abs(img.alpha - glow_image(field, view, SCALE, extent)).max())
            worst = max(worst, error)
            ok &= sane(img) and error <= 3 * baseline(method, field) + 1e-3
        out[method] = {"passed": bool(ok), "max_error": worst, "refusal": refusal}
    return out


@case("geometry", "views along each axis", "six axis-aligned views match the exact image")
def axis_views():
    views = [vrlib.View.orbit(azimuth=a, elevation=0, size=SIZE) for a in (0, 90, 180, 270)]
    views += [vrlib.View.orbit(elevation=e, size=SIZE) for e in (90, -90)]
    return judge_views(views)


@case("geometry", "exact diagonal", "the view along (1, 1, 1) and at 45 degrees in a plane")
def diagonal():
    e = math.degrees(math.atan(1 / math.sqrt(2)))
    return judge_views([vrlib.View.orbit(azimuth=45, elevation=e, size=SIZE),
                        vrlib.View.orbit(azimuth=45, elevation=0, size=SIZE)])


@case("geometry", "grazing views", "views a hair off an axis")
def grazing():
    return judge_views([vrlib.View.orbit(azimuth=1e-7, elevation=89.99999, size=SIZE),
                        vrlib.View.orbit(azimuth=90 - 1e-7, elevation=1e-7, size=SIZE)])


@case("geometry", "perspective, eye close", "eye just outside the bounding sphere")
def eye_close():
    views = [vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE, projection="perspective",
                              distance=1.05 * math.sqrt(3), fov=100)]
    return judge_views(views, refusable=("shear3", "shear2"))


@case("geometry", "perspective, eye inside", "renders or refuses with a clear message")
def eye_inside():
    views = [vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE, projection="perspective",
                              distance=0.4, fov=100)]
    return judge_views(views, refusable=tuple(METHODS))


@case("geometry", "anisotropic box", "24 x 40 x 64 samples over a 0.6 x 1.2 x 2 box, of a "
      "narrow blob that vanishes at the faces")
def anisotropic():
    field = data_gen.make_field("gaussian-blob", sigma=0.08, center=(0.05, -0.03, 0.02))
    extent = [[-1.0, 1.0], [-0.6, 0.6], [-0.3, 0.3]]
    volume = field.sample((24, 40, 64), extent=extent)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE)
    return judge_views([view], volume=volume, field=field, extent=extent)


@case("geometry", "2 x 2 x 2 volume", "a constant 2^3 volume: the exact chord image, to one "
      "sample's opacity")
def tiny_volume():
    return constant_case(np.full((2, 2, 2), 0.7))


#: Sample spacing along a ray, in voxels: the ray caster's step and the shear-warp's and
#: splatting's slices (at most sqrt(3) voxels apart along an oblique ray).
SPACING = {"raycast": 0.5, "shear3": 0.5, "shear2": math.sqrt(3), "shearwarp": math.sqrt(3),
           "splat": math.sqrt(3)}


def constant_case(data, extent=None, **kw):
    """Rays enter and leave the box between samples, so a chord is counted to within one
    sample: the bound is one sample's opacity ``1 - exp(-k c ds)``. ``kw`` goes to the
    renderer (a filter)."""
    volume = vrlib.Volume(data, extent=extent)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE, radius=volume.bounding_radius,
                            center=volume.center)
    exact = constant_image(float(data.flat[0]), view, SCALE, volume.extent)
    out = {}
    for method in METHODS:
        img, refusal = attempt(method, volume, view, **kw)
        if img is None:
            out[method] = {"passed": False, "max_error": None, "refusal": refusal}
            continue
        error = float(np.abs(img.alpha - exact).max())
        bound = -math.expm1(-SCALE * float(data.flat[0]) * SPACING[method]
                            * float(volume.spacing.min()))
        out[method] = {"passed": sane(img) and error <= bound, "max_error": error,
                       "bound": bound, "refusal": None}
    return out


@case("data", "constant volume", "a constant 33^3 volume: the exact chord image, to one "
      "sample's opacity")
def constant():
    return constant_case(np.full((33, 33, 33), 0.7))


def scaled_case(extent_factor=1.0, value_factor=1.0, **kw):
    """The blob with the world scaled by ``extent_factor`` and the values by
    ``value_factor``, the glow scale adjusted so that the image should not change (``kw``:
    a filter)."""
    base = BLOB.sample(N)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE)
    volume = vrlib.Volume(base.data * value_factor, extent=base.extent * extent_factor)
    scaled_view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE,
                                   radius=math.sqrt(3) * extent_factor)
    out = {}
    for method in METHODS:
        ref, _ = attempt(method, base, view, **kw)
        img, refusal = attempt(method, volume, scaled_view,
                               transfer=vrlib.Glow(SCALE / (extent_factor * value_factor)), **kw)
        if img is None:
            out[method] = {"passed": False, "max_error": None, "refusal": refusal}
            continue
        change = float(np.abs(img.rgba - ref.rgba).max())
        out[method] = {"passed": sane(img) and change <= 1e-6, "max_error": change,
                       "refusal": None}
    return out


@case("geometry", "huge extent", "the world 1e6 times larger (glow scaled): same image, 1e-6")
def huge_extent():
    return scaled_case(extent_factor=1e6)


@case("geometry", "tiny extent", "the world 1e-6 times smaller (glow scaled): same image")
def tiny_extent():
    return scaled_case(extent_factor=1e-6)


@case("data", "huge magnitudes", "values times 1e150 (glow scaled): same image, 1e-6")
def huge_values():
    return scaled_case(value_factor=1e150)


@case("data", "tiny magnitudes", "values times 1e-150 (glow scaled): same image, 1e-6")
def tiny_values():
    return scaled_case(value_factor=1e-150)


PREFILTERED = ("cardinal-bspline", "omoms")


def worst_of(*results):
    """Per method, every result passed; the largest error among them."""
    out = {}
    for method in METHODS:
        rows = [r[method] for r in results]
        errors = [r["max_error"] for r in rows if r["max_error"] is not None]
        out[method] = {"passed": all(r["passed"] for r in rows),
                       "max_error": max(errors) if errors else None,
                       "refusal": next((r["refusal"] for r in rows if r["refusal"]), None)}
    return out


@case("filters", "prefiltered cubics, huge and tiny magnitudes", "values times 1e150 and "
      "1e-150 with the cardinal B-spline and O-MOMS (glow scaled): same image, 1e-6")
def prefiltered_magnitudes():
    return worst_of(*[scaled_case(value_factor=v, filter=f) for v in (1e150, 1e-150)
                      for f in PREFILTERED])


@case("filters", "prefiltered cubics on 2^3 and 3^3 volumes", "constant volumes of 2 and 3 "
      "samples per axis with the cardinal B-spline and O-MOMS (prefilters of 2 and 3 samples): "
      "the exact chord image, to one sample's opacity")
def prefiltered_small():
    return worst_of(*[constant_case(np.full((n, n, n), 0.7), filter=f) for n in (2, 3)
                      for f in PREFILTERED])


def positive_mass(filt):
    """Integral of the positive part of the separable 3-D kernel: ``P^3 + 3 P M^2`` with
    ``P`` and ``M`` the 1-D kernel's positive and negative areas (a negative density is
    clamped to zero, so an impulse's image holds this much mass, not 1)."""
    x = np.linspace(-filt.radius, filt.radius, 200001)
    k = filt(x)
    dx = x[1] - x[0]
    p, m = float(np.clip(k, 0, None).sum() * dx), float(-np.clip(k, None, 0).sum() * dx)
    return p**3 + 3 * p * m**2


def impulse_case(filters):
    data = np.zeros((33, 33, 33))
    data[16, 16, 16] = 1.0
    volume = vrlib.Volume(data)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=96)
    voxel = float(np.prod(volume.spacing))
    out = {}
    for method in METHODS:
        ok, ratios, refusal = True, {}, None
        for name in filters:
            img, refusal = attempt(method, volume, view, filter=name,
                                   transfer=vrlib.Glow(0.1))
            mass = float(-np.log1p(-img.alpha).sum() * view.pixel_size**2)
            ratios[name] = mass / (0.1 * voxel) / positive_mass(vrlib.make_filter(name))
            ok &= sane(img) and abs(ratios[name] - 1.0) <= 0.05
        worst = max(ratios.values(), key=lambda r: abs(r - 1))
        out[method] = {"passed": bool(ok), "max_error": worst, "ratios": ratios,
                       "refusal": refusal}
    return out


@case("data", "single-voxel impulse, smooth filter", "finite, non-negative; image mass / "
      "(k x integral) within 5% of 1 with the B-spline")
def impulse_smooth():
    return impulse_case(["bspline"])


@case("data", "single-voxel impulse, tent and Catmull-Rom", "image mass within 5% of the "
      "kernel's positive mass (tent 1; Catmull-Rom 1.29, its clamped negative lobes adding "
      "mass)")
def impulse_sharp():
    return impulse_case(["trilinear", "catmull-rom"])


@case("filters", "step-edge ringing", "overshoot of a unit step reconstructed in 1-D, per "
      "filter, within the bound the renderers' tables span (vrlib.value_bounds: the cubics "
      "with negative lobes ring, and so do the prefiltered cubics)")
def ringing():
    out = {}
    x = np.linspace(-4.0, 4.0, 4001)
    samples = np.arange(-8, 9)
    values = (samples >= 0).astype(float)
    for name in ("box", "trilinear", "gaussian", "catmull-rom", "bspline", "mitchell",
                 *PREFILTERED):
        filt = vrlib.make_filter(name)
        weights = values if not filt.prefiltered else vrlib.prefilter.coefficients(
            values, filt.poles)  # the step extends beyond both ends: no edge effect at x = 0
        recon = (weights[None, :] * filt(x[:, None] - samples[None, :])).sum(axis=1)
        overshoot = float(max(recon.max() - 1.0, -recon.min(), 0.0))
        # In 1-D (cube roots of the 3-D sums), values in [0, 1] reconstruct within
        # [-(a - s_min) / 2, (s_max + a) / 2]: the weights' negative and positive parts.
        s_min, s_max, a_max = (v ** (1 / 3) for v in lattice_sums(filt, cardinal=True))
        allowed = max((s_max + a_max) / 2.0 - 1.0, (a_max - s_min) / 2.0)
        out[name] = {"passed": bool(np.all(np.isfinite(recon)) and overshoot <= allowed),
                     "max_error": overshoot, "bound": allowed, "refusal": None}
    return out


def judge_filters(filters):
    """Every method with each of ``filters``: finite and in range (largest error recorded)."""
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE)
    volume = BLOB.sample(N)
    exact = glow_image(BLOB, view, SCALE)
    out = {}
    for method in METHODS:
        ok, worst, refusal = True, 0.0, None
        for filt in filters:
            img, refusal = attempt(method, volume, view, filter=filt)
            if img is None:
                ok = False
                continue
            worst = max(worst, float(np.abs(img.alpha - exact).max()))
            ok &= sane(img)
        out[method] = {"passed": bool(ok), "max_error": worst, "refusal": refusal}
    return out


@case("filters", "Gaussian at its limits", "sigma 0.05 and 3 (truncated at radius 2), and "
      "sigma 1 truncated at radius 1: finite, in range")
def gaussian_limits():
    return judge_filters([vrlib.make_filter("gaussian", sigma=0.05),
                          vrlib.make_filter("gaussian", sigma=3.0),
                          vrlib.make_filter("gaussian", sigma=1.0, radius=1.0)])


@case("filters", "cubics outside the (B, C) triangle", "(B, C) = (0, 2), (2, 0), (-1, 1), "
      "(3, 3): finite, in range")
def cubics():
    return judge_filters([("mitchell-netravali", float(b), float(c))
                          for b, c in ((0, 2), (2, 0), (-1, 1), (3, 3))])


def main():
    rows = []
    for group, name, expectation, fn in progress(CASES, "stress cases"):
        results = fn()
        rows.append({"group": group, "case": name, "expectation": expectation,
                     "results": results,
                     "passed": all(r["passed"] for r in results.values())})
    write_json(result_path(__file__, "cases.json"),
               {"cases": rows, "baseline": BASELINE, "volume": N, "image": SIZE,
                "scale": SCALE, "passed": sum(r["passed"] for r in rows), "total": len(rows)})


if __name__ == "__main__":
    main()
