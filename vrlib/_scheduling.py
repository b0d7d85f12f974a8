"""How parallel loops share out their work: each thread of a numba ``prange`` takes one
contiguous run of the iteration space, so the order of the items decides the balance (and
:func:`run_in_threads` hands serial kernels one run each in the same way); and how many
threads they run on."""

from __future__ import annotations

import contextlib
import numbers
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

__all__ = ["balanced_order", "balanced_runs", "run_in_threads", "thread_count"]


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


def balanced_runs(costs, parts):
    """Items dealt to ``parts`` runs of nearly equal work: sorted by estimated cost and dealt
    in snake order (heaviest first, 0, 1, ..., p-1, p-1, ..., 0), so each run holds items
    from all over the image.

    Examples
    --------
    >>> [run.tolist() for run in balanced_runs(np.array([5.0, 1.0, 1.0, 5.0]), 2)]
    [[0, 2], [3, 1]]
    """
    order = np.argsort(-np.asarray(costs, dtype=np.float64), kind="stable")
    runs = [[] for _ in range(parts)]
    for rank, tile in enumerate(order):
        cycle, position = divmod(rank, parts)
        runs[position if cycle % 2 == 0 else parts - 1 - position].append(tile)
    return [np.asarray(run, dtype=np.int64) for run in runs]


def balanced_order(costs, parts):
    """Tile order for a parallel loop that hands each of ``parts`` threads an equal run of it:
    the runs of :func:`balanced_runs`, one after the other.

    Examples
    --------
    >>> balanced_order(np.array([5.0, 1.0, 1.0, 5.0]), 2).tolist()
    [0, 2, 3, 1]
    """
    return np.concatenate(balanced_runs(costs, parts))


def run_in_threads(work, runs):
    """Call ``work(run)`` for each of ``runs``, each on a thread of its own, and wait for all
    (``work`` calls a serial kernel that releases the GIL, numba's ``nogil``). The threads
    share nothing they write, so the result does not depend on their number or timing.
    """
    if len(runs) == 1:
        work(runs[0])
        return
    with ThreadPoolExecutor(max_workers=len(runs)) as pool:
        for done in [pool.submit(work, run) for run in runs]:
            done.result()
