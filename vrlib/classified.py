"""A volume classified once and rendered from many views: shear-warp VolPack's way.

:func:`classify` evaluates the transfer function at every voxel once (value, gradient
magnitude, shading normal), as VolPack's ``vpClassifyVolume`` does, and
:meth:`ClassifiedVolume.render` renders any orthographic view from it with the classified
shear-warp kernel (:mod:`vrlib._kernels.classified`): only visible voxels are stored and
visited, opaque intermediate pixels are skipped, and shading is a table lookup per voxel built
once per frame.

It differs from ``render(volume, view, method="shearwarp")`` (post-classification: values are
resampled with any filter, then classified) in what it interpolates: each sample mixes its
four voxels' extinctions and colours bilinearly (pre-classification, Lacroute and Levoy 1994),
so it is faster and less accurate where the transfer function is steep. Deviation from VolPack:
VolPack stores a voxel opacity and composites it uncorrected for the slice spacing along the
ray; here a voxel stores its extinction per world unit and a segment's opacity is
``1 - exp(-sigma L)`` for the view's slice spacing ``L``, so images do not darken off-axis.
"""

from __future__ import annotations

import functools
import math
import time

import numpy as np

from vrlib import validate
from vrlib._kernels.classified import composite_classified, shade_table
from vrlib._scheduling import on_threads, thread_number
from vrlib.arguments import check_transfer, framed_view
from vrlib.colormapping import default_transfer
from vrlib.filters import make_filter
from vrlib.holes import with_holes
from vrlib.image import Image, RenderStats
from vrlib.shearwarp import intermediate_plane, warp, warp_homography
from vrlib.transfer import Phong
from vrlib.view import principal_axis
from vrlib.volume import Volume

__all__ = ["classify", "ClassifiedVolume", "NORMAL_BINS", "encode_normals", "decode_normals"]

#: Octahedral normal codes per side: ``NORMAL_BINS**2`` directions (a normal is off by 0.9
#: degree at the median, 2.5 at worst; VolPack's 13-bit code has 7924) and one more code for
#: "no gradient".
NORMAL_BINS = 96

#: Intermediate-image rows per unit of parallel work.
BAND = 8

#: Axis order of ``Volume.slices(axis)`` on a ``[z, y, x]`` array: ``[slice, row, column]``.
_SLICE_ORDER = {0: (2, 0, 1), 1: (1, 0, 2), 2: (0, 1, 2)}


def encode_normals(gradient):
    """Octahedral codes of gradient directions ``(..., 3)``; zero gradients get
    ``NORMAL_BINS**2`` (no normal).

    Examples
    --------
    >>> codes = encode_normals(np.array([[0.0, 0.0, 2.0], [0.0, 0.0, 0.0]]))
    >>> np.allclose(decode_normals()[codes[0]], [0, 0, 1], atol=0.02), int(codes[1])
    (True, 9216)
    """
    g = np.asarray(gradient, dtype=np.float64)
    l1 = np.abs(g).sum(axis=-1)
    safe = np.where(l1 > 0.0, l1, 1.0)
    x, y, z = (g[..., a] / safe for a in range(3))
    below = z < 0.0
    fx = np.where(below, (1.0 - np.abs(y)) * np.where(x >= 0.0, 1.0, -1.0), x)
    fy = np.where(below, (1.0 - np.abs(x)) * np.where(y >= 0.0, 1.0, -1.0), y)
    u = np.clip(((fx + 1.0) * 0.5 * NORMAL_BINS).astype(np.int64), 0, NORMAL_BINS - 1)
    v = np.clip(((fy + 1.0) * 0.5 * NORMAL_BINS).astype(np.int64), 0, NORMAL_BINS - 1)
    return np.where(l1 > 0.0, v * NORMAL_BINS + u, NORMAL_BINS**2).astype(np.uint16)


