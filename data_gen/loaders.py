"""Loaders for volume files: ``.npy``, raw, NIfTI, NRRD, TIFF stacks, VTK image data, DICOM
series and VolPack's ``.den``; :func:`load` tells them apart.

Every loader returns a :class:`vrlib.Volume` with data ``[z, y, x]`` in the file's own units:
the voxel spacing and origin its header gives (millimetres for medical formats), or one unit
per voxel from the origin where the format has no header (``.npy``, raw). Views built from
angles alone frame any volume (:meth:`vrlib.View.fitted`), so no rescaling is needed; pass
``extent`` (e.g. :func:`fitted_extent`) to place a volume in another box.

Every loader takes ``nan="transparent"`` to read NaN samples as holes (:mod:`vrlib.holes`);
by default a file with NaN samples is refused.

Orientation is applied exactly or refused: NIfTI and NRRD volumes are turned to RAS+ by the
flips and axis swaps their affine or space directions ask for (a LAS or LPS file renders as
its RAS twin); an oblique or sheared grid is refused with a message, not rendered as a
guess. DICOM slices are ordered along their normal.

Files are untrusted (:mod:`data_gen.untrusted`): only regular files are read, a detached
data file must lie in its header's folder, and every size a header claims is checked against
the file's length and the memory available before anything is allocated.
"""

from __future__ import annotations

import contextlib
import logging
import math
import re
from pathlib import Path

import numpy as np

from data_gen.untrusted import axis_aligned, check_allocation, regular_file, to_world_axes
from vrlib import validate
from vrlib.volume import Volume, fitted_extent

__all__ = ["load", "load_npy", "load_nifti", "load_raw", "load_nrrd", "load_tiff", "load_vtk",
           "load_dicom", "load_dicom_file", "load_den", "fitted_extent", "nifti_orientation",
           "nifti_volume", "raw_dtype", "FORMATS", "OBLIQUE"]


def _existing(path):
    """``path`` if it names a regular file (not a FIFO or device, which could block a read
    or never end)."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no volume file at {str(path)!r}")
    return regular_file(path)


@contextlib.contextmanager
def _quiet(library):
    """A library's log lines held back while it reads: its complaints become the loader's
    one-line errors."""
    logger = logging.getLogger(library)
    level = logger.level
    logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        logger.setLevel(level)


# Messages from the libraries' parsers that mean the bytes ran out or make no sense.
_CORRUPT = re.compile(r"unpack requires|not enough values to unpack|division or modulo by "
                      r"zero|mmap length|out of range|cannot reshape|cannot be reshaped|"
                      r"^Expected \d+ bytes|StopIteration|EOF|truncated|Error -\d while "
                      r"decompressing", re.IGNORECASE)


def _unreadable(path, kind, error):
    """The one-line error for a file its library cannot read, its words kept, and what a
    low-level one means said first."""
    text = str(error).splitlines()[0] if str(error) else type(error).__name__
    if _CORRUPT.search(text) or isinstance(error, StopIteration | EOFError):
        text = f"it is truncated or corrupt ({text})"
    return ValueError(f"{Path(path).name} is not a readable {kind} file: {text}")


def _volume(data, extent, spacing, origin, nan, file_dtype=None):
    """A volume with ``extent`` if given, else ``spacing`` and ``origin`` (defaults 1, 0);
    ``file_dtype`` the file's sample type, default the type of ``data`` as read."""
    file_dtype = np.asarray(data).dtype if file_dtype is None else file_dtype
    if np.asarray(data).dtype == np.bool_:  # a mask: 0 and 1
        data = np.asarray(data, dtype=np.uint8)
    if extent is not None:
        return Volume(data, extent, nan=nan, copy=False, file_dtype=file_dtype)
    return Volume(data, spacing=(1.0, 1.0, 1.0) if spacing is None else spacing,
                  origin=(0.0, 0.0, 0.0) if origin is None else origin, nan=nan, copy=False,
                  file_dtype=file_dtype)


def load_npy(path, *, spacing=None, origin=None, extent=None, nan="error"):
    """Load a 3-D ``.npy`` array stored ``[z, y, x]`` (memory-mapped while it is checked).

    Parameters
    ----------
    spacing, origin : array_like of 3 floats, optional
        Voxel size and position of the first sample, ``(x, y, z)``; default 1 and 0.
    extent : array_like, shape (3, 2), optional
        The world box instead.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.npy"
    >>> np.save(f, np.zeros((2, 3, 4), dtype=np.uint8))
    >>> vol = load_npy(f)
    >>> vol.shape, vol.extent.tolist()
    ((2, 3, 4), [[0.0, 3.0], [0.0, 2.0], [0.0, 1.0]])
    """
    path = _existing(path)
    with open(path, "rb") as fh:
        magic = fh.read(6)
    if magic != b"\x93NUMPY":
        raise _unreadable(path, ".npy", "it does not start with the .npy signature")
    try:
        data = np.load(path, mmap_mode="r", allow_pickle=False)
    except Exception as error:  # numpy's header parser raises several kinds
        text = str(error)
        if "pickle" in text.lower():
            text = "it holds Python objects, not a numeric array"
        raise _unreadable(path, ".npy", text) from None
    if not isinstance(data, np.ndarray) or data.dtype.kind not in "biuf":
        raise ValueError(f"{path.name} is not a readable .npy file: it holds "
                         f"{getattr(data, 'dtype', type(data).__name__)}, not real numbers")
    check_allocation(data.size, data.dtype, path.name)
    return _volume(data, extent, spacing, origin, nan)


