"""Your own data: every file format read back to the same image, and the real volumes that
ship inside installed packages under each kind of transfer function.

1. Formats. The MNI152 template is written as .npy, raw, NIfTI (RAS and its left-right
   mirrored LAS twin, plain and gzip), NRRD, an ImageJ TIFF stack, VTK image data and a DICOM
   series (16-bit, with a rescale slope), each by that format's own library; each file is
   loaded by ``data_gen.load`` and rendered from one angle-only view. Every image is compared
   with the template's own (the DICOM series stores 1/1000 steps, so it differs by that).
2. Transfer functions on real volumes: the histogram ramp (``transfer="auto"``), a colormap
   with opacity points and shading, classification by value and gradient magnitude, labels,
   maximum- and average-intensity projections, and NaN holes.
3. Anisotropic voxels (dipy's ``aniso``, 4 x 4 x 5 mm) by every method, against a fine ray cast.

Writes ``build/results/ch10_own_data/own_data.json`` and ``images.npz``.
"""

import tempfile
from functools import partial
from pathlib import Path

import nibabel
import nrrd
import numpy as np
import pyvista
import tifffile

import data_gen
import vrlib
from chapters.common import ROOT, by_profile, progress, result_path, write_json
from data_gen.dicom import write_series
from vrlib.atomic import atomic_path
from vrlib.cost import measure
from vrlib.gradients import gradient_volumes

SIZE = by_profile(192, 384)
VIEW = {"azimuth": 120.0, "elevation": 20.0, "size": SIZE}


def write_formats(volume, folder):
    """The template as every format: ``{label: (path, load options)}``."""
    data = np.asarray(volume.data, dtype=np.float32)  # [z, y, x]
    spacing = [float(s) for s in volume.spacing]
    origin = [float(o) for o in volume.origin]
    affine = np.diag([*spacing, 1.0])
    affine[:3, 3] = origin
    ijk = np.ascontiguousarray(data.transpose(2, 1, 0))
    files = {}
    np.save(folder / "mni.npy", data)
    files[".npy"] = (folder / "mni.npy", {"spacing": spacing, "origin": origin})
    data.tofile(folder / "mni.raw")
    files[".raw"] = (folder / "mni.raw", {"shape": data.shape, "dtype": "float32",
                                          "spacing": spacing, "origin": origin})
    nibabel.save(nibabel.Nifti1Image(ijk, affine), folder / "mni.nii")
    files["NIfTI .nii (RAS)"] = (folder / "mni.nii", {})
    las = affine.copy()
    las[0, 0] = -spacing[0]
    las[0, 3] = origin[0] + spacing[0] * (data.shape[2] - 1)  # the same world points
    nibabel.save(nibabel.Nifti1Image(np.ascontiguousarray(ijk[::-1]), las),
                 folder / "mni_las.nii.gz")
    files["NIfTI .nii.gz (LAS, mirrored on disk)"] = (folder / "mni_las.nii.gz", {})
    nrrd.write(str(folder / "mni.nrrd"), data, {"space": "right-anterior-superior",
                                                "space directions": np.diag(spacing),
                                                "space origin": origin}, index_order="C")
    files[".nrrd"] = (folder / "mni.nrrd", {})
    tifffile.imwrite(folder / "mni.tif", data, imagej=True,
                     resolution=(1 / spacing[0], 1 / spacing[1]),
                     metadata={"spacing": spacing[2]})
    files[".tif (ImageJ stack)"] = (folder / "mni.tif", {})
    grid = pyvista.ImageData(dimensions=data.shape[::-1], spacing=spacing, origin=origin)
    grid.point_data["t1"] = data.ravel()
    grid.save(folder / "mni.vti")
    files[".vti"] = (folder / "mni.vti", {})
    write_series(folder / "dicom", data, spacing=spacing, origin=origin, slope=0.001,
                 shuffle=True)
    files["DICOM series (slope 0.001)"] = (folder / "dicom", {})
    return files


def formats(mni, transfer, view):
    reference = vrlib.render(mni, view, transfer=transfer)
    rows = []
    (ROOT / "build").mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory(dir=ROOT / "build") as folder:
        for label, (path, options) in progress(write_formats(mni, Path(folder)).items(),
                                               "formats"):
            seconds, volume = measure(partial(data_gen.load, path, **options), repeats=1,
                                      warmup=False)
            image = vrlib.render(volume, view, transfer=transfer)
            rows.append({"format": label, "shape": list(volume.shape),
                         "spacing": [float(s) for s in volume.spacing],
                         "load_seconds": seconds,
                         "samples_difference": float(np.abs(volume.data - mni.data).max()),
                         "image_difference": float(np.abs(image.rgba - reference.rgba).max())})
    return reference, rows


