"""The prefilter of generalized interpolation: samples into spline coefficients.

A prefiltered filter (:attr:`vrlib.filters.Filter.poles`; the cardinal cubic B-spline and the
cubic O-MOMS) reconstructs ``F(x) = sum_k c_k k(x - k)`` from coefficients ``c`` chosen so
that ``F`` passes through every sample: ``sum_k c_k k(n - k) = f_n`` (Thevenaz, Blu and Unser,
"Interpolation revisited", 2000). For a kernel of radius 2 the sampled kernel is
``k(1) / z + k(0) + k(1) z``, and its inverse, separable along the axes, is a causal and an
anticausal one-pole recursion on each axis (Unser, Aldroubi and Eden 1991):

    y_n = g f_n + p y_{n-1},    c_n = p (c_{n+1} - y_n),    g = (1 - p)(1 - 1 / p),

with ``p`` the pole inside the unit circle. The recursion (:mod:`vrlib._kernels.prefilter`) costs
:data:`OPERATIONS_PER_VOXEL` operations per sample, pole and axis (3 axes, one pole: 15 per
voxel).

**Which axes.** A renderer prefilters along the axes it reconstructs across: ray casting and
splatting along all three (:func:`prepared`); shear-warp along the two axes of its slices (the
slices are composited where they lie); three- and two-pass shearing the input of each pass
along that pass's axis (a pass's output holds field values, not coefficients, on a sheared
lattice, so the next pass prefilters them again: :func:`filter_lines`).

**Boundary rule, the same in every method.** Samples are extended half-sample symmetrically
beyond each face (``f_{-1-k} = f_k``: scipy's ``mode="reflect"``), and the coefficients are
those of the extended signal, found exactly: the causal recursion starts from the sum over a
whole period of the extension (or until ``|p|^k`` falls below 1e-17), the anticausal one from
the symmetry ``c_N = c_{N-1}``. Every renderer extends its lattice (and a shear pass each
line, beyond the part holding data) by repeating the border value; a radius-2 kernel reads one
coefficient past each end, where repetition and the symmetric extension agree, so the
reconstruction passes through every sample, faces included.

Coefficients smaller in magnitude than the storage type's resolution of the largest sample
(``eps * max |f|``) are set to zero: they change the field by less than its rounding, and the
empty space the prefilter's decaying ringing would fill stays empty for skipping and culling.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from vrlib._kernels import prefilter as _kernel
from vrlib.gradients import gradient_volumes
from vrlib.volume import Volume

__all__ = ["coefficients", "filter_lines", "coefficient_volume", "prepared",
           "prepared_gradients", "Tally", "OPERATIONS_PER_VOXEL"]

#: Operations per sample, pole and axis: the gain, the causal (multiply, add) and the
#: anticausal (subtract, multiply) steps.
OPERATIONS_PER_VOXEL = 5
_HORIZON = 1e-17  # causal start: terms below this fraction of the first are dropped


def _check_poles(poles):
    poles = np.array(poles, dtype=np.float64).reshape(-1)
    for pole in poles:
        if not -1.0 < pole < 0.0:
            raise ValueError(f"prefilter poles must lie in (-1, 0), got {pole!r}")
    terms = np.array([math.ceil(math.log(_HORIZON) / math.log(abs(p))) for p in poles],
                     dtype=np.int64)
    return poles, terms


def filter_lines(lines, lo, hi, poles, *, tiny=0.0):
    """Prefilter, in place, the lines along axis 1 of a 3-D array ``lines[s, k, r]``, each on
    its data range ``lo[s, r] .. hi[s, r]`` (int64 arrays; the boundary rule at each end).
    Results below ``tiny`` in magnitude become zeros."""
    poles, terms = _check_poles(poles)
    _kernel.filter_lines(lines, lo, hi, poles, terms, float(tiny))


def coefficients(samples, poles, *, axes=None, tiny=0.0):
    """Spline coefficients of ``samples`` for a prefilter with the given poles.

    Parameters
    ----------
    samples : array_like, 1 to 3 dimensions
        Real samples; float64 is used throughout.
    poles : sequence of float
        The prefilter's poles, each in (-1, 0) (:attr:`vrlib.filters.Filter.poles`).
    axes : sequence of int, optional
        Array axes to filter along (default: all).
    tiny : float, default 0
        Coefficients below this magnitude become zeros.

    Returns
    -------
    ndarray of float64
        Coefficients ``c`` whose reconstruction with the filter's kernel passes through the
        samples, with the boundary rule of the module docstring.

    Examples
    --------
    >>> import math
    >>> p = math.sqrt(3.0) - 2.0                       # the cubic B-spline's pole
    >>> c = coefficients([0.0, 0.0, 6.0, 0.0, 0.0], [p])
    >>> c.round(4).tolist()
    [0.5455, -2.7273, 10.3636, -2.7273, 0.5455]
    >>> round(float(c[1] + 4 * c[2] + c[3]) / 6, 12)   # the B-spline's weights 1/6, 4/6, 1/6
    6.0
    """
    c = np.array(samples, dtype=np.float64, order="C")
    if not 1 <= c.ndim <= 3:
        raise ValueError(f"samples must have 1 to 3 dimensions, got shape {c.shape}")
    shape = c.shape
    c = c.reshape((1,) * (3 - c.ndim) + shape)
    _check_poles(poles)
    for axis in range(len(shape)) if axes is None else axes:
        axis = axis % len(shape) + 3 - len(shape)
        # As [s, k, r] with the line axis in the middle (views, no copies), lines whole.
        lines = {0: c.transpose(1, 0, 2), 1: c, 2: c.reshape(-1, c.shape[2], 1)}[axis]
        lo = np.zeros((lines.shape[0], lines.shape[2]), np.int64)
        filter_lines(lines, lo, lo + lines.shape[1] - 1, poles, tiny=tiny)
    return c.reshape(shape)


def _tiny(volume):
    """The storage type's resolution of the volume's largest sample (module docstring)."""
    return np.finfo(volume.dtype).eps * max(abs(v) for v in volume.value_range)


def coefficient_volume(volume, filt, axes=(0, 1, 2)):
    """The volume of ``filt``'s coefficients along world ``axes`` (0, 1, 2 for x, y, z; same
    lattice and extent), computed once per filter and axes and cached on ``volume``.

    Parameters
    ----------
    volume : Volume
    filt : Filter
        A prefiltered filter (non-empty ``poles``).
    axes : tuple of int
        World axes to filter along.

    Returns
    -------
    coefficients : Volume
        Stored in ``volume``'s type (float32 or float64).
    seconds : float
        Time spent computing them in this call: 0.0 when they were cached.

    Examples
    --------
    >>> import numpy as np, vrlib
    >>> vol = vrlib.Volume(np.full((3, 4, 5), 2.0))
    >>> coeffs, seconds = coefficient_volume(vol, vrlib.make_filter("cardinal-bspline"))
    >>> np.allclose(coeffs.data, 2.0), coefficient_volume(vol, vrlib.make_filter(
    ...     "cardinal-bspline"))[1]                     # a constant is its own spline; cached
    (True, 0.0)
    """
    if not filt.prefiltered:
        raise ValueError(f"filter {filt.name!r} takes no prefilter")
    axes = tuple(sorted(axes))
    spent = []

    def build():
        start = time.perf_counter()
        c = coefficients(volume.data, filt.poles, axes=[2 - a for a in axes],
                         tiny=_tiny(volume))
        if not np.isfinite(c).all():  # within a factor of a few of the largest float
            raise ValueError(f"the {filt.name!r} prefilter overflows on samples this large "
                             f"(largest magnitude {max(map(abs, volume.value_range)):.3g}); "
                             "scale the volume's values down")
        made = Volume(c.astype(volume.dtype, copy=False), volume.extent, copy=False)
        spent.append(time.perf_counter() - start)
        return made

    made = volume.cached(("coefficients", filt.poles, axes), build, keep=4)
    return made, (spent[0] if spent else 0.0)


@dataclass
class Tally:
    """What the prefilter cost in one render: ``seconds``, ``operations`` and ``samples``
    filtered (0 when every coefficient was cached), and ``kept_seconds``, the part spent on
    coefficients kept with the volume for later frames."""

    seconds: float = 0.0
    operations: int = 0
    samples: int = 0
    kept_seconds: float = 0.0

    def add(self, seconds, samples, passes, *, kept=False):
        """Count ``samples`` filtered ``passes`` times (poles times axes) in ``seconds``;
        ``kept``: coefficients of the volume, kept with it."""
        self.seconds += seconds
        self.kept_seconds += seconds if kept else 0.0
        self.samples += int(samples)
        self.operations += OPERATIONS_PER_VOXEL * int(samples) * int(passes)

    def finish(self, stats, filt):
        """Record the tally in a render's statistics (prefiltered filters only): the
        ``prefilter`` entry, its operations added to the total (its time is in it already)."""
        if filt.prefiltered:
            stats.prefilter = {"seconds": self.seconds, "kept_seconds": self.kept_seconds,
                               "operations": self.operations, "samples": self.samples,
                               "cached": self.samples == 0}
            stats.operations += self.operations
        return stats


def prepared(volume, filt, tally, axes=(0, 1, 2)):
    """The volume a renderer reconstructs from with ``filt``: its coefficients along
    ``axes`` for a prefiltered filter (:func:`coefficient_volume`, counted in ``tally``),
    else ``volume`` itself."""
    if not filt.prefiltered:
        return volume
    made, seconds = coefficient_volume(volume, filt, axes)
    if seconds:
        tally.add(seconds, volume.data.size, len(axes) * len(filt.poles), kept=True)
    return made


def prepared_gradients(volume, filt, tally, axes):
    """The gradient's components that a renderer resamples like the values
    (:func:`vrlib.gradients.gradient_volumes`, the samples' central differences), prefiltered
    along world ``axes`` for a prefiltered filter (cached on the volume, counted in
    ``tally``)."""
    gradients = gradient_volumes(volume)
    if not filt.prefiltered:
        return gradients
    axes = tuple(sorted(axes))

    def build():
        start = time.perf_counter()
        store = np.empty(volume.shape + (3,), gradients.dtype)  # the same interleaved layout
        for component in range(3):
            store[..., component] = coefficients(gradients[component], filt.poles,
                                                 axes=[2 - a for a in axes])
        store.flags.writeable = False
        tally.add(time.perf_counter() - start, store.size, len(axes) * len(filt.poles),
                  kept=True)
        return np.moveaxis(store, -1, 0)

    return volume.cached(("gradient coefficients", filt.poles, axes), build, keep=4)