def raw_dtype(dtype, byteorder=None):
    """The sample type of headerless samples: ``dtype`` in the byte order ``byteorder``
    names, else the one ``dtype`` names (``">i2"``: big), else little; a ``byteorder`` that
    contradicts ``dtype``'s is refused.

    Examples
    --------
    >>> raw_dtype(">i2").str, raw_dtype("int16", "big").str, raw_dtype("float32").str
    ('>i2', '>i2', '<f4')
    """
    try:
        dt = np.dtype(dtype)
    except TypeError:
        raise ValueError(f"dtype must be a numpy sample type (uint8, int16, float32, ...), "
                         f"got {dtype!r}") from None
    if dt.kind not in "biuf":
        raise ValueError(f"dtype must be a numpy sample type (uint8, int16, float32, ...), "
                         f"got {dtype!r}")
    named = {">": "big", "<": "little"}.get(str(dtype).strip()[:1]) if isinstance(
        dtype, str) else None
    if byteorder is not None:
        validate.choice("byteorder", byteorder, ("little", "big"))
        if named is not None and named != byteorder and dt.itemsize > 1:
            raise ValueError(f"dtype {dtype!r} is {named}-endian but byteorder={byteorder!r}: "
                             "give the byte order once")
    order = byteorder or named or "little"
    return dt.newbyteorder("<" if order == "little" else ">")


def load_raw(path, shape, dtype, *, byteorder=None, offset=0, spacing=None, origin=None,
             extent=None, nan="error"):
    """Load headerless samples of ``shape = (nz, ny, nx)`` and ``dtype``, x varying fastest.

    Parameters
    ----------
    byteorder : {"little", "big"}, optional
        The samples' byte order; default the one ``dtype`` names (``">i2"``: big), else
        little. A ``byteorder`` that contradicts ``dtype``'s is refused.
    offset : int
        Bytes to skip at the start (a header).
    spacing, origin, extent
        As :func:`load_npy`.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.raw"
    >>> np.arange(8, dtype=">u2").tofile(f)
    >>> float(load_raw(f, (2, 2, 2), "uint16", byteorder="big").data[1, 1, 1])
    7.0
    """
    path = _existing(path)
    shape = tuple(validate.positive_int("shape", n, minimum=2) for n in shape)
    if len(shape) != 3:
        raise ValueError(f"shape must be (nz, ny, nx), got {shape!r}")
    dt = raw_dtype(dtype, byteorder)
    offset = validate.positive_int("offset", offset, minimum=0)
    expected = offset + math.prod(shape) * dt.itemsize
    actual = path.stat().st_size
    if actual != expected:
        raise ValueError(
            f"raw file holds {actual} bytes, but shape {shape} of {dt.name} after {offset} "
            f"header bytes needs {expected}"
        )
    check_allocation(math.prod(shape), dt, path.name)
    data = np.memmap(path, dtype=dt, mode="r", offset=offset, shape=shape)
    return _volume(data, extent, spacing, origin, nan)


#: What a loader does with an oblique or sheared grid (``oblique=``).
OBLIQUE = ("refuse", "voxel-axes")


def nifti_orientation(image, *, oblique="refuse", name="NIfTI image"):
    """How a NIfTI image's voxel axes turn to RAS+: ``(ornt, spacing, origin)``.

    ``ornt`` is nibabel's orientation array (apply it with
    ``nibabel.orientations.apply_orientation`` to ``(i, j, k)`` data); ``spacing`` and
    ``origin`` are the RAS+ voxel sizes and the position of the reoriented first voxel, in
    the file's units (mm). An affine that is not finite, or (unless ``oblique="voxel-axes"``,
    which takes each voxel axis on its closest world axis) not a signed permutation of the
    world axes, is refused, naming ``name``: every reader of NIfTI files turns them here.

    Examples
    --------
    >>> import nibabel
    >>> las = np.diag([-2.0, 1.0, 1.0, 1.0]); las[0, 3] = 10.0      # x = 10 - 2 i
    >>> ornt, spacing, origin = nifti_orientation(nibabel.Nifti1Image(np.zeros((6, 2, 2)), las))
    >>> ornt.tolist(), spacing.tolist(), origin.tolist()
    ([[0.0, -1.0], [1.0, 1.0], [2.0, 1.0]], [2.0, 1.0, 1.0], [0.0, 0.0, 0.0])
    """
    import nibabel
    from nibabel import orientations

    validate.choice("oblique", oblique, OBLIQUE)
    affine = np.asarray(image.affine, dtype=np.float64)
    if not np.all(np.isfinite(affine)):
        raise ValueError(f"{name}: its affine is not finite: {affine[:3].tolist()}")
    if oblique == "refuse":
        axis_aligned(affine[:3, :3].T, name)
    shape = image.shape[:3]
    ornt = orientations.io_orientation(affine)
    transform = orientations.inv_ornt_aff(ornt, shape)
    canonical = affine @ transform
    spacing = np.asarray(nibabel.affines.voxel_sizes(canonical), dtype=np.float64)
    return ornt, spacing, canonical[:3, 3].copy()


