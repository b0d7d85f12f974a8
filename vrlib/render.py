"""``render``: one entry point that validates its arguments and dispatches to a renderer."""

from __future__ import annotations

import functools
import inspect

from vrlib import validate
from vrlib._scheduling import thread_count
from vrlib.arguments import framed_view, refuse_gradients, render_arguments
from vrlib.auto import render_auto
from vrlib.colormapping import auto_transfer, default_transfer
from vrlib.holes import with_holes
from vrlib.projection import BLENDS, render_projection
from vrlib.raycast import render_raycast
from vrlib.reference import render_reference
from vrlib.shear import render_shear2, render_shear3
from vrlib.shearwarp import project_shearwarp, render_shearwarp
from vrlib.splat import render_splat
from vrlib.tolerance import render_within
from vrlib.volume import Volume

__all__ = ["render", "METHODS", "method_options", "chosen_method", "reference_image"]

#: The finest ray cast, the most accurate image vrlib makes of a volume without its field.
FINE = {"filter": "catmull-rom", "step": 0.125, "early_termination": 1.0}

#: Rendering methods by name: each a function ``(volume, view, *, filt, transfer, step,
#: early_termination, empty_space_skipping, **its own options) -> Image`` taking arguments
#: already checked (a new method is an entry here and its own module; chapters, the command
#: line and the cost model read this registry).
METHODS = {"raycast": render_raycast, "splat": render_splat, "shear3": render_shear3,
           "shear2": render_shear2, "shearwarp": render_shearwarp}

#: Why a method has no maximum- or average-intensity projection (said with the refusal).
_WHY_NOT_PROJECTED = {
    "splat": "a splat adds each voxel's footprint, integrated along the ray, into the image, "
             "so a pixel holds a sum over voxels, never the field's values at points of the "
             "ray, whose largest or mean a projection takes",
    "shear3": "it would be shear-warp's projection after one or two more resampling passes, "
              "slower and less accurate",
    "shear2": "it would be shear-warp's projection after one more resampling pass, slower "
              "and less accurate",
}

_COMMON = {"filt", "transfer", "step", "early_termination", "empty_space_skipping"}


def method_options(method):
    """Keyword options that one method takes beyond the common ones, with their defaults.

    Examples
    --------
    >>> method_options("splat")
    {'mode': 'sheet', 'footprint_resolution': 129, 'slab_width': 1.0}
    """
    return dict(_own_options(method))


def chosen_method(method):
    """The method :func:`render` runs for ``method``: ``"auto"`` is ray casting, the one
    method that renders to a tolerance (where one is given without a filter, the filter is
    chosen by this machine's cost model: :mod:`vrlib.auto`).

    Examples
    --------
    >>> chosen_method("auto"), chosen_method("splat")
    ('raycast', 'splat')
    """
    return "raycast" if method == "auto" else method


@functools.cache
def _own_options(method):
    """:func:`method_options`, found once per method (``inspect.signature`` takes 15 us)."""
    params = inspect.signature(METHODS[method]).parameters.values()
    return {p.name: p.default for p in params
            if p.kind is p.KEYWORD_ONLY and p.name not in _COMMON}


