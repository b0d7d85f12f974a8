"""Transfer functions: from a reconstructed value to opacity density and emitted colour.

The rendering model (eqs 1.2-1.5) needs, at every point, a differential opacity
``Omega = O(F)`` (per world unit) and an emission ``E = S(F)``. With ``1/Omega`` folded into
``S`` a segment of opacity ``alpha`` contributes ``E * alpha`` of premultiplied colour (eq 1.9).

* :class:`Glow` is the thesis's study function: ``O`` the identity (times a scale), ``S = 1``:
  "the data glows in proportion to its value", so every image error comes from reconstruction.
* :class:`LookupTransfer` tabulates density and colour for general use.
* :class:`Phong` adds gradient shading to either.
* :class:`GradientOpacity` makes the opacity depend on the gradient magnitude too (Levoy 1988):
  a transfer function of two variables, ``Omega = O(F) g(|grad F|)``.
"""

from __future__ import annotations

import pickle
import weakref
from collections import OrderedDict
from typing import NamedTuple

import numpy as np

from vrlib import validate

__all__ = ["TransferFunction", "Glow", "LookupTransfer", "Phong", "GradientOpacity",
           "PreintegratedTable", "range_maximum"]


class Phong:
    """Gradient (Phong-style) shading of the emitted colour.

    A sample with unit normal ``n = -grad F / |grad F|`` lit from direction ``l`` (towards the
    light) and seen from direction ``v`` (towards the eye) emits
    ``E * (ambient + diffuse * |n.l|) + specular * |n.h|^shininess`` with ``h`` the unit
    half-vector of ``l`` and ``v`` (two-sided lighting). Where the gradient vanishes the sample
    has no normal and is shaded as if facing the light.

    Parameters
    ----------
    ambient, diffuse, specular : float
        Non-negative coefficients.
    shininess : float
        Specular exponent (> 0).
    light : array_like of 3 floats, optional
        World direction towards the light; ``None`` (default) is a headlight along the view.

    Examples
    --------
    >>> shade = Phong(ambient=0.2, diffuse=0.8, specular=0.0)
    >>> shade.factor(np.array([[0.0, 0.0, -2.0]]), view_dir=[0, 0, 1]).tolist()
    [1.0]
    """

    def __init__(self, *, ambient=0.3, diffuse=0.7, specular=0.0, shininess=20.0, light=None):
        self.ambient = validate.finite_number("ambient", ambient, low=0.0)
        self.diffuse = validate.finite_number("diffuse", diffuse, low=0.0)
        self.specular = validate.finite_number("specular", specular, low=0.0)
        self.shininess = validate.positive_number("shininess", shininess)
        self.light = None if light is None else validate.vector3("light", light, unit=True)

    def _directions(self, view_dir):
        """Unit directions towards the eye and the light: one for every point, or per point
        (``view_dir`` of shape ``(..., 3)``, each normalised; perspective views)."""
        v = np.asarray(view_dir, dtype=np.float64)
        if v.shape == (3,):
            v = validate.vector3("view_dir", view_dir, unit=True)
        else:
            if v.ndim < 1 or v.shape[-1] != 3 or not np.all(np.isfinite(v)):
                raise ValueError("view_dir must be 3 finite floats or an array (..., 3) of "
                                 f"them, got shape {v.shape}")
            norm = np.linalg.norm(v, axis=-1, keepdims=True)
            if not np.all(norm > 0.0):
                raise ValueError("view_dir must not contain zero vectors")
            v = v / norm
        return v, v if self.light is None else self.light

    @staticmethod
    def _normals(gradient):
        """Unit normals ``-g / |g|`` and whether each gradient has one."""
        g = np.asarray(gradient, dtype=np.float64)
        norm = np.linalg.norm(g, axis=-1)
        return -g / np.where(norm > 0.0, norm, 1.0)[..., None], norm > 0.0

    def factor(self, gradient, view_dir):
        """Multiplier of the emission for gradients ``(..., 3)`` seen from ``view_dir`` (one
        unit vector towards the eye, or one per gradient)."""
        _, light = self._directions(view_dir)
        n, has = self._normals(gradient)
        ndotl = np.where(has, np.abs(np.sum(n * light, axis=-1)), 1.0)
        return self.ambient + self.diffuse * ndotl

    def highlight(self, gradient, view_dir):
        """Specular term (added to every colour channel) for gradients ``(..., 3)``."""
        v, light = self._directions(view_dir)
        half = light + v
        length = np.linalg.norm(half, axis=-1, keepdims=True)
        half = np.where(length > 0.0, half / np.where(length > 0.0, length, 1.0), light)
        n, has = self._normals(gradient)
        ndoth = np.where(has, np.abs(np.sum(n * half, axis=-1)), 1.0)
        return self.specular * ndoth**self.shininess

    def __repr__(self):
        light = None if self.light is None else self.light.tolist()
        return (
            f"Phong(ambient={self.ambient:g}, diffuse={self.diffuse:g}, "
            f"specular={self.specular:g}, shininess={self.shininess:g}, light={light})"
        )