def load_nifti(path, *, frame=None, extent=None, nan="error", oblique="refuse"):
    """Load a NIfTI volume (``.nii``, ``.nii.gz``) through nibabel, turned to RAS+.

    Voxel axes become ``(x, y, z)`` = (right, anterior, superior) after the flips and swaps
    the affine asks for (:func:`nifti_orientation`), so a left-to-right (LAS) file renders as
    its RAS twin, not mirrored; the voxel sizes and origin come from the affine (mm).
    Scaling (slope, intercept) is applied.

    Parameters
    ----------
    frame : int, optional
        The volume to take from a 4-D file (a time series); required there.
    extent : array_like, shape (3, 2), optional
        The world box instead of the affine's.
    oblique : {"refuse", "voxel-axes"}
        An affine that is not a signed permutation of the world axes (an oblique or
        sheared acquisition) is refused, unless ``"voxel-axes"``: then the voxel grid is
        rendered on its closest world axes with its voxel sizes and the rotation left out
        (the image shows the scan in its own axes, not in world space).

    Examples
    --------
    >>> import nibabel, tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.nii.gz"
    >>> affine = np.diag([2.0, 1.0, 1.0, 1.0])
    >>> nibabel.save(nibabel.Nifti1Image(np.zeros((5, 3, 2), np.float32), affine), f)
    >>> vol = load_nifti(f)
    >>> vol.shape, vol.extent[0].tolist()
    ((2, 3, 5), [0.0, 8.0])
    """
    import nibabel

    path = _existing(path)
    with _quiet("nibabel"):
        try:
            image = nibabel.load(path)
        except Exception as error:  # nibabel raises many kinds on a corrupt header
            raise _unreadable(path, "NIfTI", error) from None
        _check_nifti_size(image, path)
        return nifti_volume(image, path.name, frame=frame, extent=extent, nan=nan,
                            oblique=oblique)


def _check_nifti_size(image, path):
    """Refuse a NIfTI header whose samples would not fit in memory, or (uncompressed) in the
    file, before any is read."""
    header = image.header
    try:
        shape = tuple(int(n) for n in image.shape)
        dtype = np.dtype(header.get_data_dtype())
        # the loaded image's header is a copy with its offset reset; the data's proxy keeps it
        offset = int(getattr(image.dataobj, "offset", header.get_data_offset()))
    except Exception as error:
        raise _unreadable(path, "NIfTI", error) from None
    if len(shape) < 3 or min(shape) < 1 or offset < 0:
        raise ValueError(f"{path.name} is not a readable NIfTI file: shape {shape}, data "
                         f"offset {offset}")
    if not path.name.lower().endswith(".gz"):
        needed = offset + math.prod(shape) * dtype.itemsize
        if path.stat().st_size < needed:
            raise ValueError(f"{path.name} holds {path.stat().st_size} bytes, but its header "
                             f"claims {needed} ({'x'.join(map(str, shape))} of {dtype.name} "
                             f"after {offset} header bytes): truncated?")
    check_allocation(math.prod(shape[:3]), dtype, path.name)


def nifti_volume(image, name, *, frame=None, extent=None, nan="error", oblique="refuse"):
    """The volume of a loaded nibabel image (as :func:`load_nifti`; ``name`` for messages).

    Examples
    --------
    >>> import nibabel
    >>> image = nibabel.Nifti1Image(np.zeros((4, 3, 2), np.float32), np.diag([3, 2, 1, 1]))
    >>> nifti_volume(image, "in memory").spacing.tolist()
    [3.0, 2.0, 1.0]
    """
    from nibabel import orientations

    validate.choice("oblique", oblique, OBLIQUE)
    shape = tuple(int(n) for n in image.shape)
    if len(shape) not in (3, 4):
        raise ValueError(f"{name}: a NIfTI volume must be 3-D (or 4-D with frame=), got "
                         f"shape {shape}")
    if len(shape) == 3 and frame not in (None, 0):
        raise ValueError(f"frame: {name} is 3-D, it has no frame {frame}")
    proxy = image.dataobj
    scaled = getattr(proxy, "slope", 1.0) != 1.0 or getattr(proxy, "inter", 0.0) != 0.0
    try:
        # Unscaled samples keep their type (an uncompressed file stays memory-mapped).
        data = np.asarray(proxy[..., _frame(name, shape, frame)] if len(shape) == 4
                          else proxy, dtype=np.float64 if scaled else None)
    except Exception as error:  # nibabel's proxies raise many kinds on corrupt data
        if str(error).startswith("frame"):
            raise
        raise ValueError(f"{name} is not a readable NIfTI file: {error}") from None
    try:
        ornt, spacing, origin = nifti_orientation(image, oblique=oblique, name=name)
    except ValueError as error:
        raise _oblique_hint(error) from None
    data = orientations.apply_orientation(data, ornt)
    data = np.ascontiguousarray(data.transpose(2, 1, 0))  # (i, j, k) -> [z, y, x]
    return _volume(data, extent, spacing, origin, nan, image.get_data_dtype())


