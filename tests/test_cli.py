"""The command line, run as a user runs it: the ``vrlib`` console script and
``python -m vrlib``."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import vrlib

SCRIPT = Path(sys.executable).parent / "vrlib"


def run(*args, module=False, cwd=None, env=None, script=False):
    """``vrlib ARGS`` as a ``CompletedProcess``: the installed script (``script``) or
    ``python -m vrlib`` (``module``) in a process of their own, else the ``main`` they call,
    in this process (its output captured, in ``cwd``), which saves a Python start per call."""
    if not (script or module or env):
        return _in_process(args, cwd)
    command = [sys.executable, "-m", "vrlib", *args] if module else [str(SCRIPT), *args]
    env = {**os.environ, **(env or {})}
    if "NUMBA_CACHE_DIR" in env:  # the JIT cache stays where it is, whatever the cwd
        env["NUMBA_CACHE_DIR"] = str(Path(env["NUMBA_CACHE_DIR"]).resolve())
    return subprocess.run(command, capture_output=True, text=True, timeout=300, cwd=cwd,
                          env=env, check=False)


def _in_process(args, cwd):
    import contextlib
    import io

    from vrlib import cli

    out, err, before = io.StringIO(), io.StringIO(), os.getcwd()
    try:
        os.chdir(cwd or before)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = cli.main(list(args))
            except SystemExit as done:  # argparse's help, version and errors
                status = done.code if isinstance(done.code, int) else 0
    finally:
        os.chdir(before)
    return subprocess.CompletedProcess(args, status, out.getvalue(), err.getvalue())


def test_render_writes_the_image_both_ways(tmp_path):
    for module in (False, True):  # the installed script, and python -m vrlib
        out = tmp_path / f"ml{int(module)}.png"
        done = run("render", "marschner-lobb:17", "--size", "24", "-o", str(out),
                   module=module, script=not module)
        assert done.returncode == 0, done.stderr
        assert out.read_bytes().startswith(b"\x89PNG")


def test_render_npy_matches_the_python_api(tmp_path):
    import data_gen
    import vrlib

    out = tmp_path / "blob.npy"
    done = run("render", "gaussian-blob:20:sigma=0.3", "--method", "splat", "--filter",
               "bspline", "--size", "16", "--azimuth", "10", "--elevation", "5", "-o",
               str(out))
    assert done.returncode == 0, done.stderr
    vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(20)
    view = vrlib.View.orbit(azimuth=10, elevation=5, size=16, radius=vol.bounding_radius,
                            center=vol.center)
    expected = vrlib.render(vol, view, method="splat", filter="bspline")
    np.testing.assert_array_equal(np.load(out), expected.rgba)


def test_a_switch_option_takes_true_and_false(tmp_path):
    """``--option NAME=false`` (or ``true``, any case) gives the option a boolean, as the
    Python API takes it (the words were passed on as strings and refused); a word that is
    neither is still refused, by name."""
    import data_gen
    import vrlib

    vol = data_gen.make_field("gaussian-blob").sample(12)
    view = vrlib.View.orbit(azimuth=10, elevation=5, size=16, radius=vol.bounding_radius,
                            center=vol.center)
    for word in ("false", "False", "TRUE"):
        out = tmp_path / f"{word}.npy"
        done = run("render", "gaussian-blob:12", "--size", "16", "--azimuth", "10",
                   "--elevation", "5", "--option", f"empty_space_skipping={word}", "-o",
                   str(out))
        assert done.returncode == 0, done.stderr
        expected = vrlib.render(vol, view, empty_space_skipping=word.lower() == "true")
        np.testing.assert_array_equal(np.load(out), expected.rgba)
    done = run("render", "gaussian-blob:12", "--size", "16", "--option",
               "empty_space_skipping=no", "-o", str(tmp_path / "no.npy"))
    assert done.returncode == 2 and "empty_space_skipping must be True or False" in done.stderr


def test_render_to_a_tolerance_matches_the_python_api(tmp_path):
    """--tolerance renders as render(..., tolerance=) does and says what it chose."""
    import data_gen
    import vrlib

    out = tmp_path / "ml.npy"
    done = run("render", "marschner-lobb:17", "--tolerance", "1e-3", "--size", "24", "-o",
               str(out))
    assert done.returncode == 0, done.stderr
    assert "to rmse 0.001 (step" in done.stdout and "estimated error" in done.stdout
    vol = data_gen.make_field("marschner-lobb").sample(17)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=24)
    expected = vrlib.render(vol, view, tolerance=1e-3)
    np.testing.assert_array_equal(np.load(out), expected.rgba)


def test_method_auto_says_which_method_it_ran(tmp_path):
    for extra in ([], ["--tolerance", "1e-2"]):
        done = run("render", "gaussian-blob:8", "--method", "auto", "--size", "8", *extra,
                   "-o", str(tmp_path / "blob.png"))
        assert done.returncode == 0, done.stderr
        said = done.stdout.split(": ", 1)[1]  # after the output's path
        assert said.startswith("8x8 raycast/trilinear ") and "auto" not in said


def test_render_classified_matches_the_python_api(tmp_path):
    """``--classified`` is :func:`vrlib.classify` and its render, shading included."""
    import data_gen

    out = tmp_path / "blob.npy"
    done = run("render", "gaussian-blob:20:sigma=0.3", "--classified", "--shade", "--size",
               "16", "--azimuth", "10", "--elevation", "5", "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert "classified shear-warp" in done.stdout
    vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(20)
    view = vrlib.View.orbit(azimuth=10, elevation=5, size=16, radius=vol.bounding_radius,
                            center=vol.center)
    expected = vrlib.classify(vol, vrlib.Glow(1.0, shading=vrlib.Phong())).render(view)
    np.testing.assert_array_equal(np.load(out), expected.rgba)


def test_render_reads_files(tmp_path):
    data = np.zeros((8, 8, 8), np.uint8)
    data[2:6, 2:6, 2:6] = 200
    np.save(tmp_path / "cube.npy", data)
    data.tofile(tmp_path / "cube.raw")
    for name, extra in (("cube.npy", []), ("cube.raw", ["--shape", "8,8,8", "--dtype",
                                                        "uint8"])):
        done = run("render", str(tmp_path / name), *extra, "--transfer", "ramp:0.5:4",
                   "--size", "16", "-o", str(tmp_path / f"{name}.png"))
        assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("args, message", [
    (["render", "nothing", "-o", "x.png"], "unknown volume 'nothing'"),
    (["render", "blobs", "-o", "x.png"], "use random-blobs"),
    (["render", "marschner-lobb:17", "--method", "foo", "-o", "x.png"], "unknown method"),
    (["render", "marschner-lobb:17", "--filter", "lanczos", "-o", "x.png"],
     "unknown filter"),
    (["render", "marschner-lobb:x", "-o", "x.png"], "samples per axis must be an integer"),
    (["render", "marschner-lobb:17", "-o", "x.jpg"], "output must end in .png or .npy"),
    (["render", "marschner-lobb:17", "--size", "0", "-o", "x.png"], "size"),
    (["render", "marschner-lobb:17", "--transfer", "fog:1", "-o", "x.png"], "transfer"),
    (["render", "gaussian-blob:17:sigma=-1", "-o", "x.png"], "sigma"),
    (["render", "missing.npy", "-o", "x.png"], "volume file not found"),
    (["render", "missing.raw", "-o", "x.png"], "volume file not found"),
    (["render", "marschner-lobb:17", "--projection", "perspective", "--method", "shear3",
      "-o", "x.png"], "orthographic only"),
    (["render", "marschner-lobb:17", "--projection", "perspective", "--classified",
      "-o", "x.png"], "orthographic views only"),
    (["render", "frog", "--opacity", "0:0;1", "-o", "x.png"], "opacity points must be"),
    (["render", "frog", "--opacity", "0:0,1:2", "-o", "x.png"], "alpha must lie in [0, 1]"),
    (["render", "frog", "--cmap", "nosuchmap", "-o", "x.png"], "unknown colormap"),
    (["render", "frog", "--clim", "0,1", "--transfer", "glow:1", "-o", "x.png"],
     "not both"),
    (["render", "gaussian-blob:9", "--step", "1e-9", "-o", "x.png"], "step must be at least"),
    (["render", "gaussian-blob:9", "--size", "-o", "x.png"], "(see vrlib render --help)"),
    (["render", "frog", "--frame", "1", "-o", "x.png"], "--frame applies to .nii"),
    (["render", "gaussian-blob:8", "-o", "missing/x.png"], "no folder 'missing' for the output"),
    (["render", "gaussian-blob:8", "-o", "/etc/hostname/x.png"], "is a file"),
    (["render", "gaussian-blob:8", "-o", "/proc/x.png"], "cannot write into folder '/proc'"),
    (["turntable", "gaussian-blob:8", "-o", "missing/x.gif"], "no folder"),
    (["compare", "gaussian-blob:8", "-o", "missing/x.png"], "no folder"),
    (["render", "marschner-lobb:3000", "-o", "x.png"], "samples per axis fit"),
    (["render", "gaussian-blob:8", "--tolerance", "1e-3", "--step", "1", "-o", "x.png"],
     "leave out --step"),
    (["render", "gaussian-blob:8", "--tolerance", "1e-3", "--method", "splat", "-o",
      "x.png"], "use --method raycast or --method auto"),
    (["render", "gaussian-blob:8", "--tolerance", "2", "-o", "x.png"], "tolerance"),
    (["bench", "--model", "cost.txt"], ".json"),
    (["bench", "--size", "7"], "--size must be at least 8, got 7"),
])
def test_bad_input_exits_2_with_one_line(tmp_path, monkeypatch, capsys, args, message):
    """In process (the installed script is run in the tests around this one): the same
    ``main`` the script calls, without a Python start per case."""
    from vrlib import cli

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(cli, "_say_when_compiling", lambda: None)
    try:
        status = cli.main(list(args))
    except SystemExit as done:  # argparse's own errors
        status = done.code
    stderr = capsys.readouterr().err
    assert status == 2
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], stderr
    assert not any(tmp_path.iterdir()), "nothing may be written on bad input"


def test_a_corrupt_cost_model_exits_2_naming_it(tmp_path, monkeypatch, capsys):
    """--method auto --tolerance reads the cost model: a file that is not one is refused in
    one line that names it, and the image is not written."""
    from vrlib import cli

    model = tmp_path / "cost.json"
    model.write_text("{not json")
    monkeypatch.setenv("VRLIB_COST_MODEL", str(model))
    monkeypatch.setattr(cli, "_say_when_compiling", lambda: None)
    out = tmp_path / "x.png"
    status = cli.main(["render", "gaussian-blob:8", "--method", "auto", "--tolerance", "1e-2",
                       "-o", str(out)])
    lines = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(lines) == 1 and str(model) in lines[0] and "vrlib bench" in \
        lines[0], lines
    assert not out.exists()


def test_bad_files_exit_2_with_one_line(tmp_path):
    """Truncated and corrupt files of each kind: one line naming the problem, nothing written."""
    inputs, out = tmp_path / "in", tmp_path / "out"
    inputs.mkdir()
    out.mkdir()
    np.zeros((4, 4, 4), np.uint8).tofile(inputs / "short.raw")
    (inputs / "bad.nii").write_bytes(b"\x5c\x01" + bytes(300))
    (inputs / "bad.tif").write_bytes(b"II*\x00" + bytes(8))
    (inputs / "v.xyz").write_bytes(b"")
    np.save(inputs / "v.npy", np.zeros((4, 4, 4)))
    from data_gen.dicom import write_series

    write_series(inputs / "gap", np.zeros((5, 4, 4)))[2].unlink()
    for args, message in (
            (["gap"], "unevenly spaced"),
            (["short.raw", "--shape", "4,4,5", "--dtype", "uint8"], "raw file holds 64 bytes"),
            (["bad.nii"], "not a readable NIfTI file"),
            (["bad.tif"], "not a readable TIFF file"),
            (["v.xyz"], "vrlib does not read .xyz files; it reads .npy"),
            (["v.npy", "--offset", "8"], "--offset applies to .raw files only")):
        args[0] = str(inputs / args[0])
        done = run("render", *args, "-o", "x.png", cwd=out)
        lines = done.stderr.strip().splitlines()
        assert done.returncode == 2 and len(lines) == 1 and message in lines[0], done.stderr
    assert not any(out.iterdir())


@pytest.mark.slow  # three cold processes compile the shaded kernels; make test-all runs it
def test_real_volumes_render_by_name_with_their_transfer_functions(tmp_path):
    """Each shipped volume in one command, with a colormap and opacity points or the
    automatic ramp, comes out as a picture (not empty, not a white silhouette)."""
    for name, extra in (("frog", ["--cmap", "bone", "--opacity", "0:0,0.2:0,1:0.6", "--clim",
                                  "0,29", "--shade"]),
                        ("aniso", []), ("mni152", ["--cmap", "magma"])):
        out = tmp_path / f"{name}.npy"
        done = run("render", name, *extra, "--size", "24", "--filter", "trilinear", "-o",
                   str(out))
        assert done.returncode == 0, done.stderr
        alpha = np.load(out)[..., 3]
        assert 0.02 < alpha.mean() < 0.6 and alpha.max() > 0.3, (name, alpha.mean())
    done = run("info", "aniso")
    assert done.returncode == 0, done.stderr
    assert "spacing (x, y, z): 4, 4, 5" in done.stdout and "histogram" in done.stdout


@pytest.mark.slow  # labels, projections and turntables are tested in-process in make test
def test_labels_projections_and_turntables(tmp_path):
    """The frog's labels (nearest-sample filter by default), a maximum-intensity projection,
    and turntables as GIF and MP4."""
    done = run("render", "frog", "--labels", "--size", "24", "-o", str(tmp_path / "f.npy"))
    assert done.returncode == 0 and "raycast/box" in done.stdout, done.stderr
    rgba = np.load(tmp_path / "f.npy")
    assert rgba[..., 3].max() > 0.3 and np.ptp(rgba[..., :3].max(axis=(0, 1))) > 0.05  # colour
    done = run("render", "aniso", "--blend", "maximum", "--cmap", "gray", "--opacity",
               "0:1,1:1", "--size", "16", "-o", str(tmp_path / "mip.npy"))
    assert done.returncode == 0 and "maximum intensity projection" in done.stdout, done.stderr
    assert np.load(tmp_path / "mip.npy")[..., 3].max() > 0.9999
    for name, magic in (("spin.gif", b"GIF8"), ("spin.mp4", b"ftyp")):
        done = run("turntable", "gaussian-blob:12:sigma=0.3", "--frames", "3", "--size", "32",
                   "-o", str(tmp_path / name))
        assert done.returncode == 0 and "3 frames" in done.stdout, done.stderr
        assert magic in (tmp_path / name).read_bytes()[:12]
    done = run("turntable", "gaussian-blob:12", "-o", str(tmp_path / "spin.avi"))
    assert done.returncode == 2 and "output must end in .gif or .mp4" in done.stderr


def test_nan_samples_refused_or_holes(tmp_path):
    data = np.ones((6, 6, 6))
    data[2:4, 2:4, 2:4] = np.nan
    np.save(tmp_path / "nan.npy", data)
    done = run("render", str(tmp_path / "nan.npy"), "-o", str(tmp_path / "x.png"))
    assert done.returncode == 2 and "--nan transparent" in done.stderr  # its own flag
    done = run("render", str(tmp_path / "nan.npy"), "--nan", "transparent", "--transfer",
               "glow:1", "--size", "16", "--filter", "trilinear", "-o", str(tmp_path / "h.npy"))
    assert done.returncode == 0, done.stderr
    rgba = np.load(tmp_path / "h.npy")
    assert np.all(np.isfinite(rgba)) and 0.0 < rgba[..., 3].max() < 1.0


def test_an_empty_image_says_why_in_one_line(tmp_path):
    done = run("render", "gaussian-blob:12", "--cmap", "gray", "--opacity", "0:0,1:0", "--size",
               "8", "-o", str(tmp_path / "e.png"))
    lines = [line for line in done.stderr.strip().splitlines()
             if not line.startswith("vrlib: note: compiling")]  # said on a cold cache
    assert done.returncode == 0 and len(lines) == 1, done.stderr
    assert lines[0].startswith("vrlib: warning: the transfer function") and "transparent" in \
        lines[0]


def test_render_a_dicom_folder(tmp_path):
    from data_gen.dicom import write_series

    data = np.zeros((6, 8, 8))
    data[1:5, 2:6, 2:6] = 500
    write_series(tmp_path / "ct", data - 1000, spacing=(0.5, 0.5, 1.0), intercept=-1024)
    out = tmp_path / "ct.npy"
    done = run("render", str(tmp_path / "ct"), "--size", "16", "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert np.load(out)[..., 3].max() > 0.1


def test_version():
    done = run("--version", script=True)
    assert done.returncode == 0 and done.stdout.strip() == f"vrlib {vrlib.__version__}"


def test_compiling_is_said_once(capsys):
    """The command line says once, when numba first compiles, that it does (a cold cache's
    wait is 3 to 12 s); later compiles in the same run say nothing."""
    import numba

    from vrlib import cli

    cli._say_when_compiling()
    cli._say_when_compiling()  # the listener is registered once
    cli._say_when_compiling.said = False  # as in a fresh process
    capsys.readouterr()
    for offset in (1, 2):
        numba.njit(lambda x, offset=offset: x + offset)(1)  # a compile, not a cache load
    notes = [line for line in capsys.readouterr().err.splitlines() if "compiling" in line]
    assert len(notes) == 1 and notes[0].startswith("vrlib: note: compiling the renderer's")


def test_argparse_errors_exit_2():
    """In one line, as the command's own errors, not argparse's usage block."""
    done = run("render", "marschner-lobb:17", script=True)  # no -o
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and "-o/--output" in lines[0]
    assert lines[0].startswith("vrlib: error: ")


def test_a_ct_window_alone_with_negative_limits(tmp_path):
    """``--clim -1000,400`` (without ``=``) is a window; with no --opacity it ramps the
    opacity over the window."""
    data = np.linspace(-1200.0, 600.0, 9**3).reshape(9, 9, 9)
    np.save(tmp_path / "ct.npy", data)
    done = run("render", str(tmp_path / "ct.npy"), "--clim", "-1000,400", "--size", "16",
               "-o", str(tmp_path / "ct-image.npy"))
    assert done.returncode == 0, done.stderr
    alpha = np.load(tmp_path / "ct-image.npy")[..., 3]
    assert 0.0 < alpha.max() < 1.0


def test_a_file_name_with_a_line_break_stays_one_line(tmp_path):
    (tmp_path / "bad\nname.nii").write_bytes(b"\x5c\x01" + bytes(300))
    done = run("info", str(tmp_path / "bad\nname.nii"))
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and "bad\\nname.nii" in lines[0], lines


def test_help_shows_examples():
    for args in (["--help"], ["render", "--help"]):
        done = run(*args)
        assert done.returncode == 0
        assert "vrlib render marschner-lobb:41 -o ml.png" in done.stdout


def test_compare_prints_a_table_and_saves_a_figure(tmp_path):
    out = tmp_path / "compare.png"
    done = run("compare", "gaussian-blob:17:sigma=0.3", "--size", "24", "-o", str(out))
    assert done.returncode == 0, done.stderr
    for method in vrlib.METHODS:
        assert method in done.stdout
    assert "reference renderer" in done.stdout and "after a warm-up render" in done.stdout
    assert out.read_bytes().startswith(b"\x89PNG")


def test_bench_and_info(tmp_path):
    """``vrlib bench`` prints every method's time and error, and fits the cost model that
    ``method="auto"`` reads."""
    from vrlib.cost import load_model

    path = tmp_path / "cost.json"
    done = run("bench", "--samples", "12", "--size", "16", "--repeats", "1", "--model",
               str(path))
    assert done.returncode == 0, done.stderr
    assert "rmse" in done.stdout and done.stdout.count("\n") >= 11
    assert f"kept in {path}" in done.stdout
    model = load_model(path)
    assert sorted(model["methods"]) == sorted(vrlib.METHODS)
    assert model["methods"]["raycast"]["c_pt"] + model["methods"]["raycast"]["c_op"] > 0
    done = run("info")
    assert done.returncode == 0
    assert "numba" in done.stdout and "MPICH" in done.stdout
    assert "cost model: none at" in done.stdout  # the tests' own file, not written yet
