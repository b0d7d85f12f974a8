"""Guards for reading untrusted volume files.

A file may lie: its header may claim more samples than it holds, or more than memory can
take, a detached data file may point out of the header's folder or at a device, compressed
data may inflate far beyond its claim. The loaders check each claim here before they
allocate or read: every size against the file's length and the memory available, every
path against the header's folder, and inflate compressed data in bounded chunks.
"""

from __future__ import annotations

import bz2
import math
import os
import stat
import zlib
from pathlib import Path

import numpy as np

__all__ = ["available_bytes", "check_allocation", "regular_file", "data_file_in_folder",
           "read_exactly", "inflate", "axis_aligned", "to_world_axes", "MEMORY_SHARE"]

#: Of the memory available, the share one volume's samples may take: rendering derives more
#: (pyramids, prefiltered coefficients, the image) from them.
MEMORY_SHARE = 0.25

_CHUNK = 1 << 20  # bytes read (or inflated) at a time


def available_bytes():
    """Memory available to new allocations (Linux's MemAvailable, and the process's address
    space limit if one is set), or None if unknown."""
    found = []
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                found.append(int(line.split()[1]) * 1024)
    except OSError:
        pass
    try:
        import resource

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY:
            found.append(soft)
    except (ImportError, OSError, ValueError):
        pass
    return min(found) if found else None


def check_allocation(count, dtype, name, what="its samples"):
    """Refuse ``count`` samples of ``dtype`` (as the volume stores them:
    :func:`vrlib.volume.storage_dtype`) when they would take more than
    :data:`MEMORY_SHARE` of the memory available.

    Examples
    --------
    >>> check_allocation(10**6, "uint8", "v.den")               # 4 MB as float32: fine
    >>> check_allocation(10**15, "int16", "v.nii")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: v.nii: its samples (10^15 of them) need 4000000.0 GB in memory, ...
    """
    from vrlib.volume import storage_dtype

    needed = count * max(np.dtype(dtype).itemsize, storage_dtype(dtype).itemsize)
    available = available_bytes()
    if available is not None and needed > MEMORY_SHARE * available:
        raise ValueError(f"{name}: {what} ({_count(count)} of them) need "
                         f"{needed / 1e9:.1f} GB in memory, more than this machine can "
                         f"give one volume ({MEMORY_SHARE * available / 1e9:.1f} GB of the "
                         f"{available / 1e9:.1f} GB available)")


def _count(n):
    exponent = int(math.log10(n)) if n > 0 else 0
    return f"10^{exponent}" if n >= 10**9 and n == 10**exponent else f"{n:,}"


def regular_file(path, name=None):
    """``path`` if it is a regular file (not a folder, FIFO, socket or device, which could
    block a read or never end); raises FileNotFoundError or ValueError."""
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except OSError:
        raise FileNotFoundError(f"no file at {str(path)!r}") from None
    if not stat.S_ISREG(mode):
        kind = ("a folder" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode)
                else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "not a file")
        raise ValueError(f"{name or path.name}: {str(path)!r} is {kind}, not a regular file")
    return path


def data_file_in_folder(header, name):
    """The detached data file ``name`` that the header file ``header`` names: it must lie in
    the header's folder or below it (after following links) and be a regular file.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> (folder / "v.raw").write_bytes(b"12")
    2
    >>> data_file_in_folder(folder / "v.nhdr", "v.raw").name
    'v.raw'
    >>> data_file_in_folder(folder / "v.nhdr", "../secret.txt")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: v.nhdr: its data file '../secret.txt' lies outside the header's folder; ...
    """
    header = Path(header)
    folder = header.parent.resolve()
    if os.path.isabs(name):
        target = Path(name)
    else:
        target = folder / name
    resolved = target.resolve()
    if not resolved.is_relative_to(folder):
        raise ValueError(f"{header.name}: its data file {name!r} lies outside the header's "
                         "folder; a detached data file must lie in the header's folder or "
                         "below it")
    if not resolved.exists():
        raise FileNotFoundError(f"{header.name}: its data file {name!r} does not exist")
    return regular_file(resolved, header.name)


def read_exactly(fh, nbytes, name, what="data"):
    """``nbytes`` bytes from ``fh``, read in chunks; a file that ends first is refused as
    truncated (nothing larger than what is there is ever allocated)."""
    parts, left = [], nbytes
    while left > 0:
        part = fh.read(min(left, _CHUNK))
        if not part:
            raise ValueError(f"{name}: its {what} end after {nbytes - left} of the "
                             f"{nbytes} bytes its header claims: truncated?")
        parts.append(part)
        left -= len(part)
    return b"".join(parts)


