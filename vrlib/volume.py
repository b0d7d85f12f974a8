"""The sampled volume: samples on a regular lattice inside a world box.

Samples are stored as ``data[z, y, x]`` and sit at the corners of the world box and evenly
between them (vertex-centred), so sample ``(i, j, k)`` (x, y, z index) lies at
``origin + (i, j, k) * spacing``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vrlib import validate
from vrlib.holes import hole_value

__all__ = ["Volume", "MinMaxPyramid", "DEFAULT_EXTENT", "MAX_MAGNITUDE", "check_extent",
           "fitted_extent", "block_extremes", "lattice_extent", "storage_dtype"]

#: The largest sample magnitude a volume takes: beyond it, differences of values (gradients,
#: histograms, classification tables) overflow float64.
MAX_MAGNITUDE = 1e300

#: The default world box, ``[[xmin, xmax], [ymin, ymax], [zmin, zmax]]``: the cube [-1, 1]^3.
DEFAULT_EXTENT = ((-1.0, 1.0), (-1.0, 1.0), (-1.0, 1.0))

# Integer and small float types that float32 represents exactly are kept in float32;
# everything else is stored in float64.
_EXACT_IN_FLOAT32 = {
    np.dtype(t) for t in ("int8", "uint8", "int16", "uint16", "float16", "float32")
}


def storage_dtype(dtype):
    """The dtype a volume stores samples of ``dtype`` in: float32 for the types it holds
    exactly (8- and 16-bit integers, float16, float32), float64 for all others.

    Examples
    --------
    >>> storage_dtype("uint16"), storage_dtype(">i2"), storage_dtype("int32")
    (dtype('float32'), dtype('float32'), dtype('float64'))
    """
    native = np.dtype(dtype).newbyteorder("=")  # a big-endian file's int16 is an int16
    return np.dtype(np.float32 if native in _EXACT_IN_FLOAT32 else np.float64)


@dataclass(frozen=True)
class MinMaxPyramid:
    """Per-block minimum and maximum of a volume's samples, at successively coarser levels.

    Level 0 splits the volume's cells into blocks of ``block`` cells per axis; block
    ``(bz, by, bx)`` holds the minimum and maximum over the samples whose indices lie in
    ``[block * b - margin, block * (b + 1) + margin]`` along each axis (clipped to the volume).
    Each further level merges 2 x 2 x 2 blocks of the one below. ``margin`` widens every block
    by the reach of a reconstruction filter, so a block whose range maps to zero opacity is
    empty for every point inside it.

    Attributes
    ----------
    block : int
        Cells per block along each axis at level 0.
    margin : int
        Extra samples included on each side of a block.
    minimum, maximum : list of ndarray
        ``minimum[level][bz, by, bx]`` and likewise ``maximum``.

    Examples
    --------
    >>> import numpy as np
    >>> pyr = Volume(np.arange(27.0).reshape(3, 3, 3)).minmax_pyramid(1)
    >>> pyr.levels, pyr.minimum[0].shape, pyr.maximum[-1].item()
    (2, (2, 2, 2), 26.0)
    """

    block: int
    margin: int
    minimum: list
    maximum: list

    @property
    def levels(self):
        """Number of levels (level 0 is the finest)."""
        return len(self.minimum)

    def cells_per_block(self, level):
        """Cells along each axis covered by one block at ``level``."""
        return self.block << level


class Volume:
    """Scalar samples ``data[z, y, x]`` on a regular lattice spanning a world box.

    Parameters
    ----------
    data : array_like, shape (nz, ny, nx)
        Real, finite samples; every dimension at least 2. Types that float32 holds exactly
        (8- and 16-bit integers, float16, float32) are stored as float32, all others as float64.
    extent : array_like, shape (3, 2), optional
        World box ``[[xmin, xmax], [ymin, ymax], [zmin, zmax]]``. Samples lie on its corners
        and evenly between them.
    spacing : array_like of 3 floats, optional
        World distance between neighbouring samples along ``(x, y, z)`` (> 0), as pyvista's
        ``ImageData`` takes it; default 1 when only ``origin`` is given.
    origin : array_like of 3 floats, optional
        World position of sample ``data[0, 0, 0]``; default ``(0, 0, 0)`` when only
        ``spacing`` is given.
    nan : {"error", "transparent"}, default "error"
        What NaN samples mean. ``"error"`` refuses them; ``"transparent"`` makes each a hole
        that contributes nothing (:mod:`vrlib.holes` states the rule): the sample is stored
        as :attr:`hole_value`, far outside the data, and every renderer draws whatever a hole
        reaches as transparent. Infinite samples are refused either way.
    copy : bool, default True
        Copy ``data``. With ``copy=False`` an array that already has the storage type is used
        as is (read-only view): do not modify it afterwards.
    file_dtype : numpy dtype, optional
        The sample type of the file the samples were read from (:attr:`file_dtype`; the
        loaders of ``data_gen`` set it).
    transfer : TransferFunction, optional
        The transfer function renders use when they are given none (:attr:`transfer`). The
        analytic fields' samples carry ``Glow(1.0)``, the thesis's study function; without
        one, renders fit :func:`vrlib.auto_transfer` to the histogram, which shows real data.

    Notes
    -----
    With neither ``extent`` nor ``spacing``/``origin`` the voxels are cubes and the box is
    centred on the origin with its longest side spanning [-1, 1] (:func:`fitted_extent`): a
    cubic array fills the cube [-1, 1]^3, and a ``(10, 20, 40)`` array is not stretched to it.
    Pass ``extent=DEFAULT_EXTENT`` to stretch any array over the cube.

    Raises
    ------
    ValueError
        Non-finite samples, not exactly 3 dimensions, a dimension below 2, an extent that is
        empty, inverted or non-finite, a spacing that is not positive, or ``extent`` together
        with ``spacing``/``origin``.
    TypeError
        A non-numeric (or boolean, or complex) dtype.

    Examples
    --------
    >>> import numpy as np
    >>> vol = Volume(np.zeros((3, 4, 5)))
    >>> vol.shape
    (3, 4, 5)
    >>> vol.spacing.tolist()          # (dx, dy, dz): cubic voxels, longest side [-1, 1]
    [0.5, 0.5, 0.5]
    >>> vol.index_to_world([4, 3, 2]).tolist()
    [1.0, 0.75, 0.5]
    >>> Volume(np.zeros((3, 4, 5)), spacing=(1, 1, 2.5)).extent.tolist()
    [[0.0, 4.0], [0.0, 3.0], [0.0, 5.0]]
    """

    def __init__(self, data, extent=None, *, spacing=None, origin=None, nan="error",
                 copy=True, file_dtype=None, transfer=None):
        from vrlib.transfer import TransferFunction

        if transfer is not None and not isinstance(transfer, TransferFunction):
            raise TypeError(f"transfer must be None or a vrlib transfer function (Glow, "
                            f"LookupTransfer), got {transfer!r}")
        self._transfer = transfer
        self._file_dtype = None if file_dtype is None else np.dtype(file_dtype)
        arr = np.asarray(data)
        if arr.dtype.kind not in "iuf":
            raise TypeError(
                "volume data must be real numbers (integer or float dtype), "
                f"got dtype {arr.dtype}"
            )
        if arr.ndim != 3:
            raise ValueError(
                f"volume data must be 3-dimensional [z, y, x], got {arr.ndim} "
                f"dimension(s) with shape {arr.shape}"
            )
        if min(arr.shape) < 2:
            raise ValueError(
                f"volume data needs at least 2 samples along every axis, got shape {arr.shape}"
            )
        validate.choice("nan", nan, ("error", "transparent"))
        storage = storage_dtype(arr.dtype)
        arr = np.array(arr, dtype=storage, order="C", copy=True if copy else None)
        self._holes = None
        self._range = None
        if not np.all(np.isfinite(arr)):
            holes = np.isnan(arr)
            bad = int(arr.size - np.count_nonzero(np.isfinite(arr)))
            if nan == "error" or bad > np.count_nonzero(holes):
                hint = "" if nan == "transparent" else " (nan='transparent' makes NaN holes)"
                raise ValueError(f"volume data must be finite: found {bad} NaN or infinite "
                                 f"sample(s){hint}")
            if holes.all():
                raise ValueError("volume data are all NaN: there is nothing to render")
            valid = arr[~holes]
            self._range = (float(valid.min()), float(valid.max()))
            if not copy or arr.base is not None:
                arr = arr.copy()
            arr[holes] = hole_value(*self._range)
            holes.flags.writeable = False
            self._holes = holes
        low, high = self._range or (float(arr.min()), float(arr.max()))
        if max(abs(low), abs(high)) > MAX_MAGNITUDE:
            raise ValueError(f"volume values reach {max(abs(low), abs(high)):.3g}, beyond "
                             f"{MAX_MAGNITUDE:g}: their differences overflow; rescale them")
        self._range = (low, high)
        if arr.base is not None or not copy:
            arr = arr.view()
        arr.flags.writeable = False
        self._data = arr
        self._extent = _world_box(arr.shape, extent, spacing, origin)
        self._extent.flags.writeable = False
        counts = np.array(arr.shape[::-1], dtype=np.float64) - 1.0
        self._spacing = (self._extent[:, 1] - self._extent[:, 0]) / counts
        self._derived = {}  # cached structures built from the samples (pyramids, runs)

    # -- lattice geometry ------------------------------------------------------------------

    @property
    def transfer(self):
        """The transfer function renders use when they are given none, or None: then they use
        :func:`vrlib.default_transfer`'s histogram fit."""
        return self._transfer

    @property
    def file_dtype(self):
        """The sample type of the file the samples were read from (before any scaling), or
        None for a volume made from an array; :attr:`dtype` is the type held in memory."""
        return self._file_dtype

    @property
    def data(self):
        """Read-only samples, indexed ``[z, y, x]``."""
        return self._data

    @property
    def shape(self):
        """``(nz, ny, nx)``."""
        return self._data.shape

    @property
    def dtype(self):
        """Storage dtype (float32 or float64)."""
        return self._data.dtype

    @property
    def extent(self):
        """World box ``[[xmin, xmax], [ymin, ymax], [zmin, zmax]]`` (a copy)."""
        return self._extent.copy()

    @property
    def origin(self):
        """World position ``(x, y, z)`` of sample ``data[0, 0, 0]``."""
        return self._extent[:, 0].copy()

    @property
    def spacing(self):
        """World distance between neighbouring samples along ``(x, y, z)`` (a copy)."""
        return self._spacing.copy()

    @property
    def center(self):
        """Centre ``(x, y, z)`` of the world box."""
        return self._extent.mean(axis=1)

    @property
    def bounding_radius(self):
        """Radius of the sphere around :attr:`center` that contains the world box.

        Pass it (with :attr:`center`) to :meth:`vrlib.View.orbit` to frame this volume.
        """
        return float(0.5 * np.linalg.norm(self._extent[:, 1] - self._extent[:, 0]))

    @property
    def holes(self):
        """Where the NaN samples of a volume made with ``nan="transparent"`` were (a read-only
        boolean array like :attr:`data`), or None."""
        return self._holes

    @property
    def hole_value(self):
        """The value stored in place of each hole (None without holes)."""
        if self._holes is None:
            return None
        return hole_value(*self.value_range)

    @property
    def value_range(self):
        """``(min, max)`` of the samples, holes left out (computed once: the samples are
        read-only)."""
        if self._range is None:
            self._range = (float(self._data.min()), float(self._data.max()))
        return self._range

    def index_to_world(self, index):
        """Map index coordinates ``(i, j, k)`` (x, y, z order, float) to world ``(x, y, z)``.

        Examples
        --------
        >>> Volume(np.zeros((2, 2, 2))).index_to_world([0.5, 0, 1]).tolist()
        [0.0, -1.0, 1.0]
        """
        return self._extent[:, 0] + np.asarray(index, dtype=np.float64) * self.spacing

    def world_to_index(self, points):
        """Map world ``(x, y, z)`` points (last axis) to float index coordinates ``(i, j, k)``.

        Examples
        --------
        >>> Volume(np.zeros((5, 5, 5))).world_to_index([0.0, 0.0, 1.0]).tolist()
        [2.0, 2.0, 4.0]
        """
        return (np.asarray(points, dtype=np.float64) - self._extent[:, 0]) / self.spacing

    # -- empty-space skipping --------------------------------------------------------------

    def minmax_pyramid(self, block=8, *, margin=0):
        """Min-max block pyramid for empty-space skipping, built on first use and cached.

        Parameters
        ----------
        block : int, default 8
            Cells per block along each axis at the finest level (>= 1).
        margin : int, default 0
            Samples added on each side of every block: a filter of support radius ``r``
            voxels reaches ``ceil(r) - 1`` samples beyond a cell's corners.

        Returns
        -------
        MinMaxPyramid

        Examples
        --------
        >>> data = np.zeros((9, 9, 9)); data[8, 8, 8] = 1.0
        >>> pyr = Volume(data).minmax_pyramid(4)
        >>> pyr.maximum[0].tolist()[1][1], pyr.levels
        ([0.0, 1.0], 2)
        """
        block = validate.positive_int("block", block)
        margin = validate.positive_int("margin", margin, minimum=0)
        return self.cached(("pyramid", block, margin),
                           lambda: _build_pyramid(self._data, block, margin))

    def slices(self, axis):
        """The samples as a stack of slices along ``axis`` (0, 1, 2 for x, y, z), indexed
        ``[slice, row, column]``: rows run along the higher of the other two axes and columns
        along the lower, so that every row is contiguous in memory.

        Slices along z and y are views of the data; slices along x need a transposed copy,
        made on first use and cached (the same memory as the data), as shear-warp renderers
        keep one copy of the volume per principal axis.

        Examples
        --------
        >>> vol = Volume(np.arange(24.0).reshape(2, 3, 4))      # [z, y, x]
        >>> vol.slices(0).shape, vol.slices(0)[1, :, 0].tolist()  # slice x = 1: rows z, columns y
        ((4, 2, 3), [1.0, 13.0])
        >>> np.shares_memory(vol.slices(1), vol.data)            # along y: a view
        True
        """
        axis = validate.choice("axis", axis, (0, 1, 2))
        if axis == 2:
            return self._data
        if axis == 1:
            return self._data.transpose(1, 0, 2)

        def transposed():
            copy = np.ascontiguousarray(self._data.transpose(2, 0, 1))
            copy.flags.writeable = False
            return copy

        return self.cached(("slices", 0), transposed)

    # -- structures derived from the samples -------------------------------------------------

    def cached(self, key, build, *, keep=None):
        """What ``build()`` makes from the samples, built on first use and kept with the
        volume (its samples are read-only, so it never goes stale): pyramids, run tables,
        transposed copies, prefiltered coefficients.

        Parameters
        ----------
        key : tuple
            Names the structure; its first entry is the structure's kind, e.g.
            ``("pyramid", block, margin)``.
        build : callable
            Called with no arguments when ``key`` is not cached yet.
        keep : int, optional
            Keep at most this many structures of this kind (``key[0]``), dropping the oldest.

        Examples
        --------
        >>> vol = Volume(np.arange(8.0).reshape(2, 2, 2))
        >>> vol.cached(("total",), lambda: float(vol.data.sum()))
        28.0
        >>> vol.cached(("total",), lambda: 0.0)                  # built once
        28.0
        """
        if key not in self._derived:
            if keep is not None:
                kind = [k for k in self._derived if k[0] == key[0]]
                for old in kind[: max(0, len(kind) - keep + 1)]:
                    del self._derived[old]
            self._derived[key] = build()
        return self._derived[key]

    @classmethod
    def from_pyvista(cls, grid, scalars=None):
        """A volume from a pyvista ``ImageData`` (VTK image data): its point scalars, origin
        and spacing.

        Parameters
        ----------
        grid : pyvista.ImageData
            A regular grid with at least 2 points along each axis (axis-aligned: a
            ``direction_matrix`` other than the identity is refused).
        scalars : str, optional
            Name of the point array; default the active scalars.

        Examples
        --------
        >>> import pyvista as pv
        >>> grid = pv.ImageData(dimensions=(4, 3, 2), spacing=(0.5, 1.0, 2.0))
        >>> grid.point_data["density"] = np.arange(24.0)
        >>> vol = Volume.from_pyvista(grid)
        >>> vol.shape, vol.extent.tolist(), float(vol.data[1, 0, 0])
        ((2, 3, 4), [[0.0, 1.5], [0.0, 2.0], [0.0, 2.0]], 12.0)
        """
        import pyvista as pv

        if not isinstance(grid, pv.ImageData):
            raise TypeError(f"grid must be a pyvista.ImageData, got {type(grid).__name__}")
        direction = getattr(grid, "direction_matrix", None)
        if direction is not None and not np.allclose(np.asarray(direction), np.eye(3)):
            raise ValueError("grid must be axis-aligned (identity direction_matrix)")
        if scalars is None:
            scalars = grid.active_scalars_name
            if scalars is None:
                if len(grid.point_data.keys()) != 1:
                    raise ValueError("grid has no active point scalars: name one with "
                                     f"scalars=; point arrays: {list(grid.point_data.keys())}")
                scalars = grid.point_data.keys()[0]
        if scalars not in grid.point_data:
            raise ValueError(f"scalars {scalars!r} is not a point array of the grid; point "
                             f"arrays: {list(grid.point_data.keys())}")
        nx, ny, nz = grid.dimensions
        values = np.asarray(grid.point_data[scalars])
        if values.ndim != 1:
            raise ValueError(f"scalars {scalars!r} must hold one value per point, got shape "
                             f"{values.shape}")
        origin = np.asarray(grid.origin, float)
        spacing = np.asarray(grid.spacing, float)
        extent = np.stack([origin, origin + (np.array([nx, ny, nz]) - 1) * spacing], axis=1)
        return cls(values.reshape(nz, ny, nx), extent=extent)

    def to_pyvista(self, name="values"):
        """The volume as a pyvista ``ImageData`` with its samples as point scalars ``name``.

        Examples
        --------
        >>> vol = Volume(np.arange(24.0).reshape(2, 3, 4))
        >>> grid = vol.to_pyvista()
        >>> grid.dimensions, Volume.from_pyvista(grid).extent.tolist() == vol.extent.tolist()
        ((4, 3, 2), True)
        """
        import pyvista as pv

        nz, ny, nx = self.shape
        grid = pv.ImageData(dimensions=(nx, ny, nz), spacing=tuple(self.spacing),
                            origin=tuple(self.origin))
        grid.point_data[name] = np.ascontiguousarray(self._data).ravel()
        grid.set_active_scalars(name)
        return grid

    def __repr__(self):
        ext = ", ".join(f"[{lo:g}, {hi:g}]" for lo, hi in self._extent)
        return f"Volume(shape={self.shape}, dtype={self.dtype}, extent=[{ext}])"


