"""Reconstruction filters: the whole family in one module, built by name.

Every filter is an even 1-D kernel ``k(x)`` in voxel units; a 3-D filter is the product of
``k`` along the three axes (eq 1.1: ``F = sum f_ijk K``). Each filter offers the same small
interface:

* ``f(x)``: weights (NumPy, vectorised); ``f.derivative(x)``;
* ``f.radius``: support radius in voxels (``k`` vanishes for ``|x| >= radius``); ``f.taps``,
  the lattice samples per axis it can weight at one point, and ``f.margin``, the samples it
  reaches beyond a cell's corners;
* ``f.integral()``: the integral of ``k`` over the line;
* ``f.frequency_response(omega)``: the analytic Fourier transform, ``omega`` in radians per
  sample (the Nyquist frequency is pi);
* ``f.interpolating`` and ``f.partition_of_unity``: what theory says of the kernel;
* ``f.poles``: the prefilter's poles for a *prefiltered* filter (generalized interpolation:
  the kernel reconstructs from coefficients that :mod:`vrlib.prefilter` computes from the
  samples, so that the reconstruction passes through them), empty for the others;
  ``f.effective_response(omega)``, the response of the reconstruction from the samples;
* ``f.code``: ``(kind, p0, p1, p2)`` scalars that the numba kernels evaluate with
  :func:`vrlib._kernels.filters.weight`.

Every renderer takes filters up to :data:`MAX_RADIUS` voxels (:func:`check_radius`).

Adding a filter: a class here (the interface above; a piecewise polynomial needs only its
``pieces``) and an entry in :data:`FILTERS`. Chapters, the command line and the cost model read
:data:`FILTERS`; a kernel formula is needed only for a new ``kind`` of ``code``.

"Pyramid filter" in the volume-rendering literature of the thesis's time is the product of
tents, i.e. trilinear interpolation; a true pyramid ``1 - max |x_i|`` does not sum to one over
the lattice, so ``"pyramid"`` and ``"trilinear"`` name the same filter here.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from vrlib import validate
from vrlib._kernels import filters as _k

__all__ = [
    "Filter",
    "Box",
    "Pyramid",
    "Gaussian",
    "MitchellNetravali",
    "CardinalBSpline",
    "OMOMS",
    "FILTERS",
    "STANDARD",
    "MAX_RADIUS",
    "make_filter",
    "check_radius",
]

#: Largest filter radius (voxels) the renderers take: the kernels' tap limit over two.
MAX_RADIUS = _k.MAX_TAPS / 2
_cubic_coefficients = getattr(_k.cubic_coefficients, "py_func", _k.cubic_coefficients)


class Filter:
    """Base of the filter family (see the module docstring for the interface)."""

    name: str
    radius: float
    interpolating: bool
    partition_of_unity: bool
    #: Poles of the prefilter (:mod:`vrlib.prefilter`) whose coefficients the kernel
    #: reconstructs from; empty for a filter applied to the samples themselves.
    poles: tuple = ()

    @property
    def code(self):
        """``(kind, p0, p1, p2)``: the filter as scalars for the numba kernels."""
        raise NotImplementedError

    @property
    def params(self):
        """The filter's parameters as a dict (empty for parameter-free filters)."""
        return {}

    @property
    def taps(self):
        """Lattice samples per axis that the filter can weight at one point: ``ceil(2 r)``.

        Examples
        --------
        >>> make_filter("trilinear").taps, make_filter("catmull-rom").taps
        (2, 4)
        """
        return max(1, math.ceil(2.0 * self.radius))

    @property
    def margin(self):
        """Samples beyond a cell's corners that the filter reaches: ``ceil(r) - 1``.

        Examples
        --------
        >>> make_filter("trilinear").margin, make_filter("catmull-rom").margin
        (0, 1)
        """
        return max(0, math.ceil(self.radius) - 1)

    def __call__(self, x):
        """Weights ``k(x)`` for offsets ``x`` in voxels (array in, array out)."""
        raise NotImplementedError

    def derivative(self, x):
        """``dk/dx`` at offsets ``x`` (zero where the kernel has a kink)."""
        raise NotImplementedError

    def integral(self):
        """Integral of ``k`` over the real line."""
        raise NotImplementedError

    def frequency_response(self, omega):
        """Fourier transform ``K(omega) = int k(x) exp(-i omega x) dx`` (real: ``k`` is even)."""
        raise NotImplementedError

    @property
    def prefiltered(self):
        """True when the kernel reconstructs prefiltered coefficients, not the samples."""
        return bool(self.poles)

    @property
    def interpolates_samples(self):
        """True when the reconstruction passes through every sample: an interpolating kernel,
        or any kernel on its prefiltered coefficients."""
        return self.interpolating or self.prefiltered

    def effective_response(self, omega):
        """Frequency response of the reconstruction from the samples: the kernel's, divided
        for a prefiltered filter by the sampled kernel's ``sum_n k(n) cos(n omega)`` (the
        prefilter is its inverse; Thevenaz, Blu and Unser 2000, eq 12).

        Examples
        --------
        >>> f = make_filter("cardinal-bspline")
        >>> f.effective_response(np.array([0.0, np.pi])).round(4).tolist()  # Nyquist: 48 / pi^4
        [1.0, 0.4928]
        """
        response = self.frequency_response(omega)
        if not self.prefiltered:
            return response
        omega = np.asarray(omega, dtype=np.float64)
        sampled = np.full(omega.shape, float(self(0.0)))
        for n in range(1, math.ceil(self.radius)):
            sampled += 2.0 * float(self(float(n))) * np.cos(n * omega)
        return response / sampled

    def _key(self):
        return (type(self).__name__, self.name, tuple(self.params.values()))

    def __eq__(self, other):
        return isinstance(other, Filter) and self._key() == other._key()

    def __hash__(self):
        return hash(self._key())

    def __repr__(self):
        args = "".join(f", {k}={v:g}" for k, v in self.params.items())
        return f"make_filter({self.name!r}{args})"


