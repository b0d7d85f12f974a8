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

``vrlib bench`` fits the model per method on this machine and keeps it in a file of its own
(:func:`model_path`, :func:`save_model`); ``render(..., method="auto", tolerance=t)`` reads it
back (:func:`load_model`) to predict which filter reaches ``t`` soonest (:mod:`vrlib.auto`).
"""

from __future__ import annotations

import functools
import json
import math
import os
import platform
import re
import time
from pathlib import Path

import numpy as np

from vrlib import validate

__all__ = ["machine", "points", "measure", "fit_model", "fit_methods", "predict",
           "model_path", "save_model", "load_model", "MODEL_FORMAT"]

#: The cost model file's format, written in it: a file of another format is refused.
MODEL_FORMAT = "vrlib cost model 1"
#: A cost model file is a few hundred bytes; a larger one is not read.
_MODEL_MAX_BYTES = 1 << 16
_CONSTANTS = ("c_op", "c_pt", "c_0")
#: Models read, by path: (the file's device, inode, size and time, the model).
_LOADED = {}


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
    return dict(_machine())


@functools.cache
def _machine():
    """:func:`machine`, read once per process (``/proc/cpuinfo`` takes a millisecond)."""
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


def fit_methods(frames):
    """The model fitted per method to measured frames (:func:`fit_model` on each method's).

    Parameters
    ----------
    frames : iterable of dict
        ``method``, ``operations``, ``points`` and ``seconds`` of each frame; at least 3 per
        method.

    Returns
    -------
    dict
        Per method: ``c_op``, ``c_pt``, ``c_0``, ``frames`` and ``median_error``, the median
        of ``|predicted / measured - 1|`` over its frames.

    Examples
    --------
    >>> frames = [{"method": "raycast", "operations": 56 * p, "points": p,
    ...            "seconds": 1e-9 * 56 * p + 1e-3} for p in (1e4, 1e5, 1e6)]
    >>> fitted = fit_methods(frames)["raycast"]
    >>> round(fitted["c_op"] * 1e9, 6) + round(fitted["c_pt"] * 1e9, 6) / 56, fitted["frames"]
    (1.0, 3)
    """
    frames = list(frames)
    fitted = {}
    for method in sorted({f["method"] for f in frames}):
        own = [f for f in frames if f["method"] == method]
        seconds = np.array([f["seconds"] for f in own], float)
        constants, predicted = fit_model([f["operations"] for f in own],
                                         [f["points"] for f in own], seconds)
        fitted[method] = {**constants, "frames": len(own),
                          "median_error": float(np.median(np.abs(predicted / seconds - 1.0)))}
    return fitted


def predict(constants, operations, points):
    """A frame's time by the model: ``c_op * operations + c_pt * points + c_0`` seconds.

    Examples
    --------
    >>> predict({"c_op": 1e-9, "c_pt": 1e-8, "c_0": 1e-3}, 1e6, 1e5)
    0.003
    """
    return (constants["c_op"] * operations + constants["c_pt"] * points
            + constants["c_0"])


def model_path():
    """Where this machine's cost model is kept: ``$VRLIB_COST_MODEL`` if set, else
    ``cost-<machine id>.json`` in vrlib's folder of the user's cache (``$XDG_CACHE_HOME``,
    by default ``~/.cache``).

    Examples
    --------
    >>> model_path().name == f"cost-{machine()['id']}.json" or "VRLIB_COST_MODEL" in os.environ
    True
    """
    given = os.environ.get("VRLIB_COST_MODEL")
    if given:
        return Path(given)
    cache = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(cache) / "vrlib" / f"cost-{machine()['id']}.json"


def save_model(methods, path=None):
    """Write a fitted model (:func:`fit_methods`) with this machine's record, atomically, to
    ``path`` (default :func:`model_path`); returns the path.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "cost.json"
    >>> save_model({"raycast": {"c_op": 1e-10, "c_pt": 1e-8, "c_0": 1e-3}}, path) == path
    True
    >>> json.loads(path.read_text())["format"]
    'vrlib cost model 1'
    """
    from vrlib.atomic import atomic_path

    path = model_path() if path is None else Path(path)
    record = {"format": MODEL_FORMAT, "machine": machine(), "methods": methods}
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(record, indent=1) + "\n")
    return path


def load_model(path=None):
    """The cost model kept at ``path`` (default :func:`model_path`), or None where there is
    none.

    Returns
    -------
    dict or None
        ``machine`` (the record of the machine it was fitted on), ``methods`` (per method, the
        constants ``c_op``, ``c_pt`` and ``c_0``) and ``path``; read once per version of the
        file (its size and time) and shared between calls: not to be changed.

    Raises
    ------
    ValueError
        The file is not a cost model ``vrlib bench`` wrote (too large, not JSON, another
        format, or a constant that is not a finite number >= 0); the message names it.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "cost.json"
    >>> load_model(path) is None
    True
    >>> _ = save_model({"raycast": {"c_op": 1e-10, "c_pt": 1e-8, "c_0": 1e-3}}, path)
    >>> load_model(path)["methods"]["raycast"]["c_pt"]
    1e-08
    """
    path = model_path() if path is None else Path(path)
    try:
        stat = os.stat(path)
        version = (stat.st_dev, stat.st_ino, stat.st_size, stat.st_mtime_ns)
        held = _LOADED.get(str(path))
        if held is not None and held[0] == version:
            return held[1]  # read once per version of the file
        with open(path, "rb") as file:
            raw = file.read(_MODEL_MAX_BYTES + 1)
    except FileNotFoundError:
        return None
    except OSError as error:
        raise ValueError(f"cost model {str(path)!r}: cannot read it ({error.strerror})") from None

    def refuse(why):
        return ValueError(f"cost model {str(path)!r}: {why}; run `vrlib bench` to fit it "
                          f"again, or set VRLIB_COST_MODEL to another file")

    if len(raw) > _MODEL_MAX_BYTES:
        raise refuse(f"larger than {_MODEL_MAX_BYTES} bytes, not a file vrlib bench wrote")
    try:
        record = json.loads(raw)
    except (UnicodeDecodeError, json.JSONDecodeError):
        raise refuse("not JSON") from None
    if not isinstance(record, dict) or record.get("format") != MODEL_FORMAT:
        raise refuse(f"not a {MODEL_FORMAT!r} file")
    methods = record.get("methods")
    if not isinstance(methods, dict) or not methods:
        raise refuse("no fitted methods")
    model = {}
    for method, constants in methods.items():
        if not isinstance(constants, dict):
            raise refuse(f"method {method!r} has no constants")
        values = {name: constants.get(name) for name in _CONSTANTS}
        for name, value in values.items():
            if (isinstance(value, bool) or not isinstance(value, (int, float))
                    or not math.isfinite(value) or value < 0):
                raise refuse(f"{method} {name} is {value!r}, not a finite number >= 0")
        model[str(method)] = {name: float(value) for name, value in values.items()}
    machine_record = record.get("machine")
    loaded = {"machine": machine_record if isinstance(machine_record, dict) else {},
              "methods": model, "path": str(path)}
    _LOADED[str(path)] = (version, loaded)
    return loaded
