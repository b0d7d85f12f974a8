"""Loaders for user volumes (.npy, NIfTI, raw) and the real MRI template inside nilearn.

Every loader returns a :class:`vrlib.Volume` with data ``[z, y, x]``. By default the world box
is centred on the origin and scaled so that its longest side spans [-1, 1], which frames it in
the default views; pass ``extent`` (or ``physical=True`` for NIfTI) to keep other units.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vrlib import validate
from vrlib.volume import Volume

__all__ = ["load", "load_npy", "load_nifti", "load_raw", "load_mni_template", "fitted_extent"]


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


def _existing(path):
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no volume file at {str(path)!r}")
    return path


def load_npy(path, *, extent=None):
    """Load a 3-D ``.npy`` array stored ``[z, y, x]``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.npy"
    >>> np.save(f, np.zeros((2, 3, 4), dtype=np.uint8))
    >>> load_npy(f).shape
    (2, 3, 4)
    """
    vol = Volume(np.load(_existing(path), allow_pickle=False), extent, copy=False)
    return vol if extent is not None else Volume(vol.data, fitted_extent(vol.shape), copy=False)


def load_raw(path, shape, dtype, *, byteorder="little", offset=0, extent=None):
    """Load headerless samples of ``shape = (nz, ny, nx)`` and ``dtype``, x varying fastest.

    Parameters
    ----------
    byteorder : {"little", "big"}
    offset : int
        Bytes to skip at the start (a header).

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
    validate.choice("byteorder", byteorder, ("little", "big"))
    dt = np.dtype(dtype).newbyteorder("<" if byteorder == "little" else ">")
    offset = validate.positive_int("offset", offset, minimum=0)
    expected = offset + int(np.prod(shape)) * dt.itemsize
    actual = path.stat().st_size
    if actual != expected:
        raise ValueError(
            f"raw file holds {actual} bytes, but shape {shape} of {dt.name} after {offset} "
            f"header bytes needs {expected}"
        )
    data = np.fromfile(path, dtype=dt, offset=offset).reshape(shape)
    return Volume(data, fitted_extent(shape) if extent is None else extent)


def _from_nifti_image(img, physical):
    data = np.asarray(img.get_fdata(dtype=np.float32))
    if data.ndim == 4 and data.shape[3] == 1:
        data = data[..., 0]
    if data.ndim != 3:
        raise ValueError(f"NIfTI image must be 3-D, got shape {data.shape}")
    data = np.ascontiguousarray(data.transpose(2, 1, 0))  # (i, j, k) -> [z, y, x]
    spacing = np.asarray(img.header.get_zooms()[:3], dtype=np.float64)
    if physical:
        sizes = (np.array(data.shape[::-1]) - 1.0) * spacing
        extent = np.stack([-sizes / 2, sizes / 2], axis=1)
    else:
        extent = fitted_extent(data.shape, spacing)
    return Volume(data, extent, copy=False)


def load_nifti(path, *, physical=False):
    """Load a NIfTI volume (``.nii``/``.nii.gz``) through nibabel, in voxel-axis order.

    Voxel axes ``(i, j, k)`` become ``(x, y, z)``; the voxel sizes set the aspect. With
    ``physical=True`` the world box is in the file's units (mm), centred on the origin.

    Examples
    --------
    >>> import nibabel, tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.nii.gz"
    >>> nibabel.save(nibabel.Nifti1Image(np.zeros((5, 3, 2), np.float32), np.eye(4)), f)
    >>> vol = load_nifti(f)
    >>> vol.shape, vol.extent[0].tolist()
    ((2, 3, 5), [-1.0, 1.0])
    """
    import nibabel

    return _from_nifti_image(nibabel.load(_existing(path)), physical)


def load_mni_template(*, resolution=2, physical=False):
    """The MNI152 T1 template bundled inside nilearn (no download): a real MRI volume.

    Raises
    ------
    ImportError
        If nilearn is not installed (``pip install 'vrlib[mri]'``).

    Examples
    --------
    >>> load_mni_template().shape        # [z, y, x] at 2 mm
    (95, 117, 99)
    """
    try:
        from nilearn.datasets import load_mni152_template
    except ImportError as exc:
        raise ImportError(
            "the MRI template ships inside nilearn: install it with pip install 'vrlib[mri]'"
        ) from exc
    if resolution not in (1, 2):
        raise ValueError(f"resolution must be 1 or 2 (mm), got {resolution!r}")
    return _from_nifti_image(load_mni152_template(resolution=resolution), physical)


def load(source, **options):
    """Load a volume from a file (by suffix) or the name ``"mni152"``.

    ``.npy`` -> :func:`load_npy`; ``.nii``/``.nii.gz`` -> :func:`load_nifti`; ``.raw`` ->
    :func:`load_raw` (``shape`` and ``dtype`` required in ``options``).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.raw"
    >>> np.ones(8, dtype=np.float32).tofile(f)
    >>> load(f, shape=(2, 2, 2), dtype="float32").value_range
    (1.0, 1.0)
    """
    if str(source) == "mni152":
        return load_mni_template(**options)
    name = Path(source).name.lower()
    if name.endswith(".npy"):
        return load_npy(source, **options)
    if name.endswith((".nii", ".nii.gz")):
        return load_nifti(source, **options)
    if name.endswith(".raw"):
        return load_raw(source, **options)
    raise ValueError(
        f"cannot tell the format of {str(source)!r}: use .npy, .nii, .nii.gz, .raw "
        "or the name 'mni152'"
    )
