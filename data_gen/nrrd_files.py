"""Reading NRRD files (``.nrrd``, ``.nhdr`` with a detached data file) as untrusted input.

pynrrd parses the header; the samples are read here, so that every claim is checked first
(:mod:`data_gen.untrusted`): the header is read within :data:`HEADER_LIMIT` bytes, a detached
data file must lie in the header's folder and be a regular file, the claimed size is checked
against the memory and the file's length, and compressed data inflate in bounded chunks.
The orientation is applied exactly: ``space directions`` that are a signed permutation of the
world axes become flips and transposes of the samples, anatomical spaces other than RAS
(LPS, LAS) are turned to RAS as NIfTI volumes are, and oblique or sheared grids are refused.
"""

from __future__ import annotations

import os
import re

import numpy as np

from data_gen.untrusted import (
    check_allocation,
    data_file_in_folder,
    inflate,
    read_exactly,
    to_world_axes,
)

__all__ = ["HEADER_LIMIT", "read_nrrd"]

#: The most bytes a header may take (a detached header is all header).
HEADER_LIMIT = 1 << 20

_TYPES = {"i1": ("signed char", "int8", "int8_t"),
          "u1": ("uchar", "unsigned char", "uint8", "uint8_t"),
          "i2": ("short", "short int", "signed short", "signed short int", "int16", "int16_t"),
          "u2": ("ushort", "unsigned short", "unsigned short int", "uint16", "uint16_t"),
          "i4": ("int", "signed int", "int32", "int32_t"),
          "u4": ("uint", "unsigned int", "uint32", "uint32_t"),
          "i8": ("longlong", "long long", "long long int", "signed long long",
                 "signed long long int", "int64", "int64_t"),
          "u8": ("ulonglong", "unsigned long long", "unsigned long long int", "uint64",
                 "uint64_t"),
          "f4": ("float",), "f8": ("double",)}
_NUMPY_TYPE = {name: code for code, names in _TYPES.items() for name in names}

# World axes each anatomical space runs opposite to RAS along (x: left, y: posterior).
_FLIPPED_FROM_RAS = {"right-anterior-superior": (), "ras": (),
                     "left-anterior-superior": (0,), "las": (0,),
                     "left-posterior-superior": (0, 1), "lps": (0, 1)}


def _header(path):
    """``(header, data_offset)``: pynrrd's parse of the header, and where attached data
    start."""
    import nrrd

    with open(path, "rb") as fh:
        head = fh.read(HEADER_LIMIT + 1)
    found = re.search(rb"\r?\n\r?\n", head)
    if found is None:
        if len(head) > HEADER_LIMIT:
            raise ValueError(f"{path.name}: no end of an NRRD header within its first "
                             f"{HEADER_LIMIT} bytes")
        end = offset = len(head)
    else:
        end, offset = found.start(), found.end()
    lines = head[:end].decode("latin-1").splitlines()
    if not lines or not lines[0].startswith("NRRD"):
        raise ValueError(f"{path.name} is not a readable NRRD file: it does not start with "
                         "'NRRD000x'")
    try:
        return nrrd.read_header(lines), offset
    except Exception as error:  # pynrrd raises NRRDError, ValueError and others
        text = str(error).splitlines()[0] if str(error) else type(error).__name__
        raise ValueError(f"{path.name} is not a readable NRRD file: {text}") from None


def _sample_type(header, name):
    kind = str(header.get("type", "")).strip()
    if kind not in _NUMPY_TYPE:
        raise ValueError(f"{name}: NRRD type {kind!r} is not a sample type vrlib reads "
                         f"(one of {', '.join(sorted(_NUMPY_TYPE))})")
    dtype = np.dtype(_NUMPY_TYPE[kind])
    encoding = header.get("encoding")
    if dtype.itemsize > 1 and encoding not in ("ascii", "text", "txt"):
        endian = header.get("endian")
        if endian not in ("little", "big"):
            raise ValueError(f"{name}: a {kind} sample needs 'endian: little' or "
                             f"'endian: big', got {endian!r}")
        dtype = dtype.newbyteorder("<" if endian == "little" else ">")
    return dtype


