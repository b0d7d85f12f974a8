"""A shared work queue for parallel loops whose items cost unequal, unknown amounts.

numba's ``prange`` hands each thread one fixed, contiguous run of the iterations. When the
items' costs are known only roughly (a tile of rays that meets a sparse object), one thread
can finish long before the other. Here each thread instead takes the next item from a shared
counter until none is left (:func:`take`, an atomic fetch-and-add), so the threads finish
within one item of each other. Which thread renders an item never changes its result: the
items are independent and each is computed in a fixed order.
"""

from __future__ import annotations

from numba import types
from numba.extending import intrinsic, overload


def take(counter):
    """The next item's index from ``counter`` (an int64 array of one element), and one
    more taken: ``counter[0]++``, atomically when compiled (plain Python runs one thread).

    Examples
    --------
    >>> import numpy as np
    >>> counter = np.zeros(1, dtype=np.int64)
    >>> take(counter), take(counter), int(counter[0])
    (0, 1, 2)
    """
    item = int(counter[0])
    counter[0] += 1
    return item


@intrinsic
def _fetch_and_add(typingctx, counter):
    """``counter[0] += 1`` as one atomic instruction; returns the value before."""
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64):
        return None

    def codegen(context, builder, signature, args):
        array = context.make_array(signature.args[0])(context, builder, args[0])
        one = context.get_constant(types.int64, 1)
        return builder.atomic_rmw("add", array.data, one, "monotonic")

    return types.int64(counter), codegen


@overload(take, jit_options={"cache": True})
def _take_compiled(counter):
    return lambda counter: _fetch_and_add(counter)