def render(volume, view, *, method="raycast", filter=None, transfer=None, step=None,
           early_termination=None, empty_space_skipping=True, blend="emission-absorption",
           threads=None, tolerance=None, **options):
    """Render a volume into an image.

    Parameters
    ----------
    volume : Volume
    view : View
    method : {"raycast", "splat", "shear3", "shear2", "shearwarp", "auto"}
        The rendering method (see :data:`METHODS`). ``"auto"`` is ray casting, the one
        method that renders to a tolerance; with a ``tolerance`` and no ``filter``, it also
        chooses the filter that this machine's cost model predicts reaches the tolerance
        soonest (:mod:`vrlib.auto`; ``vrlib bench`` fits the model).
    filter : str, tuple or Filter, optional
        Reconstruction filter, by name or built with :func:`vrlib.make_filter`; left out,
        trilinear (or, with ``method="auto"`` and a ``tolerance``, the one chosen). Trilinear is
        the default here and on the command line because it is the fastest; ``"catmull-rom"``
        is more accurate (the report's chapter 3) and slower (chapter 4 times both). A prefiltered
        filter (``"cardinal-bspline"``, ``"omoms"``) reconstructs spline coefficients with its
        kernel, in every method (:mod:`vrlib.prefilter` says which axes each prefilters; the
        volume's coefficients are kept with it); ``stats.prefilter`` says what it cost.
    transfer : TransferFunction or "auto", optional
        ``"auto"`` fits a grey ramp to the volume's histogram (:func:`vrlib.auto_transfer`),
        for real data; ``Glow(1.0)`` (density = value per world unit) is the thesis's study
        function for the analytic fields. Build others with :func:`vrlib.colormap`. Default:
        :func:`vrlib.default_transfer`, the volume's own (``Glow(1.0)`` for the analytic
        fields' samples), else ``"auto"``, as on the command line.
    step : float, default 0.5
        Sample spacing along each ray, in voxels (of the smallest spacing); > 0. Opacity is
        computed per segment as ``1 - exp(-density * step)``, so images converge as the step
        shrinks.
    early_termination : float, default 0.999
        Stop a ray once its opacity reaches this value, in (0, 1]; 1 turns it off. The image
        changes by at most ``1 - early_termination`` times the brightest emission.
    empty_space_skipping : bool, default True
        Jump over blocks that the filter and transfer function make invisible; never changes
        the image.
    blend : {"emission-absorption", "maximum", "average"}
        Composite the samples front to back (the thesis's model), or project the largest or
        the mean value along each ray (:mod:`vrlib.projection`; ray casting and shear-warp,
        no shading).
    threads : int, optional
        Threads to use (default: numba's setting). The image does not depend on it.
    tolerance : float, optional
        Render an image whose rmse (premultiplied RGBA) against the exact image of the field
        the filter reconstructs (:class:`vrlib.ReconstructedField` rendered by
        :func:`vrlib.render_reference`) is at most this, in (0, 1): the step, the
        classification and the early termination are then chosen for it
        (:mod:`vrlib.tolerance`), and ``img.stats.choices`` says what was chosen and the
        error expected. Ray casting only (``method="raycast"`` or ``"auto"``); leave
        ``step`` and ``early_termination`` out. ``None`` (default) renders with the step
        and settings given, exactly as without it.
    **options
        Options of the chosen method (:func:`method_options` lists them): for ``"splat"``,
        ``mode`` ("sheet", "image-aligned" or "direct"), ``footprint_resolution`` and
        ``slab_width`` (image-aligned slabs, in voxels); for ``"shearwarp"``,
        ``min_opacity``; for ``"shear3"`` and ``"shear2"``, ``intermediate`` ("auto", "float32"
        or "float64" storage of the resampled volumes).

    Returns
    -------
    Image

    Raises
    ------
    TypeError, ValueError
        Arguments of the wrong kind or out of range; the message names the parameter.

    Examples
    --------
    >>> import data_gen, vrlib
    >>> vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(16)
    >>> img = vrlib.render(vol, vrlib.View.orbit(size=8), filter="catmull-rom")
    >>> img.shape, bool(0.0 < img.alpha.max() < 1.0)
    ((8, 8), True)
    """
    if not isinstance(volume, Volume):
        hint = ("; a ClassifiedVolume renders with its own .render(view)"
                if type(volume).__name__ == "ClassifiedVolume" else "")
        raise TypeError(f"volume must be a vrlib.Volume, got {type(volume).__name__}{hint}")
    validate.choice("method", method, (*METHODS, "auto"))
    if transfer is None:
        transfer = default_transfer(volume)
    elif isinstance(transfer, str) and transfer == "auto":
        transfer = auto_transfer(volume)
    if tolerance is not None:
        _check_tolerance_arguments(method, step, early_termination, blend, options)
    choose_filter = method == "auto" and tolerance is not None and filter is None
    filter = "trilinear" if filter is None else filter
    method = chosen_method(method)
    step = 0.5 if step is None else step
    early_termination = 0.999 if early_termination is None else early_termination
    filt, transfer, step, early_termination = render_arguments(view, filter, transfer, step,
                                                               early_termination)
    view = framed_view(view, volume.extent, transfer, volume.value_range)
    unwrapped, transfer = transfer, with_holes(volume, transfer, filt, method)
    if not isinstance(empty_space_skipping, bool):
        raise TypeError(
            f"empty_space_skipping must be True or False, got {empty_space_skipping!r}"
        )
    validate.choice("blend", blend, BLENDS)
    if blend != "emission-absorption":
        if method not in ("raycast", "shearwarp"):
            raise ValueError(
                f"blend={blend!r} takes one value per ray, which ray casting and shear-warp "
                f"give: use method='raycast' or method='shearwarp' (not {method!r}); "
                + _WHY_NOT_PROJECTED.get(method, ""))
        refuse_gradients(transfer, f"blend={blend!r}", instead="blend='emission-absorption'")
        takes = {"segment_ends"} if method == "raycast" else set()
        if set(options) - takes:
            raise TypeError(f"blend={blend!r} takes no method options"
                            f"{' but segment_ends' if takes else ''} with method={method!r}, "
                            f"got {sorted(options)}")
        with thread_count(threads):
            if method == "shearwarp":
                return project_shearwarp(volume, view, filt=filt, transfer=transfer,
                                         blend=blend)
            return render_projection(volume, view, filt=filt, transfer=transfer, step=step,
                                     blend=blend, **options)
    if choose_filter:
        with thread_count(threads):
            return render_auto(volume, view, transfer=unwrapped, tolerance=tolerance,
                               empty_space_skipping=empty_space_skipping)
    if tolerance is not None:
        with thread_count(threads):
            return render_within(volume, view, filt=filt, transfer=transfer,
                                 tolerance=tolerance,
                                 empty_space_skipping=empty_space_skipping)
    allowed = method_options(method)
    unknown = sorted(set(options) - set(allowed))
    if unknown:
        known = ", ".join(allowed) or "none"
        raise TypeError(f"method {method!r} takes no option {unknown[0]!r}; its options: {known}")
    with thread_count(threads):
        return METHODS[method](volume, view, filt=filt, transfer=transfer, step=step,
                               early_termination=early_termination,
                               empty_space_skipping=empty_space_skipping, **options)