def fitted_extent(shape, spacing=(1.0, 1.0, 1.0)):
    """World box for a ``(nz, ny, nx)`` lattice of ``(dx, dy, dz)`` spacing, centred on the
    origin with its longest side spanning [-1, 1].

    Examples
    --------
    >>> fitted_extent((2, 3, 5)).tolist()
    [[-1.0, 1.0], [-0.5, 0.5], [-0.25, 0.25]]
    """
    sizes = (np.array(shape[::-1], dtype=np.float64) - 1.0) * np.asarray(spacing, dtype=float)
    half = sizes / sizes.max()
    return np.stack([-half, half], axis=1)


def lattice_extent(shape, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0)):
    """World box of a ``(nz, ny, nx)`` lattice whose first sample lies at ``origin`` with
    ``(dx, dy, dz)`` ``spacing`` (the rule of :class:`Volume`'s ``spacing`` and ``origin``).

    Examples
    --------
    >>> lattice_extent((2, 3, 5), spacing=(1, 1, 2.5), origin=(10, 0, 0)).tolist()
    [[10.0, 14.0], [0.0, 2.0], [0.0, 2.5]]
    """
    start = np.asarray(origin, dtype=np.float64)
    sizes = (np.array(shape[::-1], dtype=np.float64) - 1.0) * np.asarray(spacing, float)
    return np.stack([start, start + sizes], axis=1)


