"""The command line: ``vrlib render | compare | bench | info`` (also ``python -m vrlib``).

Bad input ends with exit status 2 and a one-line message naming what was wrong.
"""

from __future__ import annotations

import argparse
import platform
import sys
from functools import partial
from pathlib import Path

import numpy as np

EXAMPLES = """examples:
  vrlib render marschner-lobb:41 -o ml.png
  vrlib render gaussian-blob:64:sigma=0.3 --method splat --filter catmull-rom -o blob.png
  vrlib render mni152 --transfer ramp:0.3:40 --shade --azimuth 90 --size 512 -o head.png
  vrlib render scan.raw --shape 64,64,64 --dtype uint8 -o scan.png
  vrlib compare marschner-lobb:41 --size 128 -o compare.png
  vrlib bench
  vrlib info
"""

VOLUME_HELP = ("an analytic field NAME[:SAMPLES[:KEY=VALUE...]] (e.g. marschner-lobb:41, "
               "gaussian-blob:64:sigma=0.3), a file (.npy, .nii, .nii.gz, .raw with --shape "
               "and --dtype), or mni152 (the bundled MRI template)")


class UsageError(Exception):
    """Bad input from the command line: reported in one line, exit status 2."""


def _number(text):
    try:
        value = float(text)
    except ValueError:
        return text
    return int(value) if value.is_integer() and "." not in text and "e" not in text else value


def load_volume(spec, *, shape=None, dtype=None):
    """``(volume, field or None)`` from a command-line volume spec."""
    import data_gen

    path = Path(spec)
    if spec == "mni152":
        return data_gen.load_mni_template(), None
    if path.suffix in (".npy", ".raw", ".nii", ".gz"):
        if not path.is_file():
            raise UsageError(f"volume file not found: {spec}")
        options = {}
        if path.suffix == ".raw":
            if shape is None or dtype is None:
                raise UsageError("a .raw volume needs --shape NZ,NY,NX and --dtype")
            options = {"shape": shape, "dtype": dtype}
        return data_gen.load(path, **options), None
    name, *rest = spec.split(":")
    if name not in data_gen.FIELDS:
        known = ", ".join(data_gen.FIELDS)
        raise UsageError(f"unknown volume {spec!r}: not a file, and {name!r} is not a field "
                         f"(fields: {known}; or mni152)")
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
    field = data_gen.make_field(name, **params)
    return field.sample(samples), field


def make_transfer(spec, shade=False):
    """``glow:K`` (default ``glow:1``) or ``ramp:THRESHOLD:SCALE`` (transparent below the
    threshold, a fraction of the value range); ``shade`` adds Phong shading."""
    import vrlib

    shading = vrlib.Phong() if shade else None

    kind, *args = spec.split(":")
    try:
        numbers = [float(a) for a in args]
    except ValueError:
        raise UsageError(f"transfer numbers must be numbers, got {spec!r}") from None
    if kind == "glow" and len(numbers) <= 1:
        return lambda volume: vrlib.Glow(numbers[0] if numbers else 1.0, shading=shading)
    if kind == "ramp" and len(numbers) == 2:
        threshold, scale = numbers
        if not 0.0 <= threshold < 1.0:
            raise UsageError(f"ramp threshold must lie in [0, 1), got {threshold:g}")

        def ramp(volume):
            lo, hi = volume.value_range
            hi = hi if hi > lo else lo + 1.0
            values = np.linspace(0.0, 1.0, 257)
            density = scale * np.clip((values - threshold) / (1.0 - threshold), 0.0, 1.0)
            return vrlib.LookupTransfer(density, value_range=(lo, hi), shading=shading)
        return ramp
    raise UsageError(f"transfer must be glow[:K] or ramp:THRESHOLD:SCALE, got {spec!r}")


def make_view(args, volume):
    import vrlib

    return vrlib.View.orbit(azimuth=args.azimuth, elevation=args.elevation, size=args.size,
                            projection=args.projection, zoom=args.zoom,
                            radius=volume.bounding_radius, center=volume.center)


