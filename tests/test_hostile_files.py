"""Hostile files: every reader refuses what would read outside its folder, hang, exhaust
memory or render a guess, with one line that names the file and exit status 2.

The files are built here, small on disk (sparse files and compressed bombs take kilobytes);
the command lines run in one subprocess under an address space limit and a time limit per
case (``hostile_runner.py``), each case's growth of the peak resident memory recorded.
"""

import gzip
import json
import os
import subprocess
import sys
from pathlib import Path

import nibabel
import nrrd
import numpy as np
import pytest

import data_gen

RUNNER = Path(__file__).with_name("hostile_runner.py")
#: The most one case may raise the process's peak resident memory (MB).
PEAK_GROWTH_MB = 300


def _nhdr(folder, name, data_file, *, sizes="4 4 4", kind="uint8", encoding="raw",
          extra=""):
    path = folder / name
    path.write_text(f"NRRD0004\ntype: {kind}\ndimension: 3\nsizes: {sizes}\n"
                    f"encoding: {encoding}\n{extra}data file: {data_file}\n")
    return path


def _nrrd(folder, name, payload, *, sizes="4 4 4", kind="uint8", encoding="raw", extra=""):
    path = folder / name
    path.write_bytes(f"NRRD0004\ntype: {kind}\ndimension: 3\nsizes: {sizes}\n"
                     f"encoding: {encoding}\n{extra}\n".encode() + payload)
    return path


def _sparse(path, size, head=b""):
    with open(path, "wb") as fh:
        fh.write(head)
        fh.truncate(size)
    return path


def _nifti_header(path, shape, *, data_bytes=1024, datatype=np.int16):
    header = nibabel.Nifti1Header()
    header.set_data_dtype(datatype)
    header.set_data_shape(shape)
    header["vox_offset"] = 352
    header.set_sform(np.eye(4), code=1)
    with open(path, "wb") as fh:
        fh.write(header.binaryblock + bytes(4) + bytes(data_bytes))
    return path


