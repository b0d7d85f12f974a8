"""The prefilter's recursion (:mod:`vrlib.prefilter`) on lines of a 3-D array, in place.

Lines run along axis 1 of ``a[s, k, r]``: line ``(s, r)`` holds data on ``lo[s, r] ..
hi[s, r]`` (a shear pass's intermediate lines hold data on part of their length only); each is
copied to a float64 line, filtered pole by pole, and written back. Lines are independent (one
task per ``s``), so the result does not depend on the thread count.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from vrlib._kernels._jit import helper_jit, parallel_jit


@helper_jit
def _causal_start(line, n, pole, terms):
    """``sum_k p^k f_{-k}`` over the half-sample symmetric extension of ``line[:n]``:
    ``f_0, f_0, f_1, ..., f_{n-1}, f_{n-1}, ..., f_1`` (period ``2n``), ``terms`` terms; a
    whole period is completed by the geometric series of periods."""
    total = 0.0
    power = 1.0
    count = min(2 * n, terms)
    for k in range(count):
        if k == 0:
            total += line[0]
        elif k <= n:
            total += power * line[k - 1]
        else:
            total += power * line[2 * n - k]
        power *= pole
    if count == 2 * n:
        total /= 1.0 - power
    return total


@helper_jit
def filter_line(line, n, poles, terms):
    """The prefilter on ``line[:n]`` (float64), in place: per pole, the gain, the causal
    recursion ``y_k = g f_k + p y_{k-1}`` and the anticausal ``c_k = p (c_{k+1} - y_k)``."""
    if n < 2:
        return  # one sample: the extension is constant, and so are its coefficients
    for j in range(poles.shape[0]):
        pole = poles[j]
        gain = (1.0 - pole) * (1.0 - 1.0 / pole)
        for k in range(n):
            line[k] *= gain
        line[0] = _causal_start(line, n, pole, terms[j])
        for k in range(1, n):
            line[k] += pole * line[k - 1]
        line[n - 1] *= pole / (pole - 1.0)  # from the symmetry c_n = c_{n-1}
        for k in range(n - 2, -1, -1):
            line[k] = pole * (line[k + 1] - line[k])


@parallel_jit
def filter_lines(a, lo, hi, poles, terms, tiny):
    """Prefilter every line ``a[s, lo:hi + 1, r]`` in place; results below ``tiny`` in
    magnitude become exact zeros."""
    for s in prange(a.shape[0]):
        line = np.empty(a.shape[1])
        for r in range(a.shape[2]):
            first = lo[s, r]
            n = hi[s, r] - first + 1
            if n < 1:
                continue
            for k in range(n):
                line[k] = a[s, first + k, r]
            filter_line(line, n, poles, terms)
            for k in range(n):
                value = line[k]
                a[s, first + k, r] = 0.0 if abs(value) < tiny else value  # NaN stays NaN
