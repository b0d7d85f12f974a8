"""The command line: ``vrlib render | turntable | compare | bench | info`` (also
``python -m vrlib``).

Bad input ends with exit status 2 and a one-line message naming what was wrong.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import warnings
from functools import partial
from pathlib import Path

import numpy as np

from vrlib.arguments import EmptyImageWarning

EXAMPLES = """examples:
  vrlib render marschner-lobb:41 -o ml.png
  vrlib render gaussian-blob:64:sigma=0.3 --method splat --filter catmull-rom -o blob.png
  vrlib render mni152 --shade --azimuth 90 --size 512 -o head.png
  vrlib render frog --cmap bone --opacity 0:0,0.2:0,1:0.6 --clim 0,29 --shade -o frog.png
  vrlib render scan.raw --shape 64,64,64 --dtype uint8 --offset 512 -o scan.png
  vrlib render dicom_folder/ --cmap gray -o ct.png
  vrlib render aniso --blend maximum --cmap gray --opacity 0:1,1:1 -o mip.png
  vrlib render frog --labels --shade --zoom 1.5 -o frog_labels.png
  vrlib turntable mni152 --cmap bone --shade --frames 36 -o head.gif
  vrlib info aniso
  vrlib compare marschner-lobb:41 --size 128 -o compare.png
  vrlib bench
  vrlib info
