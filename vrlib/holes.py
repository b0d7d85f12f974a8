"""Missing data: NaN samples as holes that contribute nothing (``Volume(..., nan="transparent")``).

The rule. A hole is a sample with no value. Every point of the field whose reconstruction
gives the hole a non-zero weight has no value either, and draws as fully transparent; every
other point reconstructs exactly as it would from the finite samples alone. So a hole never
poisons its neighbours: a NaN does not spread through the filter's sums, and no invented
value is blended in. Per method:

* ray casting, the three- and two-pass shears and shear-warp resample the field, so a hole
  hides the points within the filter's reach of it (one cell for trilinear, two for the
  cubics); with ``filter="box"`` only the hole's own cell;
* splatting and :func:`vrlib.classify` classify voxels: a hole's splat or voxel is empty,
  and its neighbours are drawn as before.

How. A hole is stored as :func:`hole_value`, a finite value some 1e20 ranges above the data,
so that any non-zero weight on it moves the reconstruction far outside the range the finite
samples can reconstruct; :class:`HoleTransfer` wraps the transfer function to give such values
no opacity. Only splatting's sheet modes have code of their own: they draw a hole as nothing
(:func:`vrlib.splat.drawable` zeroes its samples) and classify the sheets with the transfer
function itself, since a sheet's mean may pass the finite samples' range. What is drawn
never depends on the number stored.

Not supported, with a clear error: prefiltered filters (their prefilter runs along whole
lines, so one hole would reach every sample of its line), and shading or gradient opacity
outside ray casting (the other methods take gradients from central differences of the
samples, which a hole would distort).
"""

from __future__ import annotations

import math

import numpy as np

from vrlib.transfer import TransferFunction

__all__ = ["hole_value", "HoleTransfer", "with_holes", "check_holes", "HOLE_SCALE"]

#: A hole's stored value lies this many data ranges above the data.
HOLE_SCALE = 1e20

_LARGEST = 1e15  # data magnitudes beyond this leave no room for the hole value in float32


def hole_value(low, high):
    """The value stored in place of a NaN sample of data spanning ``[low, high]``.

    Examples
    --------
    >>> hole_value(0.0, 2.0)
    2e+20
    """
    if max(abs(low), abs(high)) > _LARGEST:
        raise ValueError(f"volume values reach {max(abs(low), abs(high)):.3g}: holes "
                         f"(nan='transparent') need data magnitudes below {_LARGEST:g}")
    return float(high + HOLE_SCALE * max(high - low, 1.0))


class HoleTransfer(TransferFunction):
    """``inner`` within the values the finite samples can reconstruct, ``[low, high]``, and
    transparent beyond, where only reconstructions that reach a hole fall.

    Density and emission are tabulated on ``inner``'s own grid, extended by two steps past
    ``[low, high]`` on each side before they drop to zero, so that interpolating the table is
    exact wherever ``inner``'s table is, for every value the finite samples can give.

    Examples
    --------
    >>> from vrlib import Glow
    >>> tf = HoleTransfer(Glow(1.0), 0.0, 2.0)
    >>> tf.opacity_density(np.array([1.0, 2.0, 1e20])).tolist()
    [1.0, 2.0, 0.0]
    >>> float(tf.max_density(1e19, 1e20))                  # only holes reach these values
    0.0
    """

    def __init__(self, inner, low, high):
        if not isinstance(inner, TransferFunction):
            raise TypeError(f"inner must be a transfer function, got {inner!r}")
        self.inner = inner
        self.shading = inner.shading
        self.gradient_opacity = inner.gradient_opacity
        if hasattr(inner, "unit_distance"):  # the projections' unit (vrlib.projection)
            self.unit_distance = inner.unit_distance
        start, stop, pieces = inner._smooth_pieces(float(low), float(high))
        step = (stop - start) / pieces if stop > start else max(high - low, 1.0)
        # The grid of inner's table, from two steps below low to two above high.
        self._start = start + step * (math.floor((low - start) / step) - 2)
        self._stop = start + step * (math.ceil((high - start) / step) + 2)
        self._pieces = max(1, int(round((self._stop - self._start) / step)))
        self._low, self._high = low - 1.5 * step, high + 1.5 * step

    def _inside(self, values):
        return (values >= self._low) & (values <= self._high)

    def opacity_density(self, values):
        values = np.asarray(values, dtype=np.float64)
        return np.where(self._inside(values), self.inner.opacity_density(values), 0.0)

    def emission(self, values):
        values = np.asarray(values, dtype=np.float64)
        return self.inner.emission(np.clip(values, self._low, self._high))

    def max_density(self, vmin, vmax):
        vmin, vmax = np.broadcast_arrays(np.asarray(vmin, float), np.asarray(vmax, float))
        low, high = np.maximum(vmin, self._low), np.minimum(vmax, self._high)
        meets = low <= high
        out = np.where(meets, self.inner.max_density(np.where(meets, low, self._low),
                                                     np.where(meets, high, self._low)), 0.0)
        return float(out) if out.ndim == 0 else out

    def _smooth_pieces(self, low, high):
        return self._start, self._stop, self._pieces

    def __repr__(self):
        return f"HoleTransfer({self.inner!r})"


def with_holes(volume, transfer, filt, method):
    """The transfer function to render ``volume`` with: ``transfer`` itself without holes,
    else wrapped in :class:`HoleTransfer`; refuses what holes cannot take (module docs).

    Examples
    --------
    >>> from vrlib import Glow, Volume, make_filter
    >>> vol = Volume(np.array([np.nan, 1, 2, 3, 4, 5, 6, 7.0]).reshape(2, 2, 2),
    ...              nan="transparent")
    >>> with_holes(vol, Glow(1.0), make_filter("trilinear"), "raycast")
    HoleTransfer(Glow(1))
    """
    from vrlib.value_bounds import reconstructed_range

    if volume.holes is None:
        return transfer
    check_holes(filt, transfer, method)
    return HoleTransfer(transfer, *reconstructed_range(volume, filt))


def check_holes(filt, transfer=None, method="raycast"):
    """Refuse what holes cannot take (module docs): a prefiltered filter, or shading and
    gradient opacity outside ray casting.

    Examples
    --------
    >>> from vrlib import make_filter
    >>> try:
    ...     check_holes(make_filter("cardinal-bspline"))
    ... except ValueError as error:
    ...     print(str(error)[:48])
    filter 'cardinal-bspline' prefilters along whole
    """
    if filt.prefiltered:
        raise ValueError(f"filter {filt.name!r} prefilters along whole lines, so a hole would "
                         "reach every sample of its line: with NaN holes use a filter applied "
                         "to the samples (e.g. 'catmull-rom', 'trilinear', 'box')")
    if transfer is not None and transfer.needs_gradient and method != "raycast":
        raise ValueError(f"with NaN holes, shading and gradient opacity are ray cast only "
                         f"(method {method!r} takes gradients from differences of samples, "
                         "which a hole would distort): use method='raycast'")
