"""This machine's limits, measured: memory bandwidth and peak sample rates.

A renderer's speed means little alone: :func:`measure` finds what the machine allows for the
work a renderer does, so that each renderer's achieved rate can be stated as a fraction of its
ceiling (``make bench``, chapter 4):

* ``bandwidth``: bytes per second of a STREAM triad over arrays far larger than the caches
  (the ceiling of any pass that streams the volume from memory);
* ``trilinear``: trilinear samples per second along rays inside a brick that stays in cache,
  float32 and float64 samples (the ceiling of ray casting with the tent filter);
* ``tricubic``: the same with a 4 x 4 x 4 Mitchell-Netravali cubic (Catmull-Rom): the
  ceiling of every 4-tap filter (the cubics, the Gaussian).

The sampling kernels (:mod:`vrlib._kernels.roofline`) do only the reconstruction, advanced
incrementally along rays, with no bounds checks, classification or compositing: no renderer
can sample faster on this machine without a different algorithm.
"""

from __future__ import annotations

import numba
import numpy as np

from vrlib import validate
from vrlib._kernels import roofline as _kernel
from vrlib.cost import measure as _time

__all__ = ["measure", "BRICK", "STEPS"]

#: Samples per side of the cache-resident brick (32^3 float64 is 256 KiB: inside a core's
#: L2 cache here, 512 KiB).
BRICK = 32
#: Samples per ray; the rays stay inside the brick.
STEPS = 24


def _rays(count, direction, seed=0):
    """Ray starts whose whole path, with a cubic's taps, stays inside the brick."""
    travel = direction * (STEPS - 1)
    low, high = 1.0, BRICK - 3.0 - travel
    return np.random.default_rng(seed).uniform(low, high, (count, 3))


def measure(*, threads=None, repeats=5, elements=1 << 24, rays=1 << 16):
    """Measure this machine's ceilings (module docstring).

    Parameters
    ----------
    threads : int, optional
        Threads (default: numba's setting).
    repeats : int
        Best of this many runs of each kernel, after a warm-up.
    elements : int
        Elements per triad array (float64; the default, 128 MiB each, is far past the caches).
    rays : int
        Rays per sampling run (``STEPS`` samples each).

    Returns
    -------
    dict
        ``bandwidth`` (bytes/s), ``trilinear_float32``, ``trilinear_float64``,
        ``tricubic_float32`` and ``tricubic_float64`` (samples/s), and ``threads``.

    Examples
    --------
    >>> limits = measure(repeats=1, elements=1 << 16, rays=1 << 10)
    >>> sorted(limits)   # doctest: +NORMALIZE_WHITESPACE
    ['bandwidth', 'threads', 'tricubic_float32', 'tricubic_float64', 'trilinear_float32',
     'trilinear_float64']
    >>> bool(limits["trilinear_float32"] > limits["tricubic_float32"] > 0)
    True
    """
    repeats = validate.positive_int("repeats", repeats)
    elements = validate.positive_int("elements", elements)
    rays = validate.positive_int("rays", rays)
    previous = numba.get_num_threads()
    if threads is not None:
        numba.set_num_threads(validate.positive_int("threads", threads))
    try:
        a, b, c = (np.full(elements, v) for v in (0.0, 1.0, 2.0))
        seconds, _ = _time(lambda: _kernel.triad(a, b, c, 3.0), repeats=repeats)
        out = {"bandwidth": 24.0 * elements / seconds}
        direction = np.array([0.36, 0.48, 0.8])
        starts = _rays(rays, direction)
        sums = np.empty(rays)
        rng = np.random.default_rng(1)
        samples = rays * STEPS
        for dtype in (np.float32, np.float64):
            brick = rng.uniform(0.0, 1.0, (BRICK,) * 3).astype(dtype)
            for name, cubic in (("trilinear", False), ("tricubic", True)):
                seconds, _ = _time(lambda brick=brick, cubic=cubic: _kernel.sample_rays(
                    brick, starts, direction, STEPS, cubic, 0.0, 0.5, sums), repeats=repeats)
                out[f"{name}_{np.dtype(dtype).name}"] = samples / seconds
        out["threads"] = numba.get_num_threads()
        return out
    finally:
        numba.set_num_threads(previous)
