"""Transfer functions the way ParaView, VTK and napari users build them: a named colormap with a
piecewise-linear opacity given as points, a default fitted to the volume's histogram, and one
colour and opacity per label of a label volume.

Opacity points are ``(x, alpha)`` pairs: ``x`` a fraction of the colour limits ``clim``
(0 at ``clim[0]``, 1 at ``clim[1]``), ``alpha`` the opacity of a slab ``unit_distance`` thick
(VTK's *scalar opacity unit distance*; here one voxel by default, so that a transfer function
means the same at any voxel size). Opacity ``alpha`` becomes the density
``-ln(1 - alpha) / unit_distance`` of the emission-absorption model (thesis eq 1.4), so an
image converges as the ray step shrinks.
"""

from __future__ import annotations

import numpy as np

from vrlib import validate
from vrlib.transfer import LookupTransfer

__all__ = ["colormap", "auto_transfer", "label_transfer", "parse_opacity", "finite_values",
           "MAX_ALPHA"]

#: Opacity points are capped below 1 (infinite density) at this value.
MAX_ALPHA = 1.0 - 1e-6

_TABLE = 1024


def parse_opacity(text):
    """Opacity points from the command-line form ``"x:alpha,x:alpha,..."``.

    Examples
    --------
    >>> parse_opacity("0:0,0.3:0,1:0.8")
    [(0.0, 0.0), (0.3, 0.0), (1.0, 0.8)]
    >>> parse_opacity("0:0;1")
    Traceback (most recent call last):
    ...
    ValueError: opacity points must be X:ALPHA pairs separated by commas \
(e.g. 0:0,0.3:0,1:0.8), got '0:0;1'
    """
    points = []
    for part in str(text).split(","):
        pieces = part.split(":")
        try:
            if len(pieces) != 2:
                raise ValueError
            points.append((float(pieces[0]), float(pieces[1])))
        except ValueError:
            raise ValueError("opacity points must be X:ALPHA pairs separated by commas "
                             f"(e.g. 0:0,0.3:0,1:0.8), got {text!r}") from None
    return points


