"""The one place where JIT compilation flags are set for every kernel.

* ``cache=True``: compiled code is stored under ``NUMBA_CACHE_DIR`` (the Makefile points it at
  ``build/numba/<hash of the kernel sources>``), so a second process loads instead of
  recompiling. numba notices when a kernel's own file changes but not when a helper it calls
  from another file does; the hash in the folder's name keeps a stale kernel from loading.
* ``fastmath`` stays off: results must not depend on how LLVM reassociates sums, and the same
  inputs must give bit-identical images for any thread count.
* ``error_model="numpy"``: a division by zero gives inf/nan as in NumPy instead of raising
  from inside a kernel (the public functions validate inputs before they get here).

Running the suite with ``NUMBA_DISABLE_JIT=1`` executes these same functions as plain Python.
"""

from __future__ import annotations

import functools

import numba

jit = functools.partial(numba.njit, cache=True, nogil=True, error_model="numpy")
"""Serial kernel decorator."""

parallel_jit = functools.partial(
    numba.njit, cache=True, nogil=True, error_model="numpy", parallel=True
)
"""Kernel decorator for loops over independent work (``numba.prange``)."""


def readonly(array):
    """A read-only view of ``array``: numba compiles a kernel once per argument type, and an
    array that is sometimes writable, sometimes not, would compile it twice over. Kernels
    take their inputs through this."""
    view = array.view()
    view.flags.writeable = False
    return view
