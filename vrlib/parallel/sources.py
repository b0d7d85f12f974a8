"""Where a distributed render's samples come from: each rank reads only its brick.

A source is an analytic field (each rank evaluates its brick and ghost samples,
:meth:`data_gen.Field.sample_region`) or a file, memory-mapped so that each rank reads only
the pages of its brick: ``.npy``, uncompressed NIfTI (``.nii``) or headerless samples
(:class:`RawFile`). Either way the ranks share one global sample lattice (:class:`Lattice`),
so bricks render on the same ray lattice and join without seams. A file's world box is the
one :func:`data_gen.load` gives it (one unit per voxel from the origin for files without a
header, :func:`vrlib.volume.lattice_extent`; the NIfTI affine's RAS+ box).
Samples of 8- and 16-bit integers, float16 and float32 are read as float32, others as
float64, as :class:`vrlib.Volume` stores them, so a brick holds no more than its share.
"""

from __future__ import annotations

import math
import mmap
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mpi4py import MPI

from vrlib import validate
from vrlib.value_bounds import value_bounds
from vrlib.volume import lattice_extent, storage_dtype

__all__ = ["Lattice", "RawFile", "open_source", "memory_map", "ghost", "global_value_range"]


@dataclass(frozen=True)
class Lattice:
    """The global sample lattice: shape (z, y, x), origin and spacing (x, y, z)."""

    shape: tuple
    origin: np.ndarray
    spacing: np.ndarray

    @property
    def cells(self):
        return tuple(n - 1 for n in self.shape)

    @property
    def extent(self):
        """World box ``[[xmin, xmax], [ymin, ymax], [zmin, zmax]]`` of the whole lattice."""
        return lattice_extent(self.shape, self.spacing, self.origin)

    def box(self, lo, hi):
        """World box (x, y, z arrays) of cells ``[lo, hi)``."""
        return (self.origin + np.array(lo[::-1]) * self.spacing,
                self.origin + np.array(hi[::-1]) * self.spacing)


@dataclass(frozen=True)
class RawFile:
    """Headerless samples in a file, ``shape = (nz, ny, nx)``, x varying fastest (as
    :func:`data_gen.load_raw` reads them).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.raw"
    >>> np.arange(27, dtype=np.uint8).tofile(f)
    >>> array, extent, scaling = memory_map(RawFile(f, (3, 3, 3), "uint8"))
    >>> int(array[2, 1, 0]), extent.tolist()[0]
    (21, [0.0, 2.0])
    """

    path: str | Path
    shape: tuple
    dtype: str
    offset: int = 0
    byteorder: str | None = None  # default the one dtype names, else little


def memory_map(source):
    """A file source's samples ``[z, y, x]``, memory-mapped (nothing is read until indexed),
    its world box, and the scaling ``(slope, intercept)`` its values take (NIfTI), or None.

    Raises ValueError naming the problem for a missing, truncated or unreadable file, a
    compressed NIfTI (which cannot be mapped) or an array that is not 3-D.
    """
    if isinstance(source, RawFile):
        from data_gen.loaders import raw_dtype

        path = _file(source.path)
        shape = tuple(validate.positive_int("shape", n, minimum=2) for n in source.shape)
        if len(shape) != 3:
            raise ValueError(f"shape must be (nz, ny, nx), got {shape!r}")
        dtype = raw_dtype(source.dtype, source.byteorder)
        offset = validate.positive_int("offset", source.offset, minimum=0)
        _check_size(path, offset + math.prod(shape) * dtype.itemsize, shape, dtype, offset)
        array = np.memmap(path, dtype=dtype, mode="r", offset=offset, shape=shape)
        return array, lattice_extent(shape), None
    path = _file(source)
    name = path.name.lower()
    if name.endswith(".npy"):
        try:
            array = np.load(path, mmap_mode="r", allow_pickle=False)
        except (ValueError, OSError, EOFError) as error:
            raise ValueError(f"source {path.name} is not a readable .npy file: {error}") \
                from None
        _check_3d(path, array.shape)
        return array, lattice_extent(array.shape), None
    if name.endswith(".nii"):
        return _map_nifti(path)
    if name.endswith(".nii.gz"):
        raise ValueError(f"source {path.name} is compressed, and each rank must read only its "
                         "brick from the file: decompress it (gunzip) to a .nii file")
    raise ValueError(f"source {path.name} is not a format a rank can read its brick from: use "
                     ".npy, .nii or vrlib.parallel.sources.RawFile(path, shape, dtype)")


def _file(path):
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"source must be an analytic field or an existing file (.npy, .nii, "
                         f"RawFile), got {str(path)!r}")
    return path


def _check_size(path, expected, shape, dtype, offset):
    actual = path.stat().st_size
    if actual < expected:
        raise ValueError(f"source {path.name} holds {actual} bytes, but shape {shape} of "
                         f"{dtype.name} after {offset} header bytes needs {expected}: the file "
                         "is truncated or the shape is wrong")


def _check_3d(path, shape):
    if len(shape) != 3 or min(shape) < 2:
        raise ValueError(f"source {path.name} must hold a 3-D array with at least 2 samples "
                         f"per axis, got shape {tuple(shape)}")


