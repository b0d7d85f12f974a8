"""Cost per reconstructed point: the machine record, the timing harness and the cost model.

A *reconstructed point* is one value of the reconstructed field that a renderer composites
into the image: a ray sample (ray casting), a footprint pixel (splatting: one voxel's kernel
integrated along one pixel's ray), a sample of the final lattice (three- and two-pass
shearing) or of a slice on the intermediate image (shear-warp). Every renderer counts its own
points and operations in :class:`vrlib.RenderStats` (``points``, ``operations``), so a new
renderer needs nothing here.

The model (the thesis's question, docs/derivations.md): a frame costs
``t = c_op * operations + c_pt * points + c_0``, with per-machine constants fitted to
measured frames by :func:`fit_model`; :func:`measure` times a render and records the machine
beside it, so that measurements from several machines can be merged.
"""

from __future__ import annotations

import os
import platform
import re
import time

import numpy as np

from vrlib import validate

__all__ = ["machine", "points", "measure", "fit_model"]


def machine():
    """A record of the machine and software a measurement ran on.

    Returns
    -------
    dict
        ``id`` (CPU model and logical cores, as a file-name-safe slug), ``cpu``, ``cores``,
        ``python``, ``numpy``, ``numba``, ``system``.

    Examples
    --------
    >>> record = machine()
    >>> sorted(record)
    ['cores', 'cpu', 'id', 'numba', 'numpy', 'python', 'system']
    """
    import numba

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as info:
            names = [line.split(":", 1)[1].strip() for line in info
                     if line.startswith("model name")]
        cpu = names[0] if names else cpu
    except OSError:
        pass
    cores = os.cpu_count() or 1
    slug = re.sub(r"[^a-z0-9]+", "-", f"{cpu} {cores}c".lower()).strip("-")
    return {"id": slug, "cpu": cpu, "cores": cores, "python": platform.python_version(),
            "numpy": np.__version__, "numba": numba.__version__,
            "system": f"{platform.system()} {platform.release()}"}


def points(stats):
    """Reconstructed points of one render, from its statistics (module docstring).

    Examples
    --------
    >>> from vrlib import RenderStats
    >>> points(RenderStats(samples=130, voxels=100, points=30))
    30
    >>> points(RenderStats(samples=130))
    130
    """
    return int(stats.points)


def measure(render, *, repeats=3, warmup=True):
    """Time ``render()`` (any callable; usually one returning an :class:`vrlib.Image`): the
    best of ``repeats`` runs, after one warm-up run (which compiles the kernels) unless
    ``warmup`` is False. The one timing loop of the package: chapters, benchmarks and the
    command line all time with it.

    Returns
    -------
    seconds : float
    image : Image
        What the last run returned (an image, with its statistics).

    Examples
    --------
    >>> import numpy as np
    >>> from vrlib import Glow, Volume, View, render as draw
    >>> vol, view = Volume(np.ones((4, 4, 4))), View.orbit(size=8)
    >>> seconds, image = measure(lambda: draw(vol, view, transfer=Glow(1.0)), repeats=2)
    >>> seconds > 0 and image.stats.samples > 0
    True
    """
    repeats = validate.positive_int("repeats", repeats)
    if warmup:
        render()
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        image = render()
        best = min(best, time.perf_counter() - start)
    return best, image


def fit_model(operations, counts, seconds):
    """Fit ``t = c_op * operations + c_pt * points + c_0`` to measured frames.

    Least squares on relative error (each frame weighted by ``1 / t``, so that short and long
    frames count alike), constants constrained to be non-negative.

    Parameters
    ----------
    operations, counts, seconds : array_like, one entry per frame
        Operation counts, reconstructed points, measured seconds.

    Returns
    -------
    constants : dict
        ``c_op``, ``c_pt`` (seconds per operation and per point) and ``c_0`` (seconds per
        frame).
    predicted : ndarray
        The model's time for each frame.

    Examples
    --------
    >>> ops = np.array([1e6, 4e6, 2e6, 8e6]); pts = np.array([1e4, 1e4, 5e4, 2e4])
    >>> t = 2e-9 * ops + 5e-8 * pts + 1e-3
    >>> constants, predicted = fit_model(ops, pts, t)
    >>> bool(np.allclose(predicted, t)), round(constants["c_op"] * 1e9, 3)
    (True, 2.0)
    """
    from scipy.optimize import nnls

    operations, counts, seconds = (np.asarray(a, float) for a in (operations, counts, seconds))
    if not (operations.shape == counts.shape == seconds.shape) or operations.ndim != 1:
        raise ValueError("operations, counts and seconds must be 1-D arrays of one length")
    if operations.size < 3:
        raise ValueError(f"fit_model needs at least 3 frames, got {operations.size}")
    if not np.all(seconds > 0):
        raise ValueError("seconds must all be > 0")
    design = np.column_stack([operations, counts, np.ones_like(seconds)])
    scale = design.max(axis=0)  # condition the columns before weighting
    weights = 1.0 / seconds
    solution, _ = nnls(design / scale * weights[:, None], seconds * weights)
    solution = solution / scale
    constants = dict(zip(("c_op", "c_pt", "c_0"), map(float, solution), strict=True))
    return constants, design @ solution
