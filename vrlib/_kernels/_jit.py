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
import threading

import numba
import numba.cpython.unsafe.numbers
from numba import types
from numba.core import cgutils
from numba.core.compiler_lock import global_compiler_lock
from numba.extending import intrinsic

jit = functools.partial(numba.njit, cache=True, nogil=True, error_model="numpy")
"""Serial kernel decorator."""

#: Held through every launch of a parallel kernel: numba's ``workqueue`` threading layer
#: (numba's fallback without TBB or OpenMP, and the Makefile's) aborts the whole process when
#: two Python threads run parallel regions at once, so renders on several threads take
#: turns in these kernels (the serial kernels on ``vrlib._scheduling.on_threads`` do not
#: need it).
PARALLEL_LAUNCH = threading.Lock()


class _LaunchedAlone:
    """A parallel kernel called from Python under :data:`PARALLEL_LAUNCH`; every other
    attribute is the numba dispatcher's."""

    def __init__(self, dispatcher):
        self._dispatcher = dispatcher
        functools.update_wrapper(self, dispatcher, updated=())  # its name and docstring

    def __call__(self, *args, **kwargs):
        with PARALLEL_LAUNCH:
            return self._dispatcher(*args, **kwargs)

    def __getattr__(self, name):
        return getattr(self._dispatcher, name)


def parallel_jit(function):
    """Kernel decorator for loops over independent work (``numba.prange``), launched from
    Python one at a time (:data:`PARALLEL_LAUNCH`)."""
    return _LaunchedAlone(numba.njit(function, cache=True, nogil=True, error_model="numpy",
                                     parallel=True))

helper_jit = functools.partial(jit, no_cpython_wrapper=True)
"""Decorator of a helper that only compiled code calls: numba builds it no Python wrapper
(about 0.03 to 0.1 s of a first compile each; it cannot be called from Python)."""


def compiled_apart(helper):
    """``helper``, a function that kernels inline (``jit(inline="always")``), compiled once
    more as a helper of its own (:data:`helper_jit`), for a kernel that calls it instead of
    inlining it. Built from the function itself rather than from a helper that calls it:
    numba inlines by running the callee's untyped passes and copying its code at the call,
    which took 0.3 to 0.6 s of a quick start's first compile for its two such helpers
    (:func:`vrlib._kernels.raycast.raycast_quick`). Inlined, ``helper`` is never compiled
    on its own (nothing calls it from Python), so only this copy of it is ever compiled and
    kept in numba's cache under its name. Without the JIT it is the function."""
    return helper_jit(getattr(helper, "py_func", helper))


def compiled_or_cached(dispatcher, args):
    """Whether calling the kernel ``dispatcher`` with ``args`` would run without compiling:
    its signature for them is compiled in this process, or is in numba's on-disk cache
    (then loaded now, as the call would load it). Never compiles.

    numba has no public call for "load, but do not compile": this takes the dispatcher's
    cache where numba keeps it (``_cache``, as in numba 0.68) and loads as
    ``Dispatcher.compile`` does. Where that is missing, or numba's JIT is off, it answers
    True, so that a caller choosing the kernel to call compiles the one it would have
    compiled anyway.
    """
    cache = getattr(dispatcher, "_cache", None)
    if numba.config.DISABLE_JIT or cache is None:
        return True
    signature = tuple(dispatcher.typeof_pyval(a) for a in args)
    if signature in dispatcher.overloads:
        return True
    with global_compiler_lock:  # as numba's own load, in Dispatcher.compile
        compiled = cache.load_overload(signature, dispatcher.targetctx)
        if compiled is None:
            return False
        dispatcher.targetctx.insert_user_function(compiled.entry_point, compiled.fndesc,
                                                  [compiled.library])
        dispatcher.add_overload(compiled)
    return True


def readonly(array):
    """A read-only view of ``array``: numba compiles a kernel once per argument type, and an
    array that is sometimes writable, sometimes not, would compile it twice over. Kernels
    take their inputs through this."""
    view = array.view()
    view.flags.writeable = False
    return view


