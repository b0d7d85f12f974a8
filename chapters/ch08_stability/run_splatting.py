"""Splatting's known defects, measured: error at the volume's faces, popping when the sheet
axis switches, perspective, aliasing when voxels project smaller than pixels, and what culling
by the transfer function saves.

Writes ``build/results/ch08_stability/splatting.json``.
"""

import math

import numpy as np
from scipy import integrate

import data_gen
import vrlib
from chapters.ch08_stability._exact import glow_image
from chapters.common import by_profile, progress, result_path, write_json
from vrlib.cost import measure
from vrlib.footprint import footprint

MODES = list(vrlib.splat.MODES)
FILTERS = ["trilinear", "catmull-rom", "gaussian"]


def rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


def faces():
    """Marschner-Lobb (non-zero at the faces) at 41^3: every mode and the ray caster against
    the reference, and splatting against the ray caster as the ray caster's step shrinks."""
    field = data_gen.make_field("marschner-lobb")
    volume = field.sample(41)
    view = vrlib.View.orbit(azimuth=30, elevation=25, size=96)
    transfer = vrlib.Glow(1.0)
    ref = vrlib.render_reference(field, view, transfer=transfer, tol=1e-6).alpha
    rows = []
    for filt in FILTERS:
        row = {"filter": filt}
        for mode in MODES:
            img = vrlib.render(volume, view, method="splat", filter=filt, mode=mode,
                               transfer=transfer, early_termination=1.0).alpha
            row[mode] = rmse(img, ref)
            if mode == "direct":
                splat = img
        row["raycast"] = rmse(vrlib.render(volume, view, filter=filt, transfer=transfer,
                                           step=0.5, early_termination=1.0).alpha, ref)
        row["against_raycast"] = []
        for step in (0.2, 0.1, 0.05):
            ray = vrlib.render(volume, view, filter=filt, transfer=transfer, step=step,
                               early_termination=1.0).alpha
            row["against_raycast"].append({"step": step, "rmse": rmse(splat, ray),
                                           "max": float(np.abs(splat - ray).max())})
        rows.append(row)
    return rows


def popping():
    """The image change between views 0.1 degree either side of 45 degrees (where the
    axis-aligned sheets switch axis), against the change between two views 0.2 degree before
    it (a step of the same size with no switch)."""
    volume = data_gen.make_field("random-blobs", count=6, seed=3).sample(32)
    transfer = vrlib.LookupTransfer([0.0, 0.0, 0.0, 40.0, 40.0], value_range=(0.0, 1.0))
    configs = [("splat", {"mode": "sheet"}), ("splat", {"mode": "image-aligned"}),
               ("shearwarp", {}), ("raycast", {})]
    rows = []
    for method, options in configs:
        images = {az: vrlib.render(volume, vrlib.View.orbit(azimuth=az, elevation=10, size=96),
                                   method=method, filter="trilinear", transfer=transfer,
                                   **options).rgba for az in (44.7, 44.9, 45.1)}
        rows.append({"method": method + (f" ({options['mode']})" if options else ""),
                     "across": float(np.abs(images[45.1] - images[44.9]).max()),
                     "before": float(np.abs(images[44.9] - images[44.7]).max())})
    return rows


def perspective():
    """The eye just outside the bounding sphere with a 100-degree field of view, and the
    planar footprint's error for a ray at an angle to the axis it was tabulated for."""
    blob = data_gen.make_field("gaussian-blob", sigma=0.3, center=(0.05, -0.1, 0.08))
    volume = blob.sample(32)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=48, projection="perspective",
                            distance=1.05 * math.sqrt(3), fov=100)
    exact = glow_image(blob, view, 2.0)
    rows = []
    for filt in FILTERS:
        row = {"filter": filt, "raycast": float(np.abs(vrlib.render(
            volume, view, filter=filt, transfer=vrlib.Glow(2.0)).alpha - exact).max())}
        for mode in MODES:
            row[mode] = float(np.abs(vrlib.render(volume, view, method="splat", filter=filt,
                                                  mode=mode, transfer=vrlib.Glow(2.0)).alpha
                                     - exact).max())
        rows.append(row)
    return {"rows": rows, "angles": footprint_angles()}