def _map_nifti(path):
    """An uncompressed NIfTI file's voxels, turned to RAS+ as :func:`data_gen.load_nifti`
    turns them (flips and axis swaps are views of the mapping: nothing is read)."""
    import nibabel
    from nibabel import orientations

    from data_gen.loaders import nifti_orientation

    try:
        image = nibabel.load(path)
        proxy = image.dataobj
        dtype, offset = np.dtype(proxy.dtype), int(proxy.offset)
        shape = tuple(int(n) for n in proxy.shape)
        slope, intercept = float(proxy.slope), float(proxy.inter)
        ornt, spacing, origin = nifti_orientation(image, name=f"source {path.name}")
    except ValueError as error:
        if "oblique" in str(error) or "affine" in str(error):  # not a guess: refused
            raise
        raise ValueError(f"source {path.name} is not a readable NIfTI file: {error}") from None
    except Exception as error:  # nibabel raises many kinds on a corrupt header
        raise ValueError(f"source {path.name} is not a readable NIfTI file: {error}") from None
    if len(shape) == 4 and shape[3] == 1:
        shape = shape[:3]
    _check_3d(path, shape)
    _check_size(path, offset + math.prod(shape) * dtype.itemsize, shape, dtype, offset)
    array = np.memmap(path, dtype=dtype, mode="r", offset=offset, shape=shape[::-1])
    array = orientations.apply_orientation(array.T, ornt).T  # [z, y, x] of the RAS+ axes
    scaling = None if (slope, intercept) == (1.0, 0.0) else (slope, intercept)
    return array, lattice_extent(array.shape, spacing, origin), scaling


def open_source(source, shape, extent):
    """The lattice and a reader ``read(region) -> ndarray`` of a field or a file.

    ``region`` is a ``(start, stop)`` pair of sample indices per axis (z, y, x).

    Examples
    --------
    >>> import data_gen
    >>> lattice, read = open_source(data_gen.make_field("gaussian-blob"), 5, None)
    >>> lattice.shape, read([(0, 2), (0, 5), (4, 5)]).shape
    ((5, 5, 5), (2, 5, 1))
    """
    if isinstance(source, str | Path | RawFile):
        array, ext, scaling = memory_map(source)
        name = Path(source.path if isinstance(source, RawFile) else source).name
        if shape is not None:
            wanted = tuple(int(n) for n in np.broadcast_to(shape, 3))
            if wanted != array.shape:
                raise ValueError(f"shape {wanted} does not match the file's {array.shape}")
        shape = array.shape
        ext = ext if extent is None else np.asarray(extent, float)
        storage = np.float64 if scaling is not None else storage_dtype(array.dtype)

        def read(region):
            block = _read_mapped(array, region, storage)
            if scaling is not None:
                block = block * scaling[0] + scaling[1]
            if not np.all(np.isfinite(block)):
                raise ValueError(f"source {name} holds NaN or infinite samples")
            return block
    elif callable(getattr(source, "sample_region", None)):
        if shape is None:
            raise ValueError("shape is required for an analytic field (samples per axis)")
        if isinstance(shape, int | np.integer):
            shape = (int(shape),) * 3
        shape = tuple(validate.positive_int("shape", n, minimum=2) for n in shape)
        ext = np.asarray(source.bounds if extent is None else extent, float)

        def read(region):
            return source.sample_region(shape, region, extent=ext)
    else:
        raise TypeError(f"source must be an analytic field (data_gen.make_field), a path to a "
                        f".npy or .nii file, or a RawFile, got {type(source).__name__}")
    origin = ext[:, 0].copy()
    spacing = (ext[:, 1] - ext[:, 0]) / (np.array(shape[::-1]) - 1)
    return Lattice(tuple(shape), origin, spacing), read


#: Bytes of a file read between releases of its mapped pages.
SLAB_BYTES = 64 << 20


def _read_mapped(array, region, storage):
    """Samples ``region`` of a memory-mapped ``array`` as ``storage``, a slab of z-planes at a
    time. Pages of a mapped file count in the process's resident memory once touched, and
    the pages under a brick's rows span much more of the file than the brick (whole rows,
    and the kernel maps the pages around each one it faults in), so each slab's pages are
    released before the next is read: a rank holds its brick and one slab, not the file."""
    (z0, z1), ys, xs = region
    out = np.empty([b - a for a, b in region], dtype=storage)
    plane = math.prod(array.shape[1:]) * array.dtype.itemsize
    step = max(1, SLAB_BYTES // plane)
    mapping = getattr(array, "_mmap", None)
    for z in range(z0, z1, step):
        out[z - z0:min(z + step, z1) - z0] = array[z:min(z + step, z1), slice(*ys), slice(*xs)]
        if mapping is not None and hasattr(mmap, "MADV_DONTNEED"):
            mapping.madvise(mmap.MADV_DONTNEED)
    return out


def ghost(filt):
    """Samples beyond a brick's box that its ray samples can read."""
    return filt.taps // 2 + 1


def global_value_range(comm, lows, highs, filt):
    """Bounds of every reconstructable value, the same on every rank: the global min and max
    of the samples, then the filter's overshoot (as
    :func:`vrlib.value_bounds.reconstructed_range`)."""
    lo = comm.allreduce(min(lows, default=math.inf), op=MPI.MIN)
    hi = comm.allreduce(max(highs, default=-math.inf), op=MPI.MAX)
    return value_bounds(lo, hi, filt)
