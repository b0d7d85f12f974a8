"""Volume files of every format data_gen.load reads, each written by the format's own library,
the real volumes that ship inside installed packages, and the clear errors of bad files."""

import gzip

import nibabel
import nrrd
import numpy as np
import pytest
import pyvista
import tifffile

import data_gen
import vrlib
from data_gen.dicom import write_multiframe, write_series
from vrlib.parallel.sources import memory_map, open_source

DATA = np.random.default_rng(0).integers(0, 1000, (4, 5, 6)).astype(np.int16)  # [z, y, x]


def test_npy_and_raw_in_voxel_units(tmp_path):
    """Formats without a header: one world unit per voxel, from the origin."""
    np.save(tmp_path / "v.npy", DATA)
    vol = data_gen.load(tmp_path / "v.npy")
    np.testing.assert_array_equal(vol.data, DATA)
    np.testing.assert_allclose(vol.extent, [[0, 5], [0, 4], [0, 3]])
    (tmp_path / "v.raw").write_bytes(b"HEAD" + DATA.astype(">i2").tobytes())
    raw = data_gen.load(tmp_path / "v.raw", shape=(4, 5, 6), dtype="int16", byteorder="big",
                        offset=4, spacing=(1, 1, 2.5))
    np.testing.assert_array_equal(raw.data, DATA)
    np.testing.assert_allclose(raw.spacing, [1, 1, 2.5])


def _nifti(path, ijk, affine):
    nibabel.save(nibabel.Nifti1Image(ijk, affine), path)
    return path


def test_nifti_axes_spacing_and_origin(tmp_path):
    ijk = DATA.transpose(2, 1, 0).astype(np.float32)  # (i, j, k) = (x, y, z)
    affine = np.diag([2.0, 1.0, 3.0, 1.0])
    affine[:3, 3] = (-5, 10, 0)
    path = _nifti(tmp_path / "v.nii.gz", ijk, affine)
    with gzip.open(path) as fh:
        assert fh.read(4)  # a real gzip-compressed NIfTI
    vol = data_gen.load(path)
    np.testing.assert_array_equal(vol.data, DATA)
    np.testing.assert_allclose(vol.extent, [[-5, 5], [10, 14], [0, 9]])


def test_nifti_las_renders_as_its_ras_twin(tmp_path):
    """A file stored left-to-right (LAS: the affine flips x) holds the same head as its RAS
    twin; loaded, both give the same samples, box and image (not mirrored). The parallel
    renderer's memory map turns the file the same way."""
    ijk = DATA.transpose(2, 1, 0).astype(np.float32)
    ras = np.diag([2.0, 1.0, 1.0, 1.0])
    las = ras.copy()
    las[0, 0], las[0, 3] = -2.0, 10.0  # voxel i at x = 10 - 2 i: the same world points
    twin = _nifti(tmp_path / "ras.nii", ijk, ras)
    mirrored = _nifti(tmp_path / "las.nii", ijk[::-1].copy(), las)
    a, b = data_gen.load(twin), data_gen.load(mirrored)
    np.testing.assert_array_equal(a.data, b.data)
    np.testing.assert_allclose(a.extent, b.extent)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=16)
    np.testing.assert_array_equal(vrlib.render(a, view).rgba, vrlib.render(b, view).rgba)
    array, extent, _ = memory_map(mirrored)
    np.testing.assert_array_equal(np.asarray(array), a.data)
    np.testing.assert_allclose(extent, a.extent)
    lattice, read = open_source(str(mirrored), None, None)
    np.testing.assert_array_equal(read([(1, 3), (0, 5), (2, 6)]), a.data[1:3, :, 2:6])


def test_nifti_4d_takes_a_frame(tmp_path):
    frames = np.stack([DATA.transpose(2, 1, 0) + 1000 * t for t in range(3)], axis=-1)
    path = _nifti(tmp_path / "t.nii", frames.astype(np.float32), np.eye(4))
    np.testing.assert_array_equal(data_gen.load(path, frame=2).data, DATA + 2000)
    with pytest.raises(ValueError, match=r"holds 3 volumes \(4-D\): choose one with frame"):
        data_gen.load(path)
    with pytest.raises(ValueError, match=r"frame must be an integer 0..2"):
        data_gen.load(path, frame=3)


