"""The bad-input matrix: every public entry point, given invalid input, raises a clear error that
names the parameter (and, where there is a list, what is allowed), before any numba kernel
runs. Nothing is half-written when a write fails."""

from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

import data_gen
import vrlib
from vrlib import Glow, LookupTransfer, View, Volume, make_filter, metrics
from vrlib.compositing import composite, correct_opacity, segment_alpha
from vrlib.parallel import decompose, mpi, network, taxonomy

VOL = data_gen.make_field("gaussian-blob").sample(9)
VIEW = View.orbit(size=8)
NAN = np.full((4, 4, 4), 1.0)
NAN[1, 2, 3] = np.nan
INF = np.ones((4, 4, 4))
INF[0, 0, 0] = np.inf


def render(**kw):
    args = {"volume": VOL, "view": VIEW}
    args.update(kw)
    return vrlib.render(args.pop("volume"), args.pop("view"), **args)


CASES = [
    # volumes
    ("NaN samples", lambda: Volume(NAN), ValueError, r"data must be finite.*NaN"),
    ("infinite samples", lambda: Volume(INF), ValueError, r"data must be finite.*infinite"),
    ("2-D data", lambda: Volume(np.ones((4, 4))), ValueError, r"data"),
    ("one sample on an axis", lambda: Volume(np.ones((1, 4, 4))), ValueError, r"data"),
    ("empty volume", lambda: Volume(np.ones((0, 4, 4))), ValueError, r"data"),
    ("complex data", lambda: Volume(np.ones((4, 4, 4), complex)), (TypeError, ValueError),
     r"data"),
    ("string data", lambda: Volume(np.full((4, 4, 4), "a")), (TypeError, ValueError), r"data"),
    ("extent wrong shape", lambda: Volume(np.ones((4, 4, 4)), extent=[0, 1]), ValueError,
     r"extent"),
    ("extent empty box", lambda: Volume(np.ones((4, 4, 4)), extent=[[0, 0], [0, 1], [0, 1]]),
     ValueError, r"extent"),
    ("extent NaN", lambda: Volume(np.ones((4, 4, 4)), extent=[[0, np.nan], [0, 1], [0, 1]]),
     ValueError, r"extent"),
    # views
    ("zero forward", lambda: View([0, 0, 0]), ValueError, r"forward"),
    ("up along forward", lambda: View([0, 0, 1], up=[0, 0, 2]), ValueError, r"up"),
    ("size zero", lambda: View.orbit(size=0), ValueError, r"size"),
    ("NaN azimuth", lambda: View.orbit(azimuth=np.nan), ValueError, r"azimuth"),
    ("unknown projection", lambda: View.orbit(projection="fisheye"), ValueError,
     r"projection.*'orthographic'"),
    ("fov 180", lambda: View.orbit(projection="perspective", fov=180), ValueError, r"fov"),
    ("zoom negative", lambda: View.orbit(zoom=-1), ValueError, r"zoom"),
    ("eye inside without fov", lambda: View.orbit(projection="perspective", distance=0.5),
     ValueError, r"eye"),
    # render
    ("volume as array", lambda: render(volume=np.ones((4, 4, 4))), TypeError, r"volume"),
    ("view as string", lambda: render(view="front"), TypeError, r"view"),
    ("unknown method", lambda: render(method="marching"), ValueError,
     r"method.*'raycast'"),
    ("unknown filter", lambda: render(filter="lanczos"), ValueError, r"filter.*'box'"),
    ("step zero", lambda: render(step=0.0), ValueError, r"step"),
    ("step NaN", lambda: render(step=np.nan), ValueError, r"step"),
    ("step infinite", lambda: render(step=np.inf), ValueError, r"step"),
    ("early termination zero", lambda: render(early_termination=0.0), ValueError,
     r"early_termination"),
    ("early termination above 1", lambda: render(early_termination=1.5), ValueError,
     r"early_termination"),
    ("threads zero", lambda: render(threads=0), ValueError, r"threads"),
    ("threads float", lambda: render(threads=1.5), TypeError, r"threads"),
    ("unknown option", lambda: render(method="splat", min_opacity=0.1), TypeError,
     r"option 'min_opacity'"),
    ("bad splat mode", lambda: render(method="splat", mode="fast"), ValueError, r"mode"),
    ("bad intermediate", lambda: render(method="shear2", intermediate="half"), ValueError,
     r"intermediate.*'float32'"),
    ("min_opacity 1", lambda: render(method="shearwarp", min_opacity=1.0), ValueError,
     r"min_opacity"),
    ("transfer not a transfer", lambda: render(transfer=lambda v: v), TypeError, r"transfer"),
    ("perspective shear3", lambda: render(method="shear3", view=View.orbit(
        size=8, projection="perspective")), ValueError, r"orthographic only"),
    ("filter too wide for ray casting", lambda: render(filter=("gaussian", 2.0, 5.0)),
     ValueError, r"radius"),
    # filters and transfer functions
    ("gaussian sigma zero", lambda: make_filter("gaussian", sigma=0.0), ValueError, r"sigma"),
    ("gaussian radius negative", lambda: make_filter("gaussian", radius=-1.0), ValueError,
     r"radius"),
    ("cubic B NaN", lambda: make_filter(("mitchell-netravali", np.nan, 0.5)), ValueError,
     r"B"),
    ("filter parameter unknown", lambda: make_filter("catmull-rom", sigma=1.0), TypeError,
     r"sigma|parameter"),
    ("filter as number", lambda: make_filter(3), TypeError, r"filter"),
    ("glow negative", lambda: Glow(-1.0), ValueError, r"scale"),
    ("glow NaN", lambda: Glow(np.nan), ValueError, r"scale"),
    ("lookup one entry", lambda: LookupTransfer([1.0]), ValueError, r"density"),
    ("lookup negative", lambda: LookupTransfer([0.0, -1.0]), ValueError, r"density"),
    ("lookup NaN", lambda: LookupTransfer([0.0, np.nan]), ValueError, r"density"),
    ("lookup range reversed", lambda: LookupTransfer([0.0, 1.0], value_range=(1, 0)),
     ValueError, r"value_range"),
    # compositing and metrics
    ("composite wrong last axis", lambda: composite(np.ones((3, 3))), ValueError, r"samples"),
    ("composite unknown order", lambda: composite(np.ones((2, 4)), order="sideways"),
     ValueError, r"order"),
    ("segment model unknown", lambda: segment_alpha(1.0, 1.0, model="quadratic"), ValueError,
     r"model"),
    ("correct opacity alpha > 1", lambda: correct_opacity(1.5, 1.0, 1.0), ValueError, r"alpha"),
    ("correct opacity step 0", lambda: correct_opacity(0.5, 0.0, 1.0), ValueError, r"step"),
    ("metric shapes differ", lambda: metrics.rmse(np.zeros((4, 4)), np.zeros((4, 5))),
     ValueError, r"shape"),
    ("metric NaN", lambda: metrics.rmse(np.full((4, 4), np.nan), np.zeros((4, 4))), ValueError,
     r"NaN|finite"),
    # reference and fields
    ("reference tol zero", lambda: vrlib.render_reference(
        data_gen.make_field("gaussian-blob"), VIEW, tol=0.0), ValueError, r"tol"),
    ("reference of a volume", lambda: vrlib.render_reference(VOL, VIEW), TypeError, r"field"),
    ("unknown field", lambda: data_gen.make_field("sphere"), ValueError,
     r"field.*'gaussian-blob'"),
    ("field bad parameter", lambda: data_gen.make_field("gaussian-blob", sigma=-1.0),
     ValueError, r"sigma"),
    ("sample shape 1", lambda: data_gen.make_field("gaussian-blob").sample(1), ValueError,
     r"shape"),
    ("sample dtype int", lambda: data_gen.make_field("gaussian-blob").sample(4, dtype=int),
     ValueError, r"dtype"),
    ("load missing file", lambda: data_gen.load("no/such/file.npy"), (FileNotFoundError,
                                                                     ValueError), r"file"),
    ("load raw without shape", lambda: data_gen.load("x.raw"), (TypeError, ValueError,
                                                               FileNotFoundError),
     r"shape|file"),
    # parallel
    ("split zero parts", lambda: decompose.split((4, 4, 4), 0), ValueError, r"parts"),
    ("split unknown shape", lambda: decompose.split((4, 4, 4), 2, shape="cubes"), ValueError,
     r"shape.*'slabs'"),
    ("more ranks than bricks", lambda: decompose.interleaved_owners(2, 4), ValueError,
     r"ranks"),
    ("screen more nodes than pixels", lambda: decompose.screen_tiles(2, 2, 5), ValueError,
     r"nodes"),
    ("network zero columns", lambda: network.Network(0, 4), ValueError, r"columns"),
    ("partition shape for image", lambda: taxonomy.Partition("image", "blocks"), ValueError,
     r"shape"),
    ("mpi unknown balance", lambda: mpi.render_object(
        MPI.COMM_SELF, data_gen.make_field("gaussian-blob"), VIEW, shape=9, balance="random"),
     ValueError, r"balance.*'even'"),
    ("mpi more ranks than cells", lambda: mpi.render_object(
        MPI.COMM_SELF, data_gen.make_field("gaussian-blob"), VIEW, shape=2, balance="interleaved",
        compositing="direct-send", bricks_per_rank=4), ValueError, r"cannot split"),
]