def inflate(fh, codec, nbytes, name):
    """Decompress ``codec`` (``"gzip"`` or ``"bzip2"``) data from ``fh`` to exactly
    ``nbytes`` bytes, in bounded chunks: data that would inflate beyond that (a
    decompression bomb) or stops short is refused before more than ``nbytes`` are held.

    Examples
    --------
    >>> import gzip, io
    >>> inflate(io.BytesIO(gzip.compress(b"abcd")), "gzip", 4, "v.nrrd")
    b'abcd'
    >>> inflate(io.BytesIO(gzip.compress(b"ab") + gzip.compress(b"cd")), "gzip", 4, "v.nrrd")
    b'abcd'
    >>> inflate(io.BytesIO(gzip.compress(bytes(10**6))), "gzip", 10, "v.nrrd")
    Traceback (most recent call last):
    ...
    ValueError: v.nrrd: its gzip data inflate to more than the 10 bytes its header claims
    """
    if codec == "gzip":
        engine = zlib.decompressobj(zlib.MAX_WBITS | 32)  # gzip or zlib headers
    else:
        engine = bz2.BZ2Decompressor()
    out = bytearray()
    pending = b""
    try:
        while True:
            if not pending:
                if getattr(engine, "eof", False):
                    break
                pending = fh.read(_CHUNK)
                if not pending:
                    break
            room = nbytes - len(out) + 1  # one byte more tells an excess
            if codec == "gzip":
                out += engine.decompress(pending, room)
                pending = engine.unconsumed_tail
                if engine.eof:
                    # A gzip file may hold several members, one after another (RFC 1952,
                    # what `cat a.gz b.gz` makes): go on with the next, if any follows.
                    pending = engine.unused_data or fh.read(_CHUNK)
                    if not pending:
                        break
                    engine = zlib.decompressobj(zlib.MAX_WBITS | 16)
            else:
                out += engine.decompress(pending, max_length=room)
                pending = b""
                if not engine.needs_input and not engine.eof and len(out) <= nbytes:
                    out += engine.decompress(b"", max_length=nbytes - len(out) + 1)
            if len(out) > nbytes:
                break
    except (zlib.error, OSError, EOFError, ValueError) as error:
        raise ValueError(f"{name}: its {codec} data are corrupt ({error})") from None
    if len(out) > nbytes:
        raise ValueError(f"{name}: its {codec} data inflate to more than the {nbytes} bytes "
                         "its header claims")
    if len(out) < nbytes:
        raise ValueError(f"{name}: its {codec} data inflate to {len(out)} bytes, fewer than "
                         f"the {nbytes} its header claims: truncated?")
    return bytes(out)


def axis_aligned(directions, name):
    """How voxel axes with world ``directions`` (3x3, one row per voxel axis i, j, k) map
    to the world's x, y, z: ``(axes, signs, spacing)`` with voxel axis ``axes[w]`` running
    along world axis ``w`` in the direction ``signs[w]`` (+1 or -1) with step
    ``spacing[w]``. Directions that are not a signed permutation of the world axes (an
    oblique or sheared grid) are refused: vrlib renders axis-aligned lattices only, and a
    guess would render a wrong volume.

    Examples
    --------
    >>> axes, signs, spacing = axis_aligned(np.array([[0, 2.0, 0], [-1.0, 0, 0],
    ...                                               [0, 0, 3.0]]), "v.nrrd")
    >>> axes.tolist(), signs.tolist(), spacing.tolist()
    ([1, 0, 2], [-1.0, 1.0, 1.0], [1.0, 2.0, 3.0])
    """
    directions = np.asarray(directions, dtype=np.float64)
    if directions.shape != (3, 3) or not np.all(np.isfinite(directions)):
        raise ValueError(f"{name}: its axis directions must be 3 finite 3-vectors, got "
                         f"{directions.tolist()}")
    lengths = np.linalg.norm(directions, axis=1)
    if np.any(lengths <= 0.0):
        raise ValueError(f"{name}: an axis direction has zero length: {directions.tolist()}")
    unit = directions / lengths[:, None]
    axes = np.argmax(np.abs(unit), axis=1)  # the world axis each voxel axis runs along
    off = np.abs(unit).copy()
    off[np.arange(3), axes] = 0.0
    if len(set(axes.tolist())) != 3 or off.max() > 1e-6:
        raise ValueError(f"{name}: its voxel axes are oblique or sheared "
                         f"({np.round(directions, 6).tolist()}); vrlib renders axis-aligned "
                         "grids only: resample the volume onto world axes first")
    world_to_voxel = np.empty(3, dtype=int)
    world_to_voxel[axes] = np.arange(3)
    signs = np.sign(unit[world_to_voxel, np.arange(3)])
    return world_to_voxel, signs, lengths[world_to_voxel]


def to_world_axes(data, directions, origin, name):
    """Samples ``data`` indexed ``[k, j, i]`` on voxel axes with world ``directions`` (3x3,
    one row per voxel axis i, j, k) and first sample at world ``origin`` (or None: 0),
    turned exactly onto the world axes: ``(data [z, y, x], spacing, origin)``. Axis swaps
    become transposes and reversed axes flips (the origin moves to the new first sample);
    oblique or sheared directions are refused (:func:`axis_aligned`).

    Examples
    --------
    >>> data = np.arange(6).reshape(1, 2, 3)                  # k, j, i = 1, 2, 3
    >>> out, spacing, origin = to_world_axes(data, np.diag([-1.0, 2.0, 1.0]), None, "v")
    >>> out.tolist(), spacing.tolist(), origin.tolist()      # i ran towards -x
    ([[[2, 1, 0], [5, 4, 3]]], [1.0, 2.0, 1.0], [-2.0, 0.0, 0.0])
    """
    world_to_voxel, signs, spacing = axis_aligned(directions, name)
    # Array axis of voxel axis v is 2 - v; world axis w becomes array axis 2 - w.
    data = data.transpose([2 - world_to_voxel[w] for w in (2, 1, 0)])
    shape_xyz = np.array(data.shape[::-1])
    start = np.zeros(3) if origin is None else np.array(origin, dtype=np.float64)
    for w in range(3):
        if signs[w] < 0:
            data = np.flip(data, axis=2 - w)
            start[w] -= (shape_xyz[w] - 1) * spacing[w]
    return np.ascontiguousarray(data), spacing, start