# -- piecewise polynomials: box, tent and the cubics ---------------------------------------


def _cos_integral(coeffs, a, b, omega):
    """``int_a^b p(x) cos(omega x) dx`` for the polynomial ``p`` of ``coeffs`` (ascending
    powers) and ``0 <= a < b``, stable for every ``omega``."""
    omega = np.abs(np.asarray(omega, dtype=np.float64))
    out = np.empty_like(omega)
    small = omega * b < 2.0
    # Near zero: the Taylor series of the cosine, integrated term by term against p.
    w2 = omega[small] ** 2
    acc = np.zeros_like(w2)
    term = np.ones_like(w2)
    for m in range(40):
        moment = sum(c * (b ** (n + 2 * m + 1) - a ** (n + 2 * m + 1)) / (n + 2 * m + 1)
                     for n, c in enumerate(coeffs))
        acc += term * moment
        term *= -w2 / ((2 * m + 1) * (2 * m + 2))
    out[small] = acc
    # Elsewhere, by parts: int p(x) exp(i w x) dx = exp(i w x) sum_k (-1)^k p^(k)(x) / (i w)^(k+1).
    iw = 1j * omega[~small]
    total = np.zeros(iw.shape)
    for x, sign in ((b, 1.0), (a, -1.0)):
        series = np.zeros(iw.shape, dtype=np.complex128)
        power = 1.0 / iw
        derivative = np.asarray(coeffs, dtype=np.float64)
        for k in range(len(coeffs)):
            series += (-1) ** k * np.polynomial.polynomial.polyval(x, derivative) * power
            derivative = np.polynomial.polynomial.polyder(derivative)
            power = power / iw
        total += sign * (np.exp(iw * x) * series).real
    out[~small] = total
    return out


class _Piecewise(Filter):
    """An even kernel given on ``x >= 0`` by polynomial pieces ``[(a, b, coeffs), ...]``.

    ``coeffs`` are in ascending order of power; pieces cover ``[0, radius)``.
    """

    pieces: tuple

    def __call__(self, x):
        ax = np.abs(np.asarray(x, dtype=np.float64))
        out = np.zeros_like(ax)
        for a, b, coeffs in self.pieces:
            inside = (ax >= a) & (ax < b)
            out[inside] = np.polynomial.polynomial.polyval(ax[inside], coeffs)
        return out

    def derivative(self, x):
        x = np.asarray(x, dtype=np.float64)
        ax = np.abs(x)
        out = np.zeros_like(ax)
        for a, b, coeffs in self.pieces:
            inside = (ax >= a) & (ax < b)
            slope = np.polynomial.polynomial.polyder(coeffs)
            out[inside] = np.polynomial.polynomial.polyval(ax[inside], slope)
        return np.sign(x) * out

    def integral(self):
        total = 0.0
        for a, b, coeffs in self.pieces:
            anti = np.polynomial.polynomial.polyint(coeffs)
            total += np.polynomial.polynomial.polyval(b, anti) - np.polynomial.polynomial.polyval(
                a, anti
            )
        return 2.0 * float(total)

    def frequency_response(self, omega):
        omega = np.asarray(omega, dtype=np.float64)
        total = np.zeros(omega.shape)
        for a, b, coeffs in self.pieces:
            total = total + _cos_integral(coeffs, a, b, omega)
        return 2.0 * total