def decode_normals():
    """The unit direction of every normal code (the centre of its octahedral bin), and a zero
    vector for the last code (no gradient): ``(NORMAL_BINS**2 + 1, 3)``."""
    centre = (np.arange(NORMAL_BINS) + 0.5) / NORMAL_BINS * 2.0 - 1.0
    fy, fx = np.meshgrid(centre, centre, indexing="ij")
    z = 1.0 - np.abs(fx) - np.abs(fy)
    below = z < 0.0
    x = np.where(below, (1.0 - np.abs(fy)) * np.sign(fx), fx)
    y = np.where(below, (1.0 - np.abs(fx)) * np.sign(fy), fy)
    n = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return np.concatenate([n, np.zeros((1, 3))])


def _slice_shape(volume, axis):
    """``(slices, rows, columns)`` of ``volume.slices(axis)``, without making the copy that
    slices along x need."""
    return tuple(volume.shape[a] for a in _SLICE_ORDER[axis])


@functools.cache
def _normals():
    return np.ascontiguousarray(decode_normals().T)  # rows of x, y and z components


def classify(volume, transfer=None, *, min_opacity=0.0):
    """Classify ``volume`` under ``transfer`` once, for fast shear-warp rendering of any view.

    Parameters
    ----------
    volume : Volume
    transfer : TransferFunction, optional
        Any transfer function, shaded or not, with or without gradient opacity
        (:class:`vrlib.GradientOpacity`); default :func:`vrlib.default_transfer`, as
        :func:`vrlib.render`.
    min_opacity : float, default 0
        Voxels whose opacity over one voxel spacing along the slice axis is at most this are
        not stored (VolPack's ``VP_MIN_VOXEL_OPACITY``): 0 drops only voxels that add nothing
        (exact), larger values drop faint voxels too (lossy).

    Returns
    -------
    ClassifiedVolume

    Examples
    --------
    >>> import data_gen, vrlib
    >>> vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(24)
    >>> scene = vrlib.classify(vol, vrlib.Glow(2.0, shading=vrlib.Phong()))
    >>> img = scene.render(vrlib.View.orbit(azimuth=30, size=16))
    >>> img.shape, bool(0.1 < img.alpha.max() < 1.0)
    ((16, 16), True)
    """
    return ClassifiedVolume(volume, transfer, min_opacity=min_opacity)


