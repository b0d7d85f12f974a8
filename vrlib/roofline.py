"""This machine's limits, measured: memory bandwidth and peak sample rates.

A renderer's speed means little alone: :func:`measure` finds what the machine allows for the
work a renderer does, so that each renderer's achieved rate can be stated as a fraction of its
ceiling (``make bench``, chapter 4):

* ``bandwidth``: bytes per second of a STREAM triad over arrays far larger than the caches
  (the ceiling of any pass that streams the volume from memory);
* ``trilinear``: trilinear samples per second along rays inside a brick that stays in cache,
  float32 and float64 samples (the ceiling of ray casting with the tent filter);
* ``packet_trilinear``: the same with eight rays sampled at once in vector form, each
  lane's corner pairs loaded and transposed, and vector arithmetic
  (:mod:`vrlib._kernels.packets`): the ceiling of a packet kernel's sampling, beside the
  scalar one;
* ``tricubic``: the same with a 4 x 4 x 4 Mitchell-Netravali cubic (Catmull-Rom): the
  ceiling of every 4-tap filter (the cubics, the Gaussian);
* ``footprint``: footprint-table pixels per second drawn into a cache-resident sheet, for the
  trilinear and Catmull-Rom footprints of a voxel :data:`PIXELS_PER_VOXEL` pixels wide (the
  ceiling of splatting, whose point is one footprint pixel);
* ``resample``: 1-D resampled samples per second along cache-resident lines with weights per
  output, 2 taps (tent) and 4 (Catmull-Rom): the ceiling of a shear pass;
* ``slice``: 2-D samples per second of a cache-resident slice at one translation (weights shared
  by the slice), 2 x 2 and 4 x 4 taps: the ceiling of orthographic shear-warp.

The sampling kernels (:mod:`vrlib._kernels.roofline`) do only the reconstruction, advanced
incrementally along rays, with no bounds checks, classification or compositing: no renderer
can sample faster on this machine without a different algorithm.
"""

from __future__ import annotations

import contextlib

import numba
import numpy as np

from vrlib import validate
from vrlib._kernels import roofline as _kernel
from vrlib._kernels.packets import LANES
from vrlib.cost import measure as _time
from vrlib.footprint import footprint
from vrlib.view import View

__all__ = ["measure", "ray_caster_ladder", "BRICK", "STEPS", "PIXELS_PER_VOXEL", "SHEET",
           "LINE", "SLICE"]

#: Samples per side of the cache-resident brick (32^3 float64 is 256 KiB: inside a core's
#: L2 cache here, 512 KiB).
BRICK = 32
#: Samples per ray; the rays stay inside the brick.
STEPS = 24
#: Pixels across one voxel in the footprint measurement: a 256^3 volume drawn into a 512^2
#: image framed by :meth:`vrlib.View.orbit`, as in the benchmarks.
PIXELS_PER_VOXEL = 1.15
#: Sheet side (pixels), line length and slice side (samples) of the other ceilings: each
#: task's working set stays in its core's L2 cache.
SHEET, LINE, SLICE = 64, 256, 64


@contextlib.contextmanager
def _threads(threads):
    """Run the block on ``threads`` threads (``None``: numba's setting), then restore it."""
    previous = numba.get_num_threads()
    if threads is not None:
        numba.set_num_threads(validate.positive_int("threads", threads))
    try:
        yield
    finally:
        numba.set_num_threads(previous)


def _rays(count, direction, seed=0):
    """Ray starts whose whole path, with a cubic's taps, stays inside the brick."""
    travel = direction * (STEPS - 1)
    low, high = 1.0, BRICK - 3.0 - travel
    return np.random.default_rng(seed).uniform(low, high, (count, 3))