class Box(_Piecewise):
    """Nearest-neighbour (box) filter: 1 on [-1/2, 1/2), radius 1/2.

    Examples
    --------
    >>> f = Box()
    >>> f([-0.5, 0.0, 0.49, 0.5]).tolist()
    [1.0, 1.0, 1.0, 0.0]
    """

    name = "box"
    radius = 0.5
    interpolating = True
    partition_of_unity = True
    pieces = ((0.0, 0.5, (1.0,)),)

    @property
    def code(self):
        return (_k.BOX, 0.0, 0.0, 0.0)

    def __call__(self, x):
        # Half-open [-1/2, 1/2), so that neighbouring boxes tile the line exactly once.
        x = np.asarray(x, dtype=np.float64)
        return ((x >= -0.5) & (x < 0.5)).astype(np.float64)


class Pyramid(_Piecewise):
    """Tent filter ``max(0, 1 - |x|)``: trilinear interpolation in 3-D (the "pyramid" filter).

    Examples
    --------
    >>> f = Pyramid()
    >>> f([0.0, 0.25, 1.0]).tolist()
    [1.0, 0.75, 0.0]
    >>> round(float(f.frequency_response(np.pi)), 4)    # 4 / pi^2 at Nyquist
    0.4053
    """

    name = "pyramid"
    radius = 1.0
    interpolating = True
    partition_of_unity = True
    pieces = ((0.0, 1.0, (1.0, -1.0)),)

    @property
    def code(self):
        return (_k.TENT, 0.0, 0.0, 0.0)


class MitchellNetravali(_Piecewise):
    """The Mitchell-Netravali (B, C) family of piecewise cubics, radius 2.

    ``(B, C) = (0, 1/2)`` is Catmull-Rom (interpolating, reproduces quadratics), ``(1, 0)`` the
    cubic B-spline, ``(1/3, 1/3)`` Mitchell's recommendation. Every member sums to one over the
    lattice; it interpolates only when ``B = 0``.

    Parameters
    ----------
    B, C : float
        The family's parameters (finite; any values are accepted, the usual triangle is
        ``B, C >= 0``, ``B + 2C <= 1.5`` or so).
    name : str, optional
        Display name; defaults to ``"mitchell-netravali"``.

    Examples
    --------
    >>> f = MitchellNetravali(0.0, 0.5)
    >>> f([0.0, 1.0, 0.5]).tolist()
    [1.0, 0.0, 0.5625]
    >>> round(float(f.frequency_response(np.pi)), 4)    # 48 / pi^4 at Nyquist
    0.4928
    """

    radius = 2.0
    partition_of_unity = True

    def __init__(self, B, C, *, name="mitchell-netravali"):
        self.B = validate.finite_number("B", B)
        self.C = validate.finite_number("C", C)
        self.name = name
        # The two cubic pieces (the kernels' one definition, run as plain Python: building a
        # filter compiles nothing), divided by 6, ascending powers.
        near, far = _cubic_coefficients(self.B, self.C, 0.0)
        self.pieces = (
            (0.0, 1.0, tuple(v / 6 for v in near)),
            (1.0, 2.0, tuple(v / 6 for v in far)),
        )

    @property
    def interpolating(self):
        """True when ``B = 0``: the kernel is 1 at 0 and 0 at the other integers."""
        return self.B == 0.0

    @property
    def params(self):
        return {"B": self.B, "C": self.C}

    @property
    def code(self):
        return (_k.CUBIC, self.B, self.C, 0.0)

    def __repr__(self):
        if self.name == "mitchell-netravali":
            return f"make_filter('mitchell-netravali', B={self.B:g}, C={self.C:g})"
        return f"make_filter({self.name!r})"