class ClassifiedVolume:
    """A volume with its transfer function applied at every voxel (see :func:`classify`).

    Per voxel it holds the extinction ``sigma = O(F) g(|grad F|)`` (per world unit), an
    emission code (the value's entry in the transfer function's table) and a normal code
    (:func:`encode_normals` of the central-difference gradient); per principal axis, built on
    first use, the run-length encoding of the visible voxels' scanlines.
    """

    def __init__(self, volume, transfer=None, *, min_opacity=0.0):
        if not isinstance(volume, Volume):
            raise TypeError(f"volume must be a vrlib.Volume, got {type(volume).__name__}")
        self.volume = volume
        self.transfer = check_transfer(default_transfer(volume) if transfer is None else transfer)
        self.min_opacity = validate.finite_number("min_opacity", min_opacity, low=0.0,
                                                  high=1.0, high_open=True)
        start = time.perf_counter()
        data = volume.data
        lo, hi = volume.value_range  # holes left out: they classify as transparent
        sigma = with_holes(volume, self.transfer, make_filter("box"), "classify").opacity_density(
            data)
        normal = np.full(volume.shape, NORMAL_BINS**2, dtype=np.uint16)
        if self.transfer.needs_gradient:
            # Central differences (one-sided at the faces), per world unit: gz, gy, gx.
            h = volume.spacing
            grad = np.stack(np.gradient(data.astype(np.float64), h[2], h[1], h[0])[::-1], -1)
            if self.transfer.gradient_opacity is not None:
                sigma = sigma * self.transfer.gradient_opacity.factor(
                    np.linalg.norm(grad, axis=-1))
            if self.transfer.shading is not None:
                normal = encode_normals(grad)
            del grad
        self._sigma = np.asarray(sigma, dtype=np.float32)
        self._normal = normal
        vstart, inv, _, emit = self.transfer.value_table(lo, hi)
        self._emission = np.ascontiguousarray(emit, dtype=np.float64)
        self._emission_code = np.clip(np.rint((data - vstart) * inv), 0,
                                      emit.shape[0] - 1).astype(np.uint16)
        self._grey = bool(np.all(emit == 1.0))
        self._encodings = {}
        self._line_runs = {}
        self.seconds = time.perf_counter() - start

    def __repr__(self):
        return (f"ClassifiedVolume({self.volume!r}, {self.transfer!r}, "
                f"min_opacity={self.min_opacity:g})")

    def encoding(self, axis):
        """Run-length encoding along ``axis`` (0, 1, 2 for x, y, z), built on first use:
        ``(run_ptr, run_start, run_end, run_voxel, sigma, emission_code, normal_code)``
        (see :func:`vrlib._kernels.classified.composite_classified`)."""
        if axis not in self._encodings:
            start = time.perf_counter()
            perm = _SLICE_ORDER[axis]
            sigma = self._sigma.transpose(perm)
            # Stored: opacity over one spacing along the axis above min_opacity.
            cutoff = -math.log1p(-self.min_opacity) / self.volume.spacing[axis]
            visible = sigma > cutoff
            n_k, n_j, n_i = visible.shape
            edges = np.diff(np.pad(visible.reshape(n_k * n_j, n_i), ((0, 0), (1, 1))).view(
                np.int8), axis=1)
            line, run_start = np.nonzero(edges == 1)
            run_end = np.nonzero(edges == -1)[1]
            run_ptr = np.zeros(n_k * n_j + 1, dtype=np.int64)
            np.cumsum(np.bincount(line, minlength=n_k * n_j), out=run_ptr[1:])
            # Each run's voxels stored between two transparent guards: run_voxel + 1 on.
            lengths = run_end - run_start
            run_voxel = np.zeros(lengths.size, dtype=np.int64)
            np.cumsum(lengths[:-1] + 2, out=run_voxel[1:])
            slots = np.ones(int(lengths.sum()) + 2 * lengths.size, dtype=bool)
            slots[run_voxel] = False
            slots[run_voxel + lengths + 1] = False
            guarded = [np.zeros(slots.size, dtype=a.dtype) for a in
                       (self._sigma, self._emission_code, self._normal)]
            for out, dense in zip(guarded, (self._sigma, self._emission_code, self._normal),
                                  strict=True):
                out[slots] = dense.transpose(perm)[visible]
            # The runs' indices in 32 bits where they fit (every volume but the largest):
            # 2.7 -> 2.3 MB of encoding read a frame on VolPack's example, 2-3% faster.
            index = np.int32 if slots.size < np.iinfo(np.int32).max else np.int64
            self._encodings[axis] = (run_ptr.astype(index), run_start.astype(index),
                                     run_end.astype(index), run_voxel.astype(index),
                                     *guarded)
            self.seconds += time.perf_counter() - start
        return self._encodings[axis]

    @property
    def stored_voxels(self):
        """Voxels stored along each axis encoded so far, ``{axis: count}``."""
        return {axis: int(enc[4].size - 2 * enc[1].size) for axis, enc in
                self._encodings.items()}

    def _shade_tables(self, view, shading):
        """Per normal code, the multiplier of the emission and the highlight added to it (for
        white emission the multiplier holds their sum: a voxel's grey is one table read)."""
        count = NORMAL_BINS**2 + 1
        if shading is None:
            return np.ones(count), np.zeros(count)
        light = -view.forward if shading.light is None else shading.light
        factor, highlight = np.empty(count), np.empty(count)
        shade_table(_normals(), np.asarray(light, np.float64), view.forward, shading.ambient,
                    shading.diffuse, shading.specular, shading.shininess, factor, highlight)
        if self._grey:
            factor += highlight
        return factor, highlight

    def _band_order(self, axis, dj, height):
        """Bands of :data:`BAND` intermediate rows, the heaviest first by the runs their
        scanlines hold (the middle slice's shift maps rows to scanlines), for the threads'
        shared queue."""
        if axis not in self._line_runs:
            run_ptr = self.encoding(axis)[0]
            n_k, n_j = _slice_shape(self.volume, axis)[:2]
            self._line_runs[axis] = np.diff(run_ptr).reshape(n_k, n_j).sum(axis=0) + 1.0
        runs = self._line_runs[axis]
        lines = np.clip(np.arange(height) + int(round(dj[dj.size // 2])), 0, runs.size - 1)
        cost = np.zeros(-(-height // BAND) * BAND)
        cost[:height] = runs[lines]
        return np.argsort(-cost.reshape(-1, BAND).sum(axis=1), kind="stable")

    def render(self, view, *, early_termination=0.999, shading=None, threads=None):
        """Render an orthographic ``view`` (other arguments as :func:`vrlib.render`).

        Parameters
        ----------
        shading : Phong, optional
            This frame's lighting, in place of the transfer function's (a light that moves
            with the eye, as VolPack's lights do); only for a volume classified with shading,
            whose normals are stored.

        Returns
        -------
        Image
            Premultiplied RGBA; ``stats.samples`` counts the composited samples.
        """
        view = framed_view(view, self.volume.extent)
        if view.is_perspective:
            raise ValueError("a ClassifiedVolume renders orthographic views only (as VolPack); "
                             "use vrlib.render(volume, view, method='shearwarp') for perspective")
        threshold = validate.finite_number("early_termination", early_termination, low=0.0,
                                           high=1.0, low_open=True)
        if shading is None:
            shading = self.transfer.shading
        elif self.transfer.shading is None:
            raise ValueError("shading needs the normals of a volume classified with shading: "
                             "classify with a shaded transfer function")
        elif not isinstance(shading, Phong):
            raise TypeError(f"shading must be a vrlib.Phong or None, got {shading!r}")
        volume = self.volume
        axis, ascending = principal_axis(view, volume)
        encoded = self.encoding(axis)
        # Every kernel here runs on Python threads (on_threads): numba's own thread count
        # is neither needed nor set.
        threads = thread_number(threads)
        start = time.perf_counter()
        _, di, dj, (oi, oj), (height, width), kf, _ = intermediate_plane(
            volume, view, axis, ascending)
        n_k, n_j = _slice_shape(volume, axis)[:2]
        order = np.arange(n_k) if ascending else np.arange(n_k)[::-1].copy()
        length = float(volume.spacing[axis] / abs(view.forward[axis]))
        factor, highlight = self._shade_tables(view, shading)
        # Grey: red and opacity alone (the warp copies red), half the memory.
        inter = np.zeros((height, width, 2 if self._grey else 4))
        counts = np.zeros(height, np.int64)
        # The bands in order on one thread; the heaviest first on several, for balance.
        bands = (self._band_order(axis, dj, height) if threads > 1 else
                 np.arange(-(-height // BAND)))
        arguments = (*encoded, n_j, order, di, dj, length, self._emission, factor,
                     highlight, True if self._grey else None,
                     True if shading is not None else None, threshold, BAND, bands,
                     np.zeros(1, np.int64), inter, counts)
        on_threads(lambda i: composite_classified(*arguments), threads)
        plane = volume.origin[axis] + kf * volume.spacing[axis]
        out = np.empty(view.shape + (4,))
        warp(inter, warp_homography(view, volume, axis, plane, (oi, oj)), out, self._grey,
             threads=threads)
        taken = int(counts.sum())
        stats = RenderStats(samples=taken, operations=taken * 40 + out.size * 8,
                            bytes=int(sum(a.nbytes for a in encoded) + inter.nbytes
                                      + out.nbytes),
                            seconds=time.perf_counter() - start, voxels=taken)
        return Image(out, stats, checked=False)  # the warp clipped it into [0, 1]