"""

VOLUME_HELP = ("an analytic field NAME[:SAMPLES[:KEY=VALUE...]] (e.g. marschner-lobb:41, "
               "gaussian-blob:64:sigma=0.3); a file (.npy, .nii, .nii.gz, .nrrd, .nhdr, .tif, "
               ".tiff, .vti, .vtk, .den, or .raw with --shape and --dtype); a folder of DICOM "
               "slices; or a named real volume: mni152, frog, aniso, brainsmall")

TRANSFER_HELP = ("auto (a grey ramp fitted to the histogram; the default for files and named "
                 "volumes), glow[:K] (density K x value; the default for analytic fields) or "
                 "ramp:THRESHOLD:SCALE (transparent below THRESHOLD, a fraction of the value "
                 "range, then density up to SCALE); glow and ramp densities are per half of the "
                 "volume's longest side. --cmap and --opacity build a colormap transfer instead")


class UsageError(Exception):
    """Bad input from the command line: reported in one line, exit status 2."""


def check_output(path, suffixes, *, source=None):
    """Refuse an output the command could not write, before any work is done: a wrong
    suffix, a missing folder (not created silently), a folder that is a file or not writable,
    a path that is a folder, or the input ``source`` itself (it would be overwritten)."""
    path = Path(path)
    if source is not None and path.exists() and Path(source).exists() and \
            os.path.samefile(path, source):
        raise UsageError(f"output {str(path)!r} is the input volume: it would be overwritten; "
                         "write the image to another file")
    if path.suffix.lower() not in suffixes:
        raise UsageError(f"output must end in {' or '.join(suffixes)}, got {str(path)!r}")
    folder = path.parent
    if not folder.exists():
        raise UsageError(f"no folder {str(folder)!r} for the output: create it first")
    if not folder.is_dir():
        raise UsageError(f"the output's folder {str(folder)!r} is a file")
    if path.is_dir():
        raise UsageError(f"output {str(path)!r} is a folder; give a file name")
    try:  # a file made and removed there: permissions, read-only and special file systems
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as error:
        raise UsageError(f"cannot write into folder {str(folder)!r} "
                         f"({error.strerror or error})") from None
    return path


def _number(text):
    try:
        value = float(text)
    except ValueError:
        return text
    return int(value) if value.is_integer() and "." not in text and "e" not in text else value


#: Fields built from a list of parts, which a ``name:key=value`` spec cannot give, and the
#: field to use instead.
_LISTED_FIELDS = {"blobs": "random-blobs"}


def load_volume(spec, *, shape=None, dtype=None, offset=0, frame=None, series=None,
                scalars=None, nan="error", oblique="refuse", spacing=None):
    """``(volume, field or None)`` from a command-line volume spec."""
    import data_gen
    from data_gen.untrusted import available_bytes

    path = Path(spec)
    name = path.name.lower()
    if spec in data_gen.DATASETS or path.is_dir() or any(
            name.endswith(e) for e in data_gen.FORMATS):
        if not (spec in data_gen.DATASETS or path.exists()):
            raise UsageError(f"volume file not found: {spec}")
        options = {}
        if name.endswith(".raw"):
            if shape is None or dtype is None:
                raise UsageError("a .raw volume needs --shape NZ,NY,NX and --dtype")
            options = {"shape": shape, "dtype": dtype, "offset": offset}
        elif offset or shape is not None or dtype is not None:
            given = [flag for flag, value in (("--offset", offset), ("--shape", shape),
                                              ("--dtype", dtype)) if value]
            raise UsageError(f"{', '.join(given)} appl{'ies' if len(given) == 1 else 'y'} "
                             f"to .raw files only, not {path.name}")
        if spacing is not None:
            if not name.endswith((".npy", ".raw", ".tif", ".tiff")):
                raise UsageError("--spacing applies to .npy, .raw and TIFF files only (the "
                                 "others carry their own)")
            options["spacing"] = _triple(spacing, "--spacing")
        for key, value, ending in (("frame", frame, (".nii", ".nii.gz")),
                                   ("scalars", scalars, (".vti", ".vtk"))):
            if value is not None:
                if not name.endswith(ending):
                    raise UsageError(f"--{key} applies to {' and '.join(ending)} files only")
                options[key] = value
        if nan != "error":
            options["nan"] = nan
        if oblique != "refuse":
            if not (name.endswith((".nii", ".nii.gz", ".dcm")) or path.is_dir()):
                raise UsageError("--oblique applies to NIfTI and DICOM volumes only")
            options["oblique"] = oblique
        if series is not None:
            if not path.is_dir():
                raise UsageError("--series applies to a folder of DICOM slices only")
            options["series"] = series
        return data_gen.load(spec, **options), None
    if path.is_file():
        endings = ", ".join(data_gen.FORMATS)
        raise UsageError(f"{spec}: vrlib does not read {path.suffix or 'extension-less'!s} "
                         f"files; it reads {endings}, and a DICOM series as a folder of "
                         "slice files")
    field_name, *rest = spec.split(":")
    if field_name in _LISTED_FIELDS:
        raise UsageError(f"field {field_name!r} takes a list of blobs, which a command line "
                         f"cannot give: use {_LISTED_FIELDS[field_name]} "
                         "(count=, seed=, region=)")
    if field_name not in data_gen.FIELDS:
        known = ", ".join(name for name in data_gen.FIELDS if name not in _LISTED_FIELDS)
        raise UsageError(f"unknown volume {spec!r}: not a file, and {field_name!r} is not a "
                         f"field (fields: {known}; named volumes: "
                         f"{', '.join(data_gen.DATASETS)})")
    samples, params = 64, {}
    for part in rest:
        if "=" in part:
            key, value = part.split("=", 1)
            params[key] = _number(value)
        else:
            try:
                samples = int(part)
            except ValueError:
                raise UsageError(f"samples per axis must be an integer, got {part!r}") \
                    from None
    field = data_gen.make_field(field_name, **params)
    if samples < 2:
        raise UsageError(f"samples per axis must be at least 2, got {samples}")
    needed, available = 8 * samples**3, available_bytes()
    # Sampling peaks at about 2.6 times the samples (measured at 200^3), and rendering
    # derives more from them: ask for 4 times the samples' size.
    if available is not None and 4 * needed > available:
        fits = int((available / 32) ** (1 / 3))
        raise UsageError(f"{spec} needs about {4 * needed / 1e9:.1f} GB to sample and render "
                         f"({needed / 1e9:.1f} GB of float64 samples), more than the "
                         f"{available / 1e9:.1f} GB available: at most {fits} samples per "
                         "axis fit")
    return field.sample(samples), field


def _triple(text, what):
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3:
        raise UsageError(f"{what} must be X,Y,Z (three numbers), got {text!r}")
    return values


def _pair(text, what):
    try:
        low, high = (float(v) for v in text.split(","))
    except ValueError:
        raise UsageError(f"{what} must be LOW,HIGH (two numbers), got {text!r}") from None
    return low, high


#: Opacity per voxel at the top of a window given alone (``--clim``), as the automatic ramp's.
AUTO_PEAK_ALPHA = 0.25


def make_transfer(args, field):
    """The transfer function the arguments ask for, as a function of the volume."""
    import vrlib

    shading = vrlib.Phong() if args.shade else None
    if args.cmap is not None and not args.cmap.strip():
        raise UsageError("--cmap needs a colormap name (bone, viridis, gray, ...)")
    if args.labels:
        if args.transfer is not None or args.opacity is not None or args.clim is not None:
            raise UsageError("--labels gives every label its own colour: it takes --cmap and "
                             "--shade, not --transfer, --opacity or --clim")
        return lambda volume: vrlib.label_transfer(volume, cmap=args.cmap or "tab20",
                                                   shading=shading)
    if args.cmap is not None or args.opacity is not None or args.clim is not None:
        if args.transfer is not None:
            raise UsageError("give either --transfer or --cmap/--opacity/--clim, not both")
        cmap = args.cmap or "gray"
        clim = None if args.clim is None else _pair(args.clim, "--clim")
        if args.opacity is None:
            if clim is None:
                return lambda volume: vrlib.auto_transfer(volume, cmap, shading=shading)
            # A window alone: colour over it, opacity ramping from 0 at its low end to the
            # automatic ramp's peak at its high end.
            points = [(0.0, 0.0), (1.0, AUTO_PEAK_ALPHA)]
        else:
            points = vrlib.colormapping.parse_opacity(args.opacity)
        return lambda volume: vrlib.colormap(cmap, points, clim=clim, volume=volume,
                                             shading=shading)
    spec = args.transfer or ("glow:1" if field is not None else "auto")
    kind, *numbers = spec.split(":")
    if kind == "auto" and not numbers:
        return lambda volume: vrlib.auto_transfer(volume, shading=shading)
    try:
        numbers = [float(a) for a in numbers]
    except ValueError:
        raise UsageError(f"transfer numbers must be numbers, got {spec!r}") from None
    if kind == "glow" and len(numbers) <= 1:
        def glow(volume):
            return vrlib.Glow((numbers[0] if numbers else 1.0) / _half_side(volume),
                              shading=shading)
        return glow
    if kind == "ramp" and len(numbers) == 2:
        threshold, scale = numbers
        if not 0.0 <= threshold < 1.0:
            raise UsageError(f"ramp threshold must lie in [0, 1), got {threshold:g}")

        def ramp(volume):
            lo, hi = volume.value_range
            hi = hi if hi > lo else lo + 1.0
            values = np.linspace(0.0, 1.0, 257)
            density = scale * np.clip((values - threshold) / (1.0 - threshold), 0.0, 1.0)
            return vrlib.LookupTransfer(density / _half_side(volume), value_range=(lo, hi),
                                        shading=shading)
        return ramp
    raise UsageError(f"transfer must be auto, glow[:K] or ramp:THRESHOLD:SCALE, got {spec!r}")


def _half_side(volume):
    """Half the volume's longest side: the unit of the command line's glow and ramp."""
    return float(np.max(volume.extent[:, 1] - volume.extent[:, 0])) / 2.0


def make_view(args, volume):
    import vrlib

    return vrlib.View.fit(volume, azimuth=args.azimuth, elevation=args.elevation,
                          size=args.size, projection=args.projection, zoom=args.zoom)


def _shape(text):
    try:
        shape = tuple(int(n) for n in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"shape must be NZ,NY,NX, got {text!r}") from None
    if len(shape) != 3:
        raise argparse.ArgumentTypeError(f"shape must be NZ,NY,NX, got {text!r}")
    return shape


def _add_volume(parser, optional=False):
    parser.add_argument("volume", help=VOLUME_HELP, nargs="?" if optional else None)
    parser.add_argument("--shape", type=_shape, help="NZ,NY,NX of a .raw file")
    parser.add_argument("--dtype", help="sample type of a .raw file (uint8, int16, float32..)")
    parser.add_argument("--offset", type=int, default=0,
                        help="header bytes to skip at the start of a .raw file")
    parser.add_argument("--frame", type=int, help="the volume to take from a 4-D NIfTI file")
    parser.add_argument("--series", help="the series (SeriesInstanceUID or its end) of a "
                                         "DICOM folder holding several")
    parser.add_argument("--scalars", help="the point or cell array of a .vti/.vtk file")
    parser.add_argument("--nan", default="error", choices=["error", "transparent"],
                        help="NaN samples in a file: refuse them (default), or holes that "
                             "contribute nothing")
    parser.add_argument("--spacing", help="X,Y,Z voxel size of a .npy, .raw or TIFF file "
                                          "(default the TIFF's own, else 1)")
    parser.add_argument("--oblique", default="refuse", choices=["refuse", "voxel-axes"],
                        help="a NIfTI or DICOM scan on an oblique grid: refuse it (default), or "
                             "show it in its own voxel axes, the rotation left out")


def _add_scene(parser):
    _add_volume(parser)
    parser.add_argument("--filter", help="reconstruction filter: box, trilinear (or pyramid), "
                        "gaussian, catmull-rom, mitchell, bspline, cardinal-bspline or omoms "
                        "(default trilinear, as in vrlib.render: the fastest; catmull-rom is "
                        "more accurate; box with --labels)")
    parser.add_argument("--transfer", help=TRANSFER_HELP)
    parser.add_argument("--cmap", help="a matplotlib colormap name (bone, viridis, ...)")
    parser.add_argument("--opacity", help="opacity points X:ALPHA,... with X a fraction of "
                        "the colour limits and ALPHA the opacity per voxel (e.g. "
                        "0:0,0.3:0,1:0.8); without it, an automatic ramp")
    parser.add_argument("--clim", help="LOW,HIGH: the data values of the colormap's ends "
                        "(default the volume's value range)")
    parser.add_argument("--labels", action="store_true",
                        help="a label volume: one colour per label (--cmap, default tab20), "
                             "label 0 transparent, nearest-sample filter")
    parser.add_argument("--shade", action="store_true", help="Phong shading (gradients)")
    parser.add_argument("--azimuth", type=float, default=30.0,
                        help="degrees about the world z axis, from +x (default 30)")
    parser.add_argument("--elevation", type=float, default=20.0,
                        help="degrees above the xy plane (default 20)")
    parser.add_argument("--size", type=int, default=256, help="image size in pixels")
    parser.add_argument("--projection", default="orthographic",
                        choices=["orthographic", "perspective"])
    parser.add_argument("--zoom", type=float, default=1.0,
                        help="magnification; at 1 the image spans the volume's bounding sphere")
    parser.add_argument("--step", type=float, default=None,
                        help="sample spacing along rays, in voxels (default 0.5)")


def _filter(args):
    """The filter asked for: trilinear by default (as ``vrlib.render``), the nearest sample for
    labels."""
    if args.filter is not None:
        return args.filter
    return "box" if args.labels else "trilinear"


def _load(args):
    return load_volume(args.volume, shape=args.shape, dtype=args.dtype, offset=args.offset,
                       frame=args.frame, series=args.series, scalars=args.scalars,
                       nan=args.nan, oblique=args.oblique, spacing=args.spacing)


def cmd_render(args):
    import vrlib
    from vrlib.cost import measure
    from vrlib.raycast import quick_starts
    from vrlib.render import chosen_method

    check_output(args.output, (".png", ".npy"), source=args.volume)
    volume, field = _load(args)
    view = make_view(args, volume)
    transfer = make_transfer(args, field)(volume)
    method, blend, options = _method_options(args)
    if args.classified:
        given = [flag for flag, value in (("--method", args.method), ("--blend", args.blend),
                                          ("--filter", args.filter), ("--step", args.step),
                                          ("--tolerance", args.tolerance),
                                          ("--option", args.option)) if value]
        if given:
            raise UsageError(f"--classified renders by shear-warp, emission-absorption, as "
                             f"VolPack does: leave out {', '.join(given)}")
        if view.is_perspective:
            raise UsageError("--classified renders orthographic views only (as VolPack)")
        scene = vrlib.classify(volume, transfer)
        seconds, img = measure(partial(scene.render, view), repeats=1, warmup=False)
        what = f"classified shear-warp (classified in {scene.seconds:.3f} s)"
    elif args.tolerance is not None:
        if args.step is not None:
            raise UsageError("--tolerance chooses the step itself: leave out --step")
        if blend != "emission-absorption":
            raise UsageError("--tolerance is kept for --blend emission-absorption only")
        if method not in ("raycast", "auto"):
            raise UsageError(f"--tolerance is kept by ray casting only: use --method raycast "
                             f"or --method auto (not {method})")
        if options:
            raise UsageError("--tolerance chooses the method's options itself: leave out "
                             "--option")
        # --method auto with no --filter: the filter is chosen too (vrlib.auto)
        filt = (None if method == "auto" and args.filter is None and not args.labels
                else _filter(args))
        seconds, img = measure(partial(
            vrlib.render, volume, view, method=method, filter=filt,
            transfer=transfer, tolerance=args.tolerance), repeats=1, warmup=False)
        chosen = img.stats.choices
        name = _filter(args) if filt is not None else chosen["auto"]["filter"]
        what = (f"{chosen['method']}/{name} to rmse {args.tolerance:g} (step "
                f"{chosen['step']:.3g} voxel, {chosen['classification']}, estimated error "
                f"{chosen['estimate']:.2g})")
    else:
        step = 0.5 if args.step is None else args.step
        with quick_starts():  # one render: the kernel that compiles sooner, if it is first
            seconds, img = measure(partial(
                vrlib.render, volume, view, method=method, filter=_filter(args),
                transfer=transfer, step=step, blend=blend, **options), repeats=1,
                warmup=False)
        what = f"{chosen_method(method)}/{_filter(args)}"
        if blend != "emission-absorption":
            what += f", {blend} intensity projection"
    img.save(args.output, bits=args.bits)
    print(f"{args.output}: {view.width}x{view.height} {what} in {seconds:.3f} s")


def cmd_turntable(args):
    import vrlib

    check_output(args.output, (".gif", ".mp4"), source=args.volume)
    volume, field = _load(args)
    transfer = make_transfer(args, field)(volume)
    method, blend, options = _method_options(args)
    images = vrlib.turntable(volume, args.output, frames=args.frames, elevation=args.elevation,
                             size=args.size, zoom=args.zoom, fps=args.fps, method=method,
                             filter=_filter(args), transfer=transfer, blend=blend,
                             step=0.5 if args.step is None else args.step, **options)
    seconds = sum(image.stats.seconds for image in images)
    print(f"{args.output}: {len(images)} frames of {args.size}x{args.size}, rendered in "
          f"{seconds:.2f} s")


def _errors(img, ref):
    import vrlib

    return {name: float(fn(img, ref)) for name, fn in
            (("rmse", vrlib.metrics.rmse), ("max", vrlib.metrics.max_abs_error))}


def cmd_compare(args):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from tqdm import tqdm

    import vrlib
    from vrlib.atomic import atomic_path
    from vrlib.cost import measure

    check_output(args.output, (".png", ".pdf", ".svg"))
    volume, field = _load(args)
    view = make_view(args, volume)
    transfer = make_transfer(args, field)(volume)
    reference, label = vrlib.reference_image(volume, view, transfer=transfer, field=field)
    label += " (exact field)" if field is not None else ", Catmull-Rom (no exact field for a file)"
    rows, images = [], {}
    for method in tqdm(vrlib.METHODS, desc="methods", file=sys.stderr, disable=None):
        try:
            seconds, img = measure(partial(vrlib.render, volume, view, method=method,
                                           filter=_filter(args), transfer=transfer,
                                           step=args.step), repeats=1, warmup=True)
        except ValueError as error:
            rows.append((method, None, None, None, str(error)))
            continue
        images[method] = img
        err = _errors(img, reference)
        rows.append((method, seconds, err["rmse"], err["max"], ""))
    print(f"errors against the {label}; filter {_filter(args)}, {view.width}x{view.height}; "
          "seconds after a warm-up render (the kernels compiled)")
    print(f"{'method':<10} {'seconds':>8} {'rmse':>10} {'max':>10}")
    for method, seconds, rmse, worst, note in rows:
        if seconds is None:
            print(f"{method:<10} {'-':>8} {'-':>10} {'-':>10}  {note}")
        else:
            print(f"{method:<10} {seconds:8.3f} {rmse:10.2e} {worst:10.2e}")
    # Differences of the composited colour (mean of R, G and B), so that errors in shading and
    # colour show as well as errors in opacity; one symmetric scale for every panel.
    seen = reference.composited()
    diffs = {m: (img.composited() - seen).mean(axis=-1) for m, img in images.items()}
    bound = max([float(np.abs(d).max()) for d in diffs.values()] + [1e-12])
    columns = len(images) + 1
    fig, axes = plt.subplots(2, columns, figsize=(2.4 * columns + 1.0, 5.2),
                             layout="constrained", squeeze=False)
    axes[0, 0].imshow(seen, interpolation="nearest")
    axes[0, 0].set_title("reference", fontsize=9)
    axes[1, 0].axis("off")
    shown = None
    for i, (method, img) in enumerate(images.items(), start=1):
        axes[0, i].imshow(img.composited(), interpolation="nearest")
        axes[0, i].set_title(method, fontsize=9)
        shown = axes[1, i].imshow(diffs[method], cmap="RdBu_r", vmin=-bound, vmax=bound,
                                  interpolation="nearest")
        axes[1, i].set_title(f"rmse {_errors(img, reference)['rmse']:.1e}", fontsize=8)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    if shown is not None:
        bar = fig.colorbar(shown, ax=axes[1, 1:], shrink=0.9, location="right")
        bar.set_label("image - reference\n(composited, mean of R, G, B)", fontsize=8)
        bar.ax.tick_params(labelsize=7)
    with atomic_path(args.output) as tmp:
        fig.savefig(tmp, dpi=120)
    print(f"figure: {args.output}")


def cmd_bench(args):
    from tqdm import tqdm

    import data_gen
    import vrlib
    from vrlib.cost import fit_methods, measure, points, save_model

    if args.model is not None:
        check_output(args.model, (".json",))
    # two image sizes (--size and half of it) for each method's three frames or more
    for name, least in (("samples", 4), ("size", 8), ("repeats", 1)):
        if getattr(args, name) < least:
            raise UsageError(f"--{name} must be at least {least}, got {getattr(args, name)}")
    field = data_gen.make_field("marschner-lobb")
    volume = field.sample(args.samples)
    transfer = vrlib.Glow(1.0)
    # The table's frames (every method and two filters at --size), and for the cost model
    # the same at half the size, and ray casting also at a step of 2 voxels: frames whose
    # points and operations differ, so that the constants separate.
    views = {size: vrlib.View.orbit(azimuth=30, elevation=20, size=size)
             for size in (max(4, args.size // 2), args.size)}
    reference = vrlib.render_reference(field, views[args.size], transfer=transfer)
    runs = [(m, f, size, step) for m in vrlib.METHODS for f in ("trilinear", "catmull-rom")
            for size in views for step in ((0.5, 2.0) if m == "raycast" else (0.5,))]
    rows, frames = [], []
    for method, filt, size, step in tqdm(runs, desc="bench", file=sys.stderr, disable=None):
        best, img = measure(partial(vrlib.render, volume, views[size], method=method,
                                    filter=filt, transfer=transfer, step=step),
                            repeats=args.repeats)
        frames.append({"method": method, "operations": img.stats.operations,
                       "points": points(img.stats), "seconds": best})
        if size == args.size and step == 0.5:
            rows.append((method, filt, best, vrlib.metrics.rmse(img, reference)))
    print(f"Marschner-Lobb {args.samples}^3 -> {args.size}^2, best of {args.repeats}, "
          f"rmse against the reference renderer")
    print(f"{'method':<10} {'filter':<12} {'seconds':>8} {'rmse':>10}")
    for method, filt, seconds, rmse in sorted(rows, key=lambda r: r[2]):
        print(f"{method:<10} {filt:<12} {seconds:8.4f} {rmse:10.2e}")
    fitted = fit_methods(frames)
    path = save_model(fitted, args.model)
    print(f"\ncost model t = c_op operations + c_pt points + c_0, fitted per method to "
          f"{len(frames)} frames, kept in {path}\n(render(..., method='auto', tolerance=t) "
          f"reads it to choose the filter)")
    print(f"{'method':<10} {'c_op ns':>8} {'c_pt ns':>8} {'c_0 ms':>8} {'median error':>13}")
    for method, c in fitted.items():
        print(f"{method:<10} {c['c_op'] * 1e9:8.3f} {c['c_pt'] * 1e9:8.2f} "
              f"{c['c_0'] * 1e3:8.3f} {c['median_error']:12.0%}")


def _type_name(dtype):
    """A sample type as a user reads it: its name and, for multi-byte types, byte order."""
    order = {">": "big", "<": "little", "=": sys.byteorder}.get(dtype.byteorder)
    return dtype.name if order is None or dtype.itemsize == 1 else f"{dtype.name}, {order}-endian"


def describe_volume(volume):
    """Lines describing a volume for choosing a transfer function: shape, spacing, box, value
    range, percentiles and a text histogram."""
    import vrlib

    data = vrlib.colormapping.finite_values(volume)
    low, high = volume.value_range
    ext = " x ".join(f"[{a:g}, {b:g}]" for a, b in volume.extent)
    stored = ("" if volume.file_dtype is None else
              f"stored in the file as {_type_name(volume.file_dtype)}, ")
    lines = [f"shape (z, y, x): {volume.shape}, {stored}held in memory as {volume.dtype}",
             f"spacing (x, y, z): {', '.join(f'{v:g}' for v in volume.spacing)}",
             f"world box: {ext}",
             f"values: {low:g} .. {high:g}"]
    if volume.holes is not None:
        lines.append(f"holes (NaN samples): {int(volume.holes.sum())}")
    percent = (1, 5, 25, 50, 75, 95, 99)
    values = np.percentile(data, percent)
    lines.append("percentiles: " + ", ".join(f"{p}%: {v:.4g}" for p, v in zip(percent, values,
                                                                            strict=True)))
    if high > low:
        counts, edges = np.histogram(data, bins=16, range=(low, high))
        width = 40 / max(1.0, np.log1p(counts.max()))
        lines.append("histogram (16 bins, bar length ~ log count):")
        for count, start in zip(counts, edges[:-1], strict=True):
            lines.append(f"  {start:>11.4g} {count:>10d} {'#' * int(np.log1p(count) * width)}")
        auto = vrlib.auto_transfer(volume)
        lines.append(f"--transfer auto ramps opacity over {auto.value_range[0]:.4g} .. "
                     f"{auto.value_range[1]:.4g} (--clim LOW,HIGH --opacity ... to choose)")
    return lines


def cmd_info(args):
    import numba

    import vrlib

    if args.volume is not None:
        first = []
        try:
            volume, field = _load(args)
        except ValueError as error:  # a 4-D file: describe its first frame
            if not str(error).startswith("frame:") or args.frame is not None:
                raise
            import nibabel

            frames = int(nibabel.load(args.volume).shape[3])
            args.frame = 0
            volume, field = _load(args)
            first = [f"4-D: {frames} frames; frame 0 below (choose one with --frame)"]
        what = f"analytic field {field!r}, sampled" if field is not None else args.volume
        print("\n".join([what] + first + describe_volume(volume)))
        return

    lines = [f"vrlib {vrlib.__version__}",
             f"python {platform.python_version()} on {platform.platform()}",
             f"machine: {platform.machine()}, {numba.config.NUMBA_NUM_THREADS} threads "
             f"for numba (threading layer {numba.config.THREADING_LAYER})",
             f"numpy {np.__version__}, numba {numba.__version__}"]
    for name in ("mpi4py", "pyvista", "vtk", "scipy", "nilearn", "sphinx"):
        try:
            module = __import__(name)
            version = getattr(module, "__version__", "?")
            if name == "mpi4py":
                from mpi4py import MPI
                version += f" ({MPI.Get_library_version().splitlines()[0].strip()})"
            lines.append(f"{name} {version}")
        except ImportError:
            lines.append(f"{name}: not installed")
    mpiexec = Path(sys.executable).parent / "mpiexec"
    lines.append(f"mpiexec: {mpiexec if mpiexec.exists() else 'not found beside python'}")
    lines.append(f"methods: {', '.join(vrlib.METHODS)}")
    lines.append(f"filters: {', '.join(vrlib.FILTERS)}")
    from vrlib.cost import load_model, model_path

    try:
        model = load_model()
        kept = (f"{model['path']} ({', '.join(model['methods'])})" if model else
                f"none at {model_path()} (vrlib bench fits it; method='auto' reads it)")
    except ValueError as error:
        kept = str(error)
    lines.append(f"cost model: {kept}")
    print("\n".join(lines))


def _version():
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("vrlib")
    except PackageNotFoundError:
        return "(not installed)"


class _Parser(argparse.ArgumentParser):
    """argparse, its errors in one line as the command's own (not nine lines of usage)."""

    def error(self, message):
        self.exit(2, f"vrlib: error: {message} (see {self.prog} --help)\n")