class GradientOpacity:
    """Opacity by gradient magnitude: a factor ``g(|grad F|)`` in [0, 1] on the opacity density.

    With it a transfer function classifies by value and gradient magnitude (Levoy 1988,
    "Display of surfaces from volume data"; VolPack's examples multiply a density ramp by a
    gradient ramp): ``Omega = O(F) g(|grad F|)``, so that flat regions fade and boundaries
    show. The factor is piecewise linear through the given points and constant beyond the
    ends. It multiplies the *density* (per world unit), not a per-sample opacity, so the image
    converges as the step shrinks; where ``g`` is 0 or 1 the two readings agree.

    Parameters
    ----------
    magnitudes : array_like, shape (n,)
        Increasing gradient magnitudes (field value per world unit), ``n >= 2``, finite, >= 0.
    factors : array_like, shape (n,)
        The factor at each magnitude, in [0, 1] (at most 1, so that empty-space skipping's
        bounds on the density stay bounds).

    Examples
    --------
    >>> ramp = GradientOpacity([5.0, 20.0], [0.0, 1.0])
    >>> ramp.factor(np.array([0.0, 12.5, 100.0])).tolist()
    [0.0, 0.5, 1.0]
    """

    def __init__(self, magnitudes, factors):
        x = validate.finite_array("magnitudes", magnitudes, ndim=1)
        y = validate.finite_array("factors", factors, ndim=1)
        if x.shape[0] < 2 or y.shape != x.shape:
            raise ValueError(f"magnitudes and factors need the same length >= 2, got "
                             f"{x.shape[0]} and {y.shape[0]}")
        if np.any(x < 0.0) or np.any(np.diff(x) <= 0.0):
            raise ValueError(f"magnitudes must be >= 0 and increasing, got {x.tolist()}")
        if np.any((y < 0.0) | (y > 1.0)):
            raise ValueError(f"factors must lie in [0, 1], got {y.tolist()}")
        self.magnitudes = np.ascontiguousarray(x)
        self.factors = np.ascontiguousarray(y)

    def factor(self, magnitude):
        """The factor at gradient magnitudes ``magnitude`` (any shape)."""
        return np.interp(np.asarray(magnitude, dtype=np.float64), self.magnitudes, self.factors)

    def __repr__(self):
        return (f"GradientOpacity(magnitudes={self.magnitudes.tolist()}, "
                f"factors={self.factors.tolist()})")