def _check_points(points):
    try:
        pts = np.array(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"opacity must be (x, alpha) pairs, got {points!r}") from None
    if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 2:
        raise ValueError(f"opacity needs at least 2 (x, alpha) points, got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        raise ValueError(f"opacity points must be finite, got {pts.tolist()}")
    if np.any(np.diff(pts[:, 0]) < 0):
        raise ValueError(f"opacity points' x must not decrease, got {pts[:, 0].tolist()}")
    if np.any((pts[:, 1] < 0) | (pts[:, 1] > 1)):
        raise ValueError(f"opacity points' alpha must lie in [0, 1], got {pts[:, 1].tolist()}")
    return pts


def finite_values(volume):
    """The volume's samples, flat, holes (NaN samples of ``nan="transparent"``) left out.

    Examples
    --------
    >>> from vrlib import Volume
    >>> data = np.arange(8.0).reshape(2, 2, 2); data[0, 0, 0] = np.nan
    >>> finite_values(Volume(data, nan="transparent")).tolist()
    [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]
    """
    values = volume.data.ravel()
    return values if volume.holes is None else values[~volume.holes.ravel()]


def _colormap(cmap):
    """A matplotlib colormap from itself or its name."""
    import matplotlib

    if isinstance(cmap, str):
        try:
            cmap = matplotlib.colormaps[cmap]
        except KeyError:
            names = ", ".join(sorted(n for n in matplotlib.colormaps if not n.endswith("_r"))[:12])
            raise ValueError(f"unknown colormap {cmap!r}: use a matplotlib colormap name "
                             f"(e.g. {names}, ...)") from None
    if not callable(cmap):
        raise TypeError(f"cmap must be a matplotlib colormap or its name, got {cmap!r}")
    return cmap


def _colors(cmap, positions):
    return np.asarray(_colormap(cmap)(positions), dtype=np.float64)[:, :3]


def colormap(cmap="gray", opacity=((0.0, 0.0), (1.0, 1.0)), *, clim=None, unit_distance=None,
             volume=None, shading=None, gradient_opacity=None):
    """A transfer function from a matplotlib colormap and opacity points.

    Parameters
    ----------
    cmap : str or matplotlib colormap, default "gray"
        Colour from ``clim[0]`` (the map's start) to ``clim[1]`` (its end); values beyond take
        the end colours.
    opacity : sequence of (x, alpha), default a ramp from 0 to 1
        Piecewise-linear opacity: ``x`` as fractions of ``clim`` (non-decreasing; the ends
        extend flat), ``alpha`` in [0, 1] per ``unit_distance`` (1 is capped at
        :data:`MAX_ALPHA`).
    clim : (low, high), optional
        Data values of the colormap's ends; default ``volume.value_range``.
    unit_distance : float, optional
        World distance over which ``alpha`` applies; default the volume's smallest voxel
        spacing, else 1.
    volume : Volume, optional
        Supplies the defaults of ``clim`` and ``unit_distance``.
    shading, gradient_opacity
        As :class:`vrlib.LookupTransfer`.

    Returns
    -------
    LookupTransfer

    Examples
    --------
    >>> tf = colormap("gray", [(0, 0), (0.5, 0), (1, 0.5)], clim=(0, 100))
    >>> tf.opacity_density(np.array([40.0, 100.0])).round(4).tolist()   # -ln(1 - 0.5)
    [0.0, 0.6931]
    >>> tf.emission(np.array([100.0])).round(3).tolist()
    [[1.0, 1.0, 1.0]]
    """
    pts = _check_points(opacity)
    if clim is None:
        if volume is None:
            raise ValueError("colormap needs clim=(low, high) or volume= (whose value range "
                             "it takes)")
        clim = volume.value_range
    low = validate.finite_number("clim[0]", clim[0])
    high = validate.finite_number("clim[1]", clim[1])
    if not high > low:
        raise ValueError(f"clim must be increasing (low < high), got ({low:g}, {high:g}); a "
                         "volume of one value has no range to colour")
    if unit_distance is None:
        unit_distance = 1.0 if volume is None else float(np.min(volume.spacing))
    unit = validate.positive_number("unit_distance", unit_distance)
    fractions = np.linspace(0.0, 1.0, _TABLE)
    alpha = np.minimum(np.interp(fractions, pts[:, 0], pts[:, 1]), MAX_ALPHA)
    return LookupTransfer.from_alpha(alpha, _colors(cmap, fractions), unit_distance=unit,
                                     value_range=(low, high), shading=shading,
                                     gradient_opacity=gradient_opacity)


def auto_transfer(volume, cmap="gray", *, shading=None, peak_alpha=0.25):
    """A transfer function that shows something of a volume it knows nothing about.

    The background is found by Otsu's threshold on the volume's histogram (the value that
    best splits it into two classes); opacity ramps from 0 there to ``peak_alpha`` per voxel
    at the 99.5th percentile of the values above it, and colour runs over the same values.
    On an MRI head that makes air transparent and the head a translucent solid; on a label
    volume, background label 0 transparent and the labels above it visible.

    Parameters
    ----------
    volume : Volume
    cmap : str, default "gray"
    shading : Phong, optional
    peak_alpha : float, default 0.25
        Opacity per voxel of the brightest values, in (0, 1).

    Examples
    --------
    >>> from vrlib import Volume
    >>> data = np.zeros((8, 8, 8)); data[2:6, 2:6, 2:6] = 100.0
    >>> tf = auto_transfer(Volume(data))
    >>> float(tf.opacity_density(np.array([0.0]))[0]), bool(tf.max_density(50, 100) > 0)
    (0.0, True)
    """
    from skimage.filters import threshold_otsu

    low, high = volume.value_range
    if not high > low:
        raise ValueError(f"the volume holds one value ({low:g}) everywhere: there is nothing "
                         "to tell apart; choose a transfer function")
    peak = validate.finite_number("peak_alpha", peak_alpha, low=0.0, high=1.0, low_open=True,
                                  high_open=True)
    values = finite_values(volume)
    if values.size > 2_000_000:  # a regular subsample keeps the histogram, costs little
        values = values[:: values.size // 1_000_000]
    threshold = float(threshold_otsu(values.astype(np.float64)))
    above = values[values > threshold]
    top = float(np.percentile(above, 99.5)) if above.size else high
    if not top > threshold:
        top = high
    return colormap(cmap, [(0.0, 0.0), (1.0, peak)], clim=(threshold, top), volume=volume,
                    shading=shading)


def default_transfer(volume):
    """The transfer function a render uses when it is given none: the volume's own
    (:attr:`vrlib.Volume.transfer`; the analytic fields' samples carry ``Glow(1.0)``), else
    :func:`auto_transfer` fitted to its histogram, built once and kept with the volume. The
    command line follows the same rule.

    Examples
    --------
    >>> import data_gen
    >>> from vrlib import Volume
    >>> default_transfer(data_gen.make_field("gaussian-blob").sample(8))
    Glow(1)
    >>> data = np.zeros((8, 8, 8)); data[2:6, 2:6, 2:6] = 100.0
    >>> type(default_transfer(Volume(data))).__name__
    'LookupTransfer'
    """
    if volume.transfer is not None:
        return volume.transfer
    return volume.cached(("auto_transfer",), lambda: auto_transfer(volume))


def label_transfer(volume, *, colors=None, opacity=0.3, hidden=(0,), cmap="tab20",
                   unit_distance=None, shading=None):
    """One colour and one opacity per label of an integer label volume (segmentations, the
    frog's tissues).

    The table holds each label's colour and opacity unchanged over ``[label - 1/4,
    label + 1/4]``, so a sample that reconstructs to exactly its label gets exactly its
    label's classification. Render with ``filter="box"`` (nearest sample, as VTK's nearest
    interpolation of labels): any other filter blends neighbouring labels' numbers, and a
    boundary between labels 3 and 5 would pass through label 4's colour.

    Parameters
    ----------
    volume : Volume
        Integer values (stored as floats).
    colors : dict, optional
        ``{label: colour}`` (a matplotlib colour name or RGB triple) overriding ``cmap``.
    opacity : float or dict, default 0.3
        Opacity per ``unit_distance`` of every shown label, or ``{label: alpha}`` (labels
        missing from the dict get 0.3).
    hidden : iterable of int, default (0,)
        Labels drawn fully transparent (the background).
    cmap : str, default "tab20"
        Colormap for the labels: a qualitative one (fewer than 256 listed colours: tab10,
        tab20, Set1, ...) gives the i-th label present its i-th colour, cycling; a continuous
        one (viridis, ...) spreads the labels over its range.
    unit_distance : float, optional
        As :func:`colormap` (default the smallest voxel spacing).

    Examples
    --------
    >>> from vrlib import Volume
    >>> labels = Volume(np.array([0, 1, 2, 5] * 2, float).reshape(2, 2, 2))
    >>> tf = label_transfer(labels, colors={2: "red"}, opacity={5: 0.9})
    >>> tf.emission(np.array([2.0]))[0].tolist(), float(tf.opacity_density([0.0])[0])
    ([1.0, 0.0, 0.0], 0.0)
    """
    import matplotlib.colors

    values = np.unique(finite_values(volume))
    if values.size > 4096 or not np.all(values == np.round(values)):
        raise ValueError("a label volume holds integer labels (at most 4096 of them); this one "
                         f"holds {values.size} values, e.g. {values[:3].tolist()}: use "
                         "colormap() or auto_transfer() for measurements")
    labels = values.astype(np.int64)
    colors = dict(colors or {})
    unknown = sorted(set(colors) - set(labels.tolist()))
    if unknown:
        raise ValueError(f"colors names label(s) {unknown} that the volume does not hold; its "
                         f"labels: {labels.tolist()[:30]}")
    import matplotlib.colors as mcolors

    table = _colormap(cmap)
    if isinstance(table, mcolors.ListedColormap) and table.N < 256:  # qualitative: in turn
        palette = np.asarray(table.colors, dtype=np.float64)[np.arange(labels.size)
                                                            % len(table.colors), :3]
    else:
        palette = _colors(table, np.linspace(0, 1, labels.size))
    alphas = {int(k): v for k, v in opacity.items()} if isinstance(opacity, dict) else {}
    default = 0.3 if isinstance(opacity, dict) else opacity
    table_rgb, table_alpha = [], []
    for i, label in enumerate(labels.tolist()):
        try:
            rgb = matplotlib.colors.to_rgb(colors[label]) if label in colors else palette[i]
        except ValueError:
            raise ValueError(f"colors[{label}] = {colors[label]!r} is not a colour") from None
        alpha = 0.0 if label in set(hidden) else float(alphas.get(label, default))
        if not 0.0 <= alpha <= 1.0:
            raise ValueError(f"opacity of label {label} must lie in [0, 1], got {alpha:g}")
        table_rgb.append(rgb)
        table_alpha.append(min(alpha, MAX_ALPHA))
    # Entries every 1/4 from the first label - 1/2 to the last + 1/2: each label's value and
    # its neighbours within 1/4 take that label's classification.
    low, high = labels[0] - 0.5, labels[-1] + 0.5
    grid = np.linspace(low, high, int(round((high - low) * 4)) + 1)
    nearest = np.clip(np.searchsorted(labels, grid, side="left"), 0, labels.size - 1)
    below = np.clip(nearest - 1, 0, labels.size - 1)
    pick = np.where(np.abs(labels[below] - grid) < np.abs(labels[nearest] - grid), below,
                    nearest)
    if unit_distance is None:
        unit_distance = float(np.min(volume.spacing))
    return LookupTransfer.from_alpha(np.asarray(table_alpha)[pick],
                                     np.asarray(table_rgb, dtype=np.float64)[pick],
                                     unit_distance=unit_distance, value_range=(low, high),
                                     shading=shading)