@intrinsic
def _without_meminfo(typingctx, array):
    """``array``'s struct with a null memory-info pointer: reference counting skips it."""
    if not isinstance(array, types.Array):
        return None

    def codegen(context, builder, signature, args):
        view = context.make_array(signature.args[0])(context, builder, args[0])
        view.meminfo = cgutils.get_null_value(view.meminfo.type)
        return view._getvalue()

    return array(array), codegen


def _same(array):
    return array


def _item_pointer(context, builder, array_type, index_type, array, index):
    """Pointer to ``array[index]`` (``index`` an integer, or a tuple of one per dimension),
    with no wraparound for a negative index."""
    if isinstance(index_type, types.Integer):
        indices = [context.cast(builder, index, index_type, types.intp)]
    else:
        indices = [context.cast(builder, builder.extract_value(index, n), t, types.intp)
                   for n, t in enumerate(index_type)]
    view = context.make_array(array_type)(context, builder, array)
    return cgutils.get_item_pointer(context, builder, array_type, view, indices,
                                    wraparound=False)


def _known_index(array, index):
    """Whether ``index`` types as an index of one element of ``array``."""
    if not isinstance(array, types.Array):
        return False
    if isinstance(index, types.Integer):
        return array.ndim == 1
    return (isinstance(index, types.BaseTuple) and len(index) == array.ndim
            and all(isinstance(t, types.Integer) for t in index))


@intrinsic
def _unchecked_load(typingctx, array, index):
    """``array[index]`` for an index known to lie inside the array: one load, without the
    test and add that a negative index would need."""
    if not _known_index(array, index):
        return None

    def codegen(context, builder, signature, args):
        aryty, indty = signature.args
        pointer = _item_pointer(context, builder, aryty, indty, args[0], args[1])
        return context.unpack_value(builder, aryty.dtype, pointer,
                                    align=None if aryty.aligned else 1)

    return array.dtype(array, index), codegen


@intrinsic
def _unchecked_store(typingctx, array, index, value):
    """``array[index] = value`` for an index known to lie inside the array, as
    :func:`_unchecked_load`."""
    if not (_known_index(array, index) and array.mutable):
        return None

    def codegen(context, builder, signature, args):
        aryty, indty, valty = signature.args
        pointer = _item_pointer(context, builder, aryty, indty, args[0], args[1])
        context.pack_value(builder, aryty.dtype,
                           context.cast(builder, args[2], valty, aryty.dtype), pointer,
                           align=None if aryty.aligned else 1)
        return context.get_dummy_value()

    return types.none(array, index, value), codegen


def _plain_load(array, index):
    return array[index]


def _plain_store(array, index, value):
    array[index] = value


def _python_trailing_zeros(n):
    return (n & -n).bit_length() - 1


trailing_zeros = (_python_trailing_zeros if numba.config.DISABLE_JIT
                  else numba.cpython.unsafe.numbers.trailing_zeros)
"""``trailing_zeros(n)``: the number of zero bits below ``n``'s lowest set bit (``n > 0``),
one instruction compiled: ``log2(n)`` for a power of two, so that ``i >> trailing_zeros(n)``
is ``i // n`` without an integer division (which takes 10 to 20 cycles here)."""

borrowed = _same if numba.config.DISABLE_JIT else _without_meminfo
"""``borrowed(array)``: ``array`` itself, for use inside a kernel call that its caller keeps
it alive for.

Compiled, the result is the same array without its reference count (the view numba's
parallel loops hand their bodies). A kernel passes such views on to the functions it calls
in its loops: each call then skips an atomic increment and decrement per array argument,
which at a call per pixel or per sample cost a third of a shaded render. Only a function's
own arguments may be borrowed (an array it allocates is freed after its last use). Without
the JIT (``NUMBA_DISABLE_JIT``) it is the identity."""


at = _plain_load if numba.config.DISABLE_JIT else _unchecked_load
"""``at(array, i)``: ``array[i]`` for an index inside the array (an integer for a 1-D array,
else a tuple of one per dimension, each in ``[0, length)``), compiled to one load: numba's own
indexing adds a test for a negative index to every load, which in the samplers' inner loops
cost a fifth of the time. Without the JIT it is plain indexing."""

put = _plain_store if numba.config.DISABLE_JIT else _unchecked_store
"""``put(array, i, value)``: ``array[i] = value``, as :data:`at` loads."""
