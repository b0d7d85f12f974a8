"""Splatting (Westover 1989, 1990): the footprint method the thesis found most efficient.

Each voxel's 3-D reconstruction kernel is projected onto the image as a precomputed 2-D
footprint (:mod:`vrlib.footprint`): the kernel's line integral along the view. Three ways to
composite (``mode``):

* ``"sheet"``: axis-aligned sheet buffers (Westover 1990). Slices of voxels perpendicular to the
  volume axis most parallel to the view are taken front to back; a slice's footprints are summed
  into a sheet, classified (reconstruct, then classify) and composited. The sheet axis switches
  when the view crosses a diagonal, and the image jumps ("popping").
* ``"image-aligned"``: image-aligned sheet buffers (Mueller and Crawfis 1998). Slabs parallel to
  the image, ``slab_width`` voxels thick, are taken front to back; each voxel adds to a slab the
  part of its line integral inside it. No axis to switch, no popping; each voxel is drawn once
  per slab its kernel reaches (about ``2 r sqrt(3) + 1`` times).
* ``"direct"`` (Westover 1989): each voxel is classified by its own value, then drawn.

Under the glow transfer function all three compute the line integral of the reconstructed
field; they differ for nonlinear transfer functions, where classifying before reconstruction
blurs the transfer function's edges, and slabs of different shapes average different stretches.

The field is the ray caster's: the lattice is extended by repeating its border samples, and
the line integral of every kernel within its radius of a face is clipped to each ray's stretch
inside the volume's box (partial footprint tables), so splatting converges to the same image as
ray casting with the same filter. In perspective every ray gets its own footprint: the radially
symmetric Gaussian's depends only on the ray's distance from the voxel; every other filter's is
read from a view-independent table over the ray's crossing of the voxel's slice plane and its
slopes (:func:`vrlib.footprint.slanted`), or where clipped integrated along the ray exactly.

Transfer functions that need gradients (shading, gradient opacity): the sheet modes splat each
voxel's central-difference gradient (:func:`vrlib.gradients.gradient_volumes`) with the same
footprints into three gradient sheets beside the value's, so a sheet holds the reconstructed
gradient's integral as it holds the value's; each segment is classified by its mean value and
mean gradient and shaded along the pixel's own ray. Direct mode classifies and shades each
voxel by its own gradient before drawing it (:func:`classify_voxels`).

Skips: voxels with zero value (and in direct mode zero density) are never drawn, the thesis's
advantage on sparse data; in sheet modes neither are voxels whose neighbourhood the transfer
function makes transparent (:func:`drawable`); with ``early_termination`` below 1, footprint
pixels that are already that opaque take nothing more (the image changes by at most
``1 - threshold``).
"""

from __future__ import annotations

import math
import time

import numba
import numpy as np

from vrlib import validate
from vrlib._kernels import splat as _kernel
from vrlib._kernels._jit import readonly
from vrlib._scheduling import on_threads
from vrlib.footprint import RADIAL, footprint, running_integral, slanted
from vrlib.gradients import SLAB, gradient_volumes, kernel_lighting, no_gradients
from vrlib.holes import HoleTransfer
from vrlib.image import Image, RenderStats
from vrlib.prefilter import Tally, prepared, prepared_gradients
from vrlib.value_bounds import reconstructed_range, subset_bounds
from vrlib.view import principal_axis

__all__ = ["render_splat", "classify_voxels", "MODES"]

#: Compositing modes of the splatter.
MODES = ("sheet", "image-aligned", "direct")
_KERNEL_MODES = {"sheet": _kernel.SHEET, "image-aligned": _kernel.IMAGE,
                 "direct": _kernel.DIRECT}
#: Image rows per parallel task.
BAND = 16
#: Cells per block (each axis) of the transfer-function culling in sheet modes.
CULL_BLOCK = 4


def _slice_order(array, axis):
    """A ``[z, y, x]`` array as ``[slice, p, q]`` for slicing ``axis`` (0, 1, 2: x, y, z), with
    p and q the other axes in increasing order (a view, no copy)."""
    p_axis, q_axis = [a for a in range(3) if a != axis]
    return np.transpose(array, (2 - axis, 2 - p_axis, 2 - q_axis))