def _world_box(shape, extent, spacing, origin):
    """The checked world box from ``extent``, or ``spacing`` and ``origin``, or the default."""
    if extent is not None:
        if spacing is not None or origin is not None:
            raise ValueError("give the world box either as extent or as spacing and origin, "
                             "not both")
        return check_extent(extent)
    if spacing is None and origin is None:
        return check_extent(fitted_extent(shape))
    step = np.ones(3) if spacing is None else validate.vector3("spacing", spacing)
    if np.any(step <= 0.0):
        raise ValueError(f"spacing must be positive along x, y and z, got {step.tolist()}")
    start = np.zeros(3) if origin is None else validate.vector3("origin", origin)
    return check_extent(lattice_extent(shape, step, start))


def check_extent(extent):
    """``extent`` as a read-only float64 ``(3, 2)`` array of ``[min, max]`` per axis (x, y, z),
    after checking it is finite and not empty or inverted along any axis.

    Examples
    --------
    >>> check_extent([[0, 1], [0, 2], [-1, 1]]).tolist()
    [[0.0, 1.0], [0.0, 2.0], [-1.0, 1.0]]
    >>> check_extent([[0, 1], [0, 1], [1, 1]])
    Traceback (most recent call last):
    ...
    ValueError: extent along z is empty: [1, 1]; it needs zmin < zmax
    """
    try:
        ext = np.array(extent, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"extent must be 3 pairs of real numbers, got {extent!r}") from None
    if ext.shape != (3, 2):
        raise ValueError(
            f"extent must have shape (3, 2): [[xmin, xmax], [ymin, ymax], [zmin, zmax]], "
            f"got shape {ext.shape}"
        )
    if not np.all(np.isfinite(ext)):
        raise ValueError(f"extent must be finite, got {ext.tolist()}")
    for axis, (lo, hi) in zip("xyz", ext, strict=True):
        if not hi > lo:
            kind = "empty" if hi == lo else "inverted"
            raise ValueError(
                f"extent along {axis} is {kind}: [{lo:g}, {hi:g}]; it needs {axis}min < {axis}max"
            )
    ext.flags.writeable = False
    return ext