def _frame(name, shape, frame):
    """The frame to take from a 4-D image of ``shape``, checked."""
    if frame is None:
        if shape[3] == 1:
            return 0
        raise ValueError(f"frame: {name} holds {shape[3]} volumes (4-D): choose one with "
                         f"frame=0..{shape[3] - 1} (--frame on the command line)")
    if not isinstance(frame, int | np.integer) or not 0 <= frame < shape[3]:
        raise ValueError(f"frame must be an integer 0..{shape[3] - 1} for {name}, got "
                         f"{frame!r}")
    return int(frame)


def load_nrrd(path, *, extent=None, nan="error"):
    """Load an NRRD file (``.nrrd``, or ``.nhdr`` with its data file in the same folder or
    below it) with every size its header claims checked first
    (:func:`data_gen.nrrd_files.read_nrrd`).

    Spacing and orientation from ``space directions`` (flips and axis swaps applied, LPS and
    LAS turned to RAS, oblique grids refused) or ``spacings``; origin from ``space origin``.

    Examples
    --------
    >>> import nrrd, tempfile, pathlib
    >>> f = str(pathlib.Path(tempfile.mkdtemp()) / "v.nrrd")
    >>> nrrd.write(f, np.zeros((4, 3, 2), np.int16), {"spacings": [0.5, 1.0, 2.0]})
    >>> vol = load_nrrd(f)
    >>> vol.shape, vol.spacing.tolist()
    ((2, 3, 4), [0.5, 1.0, 2.0])
    """
    from data_gen.nrrd_files import read_nrrd

    data, spacing, origin = read_nrrd(_existing(path))
    return _volume(data, extent, spacing, origin, nan)


def load_tiff(path, *, spacing=None, extent=None, nan="error"):
    """Load a TIFF stack (one page per z slice, or an ImageJ hyperstack of one channel)
    through tifffile, memory-mapped when the file is uncompressed.

    ImageJ's ``spacing`` (z) and the resolution tags (x, y) give the voxel size when
    ``spacing`` is not passed.

    Examples
    --------
    >>> import tifffile, tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.tif"
    >>> tifffile.imwrite(f, np.zeros((3, 4, 5), np.uint16), imagej=True,
    ...                  resolution=(2.0, 2.0), metadata={"spacing": 1.5})
    >>> vol = load_tiff(f)
    >>> vol.shape, vol.spacing.tolist()
    ((3, 4, 5), [0.5, 0.5, 1.5])
    """
    import tifffile

    path = _existing(path)
    try:
        with _quiet("tifffile"), tifffile.TiffFile(path) as tif:
            if not tif.series or not len(tif.pages):
                raise ValueError("it holds no images")
            series = tif.series[0]
            check_allocation(math.prod(series.shape), series.dtype, path.name)
            found = _tiff_spacing(tif)
            try:
                data = tifffile.memmap(path)
            except (ValueError, OSError):  # compressed or scattered pages: read them
                data = series.asarray()
    except Exception as error:  # tifffile raises TiffFileError, ValueError and others
        if str(error).startswith(f"{path.name}:"):
            raise
        raise _unreadable(path, "TIFF", error) from None
    data = np.squeeze(data)
    if data.ndim != 3:
        raise ValueError(f"{path.name} must hold a 3-D stack of one channel, got shape "
                         f"{data.shape} (axes {series.axes})")
    return _volume(data, extent, found if spacing is None else spacing, None, nan)


def _tiff_spacing(tif):
    """(x, y, z) voxel size from the resolution tags and ImageJ's spacing, or None."""
    page = tif.pages[0]
    z = (tif.imagej_metadata or {}).get("spacing")
    tags = page.tags
    if "XResolution" not in tags or "YResolution" not in tags or z is None:
        return None
    (xn, xd), (yn, yd) = tags["XResolution"].value, tags["YResolution"].value
    if not (xn and yn):
        return None
    return (xd / xn, yd / yn, float(z))


