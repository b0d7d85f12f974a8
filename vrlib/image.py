"""Rendered images: premultiplied RGBA plus what the render cost."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from vrlib import validate
from vrlib._png import encode_png
from vrlib.atomic import atomic_path

__all__ = ["Image", "RenderStats"]


@dataclass
class RenderStats:
    """What a render did: work counters and wall time.

    Attributes
    ----------
    samples : int
        Samples the renderer computed (ray samples, footprint pixels, resampled and
        composited samples...).
    operations : int
        Arithmetic operations by the renderer's own count model.
    bytes : int
        Bytes of the largest buffers the renderer held.
    seconds : float
        Wall time of the render.
    voxels : int
        Voxels drawn (splatting) or resampled (shearing); 0 for ray casting.
    passes : dict or None
        Shearing: samples resampled by each pass (``pass1``, ``pass2``, ``pass3``) and the
        bytes of the intermediate volumes (``buffers``).
    points : int, optional
        Reconstructed points composited into the image, the cost model's unit
        (:mod:`vrlib.cost`); ``samples`` unless the renderer says otherwise (three- and
        two-pass shearing: the composited samples, not the resampled ones).
    prefilter : dict or None
        Prefiltered filters (:mod:`vrlib.prefilter`): the prefilter's ``seconds``,
        ``operations`` and ``samples`` filtered in this render (included in the totals above;
        0, and ``cached`` True, when every coefficient it needed was kept from before), and
        ``kept_seconds``, the part spent on coefficients kept with the volume.
    choices : dict or None
        A render to a tolerance (``render(..., tolerance=t)``, :mod:`vrlib.tolerance`): what
        it chose (step, classification, budgets), its pilot, and its estimated error.

    Examples
    --------
    >>> RenderStats(samples=10, seconds=0.5).as_dict()     # doctest: +NORMALIZE_WHITESPACE
    {'samples': 10, 'operations': 0, 'bytes': 0, 'seconds': 0.5, 'voxels': 0, 'passes': None,
     'points': 10, 'prefilter': None, 'choices': None}
    """

    samples: int = 0
    operations: int = 0
    bytes: int = 0
    seconds: float = 0.0
    voxels: int = 0
    passes: dict | None = None
    points: int | None = None
    prefilter: dict | None = None
    choices: dict | None = None

    def __post_init__(self):
        if self.points is None:
            self.points = self.samples

    def as_dict(self):
        """The counters as a plain dict."""
        return asdict(self)


class Image:
    """A rendered image: premultiplied RGBA, float64, row 0 at the top.

    Parameters
    ----------
    rgba : array_like, shape (height, width, 4)
        Premultiplied colour and opacity, finite; alpha in [0, 1].
    stats : RenderStats, optional
    checked : bool, default True
        False skips the finiteness and range checks: only for a renderer whose kernel has
        clipped every value into [0, 1] (as the shear-warp warp does), never for other arrays.

    Examples
    --------
    >>> img = Image(np.full((2, 3, 4), 0.5))
    >>> img.shape, img.alpha.tolist()[0]
    ((2, 3), [0.5, 0.5, 0.5])
    >>> img.straight_rgb()[0, 0].tolist()
    [1.0, 1.0, 1.0]
    """

    def __init__(self, rgba, stats=None, *, checked=True):
        if not checked and isinstance(rgba, np.ndarray) and rgba.dtype == np.float64:
            arr = rgba  # a renderer's kernel clipped it into [0, 1]: finite by construction
        else:
            arr = validate.finite_array("rgba", rgba, ndim=3)
        if arr.ndim != 3 or arr.shape[2] != 4:
            raise ValueError(f"rgba must have shape (height, width, 4), got {arr.shape}")
        alpha = arr[..., 3]
        if checked and alpha.size and not (alpha.min() >= 0.0 and alpha.max() <= 1.0 + 1e-9):
            raise ValueError("rgba alpha must lie in [0, 1]")
        self.rgba = arr
        self.stats = RenderStats() if stats is None else stats

    @property
    def alpha(self):
        """Opacity per pixel, ``(height, width)``."""
        return self.rgba[..., 3]

    @property
    def shape(self):
        """``(height, width)``."""
        return self.rgba.shape[:2]

    def straight_rgb(self):
        """Un-premultiplied colour (zero where alpha is zero)."""
        a = self.alpha[..., None]
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(a > 0.0, self.rgba[..., :3] / a, 0.0)

    def composited(self, background=(0.0, 0.0, 0.0)):
        """RGB over an opaque ``background`` colour."""
        bg = validate.vector3("background", background)
        return self.rgba[..., :3] + (1.0 - self.rgba[..., 3:4]) * bg

    def quantised(self, *, bits=8, background=(0.0, 0.0, 0.0)):
        """Integer pixels of ``bits`` bits: RGB composited over ``background``, or RGBA with
        straight alpha when it is None (what :meth:`save` and :func:`vrlib.turntable` write).

        Examples
        --------
        >>> Image(np.full((1, 1, 4), 0.25)).quantised()[0, 0].tolist()
        [64, 64, 64]
        """
        if bits not in (8, 16):
            raise ValueError(f"bits must be 8 or 16, got {bits!r}")
        if background is None:
            pixels = np.concatenate([self.straight_rgb(), self.rgba[..., 3:4]], axis=-1)
        else:
            pixels = self.composited(background)
        top = (1 << bits) - 1
        dtype = np.uint8 if bits == 8 else np.uint16
        return np.round(np.clip(pixels, 0.0, 1.0) * top).astype(dtype)

    def to_png(self, *, bits=8, background=(0.0, 0.0, 0.0)):
        """The image as PNG bytes (:meth:`quantised`), as :meth:`save` writes them.

        Examples
        --------
        >>> Image(np.full((2, 2, 4), 0.25)).to_png()[:4]
        b'\\x89PNG'
        """
        return encode_png(self.quantised(bits=bits, background=background))

    def _repr_png_(self):
        """Jupyter shows an image as its PNG (over black)."""
        return self.to_png()

    def save(self, path, *, bits=8, background=(0.0, 0.0, 0.0)):
        """Write the image to ``.png`` or ``.npy``, atomically (temporary name, then rename).

        Parameters
        ----------
        path : str or Path
            ``.png``: 8- or 16-bit; ``.npy``: the float64 premultiplied RGBA array.
        bits : {8, 16}
            PNG bit depth.
        background : 3 floats or None
            PNG only: composite over this colour and write RGB; ``None`` writes RGBA with
            straight (un-premultiplied) alpha, as PNG defines it.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> out = pathlib.Path(tempfile.mkdtemp()) / "img.png"
        >>> Image(np.full((2, 2, 4), 0.25)).save(out, bits=16)
        >>> out.read_bytes()[:4]
        b'\\x89PNG'
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".png", ".npy"):
            raise ValueError(f"path must end in .png or .npy, got {path.name!r}")
        if suffix == ".npy":
            with atomic_path(path) as tmp:
                np.save(tmp, self.rgba)
            return
        data = self.to_png(bits=bits, background=background)
        with atomic_path(path) as tmp:
            tmp.write_bytes(data)

    def __repr__(self):
        return f"Image(shape={self.shape}, max_alpha={float(self.alpha.max(initial=0.0)):.4g})"
