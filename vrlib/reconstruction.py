"""``reconstruct``: the reconstructed field (eq 1.1) or its gradient at any world points.

The renderers' own separable sum (:mod:`vrlib._kernels.sampling`), with their boundary rule
(the lattice extended by its border values; a prefiltered filter reconstructs the
coefficients of :mod:`vrlib.prefilter`), exposed for filter studies: a value here is what the
ray caster reconstructs at a sample at the same point (to rounding: its unrolled paths sum the
same taps in another order).
"""

from __future__ import annotations

import numpy as np

from vrlib import validate
from vrlib._kernels.points import reconstruct_points
from vrlib.filters import check_radius, make_filter
from vrlib.holes import check_holes
from vrlib.prefilter import coefficient_volume
from vrlib.value_bounds import reconstructed_range
from vrlib.volume import Volume

__all__ = ["reconstruct", "ReconstructedField", "INSIDE_TOLERANCE"]

#: Points this far outside the volume's box (in voxels) still count as inside (round-off).
INSIDE_TOLERANCE = 1e-9


def reconstruct(volume, points, *, filter="trilinear", derivative=False):
    """The field a filter reconstructs from a volume's samples, at world points.

    Parameters
    ----------
    volume : Volume
    points : array_like, shape (n, 3)
        World points ``(x, y, z)``, finite.
    filter : str, tuple or Filter, default "trilinear"
        Any filter of :data:`vrlib.FILTERS`; a prefiltered one (``"cardinal-bspline"``,
        ``"omoms"``) reconstructs the volume's spline coefficients (computed once, kept with
        the volume).
    derivative : bool, default False
        Return the gradient ``(dF/dx, dF/dy, dF/dz)`` in world units instead of the value
        (the filter's derivative kernel along one axis, its kernel along the others). The box
        filter's derivative is zero, so it gives the samples' gradient at the sample it takes
        (central differences, :func:`numpy.gradient`): what every renderer shades by.

    Returns
    -------
    ndarray, shape (n,) or (n, 3) with ``derivative``
        float64. Points outside the volume's box (by more than :data:`INSIDE_TOLERANCE`
        voxels) give NaN: the field is defined inside the box only; so do points whose
        reconstruction gives a hole (a NaN sample of ``nan="transparent"``) any weight.

    Raises
    ------
    TypeError
        ``volume`` is not a :class:`vrlib.Volume`, ``points`` not real numbers, or
        ``derivative`` not a bool.
    ValueError
        ``points`` not of shape (n, 3) or not finite; an unknown filter name.

    Notes
    -----
    Agrees with :func:`scipy.ndimage.map_coordinates` (an implementation this package did not
    write): ``order=1`` for ``"trilinear"`` everywhere inside the box, and ``order=3,
    mode="reflect"`` for ``"cardinal-bspline"`` (the same half-sample symmetric boundary
    rule), or ``mode="mirror"`` away from the faces (the two rules' coefficients differ by
    ``|sqrt(3) - 2|^d``, ``d`` samples from a face).

    Examples
    --------
    >>> import numpy as np, vrlib
    >>> vol = vrlib.Volume(np.arange(27.0).reshape(3, 3, 3))     # f = x + 3 y + 9 z (index)
    >>> pts = np.array([[0.0, 0.0, 0.0], [0.5, -0.5, 0.25], [2.0, 0.0, 0.0]])
    >>> reconstruct(vol, pts).round(6).tolist()                 # the last point is outside
    [13.0, 14.25, nan]
    >>> reconstruct(vol, pts[1:2], derivative=True).round(6).tolist()   # per world unit
    [[1.0, 3.0, 9.0]]
    """
    if not isinstance(volume, Volume):
        raise TypeError(f"volume must be a vrlib.Volume, got {type(volume).__name__}")
    filt = check_radius(make_filter(filter))
    if not isinstance(derivative, bool | np.bool_):
        raise TypeError(f"derivative must be True or False, got {derivative!r}")
    pts = validate.finite_array("points", points)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must have shape (n, 3) (x, y, z per row), got {pts.shape}")
    holes = volume.holes is not None
    if holes:
        check_holes(filt)
        low, high = reconstructed_range(volume, filt)
    if filt.prefiltered:
        volume, _ = coefficient_volume(volume, filt)
    index = np.ascontiguousarray(volume.world_to_index(pts))
    out = np.zeros((len(pts), 3 if derivative else 1))
    fkind, fp0, fp1, fp2 = filt.code
    reconstruct_points(volume.data, index, fkind, fp0, fp1, fp2, filt.radius, filt.taps,
                       bool(derivative), out)
    last = np.array(volume.shape[::-1], dtype=np.float64) - 1.0
    outside = np.any((index < -INSIDE_TOLERANCE) | (index > last + INSIDE_TOLERANCE), axis=1)
    out[outside] = np.nan
    if holes:  # a point that gives a hole weight has no value (vrlib.holes)
        value = out[:, 0] if not derivative else reconstruct(volume, pts, filter=filt)
        out[(value < low) | (value > high)] = np.nan
    if derivative:
        return out / volume.spacing  # index units to world units, per axis
    return out[:, 0]