def load_vtk(path, *, scalars=None, extent=None, nan="error"):
    """Load VTK image data (``.vti``, or a legacy ``.vtk`` of structured points) through
    pyvista: its point scalars, origin and spacing.

    Data on cells (one value per voxel, e.g. a label volume written as cell data) becomes a
    lattice of the cell centres, one sample per cell, shifted by half a cell.

    Parameters
    ----------
    scalars : str, optional
        The array to take (point or cell data); default the active scalars.

    Examples
    --------
    >>> import pyvista, tempfile, pathlib
    >>> grid = pyvista.ImageData(dimensions=(4, 3, 2), spacing=(0.5, 1, 2), origin=(1, 0, 0))
    >>> grid.point_data["v"] = np.arange(24.0)
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.vti"
    >>> grid.save(f)
    >>> load_vtk(f).extent.tolist()
    [[1.0, 2.5], [0.0, 2.0], [0.0, 2.0]]
    """
    import pyvista
    from pyvista.core.utilities.observers import VtkErrorCatcher

    path = _existing(path)
    _check_vtk_claims(path)
    try:
        # VTK's complaints become this loader's one-line error, not log lines.
        with _quiet("root"), pyvista.vtk_verbosity("off"), VtkErrorCatcher(
                raise_errors=True, send_to_logging=False):
            grid = pyvista.read(path)
    except Exception as error:  # VTK readers raise many kinds, or return an empty dataset
        # VTK's own words, without its source file and object address.
        lines = [re.sub(r"^\w+ \(0x[0-9a-f]+\): ", "", line.strip())
                 for line in str(error).splitlines()
                 if line.strip() and not line.startswith("ERROR: In ")]
        raise _unreadable(path, "VTK", lines[0] if lines else error) from None
    if not isinstance(grid, pyvista.ImageData) or grid.n_points == 0:
        raise ValueError(f"{path.name} must hold VTK image data (a regular grid), got "
                         f"{type(grid).__name__} with {grid.n_points} points")
    points, cells = list(grid.point_data.keys()), list(grid.cell_data.keys())
    name = scalars if scalars is not None else grid.active_scalars_name or (
        points[0] if points else cells[0] if cells else None)
    if name is None:
        raise ValueError(f"{path.name} holds no point or cell arrays: no values to render")
    if name not in points and name not in cells:
        raise ValueError(f"{path.name}: no array {name!r}; point arrays {points}, cell arrays "
                         f"{cells} (choose one with scalars=)")
    spacing = np.asarray(grid.spacing, dtype=np.float64)
    origin = np.asarray(grid.origin, dtype=np.float64)
    if not (np.all(np.isfinite(spacing)) and np.all(spacing > 0) and
            np.all(np.isfinite(origin))):
        raise ValueError(f"{path.name}: its spacing {spacing.tolist()} and origin "
                         f"{origin.tolist()} must be finite, the spacing positive")
    direction = np.asarray(getattr(grid, "direction_matrix", np.eye(3)), dtype=np.float64)
    if name in points:
        nx, ny, nz = grid.dimensions
        values = np.asarray(grid.point_data[name])
    else:  # cell data: one sample per cell, at its centre
        nx, ny, nz = (n - 1 for n in grid.dimensions)
        values = np.asarray(grid.cell_data[name])
        origin = origin + spacing / 2
    if values.ndim != 1 or values.size != nx * ny * nz:
        raise ValueError(f"{path.name}: array {name!r} must hold one value per point or cell "
                         f"({nx}x{ny}x{nz}), got shape {values.shape}")
    values = values.reshape(nz, ny, nx)
    if not np.array_equal(direction, np.eye(3)):  # the grid's axes turned: apply it exactly
        if name in cells:
            origin = origin - spacing / 2 + direction @ (spacing / 2)
        values, spacing, origin = to_world_axes(values, (direction * spacing).T, origin,
                                                path.name)
    return _volume(values, extent, spacing, origin, nan)


_VTK_TYPES = {"bit": 1, "unsigned_char": 1, "char": 1, "short": 2, "unsigned_short": 2,
              "int": 4, "unsigned_int": 4, "long": 8, "unsigned_long": 8, "float": 4,
              "double": 8, "vtktypeint64": 8, "vtktypeuint64": 8}


_VTK_SCALARS = re.compile(rb"SCALARS\s+\S+\s+(\w+)(\s+\d+)?\s*\n(LOOKUP_TABLE\s+\S+\s*\n)?")


def _check_numbers(path, name, size, found):
    """Refuse a VTK header's ``name`` (if ``found``) unless it is ``size`` finite numbers
    (with a positive spacing)."""
    if found is None:
        return
    text = found.group(1).decode("latin-1")
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    spacing = name in (b"Spacing", b"SPACING", b"ASPECT_RATIO")
    if len(values) != size or not all(math.isfinite(v) and (v > 0 or not spacing)
                                       for v in values):
        raise ValueError(f"{path.name}: its {name.decode()} {text.strip()!r} must be {size} "
                         f"finite numbers{', all positive' if spacing else ''}")


def _check_vtk_claims(path):
    """Check what a VTK file's header claims before VTK reads it (VTK allocates what an
    extent claims, and aborts the process when it cannot): the grid's size against the
    memory, and a binary legacy file's samples against its length (VTK would fill the
    missing ones with whatever memory held)."""
    with open(path, "rb") as fh:
        head = fh.read(1 << 16)
    found = re.search(rb'WholeExtent="([^"]*)"', head)
    if found is not None:
        try:
            extent = [int(v) for v in found.group(1).split()]
        except ValueError:
            extent = []
        if len(extent) != 6 or any(b < a for a, b in zip(extent[::2], extent[1::2], strict=True)):
            raise ValueError(f"{path.name} is not a readable VTK file: WholeExtent "
                             f"{found.group(1).decode('latin-1')!r}")
        count = math.prod(b - a + 1 for a, b in zip(extent[::2], extent[1::2], strict=True))
        check_allocation(count, np.float64, path.name)
        # VTK reads a spacing or origin it cannot parse ("nan", "inf") as 1 or 0.
        for name, size in ((b"Spacing", 3), (b"Origin", 3), (b"Direction", 9)):
            _check_numbers(path, name, size, re.search(rb'\s' + name + rb'="([^"]*)"', head))
        return
    dims = re.search(rb"\nDIMENSIONS\s+(-?\d+)\s+(-?\d+)\s+(-?\d+)", head)
    if dims is None:
        return  # not image data: VTK says what it is
    shape = [int(v) for v in dims.groups()]
    if min(shape) < 1:
        raise ValueError(f"{path.name} is not a readable VTK file: DIMENSIONS {shape}")
    check_allocation(math.prod(shape), np.float64, path.name)
    for name in (b"SPACING", b"ASPECT_RATIO", b"ORIGIN"):
        _check_numbers(path, name, 3, re.search(rb"\n" + name + rb"\s+([^\n]*)", head))
    if b"\nBINARY" not in head[:512].replace(b"\r", b""):
        return
    size = path.stat().st_size
    for data in re.finditer(rb"\n(POINT_DATA|CELL_DATA)\s+(\d+)\s*\n", head):
        count = int(data.group(2))
        field = _VTK_SCALARS.search(head, data.end())
        if field is None:
            continue
        kind = field.group(1).decode("latin-1").lower()
        components = int(field.group(2) or 1)
        needed = count * components * _VTK_TYPES.get(kind, 1)
        if size - field.end() < needed:
            raise ValueError(f"{path.name} holds {size - field.end()} bytes of {kind} "
                             f"samples, but its header claims {needed} ({count} of them): "
                             "truncated?")