def _shape(text):
    try:
        shape = tuple(int(n) for n in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"shape must be NZ,NY,NX, got {text!r}") from None
    if len(shape) != 3:
        raise argparse.ArgumentTypeError(f"shape must be NZ,NY,NX, got {text!r}")
    return shape


def _add_scene(parser):
    parser.add_argument("volume", help=VOLUME_HELP)
    parser.add_argument("--shape", type=_shape, help="NZ,NY,NX of a .raw file")
    parser.add_argument("--dtype", help="sample type of a .raw file (uint8, int16, float32..)")
    parser.add_argument("--filter", default="catmull-rom",
                        help="reconstruction filter (default catmull-rom)")
    parser.add_argument("--transfer", default="glow:1",
                        help="glow[:K] or ramp:THRESHOLD:SCALE (default glow:1)")
    parser.add_argument("--shade", action="store_true", help="Phong shading (gradients)")
    parser.add_argument("--azimuth", type=float, default=30.0)
    parser.add_argument("--elevation", type=float, default=20.0)
    parser.add_argument("--size", type=int, default=256, help="image size in pixels")
    parser.add_argument("--projection", default="orthographic",
                        choices=["orthographic", "perspective"])
    parser.add_argument("--zoom", type=float, default=1.0)
    parser.add_argument("--step", type=float, default=0.5, help="ray step in voxels")


def cmd_render(args):
    import vrlib
    from vrlib.cost import measure

    if Path(args.output).suffix.lower() not in (".png", ".npy"):
        raise UsageError(f"output must end in .png or .npy, got {args.output!r}")
    volume, _ = load_volume(args.volume, shape=args.shape, dtype=args.dtype)
    view = make_view(args, volume)
    transfer = make_transfer(args.transfer, args.shade)(volume)
    if args.classified:
        if view.is_perspective:
            raise UsageError("--classified renders orthographic views only (as VolPack)")
        scene = vrlib.classify(volume, transfer)
        seconds, img = measure(partial(scene.render, view), repeats=1, warmup=False)
        what = f"classified shear-warp (classified in {scene.seconds:.3f} s)"
    else:
        seconds, img = measure(partial(
            vrlib.render, volume, view, method=args.method, filter=args.filter,
            transfer=transfer, step=args.step), repeats=1, warmup=False)
        what = f"{args.method}/{args.filter}"
    img.save(args.output, bits=args.bits)
    print(f"{args.output}: {view.width}x{view.height} {what} in {seconds:.3f} s")


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

    volume, field = load_volume(args.volume, shape=args.shape, dtype=args.dtype)
    view = make_view(args, volume)
    transfer = make_transfer(args.transfer, args.shade)(volume)
    reference, label = vrlib.reference_image(volume, view, transfer=transfer, field=field)
    label += " (exact field)" if field is not None else ", Catmull-Rom (no exact field for a file)"
    rows, images = [], {}
    for method in tqdm(vrlib.METHODS, desc="methods", file=sys.stderr, disable=None):
        try:
            seconds, img = measure(partial(vrlib.render, volume, view, method=method,
                                           filter=args.filter, transfer=transfer,
                                           step=args.step), repeats=1, warmup=False)
        except ValueError as error:
            rows.append((method, None, None, None, str(error)))
            continue
        images[method] = img
        err = _errors(img, reference)
        rows.append((method, seconds, err["rmse"], err["max"], ""))
    print(f"errors against the {label}; filter {args.filter}, {view.width}x{view.height}")
    print(f"{'method':<10} {'seconds':>8} {'rmse':>10} {'max':>10}")
    for method, seconds, rmse, worst, note in rows:
        if seconds is None:
            print(f"{method:<10} {'-':>8} {'-':>10} {'-':>10}  {note}")
        else:
            print(f"{method:<10} {seconds:8.3f} {rmse:10.2e} {worst:10.2e}")
    fig, axes = plt.subplots(2, len(images) + 1, figsize=(2.6 * (len(images) + 1), 5.4))
    axes[0, 0].imshow(reference.composited(), interpolation="nearest")
    axes[0, 0].set_title("reference", fontsize=9)
    axes[1, 0].axis("off")
    for i, (method, img) in enumerate(images.items(), start=1):
        axes[0, i].imshow(img.composited(), interpolation="nearest")
        axes[0, i].set_title(method, fontsize=9)
        diff = img.alpha - reference.alpha
        bound = max(float(np.abs(diff).max()), 1e-12)
        axes[1, i].imshow(diff, cmap="RdBu_r", vmin=-bound, vmax=bound)
        axes[1, i].set_title(f"difference, +-{bound:.1e}", fontsize=8)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    with atomic_path(args.output) as tmp:
        fig.savefig(tmp, dpi=120)
    print(f"figure: {args.output}")


