"""Where a distributed render's samples come from: each rank reads only its brick.

A source is an analytic field (each rank evaluates its brick and ghost samples,
:meth:`data_gen.Field.sample_region`) or a ``.npy`` file (memory-mapped; each rank reads its
brick). Either way the ranks share one global sample lattice (:class:`Lattice`), so bricks
render on the same ray lattice and join without seams.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mpi4py import MPI

from vrlib import validate
from vrlib.value_bounds import value_bounds

__all__ = ["Lattice", "open_source", "ghost", "global_value_range"]


@dataclass(frozen=True)
class Lattice:
    """The global sample lattice: shape (z, y, x), origin and spacing (x, y, z)."""

    shape: tuple
    origin: np.ndarray
    spacing: np.ndarray

    @property
    def cells(self):
        return tuple(n - 1 for n in self.shape)

    def box(self, lo, hi):
        """World box (x, y, z arrays) of cells ``[lo, hi)``."""
        return (self.origin + np.array(lo[::-1]) * self.spacing,
                self.origin + np.array(hi[::-1]) * self.spacing)


def open_source(source, shape, extent):
    """The lattice and a reader ``read(region) -> ndarray`` of a field or a ``.npy`` file.

    ``region`` is a ``(start, stop)`` pair of sample indices per axis (z, y, x).

    Examples
    --------
    >>> import data_gen
    >>> lattice, read = open_source(data_gen.make_field("gaussian-blob"), 5, None)
    >>> lattice.shape, read([(0, 2), (0, 5), (4, 5)]).shape
    ((5, 5, 5), (2, 5, 1))
    """
    if isinstance(source, str | Path):
        path = Path(source)
        if path.suffix != ".npy" or not path.is_file():
            raise ValueError(f"source must be an analytic field or an existing .npy file, got "
                             f"{str(path)!r}")
        array = np.load(path, mmap_mode="r")
        if array.ndim != 3 or min(array.shape) < 2:
            raise ValueError(f"source {path.name} must hold a 3-D array with at least 2 "
                             f"samples per axis, got shape {array.shape}")
        if shape is not None and tuple(shape) != array.shape:
            raise ValueError(f"shape {tuple(shape)} does not match the file's {array.shape}")
        shape = array.shape
        ext = np.array([[-1.0, 1.0]] * 3) if extent is None else np.asarray(extent, float)

        def read(region):
            block = np.array(array[tuple(slice(a, b) for a, b in region)], dtype=np.float64)
            if not np.all(np.isfinite(block)):
                raise ValueError(f"source {path.name} holds NaN or infinite samples")
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
        raise TypeError(f"source must be an analytic field (data_gen.make_field) or a path to "
                        f".npy samples, got {type(source).__name__}")
    origin = ext[:, 0].copy()
    spacing = (ext[:, 1] - ext[:, 0]) / (np.array(shape[::-1]) - 1)
    return Lattice(tuple(shape), origin, spacing), read


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