def _check_tolerance_arguments(method, step, early_termination, blend, options):
    """Refuse what a render to a tolerance chooses itself, or cannot do."""
    if method not in ("raycast", "auto"):
        raise ValueError(f"tolerance= is kept by ray casting only: use method='raycast' or "
                         f"method='auto' (not {method!r}), or leave tolerance out")
    given = [name for name, value in (("step", step), ("early_termination",
                                                       early_termination)) if value is not None]
    given += sorted(options)
    if given:
        raise ValueError(f"tolerance= chooses {', '.join(given)} itself: leave "
                         f"{'it' if len(given) == 1 else 'them'} out, or leave tolerance out")
    if blend != "emission-absorption":
        raise ValueError(f"tolerance= is kept for blend='emission-absorption' only, not "
                         f"{blend!r}")


def reference_image(volume, view, *, transfer=None, field=None):
    """The image others are judged against: the exact field's (:func:`render_reference`)
    when ``field`` is given, else the finest ray cast of ``volume`` (:data:`FINE`: Catmull-Rom,
    a step of 1/8 voxel, no early termination).

    Returns
    -------
    image : Image
    label : str
        What the image is, for tables and figures.

    Examples
    --------
    >>> import data_gen, vrlib
    >>> blob = data_gen.make_field("gaussian-blob", sigma=0.3)
    >>> view = vrlib.View.orbit(size=8)
    >>> reference_image(blob.sample(9), view)[1], reference_image(blob.sample(9), view,
    ...                                                           field=blob)[1]
    ('ray casting, step 1/8', 'reference renderer')
    """
    if field is not None:
        return render_reference(field, view, transfer=transfer), "reference renderer"
    return render(volume, view, transfer=transfer, **FINE), "ray casting, step 1/8"
