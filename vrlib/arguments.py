"""The arguments every renderer shares, checked and normalised in one place.

:func:`vrlib.render`, the MPI renderers (:mod:`vrlib.parallel.mpi`) and the reference renderer
(:func:`vrlib.render_reference`) all take a view, a transfer function and (the sampling
renderers) a filter and a step; each argument is checked here once, with one message, and the
filter is built once (renderers below take a :class:`vrlib.filters.Filter`, never a name).
"""

from __future__ import annotations

import warnings

from vrlib import validate
from vrlib.filters import check_radius, make_filter
from vrlib.transfer import Glow, TransferFunction
from vrlib.view import View, extent_of

__all__ = ["check_view", "check_transfer", "render_arguments", "refuse_gradients",
           "framed_view", "EmptyImageWarning"]


class EmptyImageWarning(UserWarning):
    """The image will be empty, and why: the volume lies outside the view, or the transfer
    function is transparent over every value the volume holds."""


def check_view(view):
    """Refuse anything but a :class:`vrlib.View`; return it."""
    if not isinstance(view, View):
        raise TypeError(f"view must be a vrlib.View, got {type(view).__name__}")
    return view


def check_transfer(transfer):
    """The transfer function, ``Glow(1.0)`` when None; refuse anything else."""
    transfer = Glow(1.0) if transfer is None else transfer
    if not isinstance(transfer, TransferFunction):
        raise TypeError(f"transfer must be a vrlib transfer function (Glow, LookupTransfer), "
                        f"got {transfer!r}")
    return transfer


def framed_view(view, extent, transfer=None, value_range=None):
    """The view that renders a volume of world box ``extent`` (or a Volume, or a field):
    ``view`` fitted to the box
    (:meth:`vrlib.View.fitted`) unless it names its own framing. Warns
    (:class:`EmptyImageWarning`) when the image can only come out empty, saying why.

    Examples
    --------
    >>> import vrlib
    >>> framed_view(vrlib.View.orbit(size=8), [[0, 10], [0, 10], [0, 10]]).center.tolist()
    [5.0, 5.0, 5.0]
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     _ = framed_view(vrlib.View.orbit(size=8, radius=1.0), [[0, 1], [50, 60], [0, 1]])
    >>> str(caught[0].message)[:43]
    'the volume lies outside the view: its world'
    """
    view = check_view(view).fitted(extent)
    box = extent_of(extent)
    if not view.sees(box):
        ext = " x ".join(f"[{lo:g}, {hi:g}]" for lo, hi in box)
        warnings.warn(
            f"the volume lies outside the view: its world box {ext} does not reach the image "
            f"of a view framing centre {view.center.round(4).tolist()}, radius "
            f"{view.radius:g}; build the view with View.orbit(...) (no centre or radius: it "
            "frames the volume) or View.fit(volume, ...)", EmptyImageWarning, stacklevel=3)
    elif transfer is not None and value_range is not None:
        low, high = value_range
        if transfer.densest(low, high) == 0.0:
            warnings.warn(
                f"the transfer function {transfer!r} is transparent over all the volume's "
                f"values [{low:g}, {high:g}]: the image is empty; choose opacity over that "
                "range (e.g. transfer='auto', or vrlib.colormap(..., clim=volume.value_range))",
                EmptyImageWarning, stacklevel=3)
    return view


#: The finest step a render takes, in voxels: finer would take hours (a ray of 256 voxels
#: at it takes 262144 samples), and no chapter's reference needs it.
MIN_STEP = 2.0**-10


def render_arguments(view, filter, transfer, step, early_termination=1.0):
    """Check the arguments the sampling renderers share.

    Returns
    -------
    filt : Filter
        Built from ``filter`` (a name, tuple or Filter), at most
        :data:`vrlib.filters.MAX_RADIUS` wide.
    transfer : TransferFunction
    step : float
        At least :data:`MIN_STEP`.
    early_termination : float
        In (0, 1].

    Examples
    --------
    >>> import vrlib
    >>> render_arguments(vrlib.View.orbit(), "catmull-rom", None, 0.5)[0]
    make_filter('catmull-rom')
    >>> render_arguments(vrlib.View.orbit(), "catmull-rom", None, 0.0)
    Traceback (most recent call last):
    ...
    ValueError: step must be > 0.0, got 0.0
    """
    check_view(view)
    filt = check_radius(make_filter(filter))
    transfer = check_transfer(transfer)
    step = validate.positive_number("step", step)
    if step < MIN_STEP:
        raise ValueError(f"step must be at least {MIN_STEP:g} voxel (1/1024: a finer step "
                         f"takes hours and gains nothing), got {step:g}")
    early_termination = validate.finite_number("early_termination", early_termination,
                                                low=0.0, high=1.0, low_open=True)
    return filt, transfer, step, early_termination


def refuse_gradients(transfer, who, instead="method='raycast', method='splat' with "
                     "mode='direct', or vrlib.classify for shear-warp"):
    """Refuse a transfer function that needs gradients (shading, gradient opacity) where
    ``who`` (a renderer) reconstructs values only; ``instead`` names what takes them."""
    if transfer.shading is not None:
        raise ValueError(f"{who} does not shade (it reconstructs no gradients); for shaded "
                         f"images use {instead}")
    if transfer.gradient_opacity is not None:
        raise ValueError(f"{who} reconstructs no gradients, so it cannot classify by gradient "
                         f"magnitude (gradient_opacity); use {instead}")