def load_dicom(folder, *, series=None, extent=None, nan="error", oblique="refuse"):
    """Load a DICOM series (a folder of slice files) through pydicom.

    Slices are ordered by their position along the slice normal (``ImagePositionPatient``
    against ``ImageOrientationPatient``); x and y spacing come from ``PixelSpacing``, z from
    the distance between positions, and each slice's ``RescaleSlope`` and
    ``RescaleIntercept`` are applied. A folder with several series needs ``series`` (a
    ``SeriesInstanceUID``, or its last digits); missing slices (an uneven gap) and slices of
    other sizes are refused. The patient coordinates (LPS) are turned to RAS exactly, rows
    and columns running against an axis flipped; an oblique series is refused unless
    ``oblique="voxel-axes"`` (:func:`load_nifti`).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from data_gen.dicom import write_series
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> files = write_series(folder, np.zeros((3, 4, 5), np.int16), spacing=(0.5, 0.5, 2.0))
    >>> vol = load_dicom(folder)
    >>> vol.shape, vol.spacing.tolist()
    ((3, 4, 5), [0.5, 0.5, 2.0])
    """
    import pydicom
    from pydicom.errors import InvalidDicomError

    validate.choice("oblique", oblique, OBLIQUE)
    folder = Path(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"no DICOM folder at {str(folder)!r}")
    slices = {}
    for file in sorted(p for p in folder.iterdir() if p.is_file()):
        try:
            ds = pydicom.dcmread(file, stop_before_pixels=False)
        except (InvalidDicomError, OSError, EOFError):
            continue
        except Exception as error:  # pydicom raises many kinds on a corrupt file
            raise _unreadable(file, "DICOM", error) from None
        if "PixelData" not in ds:
            continue
        slices.setdefault(str(ds.get("SeriesInstanceUID", "")), []).append((file, ds))
    if not slices:
        inner = sorted(p.name for p in folder.iterdir() if p.is_dir())
        searched = (f" (sub-folders are not searched: name one of {inner[:5]}"
                    f"{' ...' if len(inner) > 5 else ''})" if inner else "")
        raise ValueError(f"no DICOM slices with pixel data in {str(folder)!r}{searched}")
    if series is None and len(slices) > 1:
        raise ValueError(f"{folder.name} holds {len(slices)} DICOM series: choose one with "
                         f"series= (one of {sorted(slices)})")
    if series is not None:
        chosen = [uid for uid in slices if uid == series or uid.endswith(str(series))]
        if len(chosen) != 1:
            raise ValueError(f"series {series!r} names {len(chosen)} of the series in "
                             f"{folder.name}: {sorted(slices)}")
        series = chosen[0]
    else:
        series = next(iter(slices))
    members = slices[series]
    if len(members) < 2:
        raise ValueError(f"a DICOM series needs at least 2 slices, {folder.name} has "
                         f"{len(members)}")
    return _stack_dicom(folder, members, extent, nan, oblique)


def _stack_dicom(folder, members, extent, nan, oblique):
    first = members[0][1]
    try:
        cosines = np.asarray(first.ImageOrientationPatient, dtype=np.float64).reshape(2, 3)
        pixel = np.asarray(first.PixelSpacing, dtype=np.float64)  # (row, column) spacing
    except AttributeError as error:
        raise ValueError(f"{members[0][0].name} lacks the geometry of a volume slice "
                         f"({error})") from None
    normal = np.cross(cosines[0], cosines[1])
    positions = []
    for file, ds in members:
        if "ImagePositionPatient" not in ds:
            raise ValueError(f"{file.name} has no ImagePositionPatient: cannot order slices")
        positions.append(float(np.dot(np.asarray(ds.ImagePositionPatient, float), normal)))
    order, gap = _slice_order(positions, folder.name)
    planes = []
    for index in order:
        file, ds = members[index]
        try:
            stored = ds.pixel_array
            plane = stored.astype(np.float64)
        except Exception as error:
            raise _unreadable(file, "DICOM", error) from None
        if planes and plane.shape != planes[0].shape:
            raise ValueError(f"{file.name} is {plane.shape}, other slices "
                             f"{planes[0].shape}: not one series")
        slope = float(ds.get("RescaleSlope", 1.0))
        planes.append(plane * slope + float(ds.get("RescaleIntercept", 0.0)))
    data = np.stack(planes)
    first = members[order[0]][1]
    origin = np.asarray(first.ImagePositionPatient, dtype=np.float64)
    return _dicom_volume(data, cosines, pixel, gap, origin, folder.name, extent, nan, oblique,
                         stored.dtype)