def visible_neighbourhoods(volume, filt, transfer, mode):
    """True for the voxels a sheet mode must draw: those whose neighbourhood can make a
    point visible (:func:`drawable`'s test, the value aside).

    Examples
    --------
    >>> from vrlib import Volume, LookupTransfer, make_filter
    >>> data = np.full((9, 9, 9), 0.1); data[0, 0, 0] = 1.0
    >>> step = LookupTransfer([0.0, 0.0, 0.0, 5.0, 5.0])    # transparent below 0.5
    >>> int(visible_neighbourhoods(Volume(data), make_filter("trilinear"), step, "sheet").sum())
    64
    """
    # Axis-aligned sheets average a slice's kernels over the stretch of the ray they cover,
    # beyond the support's points: two voxels more keep that stretch transparent.
    reach = 2 * math.ceil(filt.radius) - 1 + (2 if mode == "sheet" else 0)
    pyr = volume.minmax_pyramid(CULL_BLOCK, margin=reach)
    low, high = subset_bounds(pyr.minimum[0].astype(np.float64),
                              pyr.maximum[0].astype(np.float64), filt)
    visible = np.asarray(transfer.max_density(low, high)) > 0.0
    # Sample i belongs to block min(i // 4, blocks - 1), whose samples include it.
    index = [np.minimum(np.arange(n) // CULL_BLOCK, visible.shape[a] - 1)
             for a, n in enumerate(volume.shape)]
    return visible[np.ix_(*index)]


def drawable(volume, filt, transfer, mode, *, cull=True):
    """Nonzero where the splatter must draw.

    Direct mode: the voxels of nonzero density (evaluated a z-slab at a time). Sheet modes: the
    nonzero samples (holes drawn as nothing), less (with ``cull``) every voxel whose
    neighbourhood makes it invisible:
    a point within a voxel's support gathers samples within ``2 ceil(r) - 1`` voxels of it, so
    when the transfer function gives zero opacity to every sum of those samples weighted by
    the kernel, whichever of them are drawn (:func:`vrlib.value_bounds.subset_bounds`), the
    voxel only ever adds to transparent points. Neighbourhoods are taken per block of 4^3
    cells from the volume's min-max pyramid (two voxels wider for axis-aligned sheets). Leaving
    such voxels out changes no point's classification; a sheet, which classifies a mean over a
    stretch of the ray, can still change by rounding-level amounts (measured in the report's
    stability chapter and checked in the tests).

    Examples
    --------
    >>> from vrlib import Volume, Glow, LookupTransfer, make_filter
    >>> data = np.full((9, 9, 9), 0.1); data[0, 0, 0] = 1.0
    >>> step = LookupTransfer([0.0, 0.0, 0.0, 5.0, 5.0])    # transparent below 0.5
    >>> marks = drawable(Volume(data), make_filter("trilinear"), step, "sheet")
    >>> int(np.count_nonzero(marks)), data.size    # the samples of the first block are kept
    (64, 729)
    >>> drawable(Volume(np.array([[[0.0, -1.0], [2.0, 0.0]]] * 2)), make_filter("trilinear"),
    ...          Glow(1.0), "direct")[0]
    array([[False, False],
           [ True, False]])
    """
    if mode != "direct":
        samples = volume.data
        if volume.holes is not None:
            # A hole's splat is empty (vrlib.holes). Drawn with its stand-in value, a
            # footprint's faint edge (a weight of 1e-20 or less) would bring that value back
            # into the data's range.
            samples = np.where(volume.holes, 0.0, samples)
        if not cull:
            return samples  # nonzero values are the ones to draw
        keep = visible_neighbourhoods(volume, filt, transfer, mode)
        return np.where(keep, samples, 0.0) if not keep.all() else samples
    mask = np.empty(volume.shape, dtype=bool)
    for z in range(0, volume.shape[0], 16):
        mask[z:z + 16] = transfer.opacity_density(volume.data[z:z + 16]) > 0.0
    return mask


def classify_voxels(volume, view, transfer):
    """Each voxel's opacity density and colour, for a transfer function that needs gradients
    (shading, gradient opacity): direct splatting classifies and shades the voxels before
    reconstruction (Westover's pre-shaded splats), as VolPack does, where the ray caster
    classifies reconstructed samples.

    The gradient is the samples' central difference in world units
    (:func:`vrlib.gradients.gradient_volumes`); a voxel is seen along the view's direction, or
    in perspective along the ray from the eye through its centre.

    Returns
    -------
    density : ndarray (nz, ny, nx) float32
        Opacity density per world unit, times the gradient opacity's factor.
    colour : ndarray (nz, ny, nx, 3) float32
        Emission, shaded: ``E * factor + highlight``.

    Examples
    --------
    >>> from vrlib import Volume, View, Glow, GradientOpacity
    >>> ramp = Volume(np.tile(np.linspace(0.0, 1.0, 4), (4, 4, 1)))   # slope 0.5 along x
    >>> glow = Glow(2.0, gradient_opacity=GradientOpacity([0.0, 1.0], [0.0, 1.0]))
    >>> density, colour = classify_voxels(ramp, View.orbit(size=8), glow)
    >>> [round(float(d), 3) for d in density[0, 0]]     # 2 f times the factor 0.5
    [0.0, 0.333, 0.667, 1.0]
    """
    nz = volume.shape[0]
    density = np.empty(volume.shape, np.float32)
    colour = np.empty(volume.shape + (3,), np.float32)
    gradients = gradient_volumes(volume)
    ramp, shading = transfer.gradient_opacity, transfer.shading
    for z0 in range(0, nz, SLAB):
        z1 = min(z0 + SLAB, nz)
        grad = np.moveaxis(gradients[:, z0:z1], 0, -1).astype(np.float64)
        f = np.asarray(volume.data[z0:z1], np.float64)
        sigma = transfer.opacity_density(f)
        if ramp is not None:
            sigma = sigma * ramp.factor(np.linalg.norm(grad, axis=-1))
        rgb = transfer.emission(f)
        if shading is not None:
            if view.is_perspective:
                k, j, i = np.meshgrid(np.arange(z0, z1), np.arange(volume.shape[1]),
                                      np.arange(volume.shape[2]), indexing="ij")
                centres = volume.index_to_world(np.stack([i, j, k], axis=-1))
                to_eye = view.eye - centres
            else:
                to_eye = -view.forward
            rgb = rgb * shading.factor(grad, to_eye)[..., None] + shading.highlight(
                grad, to_eye)[..., None]
        density[z0:z1] = sigma
        colour[z0:z1] = rgb
    return density, colour


def row_extents(volume, axis, marks):
    """For every row ``(slice, p)`` of the slicing order, the first and last ``q`` whose entry in
    ``marks`` (``[z, y, x]``, bool or numbers) is nonzero: ``first > last`` for an empty row.

    Examples
    --------
    >>> from vrlib import Volume
    >>> marks = np.zeros((2, 2, 3), bool); marks[0, 1, 1:] = True
    >>> first, last = row_extents(Volume(np.zeros((2, 2, 3))), 2, marks)
    >>> first.tolist(), last.tolist()      # slices along z, rows along x, q along y
    ([[2, 1, 1], [2, 2, 2]], [[-1, 1, 1], [-1, -1, -1]])
    """
    shape = _slice_order(marks, axis).shape[:2]
    first = np.empty(shape, np.int64)
    last = np.empty(shape, np.int64)
    arguments = (readonly(np.asarray(marks)), axis, first, last, np.zeros(1, np.int64))
    on_threads(lambda i: _kernel.row_extents(*arguments), numba.get_num_threads())
    return first, last


def full_extents(volume, axis):
    """Row extents that keep every voxel (no culling)."""
    shape = _slice_order(volume.data, axis).shape
    return (np.zeros(shape[:2], np.int64), np.full(shape[:2], shape[2] - 1, np.int64))


def _corners(box):
    """The 8 corners ``(x, y, z)`` of ``box`` (``[[xmin, xmax], ...]``)."""
    return np.array(np.meshgrid(*box, indexing="ij")).reshape(3, -1).T


def _depths(view, box):
    """Smallest and largest camera depth of the corners of ``box``."""
    depths = view.to_camera(_corners(box))[:, 2]
    return float(depths.min()), float(depths.max())


def render_splat(volume, view, *, filt, transfer, step, early_termination, empty_space_skipping,
                 mode="sheet", footprint_resolution=129, slab_width=1.0):
    """Splat ``volume`` (arguments validated by :func:`vrlib.render`; ``step`` is unused:
    footprints integrate along the whole ray).

    Parameters
    ----------
    mode : {"sheet", "image-aligned", "direct"}
        Axis-aligned sheet buffers (classify each slice's reconstructed slab), image-aligned
        sheet buffers (classify slabs parallel to the image), or direct (classify each voxel).
    footprint_resolution : int
        Footprint table entries per axis (:func:`vrlib.footprint.footprint`).
    slab_width : float
        Image-aligned mode: slab thickness along the view, in units of the smallest voxel
        spacing (0.1 to 8).
    """
    validate.choice("mode", mode, MODES)
    slab_width = validate.finite_number("slab_width", slab_width, low=0.1, high=8.0)
    if filt.prefiltered and mode == "direct":
        raise ValueError(f"direct splatting classifies each voxel before reconstruction, and "
                         f"the {filt.name!r} filter's voxels hold spline coefficients, not "
                         f"values to classify; use mode='sheet' (reconstruct, then classify)")
    start = time.perf_counter()
    tally = Tally()
    samples, volume = volume, prepared(volume, filt, tally)  # prefiltered: the coefficients
    axis, ascending = principal_axis(view, volume)
    extent = volume.extent
    if view.is_perspective and extent[axis, 0] <= view.eye[axis] <= extent[axis, 1]:
        raise ValueError("splatting needs the eye outside the volume's slab along its major "
                         f"axis ({'xyz'[axis]}); move the eye out or use method='raycast'")
    spacing = volume.spacing
    radial = footprint(filt, spacing, None, resolution=footprint_resolution) if (
        filt.name == "gaussian" and np.ptp(spacing) == 0.0) else None
    fp = radial or footprint(filt, spacing, view.basis, resolution=footprint_resolution)
    # The lattice is extended by its border samples as far as a kernel reaching into the box
    # needs: ceil(radius) - 1 ghost voxels beyond each face.
    ghost = max(math.ceil(filt.radius) - 1, 0)
    depth, farthest = _depths(view, extent)
    if view.is_perspective and depth <= 0.0:
        raise ValueError("part of the volume lies behind the eye: splatting cannot draw it; "
                         "move the eye back or use method='raycast'")
    # Perspective: ghost voxels at or behind the eye (an eye within a voxel of a face) are not
    # drawn, nor any nearer than half the box's depth, which bounds every footprint's reach.
    lattice = extent + np.outer(spacing * ghost, [-1.0, 1.0])
    near = _depths(view, lattice)[0]
    near = near if near > 0.0 else 0.5 * depth
    reach_max = max(fp.extent, fp.extent_v) / view.pixel_size
    if view.is_perspective:
        # A footprint reaches (support radius / pixel at its depth) x (1 + r^2) pixels, r the
        # image-plane radius (unit distance) where it lands.
        camera = view.to_camera(_corners(lattice))
        spread = np.hypot(camera[:, 0], camera[:, 1]) / np.maximum(camera[:, 2], near)
        reach_max = fp.extent_s * (1.0 + float(spread.max()) ** 2) / (
            view.pixel_size / view.distance * near)
    # Perspective with a planar footprint: the slanted table, for the slopes of the rays that
    # meet the box (extreme at its corners, the eye being outside its slab along the axis).
    slant = None
    if view.is_perspective and fp.kind != RADIAL:
        steps = (_corners(extent) - view.eye) / spacing
        slopes = np.abs(np.delete(steps, axis, axis=1) / steps[:, axis:axis + 1])
        slant = slanted(filt, min(float(slopes.max()), 4.0))
    # Slabs of the image-aligned mode tile the box's depth range.
    slab = slab_width * float(spacing.min())
    n_slabs = max(1, math.ceil((farthest - depth) / slab))
    if mode != "direct" and isinstance(transfer, HoleTransfer):
        # The sheets hold no hole (drawable draws holes as nothing), and a sheet's mean can
        # pass the finite samples' range, where the wrapper would make it transparent.
        transfer = transfer.inner
    # Values a sheet can hold lie within the reconstruction's bounds; widen them generously
    # (the tables are exact inside and clamp outside).
    lo, hi = reconstructed_range(volume, filt)
    span = max(hi - lo, abs(lo), abs(hi))
    vstart, vinv, density, emission = transfer.value_table(lo - 2 * span, hi + 2 * span)
    per_voxel = transfer.needs_gradient and mode == "direct"  # classified voxel by voxel
    voxel_density, voxel_colour = classify_voxels(volume, view, transfer) if per_voxel else (
        np.zeros((1, 1, 1), np.float32), np.zeros((1, 1, 1, 3), np.float32))
    # Sheet modes with gradients: each voxel's gradient splatted beside its value.
    lighting = transfer.needs_gradient and mode != "direct"
    grads = prepared_gradients(samples, filt, tally, (0, 1, 2)) if lighting else (
        no_gradients(np.float32))
    lit = kernel_lighting(transfer, view.forward) if lighting else (
        np.zeros(13), np.zeros(2), np.zeros(2))
    if per_voxel:
        marks = voxel_density
    elif mode == "direct":
        marks = drawable(volume, filt, transfer, mode)
    else:  # the samples less the voxels culled by the transfer function, kept with the volume
        marks = volume.cached(("splat-drawn", filt, transfer.cache_key(), empty_space_skipping),
                              lambda: drawable(volume, filt, transfer, mode,
                                               cull=empty_space_skipping), keep=2)
    extents = marks
    if lighting and empty_space_skipping:
        # A voxel of value zero still carries a gradient: the rows' extents are those of the
        # voxels whose neighbourhood shows, whatever their values (kept with the volume).
        extents = volume.cached(("splat-visible", filt, transfer.cache_key(), mode),
                                lambda: visible_neighbourhoods(volume, filt, transfer, mode),
                                keep=2)
    first, last = row_extents(volume, axis, extents) if (
        empty_space_skipping) else full_extents(volume, axis)
    slices = np.arange(-ghost, volume.shape[2 - axis] + ghost)
    slices = slices if ascending else np.ascontiguousarray(slices[::-1])  # one array type
    bands = -(-view.height // BAND)
    out = np.zeros(view.shape + (4,))
    voxels = np.zeros(bands, np.int64)
    pixels = np.zeros(bands, np.int64)
    dummy1, dummy2, dummy3 = np.zeros(2), np.zeros((2, 2)), np.zeros((2, 2, 2))
    arguments = (
        readonly(volume.data if mode == "direct" else marks), volume.origin, spacing,
        view.packed(), view.height, view.width, axis, slices, ghost, float(filt.radius),
        running_integral(filt), fp.kind, fp.extent, fp.extent_v or fp.extent, fp.extent_s,
        fp.sigma, fp.table if fp.kind == RADIAL else dummy1,
        fp.table if fp.kind != RADIAL else dummy2, fp.partial if fp.kind != RADIAL else dummy3,
        slant.table if slant else np.zeros((2, 2, 2, 2), np.float32),
        slant.reach if slant else 1.0, slant.slope if slant else 1.0,
        np.array(filt.code, dtype=np.float64), np.polynomial.legendre.leggauss(5),
        _KERNEL_MODES[mode], depth, slab,
        n_slabs, vstart, vinv, density,
        emission, per_voxel, voxel_density, voxel_colour, grads, *lit,
        early_termination,
        empty_space_skipping, first, last, near if view.is_perspective else -math.inf,
        reach_max, BAND,
        np.arange(bands), np.zeros(1, np.int64), out, voxels, pixels,
        # The kernel compiled for this kind of render: an orthographic or unlit one compiles
        # none of the other's code.
        True if view.is_perspective else None, True if lighting else None,
    )
    # Each thread's own scratch: a band's sheets and per-pixel records, the cuts of the
    # exact footprints.
    threads = numba.get_num_threads()
    planes = np.zeros((threads, 9, BAND, view.width))
    gplanes = np.zeros((threads, 3, BAND, view.width) if lighting else
                       (threads, 3, 1, 1))
    flags = np.zeros((threads, 2, BAND, view.width), dtype=bool)
    cuts = np.zeros((threads, 12 * math.ceil(filt.radius) + 5))
    on_threads(lambda i: _kernel.splat(*arguments, planes[i], gplanes[i], flags[i], cuts[i]),
               threads)
    drawn = int(pixels.sum())
    stats = RenderStats(
        samples=drawn,
        operations=drawn * 25 + int(voxels.sum()) * 40,
        bytes=int(volume.data.nbytes + out.nbytes + fp.table.nbytes + voxel_density.nbytes
                  + voxel_colour.nbytes
                  + numba.get_num_threads() * BAND * view.width * 9),
        seconds=time.perf_counter() - start,
        voxels=int(voxels.sum()),
    )
    # Deviation from thesis: negative lobes (Catmull-Rom, Mitchell) can leave a pixel with
    # negative optical depth in direct mode; such pixels are clamped to transparent black.
    np.maximum(out, 0.0, out=out)
    np.minimum(out[..., 3], 1.0, out=out[..., 3])
    return Image(out, tally.finish(stats, filt))
