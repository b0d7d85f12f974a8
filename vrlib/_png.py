"""A minimal PNG encoder: 8- or 16-bit grey, RGB or RGBA, no dependencies.

Pillow (behind imageio) cannot write 16-bit colour PNGs, which the report's error images need.
Rows are stored unfiltered (filter type 0) and deflated with zlib; the output is deterministic.
"""

from __future__ import annotations

import struct
import zlib

import numpy as np

_COLOR_TYPES = {1: 0, 3: 2, 4: 6}  # channels -> PNG colour type (grey, RGB, RGBA)


def _chunk(kind, payload):
    body = kind + payload
    return struct.pack(">I", len(payload)) + body + struct.pack(">I", zlib.crc32(body))


def encode_png(pixels):
    """PNG bytes for ``pixels`` of shape (h, w) or (h, w, 1|3|4), dtype uint8 or uint16."""
    arr = np.asarray(pixels)
    if arr.ndim == 2:
        arr = arr[..., None]
    if arr.ndim != 3 or arr.shape[2] not in _COLOR_TYPES:
        raise ValueError(f"PNG pixels must be (h, w) or (h, w, 1|3|4), got {arr.shape}")
    if arr.dtype not in (np.uint8, np.uint16):
        raise ValueError(f"PNG pixels must be uint8 or uint16, got {arr.dtype}")
    height, width, channels = arr.shape
    depth = 8 * arr.dtype.itemsize
    rows = np.ascontiguousarray(arr, dtype=arr.dtype.newbyteorder(">")).reshape(height, -1)
    raw = np.concatenate([np.zeros((height, 1), np.uint8), rows.view(np.uint8)], axis=1)
    header = struct.pack(">IIBBBBB", width, height, depth, _COLOR_TYPES[channels], 0, 0, 0)
    return b"".join([
        b"\x89PNG\r\n\x1a\n",
        _chunk(b"IHDR", header),
        _chunk(b"IDAT", zlib.compress(raw.tobytes(), 6)),
        _chunk(b"IEND", b""),
    ])