def build_cases(root):
    """``{id: (argv, what the message must say)}`` over files made under ``root``."""
    folder = root / "data"
    folder.mkdir()
    (root / "secret.txt").write_bytes(b"password" * 8)
    cases = {}

    def render(path, *extra):
        return ["render", str(path), "--size", "16", "-o", str(root / "out.png"), *extra]

    def info(path, *extra):
        return ["info", str(path), *extra]

    # Reading outside the header's folder.
    cases["nhdr-parent"] = (info(_nhdr(folder, "a.nhdr", "../secret.txt")),
                            "outside the header's folder")
    cases["nhdr-deeper"] = (render(_nhdr(folder, "b.nhdr", "../../../../../etc/hostname")),
                            "outside the header's folder")
    cases["nhdr-absolute"] = (info(_nhdr(folder, "c.nhdr", str(root / "secret.txt"))),
                              "outside the header's folder")
    (folder / "link.raw").symlink_to(root / "secret.txt")
    cases["nhdr-symlink-out"] = (info(_nhdr(folder, "d.nhdr", "link.raw")),
                                 "outside the header's folder")
    (folder / "zero.raw").symlink_to("/dev/zero")
    cases["nhdr-dev-zero"] = (info(_nhdr(folder, "e.nhdr", "zero.raw")), "e.nhdr")
    os.mkfifo(folder / "fifo.raw")
    cases["nhdr-fifo"] = (info(_nhdr(folder, "f.nhdr", "fifo.raw")), "a FIFO")
    cases["volume-fifo"] = (info(folder / "fifo.raw", "--shape", "4,4,4", "--dtype",
                                 "uint8"), "a FIFO")
    cases["nhdr-several-files"] = (info(_nhdr(folder, "g.nhdr", "LIST")), "several files")

    # Memory: sizes claimed beyond memory, bombs, huge sparse files.
    # 256 MB of zeros in ~260 KB: 64 gzip members of 4 MB each (RFC 1952 lets members
    # follow one another; compressing 256 MB at once took the suite 1.9 s).
    bomb = gzip.compress(bytes(4 * 1024**2), compresslevel=9) * 64
    cases["nrrd-gzip-bomb"] = (info(_nrrd(folder, "bomb.nrrd", bomb, sizes="16 16 16",
                                          encoding="gzip")), "inflate to more than")
    cases["nrrd-claims-huge"] = (info(_nrrd(folder, "huge.nrrd", bytes(64),
                                            sizes="100000 100000 100000")), "GB in memory")
    _sparse(folder / "big.raw", 3 * 1024**3)
    cases["nhdr-sparse-3gb"] = (info(_nhdr(folder, "big.nhdr", "big.raw")),
                                "header claims 64")
    den_header = np.zeros(29, ">i2")
    den_header[[0, 25, 26, 27]] = (1, 4, 4, 4)
    _sparse(folder / "big.den", 3 * 1024**3,
            den_header.tobytes() + np.array([64], ">i4").tobytes())
    cases["den-sparse-3gb"] = (info(folder / "big.den"), "truncated?")
    cases["nifti-claims-32767"] = (info(_nifti_header(folder / "n1.nii", (32767,) * 3)),
                                   "after 352 header bytes): truncated?")
    gz = folder / "n3.nii.gz"
    gz.write_bytes(gzip.compress(_nifti_header(folder / "n3.nii", (32767,) * 3).read_bytes()))
    cases["nifti-gz-claims-32767"] = (info(gz), "GB in memory")
    cases["nifti-truncated"] = (info(_nifti_header(folder / "n2.nii", (600, 600, 600))),
                                "truncated?")
    (folder / "huge.vti").write_text(
        '<?xml version="1.0"?>\n<VTKFile type="ImageData" version="1.0">\n'
        '<ImageData WholeExtent="0 99999 0 99999 0 99999" Origin="0 0 0" Spacing="1 1 1">\n'
        '<Piece Extent="0 99999 0 99999 0 99999"><PointData Scalars="v">'
        '<DataArray type="Float32" Name="v" format="ascii">0 1 2</DataArray>'
        '</PointData></Piece></ImageData></VTKFile>\n')
    cases["vti-claims-huge"] = (info(folder / "huge.vti"), "GB in memory")
    with open(folder / "huge-honest.npy", "wb") as fh:  # a header claiming 4000^3 samples
        np.lib.format.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False,
                                                  "shape": (4000, 4000, 4000)})
        fh.write(bytes(8))
    cases["npy-claims-huge"] = (info(folder / "huge-honest.npy"), "huge-honest.npy")
    cases["raw-claims-huge"] = (info(_sparse(folder / "honest.raw", 40 * 1024**3), "--shape",
                                     "2560,4096,4096", "--dtype", "uint8"), "GB in memory")

    # Odd NIfTI headers: each a one-line refusal, none a traceback or a log line.
    def odd(name, change):
        image = nibabel.Nifti1Image(np.arange(64, dtype=np.int16).reshape(4, 4, 4), np.eye(4))
        change(image.header)
        (folder / name).write_bytes(image.header.binaryblock + bytes(4) + bytes(128))
        return folder / name

    def set_field(field, index, value):
        def change(header):
            if index is None:
                header[field] = value
            else:
                header[field][index] = value
        return change

    for name, change, says in (
            ("inter.nii", lambda h: (set_field("scl_slope", None, 1.0)(h),
                                     set_field("scl_inter", None, -np.inf)(h)),
             "invalid intercept"),
            ("offset.nii", set_field("vox_offset", None, -100), "vox offset"),
            ("type77.nii", set_field("datatype", None, 77), "data code 77"),
            ("dim8.nii", set_field("dim", 0, 8), "dim8.nii"),
            ("dimneg.nii", set_field("dim", 0, -3), "dimneg.nii"),
            ("negative.nii", set_field("dim", 2, -4), "negative.nii"),
            ("zeros.nii", lambda h: (h.set_sform(np.zeros((4, 4)), code=1),
                                     h.set_qform(None, code=0)), "zero length")):
        cases[f"nifti-{name}"] = (info(odd(name, change)), says)
    cases["turntable-frames"] = (["turntable", "gaussian-blob:9", "--frames", "1000000000",
                                  "-o", str(root / "spin.gif")], "frames must be at most")
    cases["field-count"] = (info("random-blobs:8:count=100000000000"),
                            "'random-blobs': count must be at most")

    np.save(folder / "keep.npy", np.ones((4, 4, 4)))

    # Corrupt files that VTK complains about in log lines: one line, VTK's words.
    (folder / "cut.vti").write_text(
        '<VTKFile type="ImageData"><ImageData WholeExtent="0 3 0 3 0 3"><Piece Extent="0 3 '
        '0 3 0 3"><PointData><DataArray type="Float32" Name="v" format="binary">AAAA')
    cases["vti-corrupt"] = (info(folder / "cut.vti"), "Error parsing XML")
    (folder / "short.vtk").write_text(
        "# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 4 4 4\n"
        "SPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 64\nSCALARS v float 1\n"
        "LOOKUP_TABLE default\n1 2 3\n")
    cases["vtk-ascii-short"] = (info(folder / "short.vtk"), "mismatch of datasize")
    np.save(folder / "vast.npy", np.array([0.0, 1e308, -1e308] * 9).reshape(3, 3, 3))
    cases["npy-values-overflow"] = (info(folder / "vast.npy"), "rescale them")
    (folder / "series" / "one").mkdir(parents=True)
    cases["dicom-sub-folders"] = (info(folder / "series"), "sub-folders are not searched")
    (folder / "scan.mha").write_bytes(b"ObjectType = Image\n")
    cases["unsupported-format"] = (info(folder / "scan.mha"), "vrlib does not read .mha")

    # Options that do not apply are refused, in the command line's own terms.
    cases["classified-method"] = (render("gaussian-blob:9", "--classified", "--method",
                                         "splat"), "leave out --method")
    cases["shape-on-npy"] = (info(folder / "keep.npy", "--shape", "4,4,4"),
                             "--shape applies to .raw files only")
    cases["empty-cmap"] = (render("gaussian-blob:9", "--cmap", ""), "--cmap needs")
    cases["python-words"] = (render("gaussian-blob:9", "--option",
                                    "classification=preintegrated", "--option",
                                    "segment_ends=lattice"), "use --option segment_ends=exact")

    # Silently wrong volumes.
    legacy = folder / "cut.vtk"
    legacy.write_bytes(b"# vtk DataFile Version 3.0\nvolume\nBINARY\nDATASET STRUCTURED_POINTS\n"
                       b"DIMENSIONS 8 8 8\nSPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 512\n"
                       b"SCALARS v float 1\nLOOKUP_TABLE default\n" + bytes(100))
    cases["vtk-truncated"] = (info(legacy), "truncated?")

    # Hangs, data loss and options.
    cases["step-tiny"] = (render("gaussian-blob:9", "--step", "1e-9"), "step must be at least")
    cases["output-is-input"] = (["render", str(folder / "keep.npy"), "--size", "8", "-o",
                                 str(folder / "keep.npy")], "is the input volume")
    (folder / "noise.npy").write_bytes(os.urandom(300))
    cases["npy-random-bytes"] = (info(folder / "noise.npy"), "the .npy signature")
    import tifffile

    tifffile.imwrite(folder / "wide.tif", np.zeros((2, 8, 8), np.uint8),
                     compression="zlib")
    raw = bytearray((folder / "wide.tif").read_bytes())
    for tag in (256, 257):  # ImageWidth and ImageLength claim 60000 on every page
        for at in range(len(raw) - 12):
            kind = int.from_bytes(raw[at + 2:at + 4], "little")
            if raw[at:at + 2] == tag.to_bytes(2, "little") and kind in (3, 4) and \
                    raw[at + 4:at + 8] == (1).to_bytes(4, "little"):
                raw[at + 8:at + 8 + (2 if kind == 3 else 4)] = (60000).to_bytes(
                    2 if kind == 3 else 4, "little")
    (folder / "wide.tif").write_bytes(bytes(raw))
    cases["tiff-claims-huge"] = (info(folder / "wide.tif"), "wide.tif")
    grid = folder / "nan.vti"
    grid.write_text(
        '<?xml version="1.0"?>\n<VTKFile type="ImageData" version="1.0">\n'
        '<ImageData WholeExtent="0 1 0 1 0 1" Origin="0 0 0" Spacing="nan 1 1">\n'
        '<Piece Extent="0 1 0 1 0 1"><PointData Scalars="v">'
        '<DataArray type="Float32" Name="v" format="ascii">0 1 2 3 4 5 6 7</DataArray>'
        '</PointData></Piece></ImageData></VTKFile>\n')
    cases["vti-nan-spacing"] = (info(grid), "must be 3 finite numbers")
    return cases


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    root = tmp_path_factory.mktemp("hostile")
    cases = build_cases(root)
    listing = root / "cases.json"
    listing.write_text(json.dumps([{"id": k, "argv": argv} for k, (argv, _) in cases.items()]))
    results = root / "results.json"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    subprocess.run([sys.executable, str(RUNNER), str(listing), str(results)], check=True,
                   env=env, timeout=600)
    return cases, json.loads(results.read_text()), root