def _dicom_volume(data, cosines, pixel, gap, origin, name, extent, nan, oblique, file_dtype):
    """The volume of slices ``data[k, j, i]`` sorted along their normal: the rows' and
    columns' direction ``cosines``, ``pixel`` spacing (row, column), slice ``gap`` and first
    corner ``origin``, all in DICOM's patient coordinates (LPS), turned exactly to RAS as a
    NIfTI volume is (:func:`data_gen.untrusted.to_world_axes`); an oblique grid is refused
    unless ``oblique="voxel-axes"``."""
    normal = np.cross(cosines[0], cosines[1])
    directions = np.stack([cosines[0] * pixel[1], cosines[1] * pixel[0], normal * gap])
    directions[:, :2] *= -1.0  # LPS -> RAS
    origin = origin * np.array([-1.0, -1.0, 1.0])
    if oblique == "voxel-axes":  # each voxel axis on its nearest world axis
        nearest = np.argmax(np.abs(directions), axis=1)
        snapped = np.zeros_like(directions)
        snapped[np.arange(3), nearest] = (np.sign(directions[np.arange(3), nearest])
                                          * np.linalg.norm(directions, axis=1))
        directions = snapped
    try:
        data, spacing, origin = to_world_axes(data, directions, origin, name)
    except ValueError as error:
        raise _oblique_hint(error) from None
    return _volume(data, extent, spacing, origin, nan, file_dtype)


def _oblique_hint(error):
    """``error`` with, for an oblique grid, how to take its voxel axes as they are."""
    if "oblique" not in str(error):
        return error
    return ValueError(f"{error}; or take the voxel axes as they are with "
                      "oblique='voxel-axes' (--oblique voxel-axes)")


def _slice_order(positions, name):
    """``(order, gap)``: the slices sorted along their normal and their even spacing; a
    repeated position or an uneven gap (a missing slice) is refused."""
    order = np.argsort(positions)
    depth = np.diff(np.asarray(positions)[order])
    if np.any(depth <= 0):
        raise ValueError(f"{name}: two slices share a position: a repeated slice or "
                         "mixed series")
    gap = float(np.median(depth))
    if np.any(np.abs(depth - gap) > 0.01 * gap):
        worst = int(np.argmax(np.abs(depth - gap)))
        raise ValueError(f"{name}: slices are unevenly spaced ({depth[worst]:g} against "
                         f"{gap:g} mm between positions {positions[order[worst]]:g} and "
                         f"{positions[order[worst + 1]]:g}): missing slices?")
    return order, gap


def load_dicom_file(path, *, extent=None, nan="error", oblique="refuse"):
    """Load a single multi-frame DICOM file (an enhanced CT or MR image: one frame per
    slice, its geometry in the functional groups), ordered and oriented as a series is
    (:func:`load_dicom`); each frame's rescale applied.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from data_gen.dicom import write_multiframe
    >>> f = write_multiframe(pathlib.Path(tempfile.mkdtemp()) / "v.dcm",
    ...                      np.zeros((3, 4, 5), np.int16), spacing=(0.5, 0.5, 2.0))
    >>> vol = load_dicom_file(f)
    >>> vol.shape, vol.spacing.tolist()
    ((3, 4, 5), [0.5, 0.5, 2.0])
    """
    import pydicom

    validate.choice("oblique", oblique, OBLIQUE)
    path = _existing(path)
    try:
        ds = pydicom.dcmread(path)
        frames = int(ds.get("NumberOfFrames", 1))
        if "PixelData" not in ds:
            raise ValueError(f"{path.name} holds no pixel data")
        if frames < 2:
            raise ValueError(f"{path.name} holds one slice, not a volume: give the folder of "
                             "its series")
        check_allocation(frames * int(ds.Rows) * int(ds.Columns), np.float64, path.name)
        shared = ds.SharedFunctionalGroupsSequence[0]
        per_frame = ds.PerFrameFunctionalGroupsSequence
        measures = shared.PixelMeasuresSequence[0]
        pixel = np.asarray(measures.PixelSpacing, dtype=np.float64)  # rows (y), columns (x)
        groups = [g.PlaneOrientationSequence[0] if "PlaneOrientationSequence" in g else
                  shared.PlaneOrientationSequence[0] for g in per_frame]
        cosines = np.asarray(groups[0].ImageOrientationPatient, dtype=np.float64).reshape(2, 3)
        corners = [np.asarray(g.PlanePositionSequence[0].ImagePositionPatient, np.float64)
                   for g in per_frame]
        scales = []
        for g in per_frame:
            scale = (g if "PixelValueTransformationSequence" in g else shared)
            transform = (scale.PixelValueTransformationSequence[0]
                         if "PixelValueTransformationSequence" in scale else {})
            scales.append((float(transform.get("RescaleSlope", 1.0)),
                           float(transform.get("RescaleIntercept", 0.0))))
        stored = ds.pixel_array
        pixels = stored.astype(np.float64)
    except ValueError:
        raise
    except Exception as error:  # pydicom raises many kinds on a corrupt or partial file
        raise _unreadable(path, "multi-frame DICOM", error) from None
    if len(corners) != frames or pixels.shape[0] != frames:
        raise ValueError(f"{path.name}: {frames} frames but {len(corners)} positions and "
                         f"{pixels.shape[0]} images")
    if any(not np.allclose(g.ImageOrientationPatient, groups[0].ImageOrientationPatient)
           for g in groups):
        raise ValueError(f"{path.name}: its frames lie in differently oriented planes")
    normal = np.cross(cosines[0], cosines[1])
    order, gap = _slice_order([float(np.dot(c, normal)) for c in corners], path.name)
    data = np.stack([pixels[i] * scales[i][0] + scales[i][1] for i in order])
    return _dicom_volume(data, cosines, pixel, gap, corners[order[0]], path.name, extent, nan,
                         oblique, stored.dtype)


