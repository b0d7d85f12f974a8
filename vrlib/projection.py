"""Maximum- and average-intensity projections: the ray caster's rays, one value per ray
(shear-warp projects its slices: :func:`vrlib.shearwarp.project_shearwarp`).

Instead of emission-absorption compositing (eqs 1.7-1.8), a pixel takes the largest (MIP) or
the mean value reconstructed along its ray, at the ray caster's sample positions and with any
filter, and the transfer function classifies that one value as VTK's blend modes do: colour
``E(v)`` and opacity ``1 - exp(-density(v) u)``, with ``u`` the transfer function's
``unit_distance`` where it has one (:func:`vrlib.colormap` and
:meth:`~vrlib.LookupTransfer.from_alpha`: the pixel's opacity is then the opacity point's
alpha) and the smallest voxel spacing otherwise.
Rays that miss the volume stay transparent. Shading does not apply (there is no surface), and
no skipping is done: the maximum of a ray can lie anywhere along it.
"""

from __future__ import annotations

import time

import numpy as np

from vrlib import validate
from vrlib._kernels import projection as _kernel
from vrlib.compositing import SEGMENT_ENDS
from vrlib.image import Image, RenderStats
from vrlib.prefilter import Tally, prepared
from vrlib.raycast import operations_per_sample

__all__ = ["render_projection", "classify_projected", "BLENDS"]

#: Blend modes of :func:`vrlib.render`: compositing, or one value per ray.
BLENDS = ("emission-absorption", "maximum", "average")


def classify_projected(transfer, value, hit, spacing):
    """Premultiplied RGBA of projected values (module docstring): colour ``E(v)``, opacity
    ``1 - exp(-density(v) u)``, transparent where ``hit`` is False. Every method that
    projects classifies with this.

    Examples
    --------
    >>> from vrlib import Glow
    >>> rgba = classify_projected(Glow(1.0), np.array([2.0, 2.0]), np.array([True, False]),
    ...                           np.ones(3))
    >>> np.round(rgba, 3).tolist()
    [[0.865, 0.865, 0.865, 0.865], [0.0, 0.0, 0.0, 0.0]]
    """
    unit = getattr(transfer, "unit_distance", float(np.min(spacing)))
    alpha = np.where(hit, -np.expm1(-transfer.opacity_density(value) * unit), 0.0)
    return np.concatenate([transfer.emission(value) * alpha[..., None], alpha[..., None]],
                          axis=-1)


def render_projection(volume, view, *, filt, transfer, step, blend, segment_ends="lattice"):
    """Project ``volume`` by ``blend`` ("maximum" or "average"); arguments already checked
    by :func:`vrlib.render`. ``segment_ends="exact"`` takes the ray caster's exact ends: the
    segments that the volume's faces cut are sampled at the middle of their part inside, and
    the mean weighs each sample by its segment's part inside (second order in the step where
    the field is not zero at the faces, as the ray caster's compositing).

    Examples
    --------
    >>> import data_gen, vrlib
    >>> vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(17)
    >>> gray = vrlib.colormap("gray", [(0, 1), (1, 1)], clim=(0, 1))
    >>> img = vrlib.render(vol, vrlib.View.orbit(size=9), transfer=gray, blend="maximum")
    >>> round(float(img.rgba[4, 4, 0]), 3), round(float(img.alpha[4, 4]), 3)  # near the peak
    (0.992, 1.0)
    """
    exact = validate.choice("segment_ends", segment_ends, SEGMENT_ENDS) == "exact"
    start = time.perf_counter()
    tally = Tally()
    volume = prepared(volume, filt, tally)
    extent = volume.extent
    value = np.empty(view.shape)
    hit = np.empty(view.shape, dtype=np.bool_)
    samples = np.zeros(view.height, dtype=np.int64)
    _kernel.project(np.ascontiguousarray(volume.data), np.asarray(volume.shape, np.int64),
                    volume.origin, volume.spacing, extent[:, 0].copy(), extent[:, 1].copy(),
                    view.packed(), view.height, view.width, step * float(volume.spacing.min()),
                    *filt.code, filt.radius, filt.taps,
                    _kernel.MAXIMUM if blend == "maximum" else _kernel.AVERAGE,
                    value, hit, samples, exact)
    rgba = classify_projected(transfer, value, hit, volume.spacing)
    taken = int(samples.sum())
    # Per sample: the ray caster's position and reconstruction; a max or sum in place of
    # its classification and compositing.
    stats = RenderStats(samples=taken, operations=taken * operations_per_sample(filt),
                        bytes=int(volume.data.nbytes + rgba.nbytes),
                        seconds=time.perf_counter() - start)
    return Image(rgba, tally.finish(stats, filt))