def test_nrrd_spacing_and_origin(tmp_path):
    path = str(tmp_path / "v.nrrd")
    header = {"space": "right-anterior-superior", "space origin": [1.0, 2.0, 3.0],
              "space directions": np.diag([0.5, 0.75, 2.0])}
    nrrd.write(path, DATA, header, index_order="C")
    vol = data_gen.load(path)
    np.testing.assert_array_equal(vol.data, DATA)
    np.testing.assert_allclose(vol.spacing, [0.5, 0.75, 2.0])
    np.testing.assert_allclose(vol.origin, [1, 2, 3])
    detached = str(tmp_path / "d.nhdr")
    nrrd.write(detached, DATA, {"spacings": [1.0, 2.0, 3.0]}, detached_header=True,
               index_order="C")
    np.testing.assert_array_equal(data_gen.load(detached).data, DATA)
    np.testing.assert_allclose(data_gen.load(detached).spacing, [1, 2, 3])


def test_gzip_nrrd_of_several_members_reads_whole(tmp_path):
    """A gzip-encoded NRRD whose data are two gzip members one after the other (valid gzip,
    what concatenating two .gz files makes) reads all of its samples; trailing bytes that
    are not a gzip member are refused as corrupt, not ignored."""
    raw = DATA.astype("<i2").tobytes()
    header = (f"NRRD0004\ntype: short\ndimension: 3\nsizes: {DATA.shape[2]} {DATA.shape[1]} "
              f"{DATA.shape[0]}\nendian: little\nencoding: gzip\n\n").encode()
    half = len(raw) // 2
    path = tmp_path / "two.nrrd"
    path.write_bytes(header + gzip.compress(raw[:half]) + gzip.compress(raw[half:]))
    np.testing.assert_array_equal(data_gen.load(path).data, DATA)
    path.write_bytes(header + gzip.compress(raw) + b"not gzip")
    with pytest.raises(ValueError, match="corrupt"):
        data_gen.load(path)


@pytest.mark.parametrize("compression", [None, "zlib"])
def test_tiff_stack(tmp_path, compression):
    """An ImageJ stack with its resolution and z spacing; uncompressed stacks are
    memory-mapped, compressed ones read."""
    path = tmp_path / "v.tif"
    tifffile.imwrite(path, DATA.astype(np.uint16), imagej=True, resolution=(4.0, 2.0),
                     metadata={"spacing": 3.0}, compression=compression)
    vol = data_gen.load(path)
    np.testing.assert_array_equal(vol.data, DATA)
    np.testing.assert_allclose(vol.spacing, [0.25, 0.5, 3.0])


def test_vtk_image_data_points_cells_and_legacy(tmp_path):
    grid = pyvista.ImageData(dimensions=(6, 5, 4), spacing=(0.5, 1.0, 2.0), origin=(1, 2, 3))
    grid.point_data["density"] = DATA.ravel().astype(np.float32)
    grid.save(tmp_path / "v.vti")
    grid.save(tmp_path / "v.vtk")
    for name in ("v.vti", "v.vtk"):
        vol = data_gen.load(tmp_path / name)
        np.testing.assert_array_equal(vol.data, DATA)
        np.testing.assert_allclose(vol.extent, [[1, 3.5], [2, 6], [3, 9]])
    cells = pyvista.ImageData(dimensions=(7, 6, 5), spacing=(1, 1, 1))
    cells.cell_data["labels"] = DATA.ravel()
    cells.save(tmp_path / "c.vti")
    vol = data_gen.load(tmp_path / "c.vti")  # one sample per cell, at the cell centres
    np.testing.assert_array_equal(vol.data, DATA)
    np.testing.assert_allclose(vol.origin, [0.5, 0.5, 0.5])


def test_dicom_series_sorted_scaled_and_spaced(tmp_path):
    """Slices named out of order are sorted by position; slope and intercept applied."""
    hounsfield = DATA.astype(np.float64) * 2 - 1024
    write_series(tmp_path, hounsfield, spacing=(0.7, 0.7, 2.5), origin=(-10, -20, 30),
                 slope=2.0, intercept=-1024.0, shuffle=True)
    vol = data_gen.load(tmp_path)
    np.testing.assert_array_equal(vol.data, hounsfield)
    np.testing.assert_allclose(vol.spacing, [0.7, 0.7, 2.5])
    np.testing.assert_allclose(vol.origin, [-10, -20, 30])