class TransferFunction:
    """Base of the transfer functions: opacity density, emission, optional shading and
    gradient opacity."""

    shading = None
    gradient_opacity = None

    @property
    def needs_gradient(self):
        """Whether classifying a sample needs the field's gradient (shading or gradient
        opacity)."""
        return self.shading is not None or self.gradient_opacity is not None

    def opacity_density(self, values):
        """Opacity density ``Omega`` per world unit (>= 0) at reconstructed ``values``."""
        raise NotImplementedError

    def emission(self, values):
        """Emitted colour ``E`` (RGB, last axis) at reconstructed ``values``."""
        raise NotImplementedError

    def max_density(self, vmin, vmax):
        """Largest opacity density for any value in ``[vmin, vmax]``: 0 means skippable.

        ``vmin`` and ``vmax`` may be arrays (one interval per entry).
        """
        raise NotImplementedError

    def cache_key(self):
        """Bytes that name every setting of this transfer function (its pickle): equal for
        equal settings, different once one changes (an attribute set, a table changed in
        place). What is built from a transfer function and kept (its pre-integrated tables,
        a volume's skip grid) is kept under this key, so it never goes stale. A subclass
        that cannot be pickled gets a key equal to no other: nothing is kept for it.

        Examples
        --------
        >>> glow = Glow(1.0)
        >>> key = glow.cache_key()
        >>> glow.scale = 2.0
        >>> glow.cache_key() == key, Glow(1.0).cache_key() == key
        (False, True)
        """
        try:
            return pickle.dumps(self, protocol=pickle.HIGHEST_PROTOCOL)
        except (pickle.PicklingError, TypeError, AttributeError):
            return object()


    def _smooth_pieces(self, low, high):
        """Value grid points on which density and emission have kinks, within [low, high]."""
        raise NotImplementedError

    def segment_table(self, length, low, high, *, entries=4096):
        """Per-segment classification, tabulated for the renderers' kernels.

        For a segment of ``length`` world units at value ``v``: opacity
        ``alpha(v) = 1 - exp(-density(v) * length)`` (eq 1.4), emission ``E(v)`` and
        premultiplied colour ``E(v) alpha(v)`` (eq 1.9), on an even grid of at least
        ``entries`` values over ``[low, high]`` that has a node at every kink of the transfer
        function, so that linear interpolation between nodes is exact where the functions are
        linear and within ``dv^2 max|f''| / 8`` elsewhere: below 1e-8 for the glow function at
        optical depths up to 1 per segment, about 1e-7 for a colour table whose colour and
        opacity both change steeply. Values beyond ``[low, high]`` take the end entries: pass a
        bound on every value that can occur.

        Returns
        -------
        start, inverse_step : float
            Grid position of value ``v`` is ``(v - start) * inverse_step``.
        alpha : ndarray (n,)
        premultiplied : ndarray (n, 3)
        emission : ndarray (n, 3)

        Examples
        --------
        >>> start, inv, alpha, pre, emit = Glow(2.0).segment_table(0.5, -1.0, 1.0, entries=5)
        >>> start, inv, alpha.round(4).tolist()
        (0.0, 4.0, [0.0, 0.2212, 0.3935, 0.5276, 0.6321])
        """
        # Kept with the transfer function, as the pre-integrated tables are (shared: the
        # kernels only read them): a turntable renders every frame at one step, and a render
        # to a tolerance tries a few steps on one value table.
        return self._kept(("segment", length, float(low), float(high), entries),
                          lambda: self._segment_table(length, low, high, entries))

    def _segment_table(self, length, low, high, entries):
        start, inverse_step, density, emit = self._kept(
            ("values", float(low), float(high), entries),
            lambda: self.value_table(low, high, entries=entries))
        alpha = -np.expm1(-density * length)
        return start, inverse_step, alpha, emit * alpha[:, None], emit

    def _kept(self, key, build):
        """``build()``, kept with this transfer function under its settings
        (:meth:`cache_key`) and ``key``; the last :data:`_TABLES_KEPT` are kept. A subclass
        whose objects cannot be weakly referenced or hashed keeps nothing."""
        key = (self.cache_key(), *key)
        try:
            kept = _TABLES.setdefault(self, OrderedDict())
        except TypeError:
            return build()
        if key in kept:
            kept.move_to_end(key)
        else:
            kept[key] = build()
            while len(kept) > _TABLES_KEPT:
                kept.popitem(last=False)
        return kept[key]

    def preintegrated_table(self, length, low, high, *, entries=256, refine=4,
                            profile="linear"):
        """Pre-integrated classification: what a segment's opacity and colour need from its
        front and back values (Röttger et al. 2000; Engel, Kraus and Ertl 2001).

        For a segment of ``length`` world units along which the field runs from a front
        value ``a`` to a back value ``b`` (:mod:`vrlib._kernels.preintegration`):

        * its opacity is ``1 - exp(-length * mean density)``, the mean density
          ``(Psi(b) - Psi(a)) / (b - a)`` computed exactly from the density on the value
          grid of :meth:`value_table` and its running integral ``psi``;
        * its premultiplied colour is its opacity times ``mean_emission[i, j]``, the
          emission averaged with the weights of the light the segment sends (Max's model,
          self-attenuation included), tabulated for ``a`` and ``b`` on an even grid of
          ``entries`` values over ``[low, high]`` (read bilinearly, clamped) and integrated
          with ``refine`` points per table cell. A grey transfer function (emission 1
          everywhere) needs no colour table: its colour is its opacity.

        ``profile`` says what the field does along a segment: ``"linear"`` (a straight ramp,
        the assumption of pre-integration) or ``"step"`` (the box filter: one jump, taken at
        the segment's middle, so that no value between two labels is ever classified: half
        a segment at each end's value, composited, from the density and emission alone).

        Returns
        -------
        PreintegratedTable

        Examples
        --------
        >>> table = Glow(2.0).preintegrated_table(0.5, 0.0, 1.0)
        >>> table.grey, float(table.density[-1]), float(table.psi[-1])   # Psi(1) = int 2v dv
        (True, 2.0, 1.0)
        >>> rgb = LookupTransfer([1.0, 1.0], [[1, 0, 0], [0, 0, 1]])
        >>> mean = rgb.preintegrated_table(0.5, 0.0, 1.0, entries=3).mean_emission
        >>> mean[0, 2].round(3).tolist()      # red to blue: the front's colour weighs more
        [0.541, 0.0, 0.459]
        """
        length = validate.positive_number("length", length)
        entries = validate.positive_int("entries", entries, minimum=2)
        refine = validate.positive_int("refine", refine)
        validate.choice("profile", profile, ("linear", "step"))
        low, high = float(low), float(high)
        if not high > low:
            high = low + 1.0  # one value: any span will do
        # The last few tables are kept with the transfer function: a turntable renders many
        # frames with one step, and a render to a tolerance tries a few steps each time.
        return self._kept(("preintegrated", length, low, high, entries, refine, profile),
                          lambda: self._preintegrate(length, low, high, entries, refine,
                                                     profile))

    def _preintegrate(self, length, low, high, entries, refine, profile):
        from vrlib._kernels.preintegration import cumulative_at, mean_emission_table

        start, inv, density, emission = self.value_table(low, high)
        psi = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) / inv)])
        grey = bool(np.all(emission == 1.0))
        colour_start, colour_inv = low, (entries - 1) / (high - low)
        mean = np.ones((2, 2, 3))  # the step and grey cases need no colour table
        if not grey and profile == "linear":
            # The transfer function's own grid (its kinks are nodes), cut to [low, high]:
            # density and emission are linear between these nodes, constant beyond the ends.
            own = start + np.arange(density.shape[0]) / inv
            grid = np.union1d(np.clip(own, low, high), [low, high])
            points = np.linspace(low, high, (entries - 1) * refine + 1)
            cum_psi = np.empty(points.shape[0])
            cum_phi = np.empty((points.shape[0], 3))
            cumulative_at(grid, np.asarray(self.opacity_density(grid), dtype=np.float64),
                          np.ascontiguousarray(self.emission(grid), dtype=np.float64), points,
                          cum_psi, cum_phi)
            mean = np.empty((entries, entries, 3))
            emission_at = np.ascontiguousarray(self.emission(points[::refine]),
                                               dtype=np.float64)
            mean_emission_table(cum_psi, cum_phi, emission_at, refine,
                                length / (points[1] - points[0]), mean)
        return PreintegratedTable(start, inv, np.ascontiguousarray(density), psi,
                                  np.ascontiguousarray(emission), profile == "step", grey,
                                  colour_start, colour_inv, mean)

    def value_table(self, low, high, *, entries=4096):
        """Density and emission tabulated on the grid :meth:`segment_table` uses.

        Returns ``(start, inverse_step, density (n,), emission (n, 3))``; the density and
        emission are linear between nodes, so interpolating the table is exact.

        Examples
        --------
        >>> start, inv, density, emit = Glow(2.0).value_table(-1.0, 1.0, entries=3)
        >>> density.tolist(), emit.shape
        ([0.0, 1.0, 2.0], (3, 3))
        """
        start, stop, pieces = self._smooth_pieces(float(low), float(high))
        per_piece = max(1, -(-(entries - 1) // pieces))
        values = np.linspace(start, stop, pieces * per_piece + 1)
        inverse_step = (values.size - 1) / (stop - start)
        return start, inverse_step, self.opacity_density(values), self.emission(values)

    def densest(self, low, high):
        """:meth:`max_density` over ``[low, high]`` as a float, kept as the tables are (a
        render asks it of its volume's value range, to warn of an empty image: 20 to 130
        microseconds for a lookup table).

        Examples
        --------
        >>> LookupTransfer([0.0, 2.0, 0.0]).densest(0.0, 0.25)
        1.0
        """
        return self._kept(("densest", float(low), float(high)),
                          lambda: float(self.max_density(low, high)))

    def brightest_emission(self, low, high):
        """The largest value of any channel of the emission on :meth:`value_table`'s grid
        for ``[low, high]`` (which covers that interval, so that this bounds the emission
        there; exact on its linear pieces), kept as the tables are.

        Examples
        --------
        >>> LookupTransfer([1.0, 1.0], [[0.5, 2.0, 0.0], [0.5, 0.0, 0.0]]).brightest_emission(
        ...     0.0, 1.0)
        2.0
        """
        return self._kept(("brightest", float(low), float(high)),
                          lambda: float(self.value_table(low, high)[3].max()))


_TABLES = weakref.WeakKeyDictionary()  # tables kept per transfer function (_kept)
_TABLES_KEPT = 24


class PreintegratedTable(NamedTuple):
    """What pre-integrated classification reads (:meth:`TransferFunction.preintegrated_table`).

    ``density`` on the value grid of :meth:`TransferFunction.value_table` (position
    ``(v - start) * inverse_step``) and its running integral ``psi`` give a segment's exact
    opacity; ``mean_emission[front, back]`` (position ``(v - colour_start) *
    colour_inverse_step``) its colour over its opacity, unless ``grey``. ``step`` says the
    field jumps at the segment's middle (the box filter) instead of running linearly: the
    segment is then half a segment at each end's value, from ``density`` and ``emission``
    (on the same grid) alone.

    Examples
    --------
    >>> table = Glow(1.0).preintegrated_table(0.25, 0.0, 2.0)
    >>> table.step, table.grey, table.mean_emission.shape     # grey: no colour table
    (False, True, (2, 2, 3))
    """

    start: float
    inverse_step: float
    density: np.ndarray
    psi: np.ndarray
    emission: np.ndarray
    step: bool
    grey: bool
    colour_start: float
    colour_inverse_step: float
    mean_emission: np.ndarray


def _check_shading(shading):
    if shading is not None and not isinstance(shading, Phong):
        raise TypeError(f"shading must be a vrlib.Phong or None, got {shading!r}")
    return shading


def _check_gradient_opacity(ramp):
    if ramp is not None and not isinstance(ramp, GradientOpacity):
        raise TypeError(f"gradient_opacity must be a vrlib.GradientOpacity or None, got {ramp!r}")
    return ramp


def _extras_repr(transfer):
    out = "" if transfer.shading is None else f", shading={transfer.shading!r}"
    if transfer.gradient_opacity is not None:
        out += f", gradient_opacity={transfer.gradient_opacity!r}"
    return out


class Glow(TransferFunction):
    """The thesis's study transfer function: opacity density ``scale * F``, emission 1 (eq 1.9).

    A pixel's value is then its opacity ``1 - exp(-scale * tau)`` with ``tau`` the line
    integral of the field along its ray, and the image is grey (premultiplied RGB = alpha).

    Deviation from thesis: negative reconstructed values (a cubic's overshoot below zero) are
    clamped to zero density, so that opacity stays in [0, 1].

    Parameters
    ----------
    scale : float, default 1.0
        Opacity density per unit of field value per world unit (> 0).
    shading : Phong, optional
        Gradient shading of the (white) emission.
    gradient_opacity : GradientOpacity, optional
        A factor on the density by gradient magnitude.

    Examples
    --------
    >>> glow = Glow(2.0)
    >>> glow.opacity_density(np.array([0.5, -1.0])).tolist()
    [1.0, 0.0]
    >>> glow.emission(np.array([0.3])).tolist()
    [[1.0, 1.0, 1.0]]
    """

    def __init__(self, scale=1.0, *, shading=None, gradient_opacity=None):
        self.scale = validate.positive_number("scale", scale)
        self.shading = _check_shading(shading)
        self.gradient_opacity = _check_gradient_opacity(gradient_opacity)

    def opacity_density(self, values):
        return self.scale * np.maximum(np.asarray(values, dtype=np.float64), 0.0)

    def emission(self, values):
        values = np.asarray(values, dtype=np.float64)
        return np.ones(values.shape + (3,))

    def _smooth_pieces(self, low, high):
        # Negative values have zero density: the table starts at 0, its one kink.
        return 0.0, max(high, 0.0) if high > 0.0 else 1.0, 1

    def max_density(self, vmin, vmax):
        out = self.scale * np.maximum(np.asarray(vmax, dtype=np.float64), 0.0)
        return float(out) if out.ndim == 0 else out


    def __repr__(self):
        return f"Glow({self.scale:g}{_extras_repr(self)})"


#: Intervals that :func:`range_maximum` reads one by one rather than build its sparse table.
_FEW_INTERVALS = 4


def range_maximum(values, first, last):
    """``max(values[first:last])`` for arrays of ``first < last``: from a sparse table, or,
    for a few intervals (a render's check of its value range), read directly (for one
    interval of a table of 4096 entries: 3.5 microseconds, where building the sparse table
    took 26).

    Examples
    --------
    >>> range_maximum(np.array([1.0, 5.0, 2.0, 0.0]), np.array([0, 2]), np.array([2, 4]))
    array([5., 2.])
    """
    first, last = np.asarray(first), np.asarray(last)
    values = np.asarray(values, dtype=np.float64)
    if first.size <= _FEW_INTERVALS:
        return np.array([values[a:b].max() for a, b in zip(first.ravel().tolist(),
                                                           last.ravel().tolist(), strict=True)],
                        dtype=np.float64).reshape(first.shape)
    table = [values]  # table[lev][i] = max(values[i:i+2^lev])
    span = 1
    while 2 * span <= table[0].shape[0]:
        table.append(np.maximum(table[-1][:-span], table[-1][span:]))
        span *= 2
    count = last - first
    level = np.floor(np.log2(count)).astype(int)
    peak = np.empty(first.shape)
    for lev in np.unique(level):
        sel = level == lev
        span = 1 << lev
        peak[sel] = np.maximum(table[lev][first[sel]], table[lev][last[sel] - span])
    return peak


class LookupTransfer(TransferFunction):
    """Tabulated transfer function: density and colour at evenly spaced values, interpolated.

    Values below ``value_range[0]`` or above ``value_range[1]`` take the end entries.

    Parameters
    ----------
    density : array_like, shape (n,)
        Opacity density per world unit at ``n >= 2`` evenly spaced values; finite, >= 0.
    color : array_like, shape (n, 3), optional
        Emitted RGB at the same values, finite and >= 0; default white.
    value_range : pair of float, default (0, 1)
        The values of the first and last entries (first < last).
    shading : Phong, optional
    gradient_opacity : GradientOpacity, optional

    Examples
    --------
    >>> tf = LookupTransfer([0.0, 4.0], value_range=(0.0, 2.0))
    >>> tf.opacity_density(np.array([-1.0, 0.5, 3.0])).tolist()
    [0.0, 1.0, 4.0]
    >>> tf.max_density(0.0, 1.0)
    2.0
    """

    def __init__(self, density, color=None, *, value_range=(0.0, 1.0), shading=None,
                 gradient_opacity=None):
        dens = validate.finite_array("density", density, ndim=1)
        if dens.shape[0] < 2:
            raise ValueError(f"density table needs at least 2 entries, got {dens.shape[0]}")
        if np.any(dens < 0.0):
            raise ValueError("density table entries must be >= 0 (opacity density per unit)")
        if color is None:
            col = np.ones((dens.shape[0], 3))
        else:
            col = validate.finite_array("color", color, ndim=2)
            if col.shape != (dens.shape[0], 3):
                raise ValueError(
                    f"color table must have shape ({dens.shape[0]}, 3) to match the density "
                    f"table, got {col.shape}"
                )
            if np.any(col < 0.0):
                raise ValueError("color table entries must be >= 0")
        lo = validate.finite_number("value_range[0]", value_range[0])
        hi = validate.finite_number("value_range[1]", value_range[1])
        if not hi > lo:
            raise ValueError(f"value_range must be increasing (low < high), got ({lo}, {hi})")
        self.density = dens
        self.color = np.ascontiguousarray(col)
        self.value_range = (lo, hi)
        self.shading = _check_shading(shading)
        self.gradient_opacity = _check_gradient_opacity(gradient_opacity)

    @classmethod
    def from_alpha(cls, alpha, color=None, *, unit_distance=1.0, value_range=(0.0, 1.0),
                   shading=None, gradient_opacity=None):
        """Build from opacities per ``unit_distance`` (as VTK's scalar opacity defines them).

        ``alpha`` in [0, 1) becomes density ``-ln(1 - alpha) / unit_distance``.

        Examples
        --------
        >>> tf = LookupTransfer.from_alpha([0.0, 1 - np.exp(-2.0)], unit_distance=0.5)
        >>> np.round(tf.density, 12).tolist()
        [0.0, 4.0]
        """
        a = validate.finite_array("alpha", alpha, ndim=1)
        if np.any((a < 0.0) | (a >= 1.0)):
            raise ValueError("alpha entries must lie in [0, 1) (1 would be infinite density)")
        unit = validate.positive_number("unit_distance", unit_distance)
        made = cls(-np.log1p(-a) / unit, color, value_range=value_range, shading=shading,
                   gradient_opacity=gradient_opacity)
        made.unit_distance = unit  # the projections classify one value over this distance
        return made

    def _grid(self, table):
        """The values at which ``table``'s entries lie."""
        return np.linspace(*self.value_range, table.shape[0])

    def _interp(self, table, values, grid=None):
        values = np.asarray(values, dtype=np.float64)
        return np.interp(values, self._grid(table) if grid is None else grid, table)

    def opacity_density(self, values):
        return self._interp(self.density, values)

    def _smooth_pieces(self, low, high):
        # Density and colour are linear between the table's entries and constant outside.
        return (*self.value_range, self.density.shape[0] - 1)

    def emission(self, values):
        grid = self._grid(self.color)
        return np.stack([self._interp(self.color[:, c], values, grid) for c in range(3)],
                        axis=-1)

    def max_density(self, vmin, vmax):
        vmin, vmax = np.broadcast_arrays(np.asarray(vmin, float), np.asarray(vmax, float))
        scalar = vmin.ndim == 0
        vmin, vmax = np.atleast_1d(vmin), np.atleast_1d(vmax)
        # The interpolated function peaks at an end of the interval or at a table entry
        # strictly inside it; the entries' maximum comes from a sparse table (range maximum).
        grid = self._grid(self.density)
        best = np.maximum(self._interp(self.density, vmin, grid),
                          self._interp(self.density, vmax, grid))
        first = np.searchsorted(grid, vmin, side="right")
        last = np.searchsorted(grid, vmax, side="left")  # entries first .. last - 1
        has = last > first
        if np.any(has):
            best[has] = np.maximum(best[has], range_maximum(self.density, first[has],
                                                            last[has]))
        return float(best[0]) if scalar else best


    def __repr__(self):
        return (f"LookupTransfer(<{self.density.shape[0]} entries>, "
                f"value_range={self.value_range}{_extras_repr(self)})")