#: Options whose values may start with a minus sign (CT windows: --clim -1000,400).
_SIGNED_VALUES = ("--clim",)


def _signed_values(argv):
    """``argv`` with ``--clim -1000,400`` joined into ``--clim=-1000,400`` (argparse would
    take the value for an option)."""
    out, i = [], 0
    while i < len(argv):
        if argv[i] in _SIGNED_VALUES and i + 1 < len(argv) and argv[i + 1].startswith("-") \
                and argv[i + 1][1:2].isdigit():
            out.append(f"{argv[i]}={argv[i + 1]}")
            i += 2
        else:
            out.append(argv[i])
            i += 1
    return out


def _add_method(parser):
    parser.add_argument("--method", default=None,
                        help="raycast, splat, shear3, shear2, shearwarp or auto (default "
                             "raycast)")
    parser.add_argument("--blend", default=None,
                        choices=["emission-absorption", "maximum", "average"],
                        help="composite the samples (default), or project the largest "
                             "(maximum intensity) or mean value along each ray (ray casting)")
    parser.add_argument("--option", action="append", default=[], metavar="NAME=VALUE",
                        help="a method's own option, e.g. --option mode=direct (splat), "
                             "--option segment_ends=exact (raycast), --option "
                             "empty_space_skipping=false; repeat for more")