CASE_IDS = ["nhdr-parent", "nhdr-deeper", "nhdr-absolute", "nhdr-symlink-out",
            "nhdr-dev-zero", "nhdr-fifo", "volume-fifo", "nhdr-several-files",
            "nrrd-gzip-bomb", "nrrd-claims-huge", "nhdr-sparse-3gb", "den-sparse-3gb",
            "nifti-claims-32767", "nifti-gz-claims-32767", "nifti-truncated", "vti-claims-huge",
            "npy-claims-huge",
            "raw-claims-huge", "vtk-truncated", "step-tiny", "output-is-input",
            "npy-random-bytes", "nifti-inter.nii", "nifti-offset.nii", "nifti-type77.nii",
            "nifti-dim8.nii", "nifti-dimneg.nii", "nifti-negative.nii", "nifti-zeros.nii",
            "turntable-frames", "field-count", "vti-corrupt", "vtk-ascii-short",
            "npy-values-overflow", "dicom-sub-folders", "unsupported-format",
            "classified-method", "shape-on-npy", "empty-cmap", "python-words",
            "tiff-claims-huge", "vti-nan-spacing"]


@pytest.mark.parametrize("case", CASE_IDS)
def test_hostile_file_is_refused_in_one_line(outcomes, case):
    cases, results, _ = outcomes
    argv, says = cases[case]
    result = results[case]
    lines = result["stderr"].strip().splitlines()
    assert result["status"] == 2, result
    assert len(lines) == 1 and lines[0].startswith("vrlib: error: "), result["stderr"]
    assert "Traceback" not in result["stderr"]
    assert says in lines[0], lines[0]
    named = [Path(a).name for a in argv[1:2]]  # the file the command was given
    assert any(name in lines[0] for name in named) or case in (
        "step-tiny", "turntable-frames", "field-count", "classified-method", "empty-cmap",
        "python-words"), lines[0]
    assert result["peak_growth_mb"] < PEAK_GROWTH_MB, result
    assert result["seconds"] < 20, result