@pytest.mark.parametrize("name, call, kind, message", CASES, ids=[c[0] for c in CASES])
def test_bad_input_gets_a_clear_error(name, call, kind, message):
    with pytest.raises(kind, match=message):
        call()


def test_no_renderer_can_be_handed_a_nan():
    """A Volume refuses NaN at construction (above) and its samples are read-only, so no NaN
    can be put into one afterwards: no renderer ever sees one."""
    vol = Volume(np.ones((5, 5, 5)))
    with pytest.raises(ValueError):
        vol.data[2, 2, 2] = np.nan  # read-only: the samples cannot be changed in place


@pytest.mark.parametrize("suffix", [".png", ".npy"])
def test_a_failed_save_leaves_nothing_behind(tmp_path, monkeypatch, suffix):
    """A write that fails half-way leaves neither a partial file nor a temporary one."""
    img = render()
    target = tmp_path / f"out{suffix}"
    target.write_bytes(b"previous")  # an earlier, complete result

    def half_npy(file, array):  # write part of the file, then fail
        Path(file).write_bytes(b"\x93NUMPY partial")
        raise OSError("disk full")

    real_write = Path.write_bytes

    def half_png(self, data):
        real_write(self, data[: len(data) // 2])
        raise OSError("disk full")

    monkeypatch.setattr(np, "save", half_npy)
    monkeypatch.setattr(Path, "write_bytes", half_png)
    with pytest.raises(OSError, match="disk full"):
        img.save(target)
    assert target.read_bytes() == b"previous"
    assert [p.name for p in tmp_path.iterdir()] == [target.name]


def test_save_refuses_unknown_suffix_and_bits(tmp_path):
    img = render()
    with pytest.raises(ValueError, match="path must end in .png or .npy"):
        img.save(tmp_path / "out.jpg")
    with pytest.raises(ValueError, match="bits must be 8 or 16"):
        img.save(tmp_path / "out.png", bits=12)
    assert not any(Path(tmp_path).iterdir())


def test_messages_are_one_clear_line():
    """Error messages are single lines that a user can read (no kernel tracebacks)."""
    for name, call, kind, _ in CASES:
        try:
            call()
        except kind as error:
            text = str(error)
            assert text and "\n" not in text and len(text) < 400, name
            assert "numba" not in text.lower(), name


def test_an_output_that_cannot_be_written_is_named_not_its_temporary(tmp_path):
    """Outputs are written to a hidden temporary name and renamed; when the folder refuses
    the file, the error names the file asked for."""
    from vrlib.atomic import atomic_path

    folder = tmp_path / "a-file"
    folder.write_text("not a folder")
    with pytest.raises(OSError, match="cannot write '.*a-file/out.png'") as caught:
        with atomic_path(folder / "out.png"):
            pass
    assert ".out." not in str(caught.value)