def _other_ceilings(repeats, count, rng):
    """The footprint, resampling and slice ceilings (module docstring); ``count`` sets the
    work per run (footprints drawn, lines resampled)."""
    out = {}
    tasks = numba.get_num_threads()
    px = 1.0 / PIXELS_PER_VOXEL
    view_basis = View.orbit(azimuth=30.0, elevation=20.0).basis
    for name in ("trilinear", "catmull-rom"):
        fp = footprint(name, (1.0, 1.0, 1.0), view_basis)
        reach = max(fp.extent, fp.extent_v) / px
        centres = rng.uniform(reach + 1.0, SHEET - reach - 2.0, (count, 2))
        sheets = np.zeros((tasks, SHEET, SHEET))
        seconds, drawn = _time(lambda fp=fp, centres=centres, sheets=sheets:
                               _kernel.draw_footprints(fp.table, fp.extent, fp.extent_v, px,
                                                       centres, sheets), repeats=repeats)
        out[f"footprint_{name}"] = drawn / seconds
    lines = rng.uniform(0.0, 1.0, (16, LINE)).astype(np.float32)
    resampled = np.empty((max(tasks, count // 16), LINE - 8), np.float32)
    slices = rng.uniform(0.0, 1.0, (4, SLICE + 4, SLICE + 4))
    planes = np.empty((max(tasks, count // 256), SLICE, SLICE))
    for name, ntaps in (("trilinear", 2), ("catmull-rom", 4)):
        seconds, _ = _time(lambda ntaps=ntaps: _kernel.resample_lines(
            lines, 1.004, 2.0, ntaps, 0.0, 0.5, resampled), repeats=repeats)
        out[f"resample_{name}"] = resampled.size / seconds
        weights = np.full(ntaps, 1.0 / ntaps)
        seconds, _ = _time(lambda ntaps=ntaps, weights=weights: _kernel.resample_slices(
            slices, ntaps, weights, weights, planes), repeats=repeats)
        out[f"slice_{name}"] = planes.size / seconds
    return out


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
        ``packet_trilinear_float32``, ``packet_trilinear_float64``, ``tricubic_float32``
        and ``tricubic_float64`` (samples/s), ``footprint_trilinear``
        and ``footprint_catmull-rom`` (pixels/s), ``resample_trilinear``,
        ``resample_catmull-rom``, ``slice_trilinear`` and ``slice_catmull-rom`` (samples/s;
        named by the filter whose 1-D kernel they use), and ``threads``.

    Examples
    --------
    >>> limits = measure(repeats=1, elements=1 << 16, rays=1 << 10)
    >>> sorted(limits)   # doctest: +NORMALIZE_WHITESPACE
    ['bandwidth', 'footprint_catmull-rom', 'footprint_trilinear', 'packet_trilinear_float32',
     'packet_trilinear_float64', 'resample_catmull-rom', 'resample_trilinear',
     'slice_catmull-rom', 'slice_trilinear', 'threads', 'tricubic_float32',
     'tricubic_float64', 'trilinear_float32', 'trilinear_float64']
    >>> all(v > 0 for v in limits.values())   # rates only: comparing them is a benchmark's job
    True
    """
    repeats = validate.positive_int("repeats", repeats)
    elements = validate.positive_int("elements", elements)
    rays = validate.positive_int("rays", rays)
    with _threads(threads):
        a, b, c = (np.full(elements, v) for v in (0.0, 1.0, 2.0))
        seconds, _ = _time(lambda: _kernel.triad(a, b, c, 3.0), repeats=repeats)
        out = {"bandwidth": 24.0 * elements / seconds}
        direction = np.array([0.36, 0.48, 0.8])
        starts = _rays(rays, direction)
        sums = np.empty(rays)
        # The packets' rays: the same, the last repeated to fill the last packet.
        packed = np.concatenate([starts, np.repeat(starts[-1:], -rays % LANES, axis=0)])
        packed_sums = np.empty(packed.shape[0])
        rng = np.random.default_rng(1)
        samples = rays * STEPS
        for dtype in (np.float32, np.float64):
            brick = rng.uniform(0.0, 1.0, (BRICK,) * 3).astype(dtype)
            for name, cubic in (("trilinear", False), ("tricubic", True)):
                seconds, _ = _time(lambda brick=brick, cubic=cubic: _kernel.sample_rays(
                    brick, starts, direction, STEPS, cubic, 0.0, 0.5, sums), repeats=repeats)
                out[f"{name}_{np.dtype(dtype).name}"] = samples / seconds
            seconds, _ = _time(lambda brick=brick: _kernel.sample_packets(
                brick, packed, direction, STEPS, packed_sums), repeats=repeats)
            out[f"packet_trilinear_{np.dtype(dtype).name}"] = packed.shape[0] * STEPS / seconds
        out.update(_other_ceilings(repeats, rays, rng))
        out["threads"] = numba.get_num_threads()
        return out


def ray_caster_ladder(*, threads=None, repeats=5, rays=1 << 16):
    """Where the ray caster's time goes between the trilinear ceiling and a render: the rate
    (samples/s, float64 brick in cache) of the ceiling's kernel, of the renderer's own sampling
    (positions from the global lattice, floor and bounds check), and of that sampling with the
    renderer's classification and compositing. A render's rate below the last step is lost to
    what the brick leaves out: a volume larger than the caches, ray set-up, skipping.

    Examples
    --------
    >>> ladder = ray_caster_ladder(repeats=1, rays=1 << 10)
    >>> list(ladder)
    ['ceiling', 'renderer sampling', 'with classification and compositing']
    """
    repeats = validate.positive_int("repeats", repeats)
    rays = validate.positive_int("rays", rays)
    with _threads(threads):
        direction = np.array([0.36, 0.48, 0.8])
        starts = _rays(rays, direction)
        brick = np.random.default_rng(1).uniform(0.0, 1.0, (BRICK,) * 3)
        table = np.linspace(0.0, 0.01, 256)  # a segment-opacity table over the values [0, 1]
        sums = np.empty(rays)
        samples = rays * STEPS
        runs = {
            "ceiling": lambda: _kernel.sample_rays(brick, starts, direction, STEPS, False, 0.0,
                                                   0.5, sums),
            "renderer sampling": lambda: _kernel.march_rays(brick, starts, direction, STEPS,
                                                            False, 0.0, 255.0, table, sums),
            "with classification and compositing": lambda: _kernel.march_rays(
                brick, starts, direction, STEPS, True, 0.0, 255.0, table, sums),
        }
        return {name: samples / _time(run, repeats=repeats)[0] for name, run in runs.items()}