def _samples(path, header, offset, shape, dtype):
    """The samples, C order, read with every size checked."""
    name = path.name
    count = int(np.prod(shape, dtype=object))
    check_allocation(count, dtype, name)
    nbytes = count * dtype.itemsize
    detached = header.get("data file", header.get("datafile"))
    if detached is not None:
        if detached.startswith("LIST") or re.search(r"%\d*d|\s", detached.strip()):
            raise ValueError(f"{name}: its data in several files ({detached!r}) are not read "
                             "by vrlib: write them into one data file")
        source, offset = data_file_in_folder(path, detached.strip()), 0
    else:
        source = path
    encoding = str(header.get("encoding", "")).lower()
    codecs = {"raw": "raw", "gzip": "gzip", "gz": "gzip", "bzip2": "bzip2", "bz2": "bzip2",
              "ascii": "ascii", "text": "ascii", "txt": "ascii"}
    if encoding not in codecs:
        raise ValueError(f"{name}: NRRD encoding {encoding!r} is not read by vrlib (raw, "
                         "gzip, bzip2 or ascii)")
    codec = codecs[encoding]
    line_skip = int(header.get("line skip", header.get("lineskip", 0)))
    byte_skip = int(header.get("byte skip", header.get("byteskip", 0)))
    if line_skip < 0 or byte_skip < -1 or (byte_skip == -1 and codec != "raw"):
        raise ValueError(f"{name}: line skip {line_skip} and byte skip {byte_skip} are "
                         "not valid NRRD skips here")
    size = os.stat(source).st_size
    with open(source, "rb") as fh:
        fh.seek(offset)
        for _ in range(line_skip):
            if not fh.readline(HEADER_LIMIT).endswith(b"\n"):
                raise ValueError(f"{name}: its data end before the {line_skip} lines to skip")
        start = fh.tell() + max(byte_skip, 0) if byte_skip != -1 else size - nbytes
        if codec == "raw":
            if start < 0 or size - start != nbytes:
                raise ValueError(f"{name}: its data file holds {max(size - start, 0)} sample "
                                 f"bytes, but its header claims {nbytes} "
                                 f"({'x'.join(map(str, shape[::-1]))} of {dtype.name})")
            fh.seek(start)
            raw = read_exactly(fh, nbytes, name)
        elif codec == "ascii":
            if size - start > 64 * count + HEADER_LIMIT:
                raise ValueError(f"{name}: its text data hold {size - start} bytes, far more "
                                 f"than {count} numbers need")
            fh.seek(start)
            text = fh.read().split()
            if len(text) != count:
                raise ValueError(f"{name}: its text data hold {len(text)} numbers, but its "
                                 f"header claims {count}")
            try:
                return np.array(text, dtype=np.float64).astype(dtype).reshape(shape)
            except ValueError:
                raise ValueError(f"{name}: its text data are not all numbers") from None
        else:
            fh.seek(start)
            raw = inflate(fh, codec, nbytes + max(byte_skip, 0), name)[max(byte_skip, 0):]
    return np.frombuffer(raw, dtype=dtype).reshape(shape)


def _orientation(header, name):
    """``(directions or None, origin or None, spacings or None)`` from the header, with
    anatomical spaces turned to RAS; non-finite values refused."""
    space = str(header.get("space", "")).strip().lower()
    flipped = _FLIPPED_FROM_RAS.get(space, ())
    directions = header.get("space directions")
    origin = header.get("space origin")
    spacings = header.get("spacings")
    if directions is not None:
        rows = [d for d in directions if d is not None and not np.all(np.isnan(d))]
        directions = np.array(rows, dtype=np.float64)
        if directions.shape != (3, 3):
            raise ValueError(f"{name}: 'space directions' must give 3 vectors of 3 numbers "
                             f"for a volume, got {directions.tolist()}")
        directions[:, list(flipped)] *= -1.0
    if origin is not None:
        origin = np.array(origin, dtype=np.float64).ravel()
        if origin.shape != (3,) or not np.all(np.isfinite(origin)):
            raise ValueError(f"{name}: 'space origin' must be 3 finite numbers, got "
                             f"{origin.tolist()}")
        origin[list(flipped)] *= -1.0
    if spacings is not None and directions is None:
        spacings = np.array(spacings, dtype=np.float64).ravel()
        if spacings.shape != (3,) or not np.all(np.isfinite(spacings) & (spacings > 0)):
            raise ValueError(f"{name}: 'spacings' must be 3 finite positive numbers, got "
                             f"{spacings.tolist()}")
    return directions, origin, spacings


def read_nrrd(path):
    """``(data [z, y, x], spacing (x, y, z) or None, origin or None)`` of an NRRD file, its
    orientation applied (module docstring).

    Examples
    --------
    >>> import nrrd, tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "v.nrrd"
    >>> data = np.arange(24, dtype=np.int16).reshape(2, 3, 4)        # [k, j, i]
    >>> nrrd.write(str(f), data, {"space": "left-posterior-superior",
    ...                           "space directions": np.diag([1.0, 1.0, 2.0]),
    ...                           "space origin": [10.0, 20.0, 0.0]}, index_order="C")
    >>> out, spacing, origin = read_nrrd(f)        # LPS: x and y run the other way in RAS
    >>> out[0, -1, :].tolist(), spacing.tolist(), origin.tolist()
    ([3, 2, 1, 0], [1.0, 1.0, 2.0], [-13.0, -22.0, 0.0])
    """
    name = path.name
    header, offset = _header(path)
    sizes = [int(n) for n in np.ravel(header.get("sizes", []))]
    if int(header.get("dimension", 0)) != 3 or len(sizes) != 3:
        raise ValueError(f"{name} must hold a 3-D volume, got {header.get('dimension')} "
                         f"dimension(s) of sizes {sizes}")
    if min(sizes) < 2:
        raise ValueError(f"{name}: every axis needs at least 2 samples, got sizes {sizes}")
    dtype = _sample_type(header, name)
    directions, origin, spacings = _orientation(header, name)
    data = _samples(path, header, offset, tuple(sizes[::-1]), dtype)  # [k, j, i]
    if directions is None:
        return data, spacings, origin
    return to_world_axes(data, directions, origin, name)