class Gaussian(Filter):
    """Gaussian ``exp(-x^2 / (2 sigma^2))`` truncated at ``radius`` and normalised to unit area.

    The Gaussian does not sum to one over the lattice: a constant field is reconstructed with a
    ripple whose size follows from Poisson summation, ``sum_n k(x - n) = sum_m K(2 pi m)
    cos(2 pi m x)``, about ``2 K(2 pi)`` (1.4% at sigma = 0.5, 0.16% at 0.6).

    Parameters
    ----------
    sigma : float, default 0.6
        Standard deviation in voxels (> 0).
    radius : float, default 2.0
        Truncation radius in voxels (> 0).

    Examples
    --------
    >>> f = Gaussian(0.6, 2.0)
    >>> round(f.integral(), 12)
    1.0
    >>> bool(f(2.0) == 0.0)
    True
    """

    name = "gaussian"
    interpolating = False
    partition_of_unity = False

    def __init__(self, sigma=0.6, radius=2.0):
        self.sigma = validate.positive_number("sigma", sigma)
        self.radius = validate.positive_number("radius", radius)
        u = self.radius / (self.sigma * math.sqrt(2.0))
        self._norm = self.sigma * math.sqrt(2.0 * math.pi) * math.erf(u)

    @property
    def params(self):
        return {"sigma": self.sigma, "radius": self.radius}

    @property
    def code(self):
        return (_k.GAUSSIAN, self.sigma, self.radius, 1.0 / self._norm)

    def __call__(self, x):
        x = np.asarray(x, dtype=np.float64)
        inside = np.abs(x) < self.radius
        return np.where(inside, np.exp(-0.5 * (x / self.sigma) ** 2) / self._norm, 0.0)

    def derivative(self, x):
        x = np.asarray(x, dtype=np.float64)
        return -x / self.sigma**2 * self(x)

    def integral(self):
        return 1.0

    def frequency_response(self, omega):
        # int_{-R}^{R} exp(-x^2/2s^2 - i w x) dx = s sqrt(2 pi) exp(-s^2 w^2 / 2)
        #   * Re erf((R + i s^2 w) / (s sqrt 2)), divided by the normaliser.
        w = np.asarray(omega, dtype=np.float64)
        s, r = self.sigma, self.radius
        z = (r + 1j * s * s * w) / (s * math.sqrt(2.0))
        # exp(-s^2 w^2 / 2) * erf(z) overflows for large w; use erf(z) = 1 - exp(-z^2) w(iz).
        # exp(-s^2w^2/2 - z^2) = exp(-r^2/2s^2 - i r w), so the product stays bounded.
        gauss = np.exp(-0.5 * (s * w) ** 2)
        from scipy import special  # imported on first use: it slows `import vrlib` down

        tail = np.exp(-0.5 * (r / s) ** 2 - 1j * r * w) * special.wofz(1j * z)
        value = (gauss - tail).real
        return value * s * math.sqrt(2.0 * math.pi) / self._norm


class _Prefiltered:
    """A radius-2 kernel on prefiltered coefficients: its prefilter's one pole is derived from
    the kernel. The sampled kernel ``k(1) z + k(0) + k(1) / z`` vanishes at ``z = p`` and
    ``1 / p``, the roots of ``k(1) p^2 + k(0) p + k(1) = 0``; the prefilter ``1 / (sampled
    kernel)`` is the causal and anticausal recursion on ``p``, the root inside the unit
    circle."""

    @functools.cached_property
    def poles(self):
        """The prefilter's pole: the root of ``k(1) p^2 + k(0) p + k(1) = 0`` in (-1, 0)."""
        k0, k1 = float(self(0.0)), float(self(1.0))
        return ((math.sqrt(k0 * k0 - 4.0 * k1 * k1) - k0) / (2.0 * k1),)

    def __repr__(self):
        return f"make_filter({self.name!r})"


class CardinalBSpline(_Prefiltered, MitchellNetravali):
    """The cubic B-spline on prefiltered coefficients: the interpolating cubic spline
    (Unser 1999; Thevenaz, Blu and Unser 2000), radius 2, prefilter pole ``sqrt(3) - 2``.

    Its kernel is the cubic B-spline (``B, C = 1, 0``), not interpolating by itself; the
    reconstruction from the coefficients is (``interpolates_samples``).

    Examples
    --------
    >>> f = CardinalBSpline()
    >>> round(f.poles[0], 12) == round(math.sqrt(3.0) - 2.0, 12), f.interpolates_samples
    (True, True)
    >>> (f([0.0, 1.0, 2.0]) * 6).round(12).tolist()
    [4.0, 1.0, 0.0]
    """

    def __init__(self):
        super().__init__(1.0, 0.0, name="cardinal-bspline")

    @property
    def params(self):
        return {}