def test_dicom_multiframe_file_matches_its_series(tmp_path):
    """One enhanced CT file, its frames stored last plane first, loads as the series of the
    same planes does: sorted along the normal, rescaled, spaced."""
    hounsfield = DATA.astype(np.float64) * 2 - 1024
    write_series(tmp_path / "series", hounsfield, spacing=(0.7, 0.7, 2.5),
                 origin=(-10, -20, 30), slope=2.0, intercept=-1024.0)
    write_multiframe(tmp_path / "v.dcm", hounsfield, spacing=(0.7, 0.7, 2.5),
                     origin=(-10, -20, 30), slope=2.0, intercept=-1024.0, reverse=True)
    series, single = data_gen.load(tmp_path / "series"), data_gen.load(tmp_path / "v.dcm")
    np.testing.assert_array_equal(single.data, series.data)
    np.testing.assert_allclose(single.extent, series.extent)
    write_series(tmp_path / "one", DATA[:1])
    with pytest.raises(ValueError, match="holds one slice, not a volume"):
        data_gen.load(next((tmp_path / "one").iterdir()))


def _reorient(files, orientation, positions):
    """Rewrite a series' files with another ``ImageOrientationPatient`` and positions."""
    import pydicom

    for file, position in zip(sorted(files), positions, strict=True):
        ds = pydicom.dcmread(file)
        ds.ImageOrientationPatient = orientation
        ds.ImagePositionPatient = [float(v) for v in position]
        ds.save_as(file)


def test_dicom_patient_axes_are_turned_to_ras(tmp_path):
    """A series whose rows run along patient +x (LPS: towards the left) and columns along
    patient +y (posterior), as a scanner writes an axial series, loads as the RAS volume:
    flipped along x and y, its origin the RAS corner."""
    files = write_series(tmp_path, DATA, spacing=(0.5, 0.75, 2.0))
    _reorient(files, [1, 0, 0, 0, 1, 0], [(10.0, 20.0, 2.0 * z) for z in range(DATA.shape[0])])
    vol = data_gen.load(tmp_path)
    np.testing.assert_array_equal(vol.data, DATA[:, ::-1, ::-1])
    nz, ny, nx = DATA.shape
    np.testing.assert_allclose(vol.origin, [-10.0 - 0.5 * (nx - 1), -20.0 - 0.75 * (ny - 1),
                                            0.0])
    np.testing.assert_allclose(vol.spacing, [0.5, 0.75, 2.0])


def test_dicom_oblique_series_refused_unless_asked(tmp_path):
    files = write_series(tmp_path, DATA)
    c, s = np.cos(0.3), np.sin(0.3)
    _reorient(files, [c, s, 0.0, -s, c, 0.0], [(0.0, 0.0, float(z)) for z in
                                                range(DATA.shape[0])])
    with pytest.raises(ValueError, match="oblique or sheared.*voxel-axes"):
        data_gen.load(tmp_path)
    assert data_gen.load(tmp_path, oblique="voxel-axes").shape == DATA.shape


def test_dicom_bad_series(tmp_path):
    write_series(tmp_path / "two", DATA, series_uid="1.2.3.4")
    write_series(tmp_path / "two", DATA[:, :4], series_uid="1.2.3.5", prefix="other")
    with pytest.raises(ValueError, match="holds 2 DICOM series: choose one with series="):
        data_gen.load(tmp_path / "two")
    assert data_gen.load(tmp_path / "two", series="3.5").shape == (4, 4, 6)
    files = write_series(tmp_path / "gap", DATA)
    files[2].unlink()
    with pytest.raises(ValueError, match="unevenly spaced .* missing slices"):
        data_gen.load(tmp_path / "gap")
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.txt").write_text("not a slice")
    with pytest.raises(ValueError, match="no DICOM slices"):
        data_gen.load(tmp_path / "empty")


def test_den_both_byte_orders(tmp_path):
    for order in (">", "<"):
        header = np.zeros(29, order + "i2")
        header[[0, 25, 26, 27]] = (1, 6, 5, 4)
        path = tmp_path / f"v{order == '<'}.den"
        path.write_bytes(header.tobytes() + np.array([120], order + "i4").tobytes()
                         + DATA.astype(np.uint8).tobytes())
        np.testing.assert_array_equal(data_gen.load(path).data, DATA.astype(np.uint8))


