"""Analytic scalar fields, exact at any point in world coordinates.

Each field can be evaluated anywhere (``field(points)`` with ``points[..., :3] = (x, y, z)``),
sampled into a :class:`vrlib.Volume` (``field.sample(n)``), and where a closed form exists it
gives its exact line integrals (for reference images) and its integral over a box (for the
mass invariant).
"""

from __future__ import annotations

import math

import numpy as np

from vrlib import validate
from vrlib.transfer import Glow
from vrlib.volume import DEFAULT_EXTENT, Volume, check_extent

__all__ = [
    "Field",
    "GaussianBlob",
    "BlobSum",
    "MarschnerLobb",
    "SmoothSphere",
    "Grating",
    "StepEdge",
]

# Points evaluated per chunk while sampling, to bound temporary memory.
_CHUNK = 1 << 21


def _points(points):
    p = np.asarray(points, dtype=np.float64)
    if p.ndim == 0 or p.shape[-1] != 3:
        raise ValueError(f"points must have (x, y, z) in their last axis, got shape {p.shape}")
    return p


def _rays(origins, directions):
    o = _points(origins)
    d = _points(directions)
    norm = np.linalg.norm(d, axis=-1, keepdims=True)
    if np.any(norm == 0.0):
        raise ValueError("directions must be non-zero vectors")
    return o, d / norm


#: The most blobs a random field takes (each is summed at every sample).
MAX_BLOBS = 10000