def cmd_bench(args):
    from tqdm import tqdm

    import data_gen
    import vrlib
    from vrlib.cost import measure

    field = data_gen.make_field("marschner-lobb")
    volume = field.sample(args.samples)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=args.size)
    transfer = vrlib.Glow(1.0)
    reference = vrlib.render_reference(field, view, transfer=transfer)
    runs = [(m, f) for m in vrlib.METHODS for f in ("trilinear", "catmull-rom")]
    rows = []
    for method, filt in tqdm(runs, desc="bench", file=sys.stderr, disable=None):
        best, img = measure(partial(vrlib.render, volume, view, method=method, filter=filt,
                                    transfer=transfer), repeats=args.repeats)
        rows.append((method, filt, best, vrlib.metrics.rmse(img, reference)))
    print(f"Marschner-Lobb {args.samples}^3 -> {args.size}^2, best of {args.repeats}, "
          f"rmse against the reference renderer")
    print(f"{'method':<10} {'filter':<12} {'seconds':>8} {'rmse':>10}")
    for method, filt, seconds, rmse in sorted(rows, key=lambda r: r[2]):
        print(f"{method:<10} {filt:<12} {seconds:8.4f} {rmse:10.2e}")


def cmd_info(args):
    import numba

    import vrlib

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
    print("\n".join(lines))


def parser():
    top = argparse.ArgumentParser(
        prog="vrlib", description="Render volumes and compare renderers (vrlib).",
        epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = top.add_subparsers(dest="command", required=True, metavar="COMMAND")
    render = sub.add_parser("render", help="render a volume to an image",
                            epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_scene(render)
    render.add_argument("--method", default="raycast",
                        help="raycast, splat, shear3, shear2 or shearwarp (default raycast)")
    render.add_argument("--classified", action="store_true",
                        help="classify once and render by shear-warp as VolPack does (takes "
                             "--shade; --method, --filter and --step do not apply)")
    render.add_argument("--bits", type=int, default=8, choices=[8, 16], help="PNG bit depth")
    render.add_argument("-o", "--output", required=True, help="output .png or .npy")
    render.set_defaults(run=cmd_render)
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
    bench.set_defaults(run=cmd_bench)
    info = sub.add_parser("info", help="machine, backends and versions")
    info.set_defaults(run=cmd_info)
    return top


def main(argv=None):
    """Run the command line; returns the exit status (2 on bad input).

    Examples
    --------
    >>> main(["render", "no-such-volume", "-o", "x.png"])   # the message goes to stderr
    2
    """
    args = parser().parse_args(argv)
    try:
        args.run(args)
    except (UsageError, ValueError, TypeError, FileNotFoundError, ImportError) as error:
        message = str(error).splitlines()[0] if str(error) else type(error).__name__
        print(f"vrlib: error: {message}", file=sys.stderr)
        return 2
    return 0


def main_exit():
    """Entry point of the ``vrlib`` console script."""
    raise SystemExit(main())