def transfer_kinds(mni, frog):
    """``{name: (volume, render options, what)}`` for the second figure."""
    shaded = vrlib.Phong()
    bone = vrlib.colormap("bone", [(0, 0), (0.3, 0), (0.6, 0.3), (1, 0.9)], volume=mni,
                          shading=shaded)
    # Opaque only where the gradient magnitude (per mm) passes its 75th percentile inside the
    # head: boundaries between tissues, not their insides.
    magnitude = np.linalg.norm(gradient_volumes(mni), axis=0)
    inside = magnitude[mni.data > 0.3 * mni.value_range[1]]
    edges = [float(np.percentile(inside, q)) for q in (75, 95)]
    by_gradient = vrlib.colormap("bone", [(0, 0), (0.3, 0), (0.6, 0.6), (1, 0.9)], volume=mni,
                                 shading=shaded, gradient_opacity=vrlib.GradientOpacity(
                                     [0.0, *edges], [0.0, 0.0, 1.0]))
    # The maximum along nearly every ray through the head lies in white matter: the rays'
    # maxima lie between 0.78 and 0.92 (25th and 95th percentiles, measured on this
    # template; its top value is 0.99), so a window from 0.4 up drew a flat silhouette.
    top = mni.value_range[1]
    fire = vrlib.colormap("inferno", [(0, 1), (1, 1)], clim=(0.75 * top, 0.94 * top),
                          volume=mni)
    cut = np.array(mni.data, dtype=np.float64)
    half_y, half_x = cut.shape[1] // 2, cut.shape[2] // 2
    cut[:, half_y:, :half_x] = np.nan  # the quarter of the head facing the viewer is missing
    holed = vrlib.Volume(cut, mni.extent, nan="transparent")
    return {
        "MNI152, transfer='auto'": (mni, {"transfer": "auto"}, "histogram ramp"),
        "MNI152, bone with opacity points, shaded": (mni, {"transfer": bone},
                                                     "colormap + opacity points"),
        "MNI152, value x gradient magnitude": (mni, {"transfer": by_gradient},
                                               "gradient-magnitude classification"),
        "MNI152, maximum intensity": (mni, {"transfer": fire, "blend": "maximum"}, "MIP"),
        "MNI152, average intensity": (mni, {"transfer": vrlib.colormap(
            "gray", [(0, 1), (1, 1)], clim=(0, 0.5), volume=mni), "blend": "average"},
            "average intensity"),
        "MNI152 with a NaN quarter, nan='transparent'": (holed, {"transfer": bone},
                                                         "holes"),
        "frog tissues, labels (box filter)": (frog, {"transfer": vrlib.label_transfer(
            frog, opacity={1: 0.02}, shading=shaded), "filter": "box"}, "labels"),
        "frog tissues, viridis with opacity points": (frog, {"transfer": vrlib.colormap(
            "viridis", [(0, 0), (0.15, 0), (0.2, 0.05), (1, 0.5)], clim=(0, 29),
            volume=frog)}, "colormap on labels"),
    }


def main():
    images, results = {}, {}
    mni = data_gen.load("mni152")
    view = vrlib.View.orbit(**VIEW)
    reference, results["formats"] = formats(mni, vrlib.auto_transfer(mni), view)
    images["formats/reference"] = reference.rgba
    frog = data_gen.load("frog")
    results["transfer_functions"] = []
    for name, (volume, options, kind) in progress(transfer_kinds(mni, frog).items(),
                                                  "transfer functions"):
        zoom = 1.25 if volume is frog else 1.0
        image = vrlib.render(volume, vrlib.View.orbit(**{**VIEW, "azimuth": -60.0
                                                         if volume is frog else 120.0},
                                                      zoom=zoom),
                             **{"filter": "catmull-rom", **options})
        images[f"tf/{name}"] = image.rgba
        results["transfer_functions"].append({
            "name": name, "kind": kind, "seconds": image.stats.seconds,
            "shape": list(volume.shape), "mean_alpha": float(image.alpha.mean())})
    aniso = data_gen.load("aniso")
    fine, _ = vrlib.reference_image(aniso, view, transfer=vrlib.auto_transfer(aniso))
    images["aniso/reference"] = fine.rgba
    results["anisotropic"] = {"spacing": [float(s) for s in aniso.spacing],
                              "shape": list(aniso.shape), "methods": {}}
    for method in progress(vrlib.METHODS, "anisotropic voxels"):
        image = vrlib.render(aniso, view, method=method, filter="catmull-rom",
                             transfer=vrlib.auto_transfer(aniso))
        images[f"aniso/{method}"] = image.rgba
        results["anisotropic"]["methods"][method] = {
            "rmse": vrlib.metrics.rmse(image, fine), "seconds": image.stats.seconds}
    try:
        brain = data_gen.load("brainsmall")
    except ImportError as error:
        results["brainsmall"] = {"available": False, "why": str(error)}
    else:
        image = vrlib.render(brain, view, filter="catmull-rom", transfer=vrlib.auto_transfer(
            brain, "bone", shading=vrlib.Phong()))
        images["brainsmall"] = image.rgba
        results["brainsmall"] = {"available": True, "shape": list(brain.shape),
                                 "seconds": image.stats.seconds}
    results["size"] = SIZE
    with atomic_path(result_path(__file__, "images.npz")) as tmp:
        np.savez_compressed(tmp, **images)
    write_json(result_path(__file__, "own_data.json"), results)


if __name__ == "__main__":
    main()