def test_named_real_volumes():
    """The real volumes that ship inside installed packages, in their own units."""
    frog = data_gen.load("frog")
    assert frog.shape == (136, 470, 500) and frog.value_range == (0.0, 29.0)
    np.testing.assert_allclose(frog.spacing, [1.0, 1.0, 1.5])
    aniso = data_gen.load("aniso")
    assert aniso.shape == (24, 58, 58)
    np.testing.assert_allclose(aniso.spacing, [4, 4, 5], rtol=1e-6)  # anisotropic voxels
    mni = data_gen.load("mni152")
    assert mni.shape == (95, 117, 99)
    np.testing.assert_allclose(mni.spacing, [2, 2, 2])
    assert mni.value_range[1] > 0.5 and np.count_nonzero(mni.data) > mni.data.size // 4
    try:
        brain = data_gen.load("brainsmall")
    except ImportError as error:
        pytest.skip(str(error))
    assert brain.shape == (84, 128, 128) and brain.value_range[1] > 100


def test_a_volume_in_its_own_units_renders_framed():
    """The frog (world box 0..499) seen from angles alone: the view frames it, so the image
    is not empty; a view framed elsewhere says why it is."""
    frog = data_gen.load("frog")
    coarse = vrlib.Volume(frog.data[::8, ::8, ::8], spacing=frog.spacing * 8)
    img = vrlib.render(coarse, vrlib.View.orbit(azimuth=30, elevation=20, size=24),
                       transfer=vrlib.Glow(0.01))
    assert img.alpha[12, 12] > 0.1 and img.alpha[0, 0] == 0.0
    with pytest.warns(vrlib.EmptyImageWarning, match="lies outside the view"):
        vrlib.render(coarse, vrlib.View.orbit(size=8, center=(0, -900, 0), radius=2.0))
    with pytest.warns(vrlib.EmptyImageWarning, match="transparent over all"):
        vrlib.render(coarse, vrlib.View.orbit(size=8),
                     transfer=vrlib.LookupTransfer([0, 0, 1], value_range=(0, 100)))


@pytest.mark.parametrize("name, content, message", [
    ("v.nii", b"\x5c\x01" + bytes(100), "not a readable NIfTI file"),
    ("v.nrrd", b"NRRD0004\ntype: short\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n"
     b"endian: little\n\n" + bytes(10), "holds 10 sample bytes, but its header claims 128"),
    ("v.tif", b"II*\x00" + bytes(4), "not a readable TIFF file"),
    ("v.vti", b"<VTKFile type='ImageData'>", "VTK"),
    ("v.den", bytes(30), "shorter than its 62-byte header"),
    ("v.npy", b"\x93NUMPY garbage", "not a readable .npy file"),
    ("v.xyz", b"", "cannot tell the format"),
])
def test_corrupt_files_say_so(tmp_path, name, content, message):
    (tmp_path / name).write_bytes(content)
    with pytest.raises(ValueError, match=message):
        data_gen.load(tmp_path / name)


def test_truncated_files_say_so(tmp_path):
    path = _nifti(tmp_path / "t.nii", DATA.astype(np.float32), np.eye(4))
    path.write_bytes(path.read_bytes()[:-40])
    with pytest.raises(ValueError, match=r"t.nii holds .* after 352 header bytes\): truncated"):
        data_gen.load(path)
    header = np.zeros(29, ">i2")
    header[[0, 25, 26, 27]] = (1, 6, 5, 4)
    (tmp_path / "t.den").write_bytes(header.tobytes() + np.array([120], ">i4").tobytes()
                                     + bytes(100))
    with pytest.raises(ValueError, match="truncated"):
        data_gen.load(tmp_path / "t.den")
    with pytest.raises(FileNotFoundError, match="no volume file"):
        data_gen.load(tmp_path / "missing.npy")


def test_real_files_that_dependencies_ship():
    """Files written by other software, not by this test: pyvista's legacy structured points
    (uniform.vtk) and its cell-data image (channels.vti, 250x250x100 cells), and
    scikit-image's multi-page TIFF. (No DICOM series or NRRD volume ships in a wheel.)"""
    from pathlib import Path

    import skimage

    examples = Path(pyvista.__file__).parent / "examples"
    uniform = data_gen.load(examples / "uniform.vtk")
    assert uniform.shape == (10, 10, 10) and uniform.value_range == (0.0, 729.0)
    channels = data_gen.load(examples / "channels.vti")
    assert channels.shape == (100, 250, 250)
    np.testing.assert_allclose(channels.origin, [0.5, 0.5, 0.5])  # cell centres
    stack = data_gen.load(Path(skimage.__file__).parent / "data" / "multipage.tif")
    assert stack.shape == (2, 15, 10)
    np.testing.assert_array_equal(stack.data, tifffile.imread(
        Path(skimage.__file__).parent / "data" / "multipage.tif"))