def _method_options(args):
    """``(method, blend, options)`` from --method, --blend and --option."""
    options = {}
    for text in args.option:
        name, equals, value = text.partition("=")
        if not equals or not name.strip():
            raise UsageError(f"--option must be NAME=VALUE, got {text!r}")
        value = value.strip()
        truth = {"true": True, "false": False}.get(value.lower())  # a switch: --option x=false
        options[name.strip().replace("-", "_")] = _number(value) if truth is None else truth
    return (args.method or "raycast", args.blend or "emission-absorption", options)


def parser():
    top = _Parser(
        prog="vrlib", description="Render volumes and compare renderers (vrlib).",
        epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    top.add_argument("--version", action="version", version=f"vrlib {_version()}")
    sub = top.add_subparsers(dest="command", required=True, metavar="COMMAND")
    render = sub.add_parser("render", help="render a volume to an image",
                            epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_scene(render)
    _add_method(render)
    render.add_argument("--classified", action="store_true",
                        help="classify once and render by shear-warp as VolPack does (takes "
                             "--shade; --method, --filter and --step do not apply)")
    render.add_argument("--tolerance", type=float,
                        help="render within this rmse (premultiplied RGBA, in (0, 1)) of the "
                             "exact image of the field the filter reconstructs: the step is "
                             "chosen for it (ray casting; no --step)")
    render.add_argument("--bits", type=int, default=8, choices=[8, 16], help="PNG bit depth")
    render.add_argument("-o", "--output", required=True, help="output .png or .npy")
    render.set_defaults(run=cmd_render)
    spin = sub.add_parser("turntable", help="views around the volume as a .gif or .mp4",
                          epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_scene(spin)
    _add_method(spin)
    spin.add_argument("--frames", type=int, default=36, help="views around the turntable")
    spin.add_argument("--fps", type=float, default=12.0, help="frames per second")
    spin.add_argument("-o", "--output", required=True, help="output .gif or .mp4")
    spin.set_defaults(run=cmd_turntable)
    compare = sub.add_parser("compare", help="every method on one volume, with errors",
                             epilog=EXAMPLES,
                             formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_scene(compare)
    compare.add_argument("-o", "--output", default="compare.png", help="figure to write")
    compare.set_defaults(run=cmd_compare, size=128)
    bench = sub.add_parser("bench", help="run time against error on this machine")
    bench.add_argument("--samples", type=int, default=64)
    bench.add_argument("--size", type=int, default=128)
    bench.add_argument("--repeats", type=int, default=3)
    bench.add_argument("--model", help="where to keep the cost model fitted to the frames, "
                                       "a .json file (default $VRLIB_COST_MODEL, else "
                                       "~/.cache/vrlib/cost-<machine>.json)")
    bench.set_defaults(run=cmd_bench)
    info = sub.add_parser("info", help="a volume's shape, spacing and values (to choose a "
                                       "transfer function); without one, the machine, "
                                       "backends and versions")
    _add_volume(info, optional=True)
    info.set_defaults(run=cmd_info)
    return top


def _one_line(text, source):
    """The message's first line in the command line's terms: a file name with line breaks
    in it escaped, Python's keywords (``nan='transparent'``, ``series=``) named by their
    flags (:func:`_as_flags`)."""
    if source and any(c in str(source) for c in "\r\n"):
        for name in (str(source), Path(source).name):
            text = text.replace(name, ascii(name)[1:-1])
    return _as_flags(text.splitlines()[0]) if text else ""


def _as_flags(text):
    """``text`` with each ``name='value'`` or ``name=value`` (and a bare ``name=``) of a
    keyword the command line has a flag for written as that flag, and a method's own option
    as ``--option name=value``.

    Examples
    --------
    >>> _as_flags("use nan='transparent', mode='sheet' or method='raycast'; frame=0..3")
    'use --nan transparent, --option mode=sheet or --method raycast; --frame 0..3'
    """
    import re

    from vrlib.render import METHODS, method_options

    flags = {"nan", "series", "frame", "scalars", "oblique", "filter", "method", "blend",
             "step", "transfer", "tolerance", "spacing", "shape", "dtype", "offset"}
    own = {name for method in METHODS for name in method_options(method)}

    def flag(match):
        name, value = match.group(1), match.group(2) or match.group(3) or ""
        if name in flags:
            return f"--{name} {value}".rstrip()
        return f"--option {name}={value}"

    names = "|".join(sorted(flags | own, key=len, reverse=True))
    return re.sub(rf"(?<![\w-])({names})=(?:'([^']*)'|([^\s,;)]*))", flag, text)


#: What the command line says when numba compiles (:func:`_say_when_compiling`).
_COMPILING = ("compiling the renderer's kernels for this machine, once (3 to 12 s; later "
              "runs load them from the cache)")


def _say_when_compiling():
    """Say once, on stderr, when numba starts compiling a kernel (a first run on a machine, or
    a first use of a kernel variant): a wait with nothing said looks like a hang. Loading a
    compiled kernel from the cache raises no compile event, so a warm run says nothing."""
    from numba.core import event

    class Note(event.Listener):
        def on_start(self, ev):
            if not _say_when_compiling.said:
                _say_when_compiling.said = True
                print(f"vrlib: note: {_COMPILING}", file=sys.stderr, flush=True)

        def on_end(self, ev):
            pass

    if not hasattr(_say_when_compiling, "said"):
        _say_when_compiling.said = False
        event.register("numba:compile", Note())


def main(argv=None):
    """Run the command line; returns the exit status (2 on bad input).

    Examples
    --------
    >>> main(["render", "no-such-volume", "-o", "x.png"])   # the message goes to stderr
    2
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser().parse_args(_signed_values(argv))
    _say_when_compiling()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", EmptyImageWarning)
            args.run(args)
    except (UsageError, ValueError, TypeError, OSError, ImportError) as error:
        if isinstance(error, OSError) and error.strerror:  # without the "[Errno n]"
            message = f"{error.strerror}: {error.filename}" if error.filename else error.strerror
        else:
            message = _one_line(str(error), getattr(args, "volume", None)) or \
                type(error).__name__
        print(f"vrlib: error: {message}", file=sys.stderr)
        return 2
    except MemoryError:
        source = getattr(args, "volume", None)
        print(f"vrlib: error: out of memory{f' with {source}' if source else ''}: try a "
              "smaller volume or image", file=sys.stderr)
        return 2
    for warning in caught:  # one line each, as the errors
        if issubclass(warning.category, EmptyImageWarning):
            print(f"vrlib: warning: {warning.message}", file=sys.stderr)
        else:
            warnings.showwarning(warning.message, warning.category, warning.filename,
                                 warning.lineno)
    return 0


def main_exit():
    """Entry point of the ``vrlib`` console script."""
    raise SystemExit(main())