def footprint_angles():
    """Largest error of the view-axis footprint table for rays tilted by an angle, relative
    to the footprint's peak (60 random offsets per angle, exact line integrals by quad)."""
    rng = np.random.default_rng(0)
    view = vrlib.View.orbit(azimuth=30, elevation=20)
    right, up, forward = view.basis
    out = []
    for name in ("trilinear", "catmull-rom"):
        filt = vrlib.make_filter(name)
        table = footprint(filt, (1.0, 1.0, 1.0), view.basis)
        peak = float(table(0.0, 0.0))
        for angle in (5, 10, 20, 30, 45):
            tilt = math.radians(angle)
            d = math.cos(tilt) * forward + math.sin(tilt) * (0.6 * right + 0.8 * up)
            worst = 0.0
            for _ in range(60):
                o = rng.uniform(-1.5, 1.5, 3)
                o -= (o @ d) * d
                line = integrate.quad(lambda t, o=o, d=d, filt=filt: float(
                    np.prod(filt(o + t * d))), -4, 4, limit=200, points=[0.0])[0]
                worst = max(worst, abs(float(table(o @ right, o @ up)) - line))
            out.append({"filter": name, "angle": angle, "relative_error": worst / peak})
    return out


def aliasing():
    """Marschner-Lobb at 128^3 drawn 32 pixels across (4 voxels a pixel): error against the
    reference sampled at pixel centres, and against its mean over each pixel (4 x 4 rays)."""
    field = data_gen.make_field("marschner-lobb")
    volume = field.sample(by_profile(96, 128))
    transfer = vrlib.Glow(1.0)
    view = vrlib.View.orbit(azimuth=30, elevation=25, size=32)
    centre = vrlib.render_reference(field, view, transfer=transfer, tol=1e-5).alpha
    fine = vrlib.render_reference(field, vrlib.View.orbit(azimuth=30, elevation=25, size=128),
                                  transfer=transfer, tol=1e-5).alpha
    area = fine.reshape(32, 4, 32, 4).mean(axis=(1, 3))
    rows = []
    for name, options in [("raycast", {}), *[("splat", {"mode": m}) for m in MODES]]:
        img = vrlib.render(volume, view, method=name, filter="trilinear", transfer=transfer,
                           early_termination=1.0, **options).alpha
        rows.append({"method": name + (f" ({options['mode']})" if options else ""),
                     "rmse_centres": rmse(img, centre), "rmse_area": rmse(img, area)})
    return {"voxels": volume.shape[0], "pixels": 32,
            "centres_vs_area": rmse(centre, area), "rows": rows}


def culling():
    """A sparse scene whose background is 0.01 (no exact zeros) under a transfer function
    transparent below 0.5: footprints drawn, frame time and image change with and without
    culling by the transfer function."""
    n = by_profile(64, 128)
    data = data_gen.make_field("random-blobs", count=6, seed=3).sample(n).data + 0.01
    volume = vrlib.Volume(data)
    transfer = vrlib.LookupTransfer([0.0, 0.0, 0.0, 40.0, 40.0], value_range=(0.0, 1.0))
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=2 * n)
    rows = []
    for mode in ("sheet", "image-aligned"):
        for filt in ("trilinear", "catmull-rom"):
            timed = {}
            for cull in (False, True):
                timed[cull] = measure(lambda cull=cull, mode=mode, filt=filt: vrlib.render(
                    volume, view, method="splat", filter=filt, mode=mode, transfer=transfer,
                    empty_space_skipping=cull))
            rows.append({"mode": mode, "filter": filt,
                         "speedup": timed[False][0] / timed[True][0],
                         "footprints": [int(timed[c][1].stats.voxels) for c in (False, True)],
                         "change": float(np.abs(timed[True][1].rgba
                                                - timed[False][1].rgba).max())})
    return {"n": n, "rows": rows}


def main():
    parts = {"faces": faces, "popping": popping, "perspective": perspective,
             "aliasing": aliasing, "culling": culling}
    out = {name: fn() for name, fn in progress(list(parts.items()), "splatting")}
    write_json(result_path(__file__, "splatting.json"), out)


if __name__ == "__main__":
    main()