def test_masks_and_memory_maps(tmp_path):
    """Boolean masks load as 0 and 1; an uncompressed float32 file stays memory-mapped
    (its samples are not copied into memory)."""
    mask = DATA > 500
    np.save(tmp_path / "mask.npy", mask)
    np.testing.assert_array_equal(data_gen.load(tmp_path / "mask.npy").data, mask)

    def mapped(array):
        while array is not None and not isinstance(array, np.memmap):
            array = getattr(array, "base", None)
        return array is not None

    np.save(tmp_path / "f.npy", DATA.astype(np.float32))
    assert mapped(data_gen.load(tmp_path / "f.npy").data)
    _nifti(tmp_path / "f.nii", DATA.transpose(2, 1, 0).astype(np.float32), np.eye(4))
    vol = data_gen.load(tmp_path / "f.nii")
    np.testing.assert_array_equal(vol.data, DATA)
    assert mapped(vol.data)


@pytest.mark.slow  # a float64 kernel per method to compile; ch10 measures the same on make all
def test_anisotropic_voxels_in_every_method():
    """dipy's 4 x 4 x 5 mm volume: every method agrees with a fine ray cast of the same box,
    and the box matters (the same samples on cubic voxels give a visibly different image)."""
    aniso = data_gen.load("aniso")
    view = vrlib.View.orbit(azimuth=120, elevation=20, size=32)
    transfer = vrlib.auto_transfer(aniso)
    fine = vrlib.render(aniso, view, transfer=transfer, step=0.125, early_termination=1.0)
    for method in vrlib.METHODS:
        image = vrlib.render(aniso, view, method=method, transfer=transfer)
        assert vrlib.metrics.rmse(image, fine) < 0.02, method  # measured 1e-3 .. 1e-2
    cubic = vrlib.Volume(aniso.data, spacing=(4, 4, 4))
    assert vrlib.metrics.rmse(vrlib.render(cubic, view, transfer=transfer), fine) > 0.03  # 0.05


def test_each_loader_names_the_files_sample_type(tmp_path):
    """``Volume.file_dtype`` is the type the file stores (before any scaling), which
    ``vrlib info`` prints beside the type held in memory."""
    from vrlib.cli import describe_volume

    big = DATA.astype(">i2")
    np.save(tmp_path / "v.npy", big)
    scaled = nibabel.Nifti1Image(np.ascontiguousarray(DATA.transpose(2, 1, 0)), np.eye(4))
    scaled.header.set_slope_inter(0.5, 10.0)
    nibabel.save(scaled, tmp_path / "v.nii")
    nrrd.write(str(tmp_path / "v.nrrd"), DATA, index_order="C")
    tifffile.imwrite(tmp_path / "v.tif", DATA.astype(np.uint16), imagej=True)
    grid = pyvista.ImageData(dimensions=(6, 5, 4))
    grid.point_data["v"] = DATA.ravel()
    grid.save(tmp_path / "v.vti")
    (tmp_path / "series").mkdir()
    write_series(tmp_path / "series", DATA.astype(np.float64) * 2 - 1024, slope=2.0,
                 intercept=-1024.0)
    big.tofile(tmp_path / "v.raw")
    found = {name: data_gen.load(tmp_path / name).file_dtype.name
             for name in ("v.npy", "v.nii", "v.nrrd", "v.tif", "v.vti", "series")}
    found["v.raw"] = data_gen.load(tmp_path / "v.raw", shape=DATA.shape,
                                   dtype=">i2").file_dtype.name
    assert found == {"v.npy": "int16", "v.nii": "int16", "v.nrrd": "int16", "v.tif": "uint16",
                     "v.vti": "int16", "series": "int16", "v.raw": "int16"}
    assert data_gen.load(tmp_path / "v.nii").dtype == np.float64  # scaled on reading
    first = describe_volume(data_gen.load(tmp_path / "v.npy"))[0]
    assert first == ("shape (z, y, x): (4, 5, 6), stored in the file as int16, big-endian, "
                     "held in memory as float32")
    assert "stored in the file" not in describe_volume(vrlib.Volume(DATA))[0]