# VolPack's .den header (Levoy's format): 28 shorts (version, then original, extracted and
# mapped minimum, maximum and length per axis), the map's warp count and its length in bytes.
_DEN_HEADER = 62


def load_den(path, *, extent=None, nan="error"):
    """Load a VolPack/Levoy ``.den`` density file (8-bit samples after a 62-byte header whose
    mapped lengths give the shape; either byte order, told by the version word).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.den"
    >>> header = np.zeros(29, ">i2"); header[[0, 25, 26, 27]] = (1, 4, 3, 2)
    >>> with open(f, "wb") as out:
    ...     _ = out.write(header.tobytes() + np.array([24], ">i4").tobytes() + bytes(range(24)))
    >>> vol = load_den(f)
    >>> vol.shape, float(vol.data[1, 2, 3])
    ((2, 3, 4), 23.0)
    """
    path = _existing(path)
    length = path.stat().st_size
    with open(path, "rb") as fh:
        raw = fh.read(_DEN_HEADER)  # the header alone: the samples are mapped, not read
    if len(raw) < _DEN_HEADER:
        raise ValueError(f"{path.name} is not a .den file: {len(raw)} bytes, shorter than its "
                         f"{_DEN_HEADER}-byte header")
    for order in (">", "<"):  # the version word is 1 in the file's byte order
        version = int(np.frombuffer(raw, dtype=order + "i2", count=1)[0])
        lengths = np.frombuffer(raw, dtype=order + "i2", count=3, offset=50).astype(int)
        size = int(np.frombuffer(raw, dtype=order + "i4", count=1, offset=58)[0])
        if version == 1:
            break
    else:
        raise ValueError(f"{path.name} is not a .den file: its version word is not 1 in "
                         "either byte order")
    if np.any(lengths < 2) or size != math.prod(lengths.tolist()):
        raise ValueError(f"{path.name} is not a .den file: its header's map lengths "
                         f"{lengths.tolist()} and size {size} disagree")
    if length != _DEN_HEADER + size:
        raise ValueError(f"{path.name} holds {length - _DEN_HEADER} sample bytes, but its "
                         f"header says {size} ({'x'.join(map(str, lengths))}): truncated?")
    nx, ny, nz = lengths.tolist()
    check_allocation(size, np.uint8, path.name)
    data = np.memmap(path, dtype=np.uint8, mode="r", offset=_DEN_HEADER, shape=(nz, ny, nx))
    return _volume(data, extent, None, None, nan)


#: The loader :func:`load` takes for each file name ending (a DICOM series is a folder).
FORMATS = {".npy": load_npy, ".nii": load_nifti, ".nii.gz": load_nifti, ".raw": load_raw,
           ".nrrd": load_nrrd, ".nhdr": load_nrrd, ".tif": load_tiff, ".tiff": load_tiff,
           ".vti": load_vtk, ".vtk": load_vtk, ".den": load_den, ".dcm": load_dicom_file}


def load(source, **options):
    """Load a volume from a file, a DICOM folder, or a named real volume
    (:data:`data_gen.datasets.DATASETS`: ``mni152``, ``frog``, ``aniso``, ``brainsmall``).

    The file's name ending picks the loader (:data:`FORMATS`); ``options`` go to it (a raw
    file needs ``shape`` and ``dtype``).

    Raises
    ------
    FileNotFoundError
        No such file or folder.
    ValueError
        An unknown format, or a file its loader cannot read (the message names the problem).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.raw"
    >>> np.ones(8, dtype=np.float32).tofile(f)
    >>> load(f, shape=(2, 2, 2), dtype="float32").value_range
    (1.0, 1.0)
    """
    from data_gen import datasets

    if str(source) in datasets.DATASETS:
        return datasets.load_dataset(str(source), **options)
    path = Path(source)
    if path.is_dir():
        return load_dicom(path, **options)
    name = path.name.lower()
    for ending, loader in FORMATS.items():
        if name.endswith(ending):
            if ending == ".raw" and not {"shape", "dtype"} <= set(options):
                raise ValueError("a .raw file needs shape=(nz, ny, nx) and dtype= (on the "
                                 "command line --shape NZ,NY,NX --dtype TYPE)")
            try:
                return loader(path, **options)
            except ValueError as error:  # the volume's own checks: name the file too
                if path.name in str(error):
                    raise
                raise ValueError(f"{path.name}: {error}") from None
    if not path.exists():
        raise FileNotFoundError(f"no volume file or folder at {str(source)!r}")
    endings = ", ".join(FORMATS)
    raise ValueError(f"cannot tell the format of {str(source)!r}: use a file ending in "
                     f"{endings}, a folder of DICOM slices, or one of the named volumes "
                     f"{', '.join(datasets.DATASETS)}")