class OMOMS(_Prefiltered, _Piecewise):
    """The cubic O-MOMS kernel on prefiltered coefficients (Blu, Thevenaz and Unser 2001):
    ``B3(x) + B3''(x) / 42``, the cubic of support 4 with the smallest asymptotic
    approximation error; radius 2, prefilter pole ``(sqrt(105) - 13) / 8``.

    Its pieces on ``|x| < 1`` and ``1 <= |x| < 2`` are ``|x|^3 / 2 - x^2 + |x| / 14 + 13 / 21``
    and ``-|x|^3 / 6 + x^2 - 85 |x| / 42 + 29 / 21``; it is continuous, with a kink at 0.

    Examples
    --------
    >>> f = OMOMS()
    >>> (f([0.0, 1.0, 2.0]) * 21).round(12).tolist()
    [13.0, 4.0, 0.0]
    >>> round(f.poles[0], 12) == round((math.sqrt(105.0) - 13.0) / 8.0, 12)
    True
    """

    name = "omoms"
    radius = 2.0
    interpolating = False
    partition_of_unity = True
    _D = 1.0 / 42.0

    def __init__(self):
        near, far = _cubic_coefficients(1.0, 0.0, self._D)
        self.pieces = ((0.0, 1.0, tuple(v / 6 for v in near)),
                       (1.0, 2.0, tuple(v / 6 for v in far)))

    @property
    def code(self):
        return (_k.CUBIC, 1.0, 0.0, self._D)


def _catmull_rom():
    return MitchellNetravali(0.0, 0.5, name="catmull-rom")


def _bspline():
    return MitchellNetravali(1.0, 0.0, name="bspline")


def _mitchell():
    return MitchellNetravali(1.0 / 3.0, 1.0 / 3.0, name="mitchell")


#: Filter constructors by name. ``"trilinear"`` is an alias of ``"pyramid"``.
FILTERS = {
    "box": Box,
    "pyramid": Pyramid,
    "trilinear": Pyramid,
    "gaussian": Gaussian,
    "catmull-rom": _catmull_rom,
    "mitchell": _mitchell,
    "bspline": _bspline,
    "cardinal-bspline": CardinalBSpline,
    "omoms": OMOMS,
    "mitchell-netravali": MitchellNetravali,
}


def _standard():
    names = []
    for name, build in FILTERS.items():
        try:
            filt = build()
        except TypeError:  # a family that needs its parameters
            continue
        if filt.name == name:  # an alias builds a filter of another name
            names.append(name)
    return tuple(names)


#: The distinct filters that build by name alone (no alias, no parametric family), in the
#: order of :data:`FILTERS`: the set chapters, the command line and the cost model compare.
STANDARD = _standard()


def make_filter(spec, *args, **params):
    """Build a filter by name, or pass a :class:`Filter` through unchanged.

    Parameters
    ----------
    spec : str, tuple or Filter
        A name from :data:`FILTERS`, a tuple ``(name, *args)`` such as
        ``("mitchell-netravali", B, C)`` or ``("gaussian", sigma, radius)``, or a filter.
    *args, **params
        Parameters of the named filter (``sigma``, ``radius``, ``B``, ``C``).

    Raises
    ------
    ValueError
        An unknown name (the message lists the known ones) or an out-of-range parameter.
    TypeError
        Parameters the named filter does not take.

    Examples
    --------
    >>> make_filter("trilinear")
    make_filter('pyramid')
    >>> make_filter(("mitchell-netravali", 0.0, 0.5)).frequency_response(0.0).item()
    1.0
    >>> make_filter("gaussian", sigma=0.7).radius
    2.0
    """
    if isinstance(spec, Filter):
        if args or params:
            raise TypeError("parameters cannot be given with a Filter instance")
        return spec
    if isinstance(spec, tuple):
        if not spec:
            raise ValueError("filter tuple must start with a filter name")
        spec, args = spec[0], tuple(spec[1:]) + args
    if not isinstance(spec, str):
        raise TypeError(
            f"filter must be a name, a (name, *params) tuple or a Filter, got {spec!r}"
        )
    validate.choice("filter", spec, tuple(FILTERS))
    try:
        return FILTERS[spec](*args, **params)
    except TypeError as exc:
        raise TypeError(f"bad parameters for filter {spec!r}: {exc}") from None


def check_radius(filt):
    """Refuse a filter wider than the renderers take (:data:`MAX_RADIUS`); return it.

    Examples
    --------
    >>> check_radius(make_filter("gaussian", radius=5.0))
    Traceback (most recent call last):
    ...
    ValueError: filter radius 5 is out of range: the renderers take radii up to 4 voxels
    """
    if filt.radius > MAX_RADIUS:
        raise ValueError(f"filter radius {filt.radius:g} is out of range: the renderers take "
                         f"radii up to {MAX_RADIUS:g} voxels")
    return filt
