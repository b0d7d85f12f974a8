"""How parallel loops share out their work: each thread of a numba ``prange`` takes one
contiguous run of the iteration space, so the order of the items decides the balance; and how
many threads they run on."""

from __future__ import annotations

import contextlib
import numbers

import numba
import numpy as np

__all__ = ["balanced_order", "thread_count"]


@contextlib.contextmanager
def thread_count(threads):
    """Run the block on ``threads`` numba threads (None: numba's setting), then restore it.

    Raises
    ------
    TypeError, ValueError
        ``threads`` not an integer, or outside 1 .. ``NUMBA_NUM_THREADS``.
    """
    if threads is None:
        yield
        return
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral):
        raise TypeError(f"threads must be an integer, got {threads!r}")
    limit = numba.config.NUMBA_NUM_THREADS
    if not 1 <= threads <= limit:
        raise ValueError(f"threads must be between 1 and {limit}, got {threads}")
    previous = numba.get_num_threads()
    numba.set_num_threads(int(threads))
    try:
        yield
    finally:
        numba.set_num_threads(previous)


def balanced_order(costs, parts):
    """Tile order for a parallel loop that hands each of ``parts`` threads an equal run of it.

    Tiles are sorted by estimated cost and dealt to ``parts`` runs in snake order (heaviest
    first, 0, 1, ..., p-1, p-1, ..., 0), so the runs carry nearly equal work and each holds
    tiles from all over the image.

    Examples
    --------
    >>> balanced_order(np.array([5.0, 1.0, 1.0, 5.0]), 2).tolist()
    [0, 2, 3, 1]
    """
    order = np.argsort(-np.asarray(costs, dtype=np.float64), kind="stable")
    runs = [[] for _ in range(parts)]
    for rank, tile in enumerate(order):
        cycle, position = divmod(rank, parts)
        runs[position if cycle % 2 == 0 else parts - 1 - position].append(tile)
    return np.concatenate([np.asarray(run, dtype=np.int64) for run in runs])