def test_all_cases_are_checked(outcomes):
    assert sorted(outcomes[0]) == sorted(CASE_IDS)


def test_output_named_as_input_is_left_whole(outcomes):
    _, _, root = outcomes
    np.testing.assert_array_equal(np.load(root / "data" / "keep.npy"), np.ones((4, 4, 4)))


def test_secret_never_read(outcomes):
    """No refused file's message shows what the secret holds."""
    _, results, _ = outcomes
    assert all("password" not in r["stderr"] for r in results.values())


# -- orientation: applied exactly, or refused -------------------------------------------------

DATA = np.arange(4 * 5 * 6, dtype=np.int16).reshape(4, 5, 6)  # [z, y, x], asymmetric


def _write_nrrd(path, data_kji, directions, origin, space="right-anterior-superior"):
    nrrd.write(str(path), data_kji, {"space": space, "space directions": directions,
                                     "space origin": origin}, index_order="C")


def test_nrrd_negative_axis_is_flipped(tmp_path):
    """An x axis running towards -x: the loaded volume is the same world volume, its first
    sample the far one."""
    _write_nrrd(tmp_path / "v.nrrd", DATA[:, :, ::-1], np.diag([-2.0, 1.0, 1.0]),
                [10.0, 0.0, 0.0])
    vol = data_gen.load(tmp_path / "v.nrrd")
    np.testing.assert_array_equal(vol.data, DATA)
    np.testing.assert_allclose(vol.origin, [0.0, 0.0, 0.0])
    np.testing.assert_allclose(vol.spacing, [2.0, 1.0, 1.0])