class ReconstructedField:
    """The field a filter reconstructs from a volume, as an analytic field that
    :func:`vrlib.render_reference` integrates exactly: the reference for a renderer's own
    error along rays (step, segment ends, skipping), with the reconstruction error left out.

    It is the piecewise polynomial (or, for the Gaussian, piecewise smooth) function
    :func:`reconstruct` evaluates; its pieces meet on the lattice planes (and, for a filter
    whose radius is not a whole number of voxels, on the planes offset by that radius), which
    :meth:`breakpoints` gives to the quadrature so that each piece is integrated as a smooth
    function.

    Parameters
    ----------
    volume : Volume
    filter : str, tuple or Filter, default "trilinear"

    Examples
    --------
    >>> import numpy as np, vrlib
    >>> vol = vrlib.Volume(np.arange(27.0).reshape(3, 3, 3))
    >>> field = ReconstructedField(vol)
    >>> field(np.array([[0.5, -0.5, 0.25]])).round(6).tolist(), field.bounds.tolist()[0]
    ([14.25], [-1.0, 1.0])
    >>> o, d = np.array([[-2.0, 0.1, 0.1]]), np.array([[1.0, 0.0, 0.0]])
    >>> np.sort(field.breakpoints(o, d)[0])[:3].tolist()     # x planes -1, 0, 1 at t = 1, 2, 3
    [1.0, 2.0, 3.0]
    """

    name = "reconstructed"

    def __init__(self, volume, filter="trilinear"):
        if not isinstance(volume, Volume):
            raise TypeError(f"volume must be a vrlib.Volume, got {type(volume).__name__}")
        self.volume = volume
        self.filter = check_radius(make_filter(filter))
        self.bounds = volume.extent

    def __call__(self, points):
        """Reconstructed values at world points ``(..., 3)``."""
        return self._at(points, derivative=False)

    def gradient(self, points):
        """Gradient of the reconstruction at world points ``(..., 3)``, per world unit."""
        return self._at(points, derivative=True)

    def _at(self, points, *, derivative):
        # Quadrature nodes that rounding puts a hair outside the box are moved onto it.
        pts = np.asarray(points, dtype=np.float64)
        flat = np.clip(pts.reshape(-1, 3), self.bounds[:, 0], self.bounds[:, 1])
        out = reconstruct(self.volume, flat, filter=self.filter, derivative=derivative)
        return out.reshape(pts.shape if derivative else pts.shape[:-1])

    def breakpoints(self, origins, directions):
        """Ray parameters ``(n_rays, m)`` where each ray crosses a plane on which the
        reconstruction's pieces meet (``nan`` where a ray runs parallel to a plane)."""
        o = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
        d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
        d = d / np.linalg.norm(d, axis=1, keepdims=True)
        offsets = {0.0, float(self.filter.radius % 1.0)}
        crossings = []
        for axis, n in enumerate(self.volume.shape[::-1]):
            for shift in sorted(offsets):
                planes = self.volume.origin[axis] + (np.arange(n) + shift) * \
                    self.volume.spacing[axis]
                with np.errstate(divide="ignore", invalid="ignore"):
                    t = (planes[None, :] - o[:, axis, None]) / d[:, axis, None]
                crossings.append(np.where(np.isfinite(t), t, np.nan))
        return np.concatenate(crossings, axis=1)

    def __repr__(self):
        return f"ReconstructedField(<volume {self.volume.shape}>, filter={self.filter!r})"
