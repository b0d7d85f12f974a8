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

__all__ = ["reconstruct", "INSIDE_TOLERANCE"]

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
        (the filter's derivative kernel along one axis, its kernel along the others).

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