def test_nrrd_swapped_axes_are_transposed(tmp_path):
    """Voxel axis i running along world y and j along x."""
    swapped = np.ascontiguousarray(DATA.transpose(0, 2, 1))  # [k, j, i] = [z, x, y]
    _write_nrrd(tmp_path / "v.nrrd", swapped, np.array([[0, 1.5, 0], [0.5, 0, 0], [0, 0, 1.0]]),
                [0.0, 0.0, 0.0])
    vol = data_gen.load(tmp_path / "v.nrrd")
    np.testing.assert_array_equal(vol.data, DATA)
    np.testing.assert_allclose(vol.spacing, [0.5, 1.5, 1.0])


def test_nrrd_lps_matches_nifti_ras(tmp_path):
    """The same scan as NRRD in LPS and NIfTI in RAS loads as one volume."""
    affine = np.diag([1.0, 2.0, 3.0, 1.0])
    affine[:3, 3] = [-5.0, -6.0, 7.0]
    nibabel.save(nibabel.Nifti1Image(DATA.transpose(2, 1, 0), affine), tmp_path / "v.nii")
    lps = np.diag([-1.0, -2.0, 3.0])  # the same axes, in LPS coordinates
    _write_nrrd(tmp_path / "v.nrrd", DATA, lps, [5.0, 6.0, 7.0],
                space="left-posterior-superior")
    ras, other = data_gen.load(tmp_path / "v.nii"), data_gen.load(tmp_path / "v.nrrd")
    np.testing.assert_array_equal(other.data, ras.data)
    np.testing.assert_allclose(other.extent, ras.extent)