class Field:
    """Base of the analytic fields.

    Subclasses define ``__call__``; closed forms (``line_integral``, ``integral``) are
    optional and raise ``NotImplementedError`` where none exists.
    """

    name = "field"
    #: World box that :meth:`sample` covers by default.
    bounds = np.array(DEFAULT_EXTENT)

    def __call__(self, points):
        """Field values at world points ``(..., 3)``."""
        raise NotImplementedError

    def gradient(self, points, *, h=1e-5):
        """Gradient at world points ``(..., 3)`` (central differences unless overridden)."""
        p = _points(points)
        grad = np.empty(p.shape)
        for axis in range(3):
            step = np.zeros(3)
            step[axis] = h
            grad[..., axis] = (self(p + step) - self(p - step)) / (2.0 * h)
        return grad

    def line_integral(self, origins, directions, t0=-np.inf, t1=np.inf):
        """Exact integral of the field along rays ``origin + t * unit(direction)``, t in
        [t0, t1]."""
        raise NotImplementedError(f"{self.name} has no closed-form line integral")

    def breakpoints(self, origins, directions):
        """Ray parameters ``(n_rays, m)`` where the field jumps or kinks along each ray
        (``nan`` for none), or ``None`` for a smooth field. Quadrature splits there."""
        return None

    def integral(self, extent=None):
        """Exact integral of the field over a world box (default: all of space)."""
        raise NotImplementedError(f"{self.name} has no closed-form integral")

    def sample(self, shape, *, extent=None, dtype=np.float64):
        """Sample the field on a vertex-centred lattice into a :class:`vrlib.Volume`.

        Parameters
        ----------
        shape : int or (int, int, int)
            ``n`` for ``n^3`` samples, or ``(nz, ny, nx)``; each at least 2.
        extent : array_like, shape (3, 2), optional
            World box to cover; default :attr:`bounds`.
        dtype : {numpy.float64, numpy.float32}
            Storage type of the samples.

        Examples
        --------
        >>> from data_gen import make_field
        >>> vol = make_field("gaussian-blob", sigma=0.5).sample(5)
        >>> vol.shape, float(vol.data[2, 2, 2])
        ((5, 5, 5), 1.0)
        """
        if isinstance(shape, int | np.integer):
            shape = (shape, shape, shape)
        shape = tuple(validate.positive_int("shape", n, minimum=2) for n in shape)
        if len(shape) != 3:
            raise ValueError(f"shape must be an int or (nz, ny, nx), got {shape!r}")
        if np.dtype(dtype) not in (np.dtype(np.float32), np.dtype(np.float64)):
            raise ValueError(f"dtype must be float32 or float64, got {np.dtype(dtype)}")
        ext = check_extent(self.bounds if extent is None else extent)
        data = self.sample_region(shape, [(0, n) for n in shape], extent=ext, dtype=dtype)
        return Volume(data, ext, copy=False, transfer=Glow(1.0))

    def sample_region(self, shape, region, *, extent=None, dtype=np.float64):
        """The samples ``region`` (``(start, stop)`` per axis, z, y, x) of the lattice that
        :meth:`sample` would make with ``shape``, without the rest: how a rank of a parallel
        renderer generates only its own brick. The values equal the same entries of
        :meth:`sample`, bit for bit.

        Examples
        --------
        >>> from data_gen import make_field
        >>> field = make_field("marschner-lobb")
        >>> part = field.sample_region((9, 9, 9), [(2, 5), (0, 9), (4, 6)])
        >>> part.shape, bool((part == field.sample(9).data[2:5, :, 4:6]).all())
        ((3, 9, 2), True)
        """
        shape = tuple(int(n) for n in shape)
        ext = check_extent(self.bounds if extent is None else extent)
        region = [(int(a), int(b)) for a, b in region]
        if len(region) != 3 or any(not 0 <= a < b <= n for (a, b), n in zip(region, shape,
                                                                           strict=True)):
            raise ValueError(f"region must be (start, stop) per axis within {shape}, with "
                             f"start < stop; got {region}")
        lattice = [np.linspace(lo, hi, n) for (lo, hi), n in zip(ext, shape[::-1], strict=True)]
        axes = [lattice[a][slice(*region[2 - a])] for a in range(3)]  # x, y, z
        size = tuple(b - a for a, b in region)
        data = np.empty(size, dtype=dtype)
        plane = size[1] * size[2]
        zs_per_chunk = max(1, _CHUNK // plane)
        y, x = np.meshgrid(axes[1], axes[0], indexing="ij")
        for z0 in range(0, size[0], zs_per_chunk):
            zs = axes[2][z0 : z0 + zs_per_chunk]
            pts = np.empty((len(zs), size[1], size[2], 3))
            pts[..., 0] = x
            pts[..., 1] = y
            pts[..., 2] = zs[:, None, None]
            data[z0 : z0 + len(zs)] = self(pts)
        return data

    def __repr__(self):
        params = ", ".join(f"{k}={v!r}" for k, v in self.params().items())
        return f"make_field({self.name!r}, {params})"

    def params(self):
        """The field's parameters as a dict."""
        return {}


class GaussianBlob(Field):
    """``amplitude * exp(-|x - center|^2 / (2 sigma^2))``.

    Its line integral along a line at distance ``r`` from the centre is
    ``amplitude * sigma * sqrt(2 pi) * exp(-r^2 / (2 sigma^2))``, so a Glow image has a closed
    form for every view; :meth:`line_integral` also handles finite segments (with erf).

    Parameters
    ----------
    center : 3 floats, default (0, 0, 0)
    sigma : float, default 0.3
        Standard deviation in world units (> 0): the feature size.
    amplitude : float, default 1.0

    Examples
    --------
    >>> blob = GaussianBlob(sigma=0.5)
    >>> round(float(blob.line_integral([0, 0, -5], [0, 0, 1])), 6)   # 0.5 sqrt(2 pi)
    1.253314
    """

    name = "gaussian-blob"

    def __init__(self, center=(0.0, 0.0, 0.0), sigma=0.3, amplitude=1.0):
        self.center = validate.vector3("center", center)
        self.sigma = validate.positive_number("sigma", sigma)
        self.amplitude = validate.finite_number("amplitude", amplitude)

    def params(self):
        return {"center": self.center.tolist(), "sigma": self.sigma, "amplitude": self.amplitude}

    def __call__(self, points):
        d = _points(points) - self.center
        return self.amplitude * np.exp(-np.einsum("...i,...i->...", d, d) / (2 * self.sigma**2))

    def gradient(self, points, *, h=None):
        d = _points(points) - self.center
        return -d / self.sigma**2 * self(points)[..., None]

    def line_integral(self, origins, directions, t0=-np.inf, t1=np.inf):
        from scipy import special  # here: SciPy's special functions take 0.3 s to import

        o, d = _rays(origins, directions)
        rel = self.center - o
        tc = np.einsum("...i,...i->...", rel, d)  # ray parameter closest to the centre
        r2 = np.einsum("...i,...i->...", rel, rel) - tc**2
        s2 = self.sigma * math.sqrt(2.0)
        span = special.erf((np.asarray(t1) - tc) / s2) - special.erf((np.asarray(t0) - tc) / s2)
        peak = self.amplitude * np.exp(-np.maximum(r2, 0.0) / (2 * self.sigma**2))
        return peak * self.sigma * math.sqrt(math.pi / 2.0) * span

    def integral(self, extent=None):
        if extent is None:
            return self.amplitude * (2 * math.pi) ** 1.5 * self.sigma**3
        ext = check_extent(extent)
        s2 = self.sigma * math.sqrt(2.0)
        total = self.amplitude
        for (lo, hi), c in zip(ext, self.center, strict=True):
            total *= self.sigma * math.sqrt(math.pi / 2.0) * (
                math.erf((hi - c) / s2) - math.erf((lo - c) / s2)
            )
        return total


class BlobSum(Field):
    """A sum of Gaussian blobs; closed forms add up.

    Parameters
    ----------
    blobs : sequence of GaussianBlob or dict
        The blobs, or their parameters as dicts.

    Examples
    --------
    >>> field = BlobSum.random(4, seed=1)
    >>> len(field.blobs), field.name
    (4, 'blobs')
    """

    name = "blobs"

    def __init__(self, blobs):
        made = [b if isinstance(b, GaussianBlob) else GaussianBlob(**b) for b in blobs]
        if not made:
            raise ValueError("blobs must hold at least one blob")
        self.blobs = made

    @classmethod
    def random(cls, count=8, *, seed=0, sigma=(0.05, 0.15), amplitude=(0.5, 1.0), region=0.7):
        """``count`` blobs with centres uniform in ``[-region, region]^3`` (reproducible).

        ``sigma`` and ``amplitude`` are (low, high) ranges drawn uniformly.
        """
        count = validate.positive_int("count", count)
        if count > MAX_BLOBS:
            raise ValueError(f"count must be at most {MAX_BLOBS} blobs, got {count}")
        rng = np.random.default_rng(seed)
        centers = rng.uniform(-region, region, size=(count, 3))
        sigmas = rng.uniform(*sigma, size=count)
        amps = rng.uniform(*amplitude, size=count)
        return cls([GaussianBlob(c, s, a) for c, s, a in zip(centers, sigmas, amps, strict=True)])

    def params(self):
        return {"blobs": [b.params() for b in self.blobs]}

    def __call__(self, points):
        return sum(b(points) for b in self.blobs)

    def gradient(self, points, *, h=None):
        return sum(b.gradient(points) for b in self.blobs)

    def line_integral(self, origins, directions, t0=-np.inf, t1=np.inf):
        return sum(b.line_integral(origins, directions, t0, t1) for b in self.blobs)

    def integral(self, extent=None):
        return sum(b.integral(extent) for b in self.blobs)


class MarschnerLobb(Field):
    """The Marschner-Lobb (1994) filter test signal on [-1, 1]^3.

    ``rho = (1 - sin(pi z / 2) + alpha (1 + cos(2 pi fM cos(pi r / 2)))) / (2 (1 + alpha))``
    with ``r = sqrt(x^2 + y^2)``, the 2-D radius. Values lie in [0, 1]. Usually sampled at
    40^3 or 41^3, just under its Nyquist rate.

    Parameters
    ----------
    fM : float, default 6
    alpha : float, default 0.25

    Examples
    --------
    >>> round(float(MarschnerLobb()([0.0, 0.0, -1.0])), 6)
    1.0
    """

    name = "marschner-lobb"

    def __init__(self, fM=6.0, alpha=0.25):
        self.fM = validate.positive_number("fM", fM)
        self.alpha = validate.finite_number("alpha", alpha, low=0.0)

    def params(self):
        return {"fM": self.fM, "alpha": self.alpha}

    def __call__(self, points):
        p = _points(points)
        r = np.hypot(p[..., 0], p[..., 1])
        ripple = 1.0 + np.cos(2 * np.pi * self.fM * np.cos(np.pi * r / 2))
        return (1.0 - np.sin(np.pi * p[..., 2] / 2) + self.alpha * ripple) / (2 * (1 + self.alpha))


class SmoothSphere(Field):
    """A ball with a smooth (Gaussian-blurred) surface.

    ``amplitude * erfc((|x - center| - radius) / (width sqrt 2)) / 2``: the indicator of a
    ball of ``radius`` blurred radially by a Gaussian of standard deviation ``width``.

    Examples
    --------
    >>> round(float(SmoothSphere(radius=0.5)([0.5, 0.0, 0.0])), 6)
    0.5
    """

    name = "smooth-sphere"

    def __init__(self, center=(0.0, 0.0, 0.0), radius=0.6, width=0.05, amplitude=1.0):
        self.center = validate.vector3("center", center)
        self.radius = validate.positive_number("radius", radius)
        self.width = validate.positive_number("width", width)
        self.amplitude = validate.finite_number("amplitude", amplitude)

    def params(self):
        return {"center": self.center.tolist(), "radius": self.radius, "width": self.width,
                "amplitude": self.amplitude}

    def __call__(self, points):
        from scipy import special  # as in line_integral

        dist = np.linalg.norm(_points(points) - self.center, axis=-1)
        return 0.5 * self.amplitude * special.erfc((dist - self.radius) / (self.width * 2**0.5))


class Grating(Field):
    """A sinusoidal grating ``amplitude * (1 + cos(2 pi f (u . x) + phase)) / 2`` (>= 0).

    Parameters
    ----------
    frequency : float, default 4
        Cycles per world unit along ``direction`` (> 0).
    direction : 3 floats, default (1, 0, 0)
        Normalised here.
    amplitude, phase : float

    Examples
    --------
    >>> g = Grating(frequency=1.0)
    >>> g([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]]).round(12).tolist()
    [1.0, 0.0]
    >>> round(float(g.line_integral([0, 0, 0], [1, 0, 0], 0.0, 1.0)), 12)
    0.5
    """

    name = "grating"

    def __init__(self, frequency=4.0, direction=(1.0, 0.0, 0.0), amplitude=1.0, phase=0.0):
        self.frequency = validate.positive_number("frequency", frequency)
        self.direction = validate.vector3("direction", direction, unit=True)
        self.amplitude = validate.finite_number("amplitude", amplitude)
        self.phase = validate.finite_number("phase", phase)

    def params(self):
        return {"frequency": self.frequency, "direction": self.direction.tolist(),
                "amplitude": self.amplitude, "phase": self.phase}

    def __call__(self, points):
        arg = 2 * np.pi * self.frequency * (_points(points) @ self.direction) + self.phase
        return 0.5 * self.amplitude * (1.0 + np.cos(arg))

    def line_integral(self, origins, directions, t0=-np.inf, t1=np.inf):
        o, d = _rays(origins, directions)
        t0, t1 = np.broadcast_arrays(np.asarray(t0, float), np.asarray(t1, float))
        if not (np.all(np.isfinite(t0)) and np.all(np.isfinite(t1))):
            raise ValueError("a grating's line integral needs finite t0 and t1")
        k = 2 * np.pi * self.frequency
        a = k * (d @ self.direction)  # phase speed along the ray
        b = k * (o @ self.direction) + self.phase
        with np.errstate(divide="ignore", invalid="ignore"):
            osc = (np.sin(a * t1 + b) - np.sin(a * t0 + b)) / a
        osc = np.where(np.abs(a) > 1e-12, osc, np.cos(b) * (t1 - t0))
        return 0.5 * self.amplitude * ((t1 - t0) + osc)


class StepEdge(Field):
    """``high`` where ``normal . x >= offset``, else ``low``: a sharp edge for ringing tests.

    Examples
    --------
    >>> edge = StepEdge(normal=(0, 0, 1))
    >>> edge([[0, 0, -0.5], [0, 0, 0.5]]).tolist()
    [0.0, 1.0]
    >>> float(edge.line_integral([0, 0, -1], [0, 0, 1], 0.0, 2.0))
    1.0
    """

    name = "step-edge"

    def __init__(self, normal=(1.0, 0.0, 0.0), offset=0.0, low=0.0, high=1.0):
        self.normal = validate.vector3("normal", normal, unit=True)
        self.offset = validate.finite_number("offset", offset)
        self.low = validate.finite_number("low", low)
        self.high = validate.finite_number("high", high)

    def params(self):
        return {"normal": self.normal.tolist(), "offset": self.offset, "low": self.low,
                "high": self.high}

    def __call__(self, points):
        inside = _points(points) @ self.normal >= self.offset
        return np.where(inside, self.high, self.low)

    def gradient(self, points, *, h=None):
        return np.zeros(_points(points).shape)

    def breakpoints(self, origins, directions):
        o, d = _rays(origins, directions)
        speed = d @ self.normal
        with np.errstate(divide="ignore", invalid="ignore"):
            cross = (self.offset - o @ self.normal) / speed
        return np.where(speed != 0, cross, np.nan)[..., None]

    def line_integral(self, origins, directions, t0=-np.inf, t1=np.inf):
        o, d = _rays(origins, directions)
        t0, t1 = np.broadcast_arrays(np.asarray(t0, float), np.asarray(t1, float))
        if not (np.all(np.isfinite(t0)) and np.all(np.isfinite(t1))):
            raise ValueError("a step edge's line integral needs finite t0 and t1")
        speed = d @ self.normal
        start = o @ self.normal - self.offset  # signed distance at t = 0
        with np.errstate(divide="ignore", invalid="ignore"):
            cross = -start / speed
        # Length of [t0, t1] on the high side: t >= cross if speed > 0, t <= cross if < 0.
        high_len = np.where(
            speed > 0, np.clip(t1 - np.maximum(cross, t0), 0, None),
            np.where(speed < 0, np.clip(np.minimum(cross, t1) - t0, 0, None),
                     np.where(start >= 0, t1 - t0, 0.0)),
        )
        return self.high * high_len + self.low * ((t1 - t0) - high_len)
