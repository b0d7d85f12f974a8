"""How many threads the kernels run on (:func:`thread_count`), and running a compiled
worker that takes its items from a shared queue on that many threads (:func:`on_threads`)."""

from __future__ import annotations

import concurrent.futures
import contextlib
import numbers
import threading

import numba

__all__ = ["on_threads", "thread_count", "thread_number"]


def thread_number(threads):
    """``threads`` checked, or numba's setting for None: how many threads a render runs on.

    For renderers whose kernels all run on :func:`on_threads` (no ``prange``), which need
    the number alone: setting numba's and restoring it (:func:`thread_count`) costs some
    10 microseconds a frame.

    Raises
    ------
    TypeError, ValueError
        ``threads`` not an integer, or outside 1 .. ``NUMBA_NUM_THREADS``.
    """
    if threads is None:
        return numba.get_num_threads()
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral):
        raise TypeError(f"threads must be an integer, got {threads!r}")
    limit = numba.config.NUMBA_NUM_THREADS
    if not 1 <= threads <= limit:
        raise ValueError(f"threads must be between 1 and {limit}, got {threads}")
    return int(threads)


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
    threads = thread_number(threads)
    previous = numba.get_num_threads()
    if previous == threads:  # nothing to set or restore (each costs microseconds)
        yield
        return
    numba.set_num_threads(int(threads))
    try:
        yield
    finally:
        numba.set_num_threads(previous)


_pool = None
_pool_lock = threading.Lock()


def on_threads(work, threads):
    """Call ``work(i)`` for ``i`` in ``range(threads)`` on as many threads at once (the
    caller's among them: ``i = 0``) and return when every call has; an exception in any is
    raised here. ``i`` lets each call keep scratch of its own.

    ``work`` is a compiled kernel that releases the GIL (``nogil``) and takes its items from
    a shared queue (:func:`vrlib._kernels.queue.take`) until none is left, so the calls
    share the items out between them. Python threads run it instead of a numba ``prange``:
    the kernel compiles as a plain serial function, without numba's parallel passes (1.4 s
    of the ray caster's first compile, 5 s of splatting's). Starting the calls costs tens of
    microseconds (the dispatch runs under the GIL), so a kernel whose whole run lasts about
    a millisecond keeps its ``prange``. Without the JIT (``NUMBA_DISABLE_JIT``) the queue is
    a plain counter, not atomic, and one call takes every item.

    Examples
    --------
    >>> import numpy as np
    >>> from vrlib._kernels.queue import take
    >>> counter, seen = np.zeros(1, np.int64), []
    >>> def work(i):
    ...     while (item := take(counter)) < 5:
    ...         seen.append(item)
    >>> on_threads(work, 1)
    >>> seen
    [0, 1, 2, 3, 4]
    """
    global _pool
    if threads <= 1 or numba.config.DISABLE_JIT:
        work(0)
        return
    with _pool_lock:
        if _pool is None:
            _pool = concurrent.futures.ThreadPoolExecutor(
                max(1, numba.config.NUMBA_NUM_THREADS - 1), thread_name_prefix="vrlib")
        others = [_pool.submit(work, i) for i in range(1, threads)]
    try:
        work(0)
    finally:
        concurrent.futures.wait(others)
    for call in others:
        call.result()