def _block_reduce_1d(arr, axis, block, reduce):
    """Reduce blocks of ``block`` cells along ``axis``, each including both end samples."""
    n = arr.shape[axis]
    nblocks = -(-(n - 1) // block)
    pad = nblocks * block + 1 - n
    widths = [(0, 0)] * arr.ndim
    widths[axis] = (0, pad)
    padded = np.pad(arr, widths, mode="edge")
    body = np.take(padded, np.arange(nblocks * block), axis=axis)
    shape = list(body.shape)
    shape[axis : axis + 1] = [nblocks, block]
    inner = reduce(body.reshape(shape), axis=axis + 1)
    ends = np.take(padded, np.arange(1, nblocks + 1) * block, axis=axis)
    return reduce(np.stack([inner, ends]), axis=0)


def _merge_2x2x2(arr, reduce):
    for axis in range(3):
        if arr.shape[axis] % 2:
            widths = [(0, 0)] * 3
            widths[axis] = (0, 1)
            arr = np.pad(arr, widths, mode="edge")
        shape = list(arr.shape)
        shape[axis : axis + 1] = [arr.shape[axis] // 2, 2]
        arr = reduce(arr.reshape(shape), axis=axis + 1)
    return arr


def block_extremes(arr, block, reduce, *, margin=0):
    """``reduce`` (``np.min`` or ``np.max``) of ``arr`` over each block of ``block`` cells
    per axis (both end samples), each block widened by ``margin`` samples each side: the
    finest level of a min-max pyramid (:meth:`Volume.minmax_pyramid`).

    Examples
    --------
    >>> arr = np.zeros((9, 9, 9)); arr[8, 8, 8] = 1.0
    >>> block_extremes(arr, 4, np.max)[:, 1, 1].tolist()
    [0.0, 1.0]
    """
    if margin:
        from scipy import ndimage  # here: SciPy's import is a quarter of vrlib's

        window = {np.min: ndimage.minimum_filter, np.max: ndimage.maximum_filter}[reduce]
        # Widen every sample's reach by `margin` before the block reduction (separable).
        arr = window(arr, size=2 * margin + 1, mode="nearest")
    for axis in range(3):
        arr = _block_reduce_1d(arr, axis, block, reduce)
    return arr


def _build_pyramid(data, block, margin):
    levels = {}
    for name, reduce in (("minimum", np.min), ("maximum", np.max)):
        # min and max are exact in the storage type
        stack = [block_extremes(data, block, reduce, margin=margin)]
        while max(stack[-1].shape) > 1:
            stack.append(_merge_2x2x2(stack[-1], reduce))
        levels[name] = stack
    return MinMaxPyramid(block, margin, levels["minimum"], levels["maximum"])
