"""The gallery: the same volumes rendered by every method, with difference images, and a
turntable of the MRI template.

Scenes: the Marschner-Lobb signal and six random Gaussian blobs (analytic: compared with the
reference renderer), and the MNI152 brain template (a real volume: compared with ray casting
at a step of 1/8 voxel, the most accurate image vrlib can make of it). Every method renders
with Catmull-Rom. Then colour scenes on the real volumes (a colormap with Phong shading, the
frog's tissue labels), again by every method, each judged by the composited colour against
the finest ray cast with the same filter. Writes the images to
``build/results/ch09_gallery/gallery.npz`` and ``colour.npz``, the errors to
``gallery.json``, and the turntable frames to ``turntable.npz``.
"""

import numpy as np

import data_gen
import vrlib
from chapters.common import by_profile, progress, result_path, write_json
from vrlib.atomic import atomic_path
from vrlib.render import FINE

SIZE = by_profile(160, 320)
FRAMES = by_profile(24, 72)
SCENES = {
    "Marschner-Lobb 64^3": ("marschner-lobb", {}, 64, vrlib.Glow(1.0)),
    "six Gaussian blobs 64^3": ("random-blobs", {"count": 6, "seed": 7}, 64, vrlib.Glow(4.0)),
    "MNI152 brain, 2 mm": ("mni152", {}, None, None),
}


def mri_transfer(volume):
    """Glow on the normalised intensity above a threshold that leaves air transparent."""
    lo, hi = volume.value_range
    values = np.linspace(0.0, 1.0, 257)
    density = 3.0 * np.clip((values - 0.25) / 0.75, 0.0, 1.0)
    return vrlib.LookupTransfer(density / volume.bounding_radius, value_range=(lo, hi))


def colour_scenes():
    """``{name: (volume, filter, transfer, view options)}``: what a user draws from real data."""
    mni = data_gen.load("mni152")
    frog = data_gen.load("frog")
    shaded = vrlib.Phong()
    bone = vrlib.colormap("bone", [(0, 0), (0.3, 0), (0.6, 0.3), (1, 0.9)], volume=mni,
                          shading=shaded)
    warm = vrlib.colormap("magma", [(0, 0), (0.25, 0), (0.45, 0.05), (1, 0.6)], volume=mni,
                          shading=shaded)
    # Unshaded: flat colours show each label's extent. (Shaded, every method lights labels by
    # the samples' central differences, the ray caster's box filter included.)
    labels = vrlib.label_transfer(frog, opacity={1: 0.02})
    return {
        "MNI152, bone colormap, shaded": (mni, "catmull-rom", bone, {"azimuth": 120.0}),
        "MNI152, magma colormap, shaded": (mni, "catmull-rom", warm, {"azimuth": 200.0}),
        "frog tissue labels (box filter)": (frog, "box", labels,
                                            {"azimuth": -60.0, "zoom": 1.25}),
    }


def colour_gallery():
    """Every method on the colour scenes: images, and the rmse and largest difference of the
    composited colour against the finest ray cast (step 1/8, no early termination)."""
    images, errors = {}, {}
    for name, (volume, filt, transfer, placement) in progress(colour_scenes().items(),
                                                              "colour scenes"):
        view = vrlib.View.orbit(**{"elevation": 20.0, "size": SIZE, **placement},
                                radius=volume.bounding_radius, center=volume.center)
        reference = vrlib.render(volume, view, transfer=transfer,
                                 **{**FINE, "filter": filt})
        target = reference.composited()
        images[f"{name}/reference"] = target
        errors[name] = {}
        for method in vrlib.METHODS:
            img = vrlib.render(volume, view, method=method, filter=filt, transfer=transfer)
            colour = img.composited()
            images[f"{name}/{method}"] = colour
            errors[name][method] = {
                "rmse": vrlib.metrics.rmse(colour, target),
                "max": vrlib.metrics.max_abs_error(colour, target),
                "seconds": img.stats.seconds}
    with atomic_path(result_path(__file__, "colour.npz")) as tmp:
        np.savez_compressed(tmp, **images)
    return {"errors": errors, "scenes": list(errors)}


def main():
    images, errors = {}, {}
    for name, (kind, params, n, transfer) in progress(SCENES.items(), "gallery"):
        if kind == "mni152":
            volume = data_gen.load("mni152")
            transfer = mri_transfer(volume)
            field = None
        else:
            field = data_gen.make_field(kind, **params)
            volume = field.sample(n)
        view = vrlib.View.orbit(azimuth=120 if field is None else 30, elevation=15,
                                size=SIZE, zoom=1.6 if field is None else 1.0,
                                radius=volume.bounding_radius, center=volume.center)
        reference, label = vrlib.reference_image(volume, view, transfer=transfer, field=field)
        images[f"{name}/reference"] = reference.rgba
        errors[name] = {"reference": label}
        for method in vrlib.METHODS:
            img = vrlib.render(volume, view, method=method, filter="catmull-rom",
                               transfer=transfer)
            images[f"{name}/{method}"] = img.rgba
            errors[name][method] = {"rmse": vrlib.metrics.rmse(img, reference),
                                    "max": vrlib.metrics.max_abs_error(img, reference)}
    with atomic_path(result_path(__file__, "gallery.npz")) as tmp:
        np.savez_compressed(tmp, **images)
    volume = data_gen.load("mni152")
    transfer = vrlib.LookupTransfer(mri_transfer(volume).density * 40.0,
                                    value_range=volume.value_range, shading=vrlib.Phong())
    frames = []
    for azimuth in progress(np.linspace(0.0, 360.0, FRAMES, endpoint=False), "turntable"):
        view = vrlib.View.orbit(azimuth=float(azimuth), elevation=15, size=SIZE, zoom=1.6,
                                radius=volume.bounding_radius, center=volume.center)
        frames.append(vrlib.render(volume, view, filter="catmull-rom",
                                   transfer=transfer).composited())
    with atomic_path(result_path(__file__, "turntable.npz")) as tmp:
        np.savez_compressed(tmp, frames=np.array(frames))
    write_json(result_path(__file__, "gallery.json"),
               {"size": SIZE, "frames": FRAMES, "errors": errors, "scenes": list(SCENES),
                "colour": colour_gallery()})


if __name__ == "__main__":
    main()