def test_oblique_grids_are_refused_unless_asked(tmp_path):
    turn = np.eye(4)
    c, s = np.cos(0.3), np.sin(0.3)
    turn[:2, :2] = [[c, -s], [s, c]]
    nibabel.save(nibabel.Nifti1Image(DATA.transpose(2, 1, 0), turn), tmp_path / "o.nii")
    with pytest.raises(ValueError, match="oblique or sheared.*voxel-axes"):
        data_gen.load(tmp_path / "o.nii")
    assert data_gen.load(tmp_path / "o.nii", oblique="voxel-axes").shape == DATA.shape
    _write_nrrd(tmp_path / "o.nrrd", DATA, turn[:3, :3].T, [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="oblique or sheared"):
        data_gen.load(tmp_path / "o.nrrd")


def test_vti_direction_is_applied(tmp_path):
    import pyvista

    grid = pyvista.ImageData(dimensions=(6, 5, 4), spacing=(1.0, 1.0, 1.0))
    if not hasattr(grid, "direction_matrix"):
        pytest.skip("this VTK has no direction matrix")
    grid.direction_matrix = np.diag([-1.0, 1.0, 1.0])
    grid.point_data["v"] = DATA[:, :, ::-1].ravel()
    grid.save(tmp_path / "d.vti")
    vol = data_gen.load(tmp_path / "d.vti")
    np.testing.assert_array_equal(vol.data, DATA)
    np.testing.assert_allclose(vol.origin, [-5.0, 0.0, 0.0])


def test_mpi_sources_refuse_oblique_nifti_and_keep_byte_order(tmp_path):
    """The MPI ranks' file reader turns NIfTI files as the loader does (oblique refused,
    not dropped) and takes a raw dtype's byte order as the loader does."""
    from vrlib.parallel.sources import RawFile, memory_map

    turn = np.eye(4)
    turn[:2, :2] = [[np.cos(0.3), -np.sin(0.3)], [np.sin(0.3), np.cos(0.3)]]
    nibabel.save(nibabel.Nifti1Image(DATA.transpose(2, 1, 0), turn), tmp_path / "o.nii")
    with pytest.raises(ValueError, match="source o.nii: its voxel axes are oblique"):
        memory_map(tmp_path / "o.nii")
    np.arange(8, dtype=">i2").tofile(tmp_path / "v.raw")
    array, _, _ = memory_map(RawFile(tmp_path / "v.raw", (2, 2, 2), ">i2"))
    assert int(array[1, 1, 1]) == 7


def test_raw_dtype_names_its_byte_order(tmp_path):
    np.arange(8, dtype=">i2").tofile(tmp_path / "v.raw")
    vol = data_gen.load(tmp_path / "v.raw", shape=(2, 2, 2), dtype=">i2")
    assert float(vol.data[1, 1, 1]) == 7.0
    with pytest.raises(ValueError, match="give the byte order once"):
        data_gen.load_raw(tmp_path / "v.raw", (2, 2, 2), ">i2", byteorder="little")


# -- corrupted copies of good files -----------------------------------------------------------

def _good_files(folder):
    """One small good file of every format."""
    import pyvista
    import tifffile

    data = (np.arange(6 * 7 * 8) % 251).reshape(6, 7, 8).astype(np.int16)
    affine = np.diag([1.0, 2.0, 3.0, 1.0])
    np.save(folder / "v.npy", data)
    nibabel.save(nibabel.Nifti1Image(data.transpose(2, 1, 0), affine), folder / "v.nii")
    nibabel.save(nibabel.Nifti1Image(data.transpose(2, 1, 0), affine), folder / "v.nii.gz")
    nrrd.write(str(folder / "v.nrrd"), data, {"space directions": np.eye(3), "space": "RAS",
                                              "encoding": "raw"}, index_order="C")
    nrrd.write(str(folder / "g.nrrd"), data, {"encoding": "gzip"}, index_order="C")
    tifffile.imwrite(folder / "v.tif", data.astype(np.uint16), imagej=True)
    tifffile.imwrite(folder / "c.tif", data.astype(np.uint16), compression="zlib")
    grid = pyvista.ImageData(dimensions=(8, 7, 6))
    grid.point_data["v"] = data.ravel().astype(np.float32)
    grid.save(folder / "v.vti")
    grid.save(folder / "v.vtk")
    header = np.zeros(29, ">i2")
    header[[0, 25, 26, 27]] = (1, 8, 7, 6)
    (folder / "v.den").write_bytes(header.tobytes() + np.array([336], ">i4").tobytes()
                                   + (data % 256).astype(np.uint8).tobytes())
    return sorted(folder.iterdir())


@pytest.mark.slow  # 12 s: in make test-all
def test_corrupted_copies_of_every_format_never_raise(tmp_path):
    """Truncated, bit-flipped and overwritten copies of a good file of every format: each
    is read (a flip in the samples changes only values) or refused in one line naming it,
    never a traceback, a crash or a hang."""
    good, bad = tmp_path / "good", tmp_path / "bad"
    good.mkdir()
    bad.mkdir()
    rng = np.random.default_rng(0)
    cases = []
    for source in _good_files(good):
        raw = source.read_bytes()
        for i in range(9):
            copy = bytearray(raw)
            if i % 3 == 0:
                copy = copy[: int(rng.integers(1, len(copy)))]
            elif i % 3 == 1:
                for at in rng.integers(0, len(copy), 6):
                    copy[int(at)] = int(rng.integers(0, 256))
            else:
                at = int(rng.integers(0, min(len(copy), 400)))
                copy[at:at + 4] = rng.integers(0, 256, 4).astype(np.uint8).tobytes()
            path = bad / f"{source.name.split('.')[0]}-{i}{''.join(source.suffixes)}"
            path.write_bytes(bytes(copy))
            cases.append({"id": path.name, "argv": ["info", str(path)]})
    listing, results = tmp_path / "cases.json", tmp_path / "results.json"
    listing.write_text(json.dumps(cases))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    subprocess.run([sys.executable, str(RUNNER), str(listing), str(results)], check=True,
                   env=env, timeout=600)
    outcomes = json.loads(results.read_text())
    for name, result in outcomes.items():
        lines = result["stderr"].strip().splitlines()
        assert result["status"] in (0, 2), (name, result)
        if result["status"] == 2:
            assert len(lines) == 1 and lines[0].startswith("vrlib: error: "), (name, result)
            assert name in lines[0], (name, lines[0])
    assert sum(r["status"] == 2 for r in outcomes.values()) > len(outcomes) // 3
