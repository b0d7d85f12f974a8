"""A turntable: the volume seen from evenly spaced azimuths, written as an animated GIF or an
MP4 movie, as people share volume renderings."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from vrlib import validate
from vrlib.atomic import atomic_path
from vrlib.render import render
from vrlib.view import View

__all__ = ["turntable"]


#: The most views a turntable takes (a view every 0.1 degree); its frames are kept in memory.
MAX_FRAMES = 3600


def turntable(volume, path, *, frames=36, elevation=20.0, size=256, zoom=1.0, fps=12,
              progress=True, **options):
    """Render ``frames`` views around the world z axis and write them to ``path``.

    Parameters
    ----------
    volume : Volume
    path : str or Path
        ``.gif`` (Pillow) or ``.mp4`` (needs the ``imageio-ffmpeg`` package); written under a
        temporary name and renamed when complete.
    frames : int, default 36
        Views at azimuths ``360 i / frames`` degrees (1 to :data:`MAX_FRAMES`).
    elevation : float, default 20
        Degrees above the xy plane.
    size, zoom
        As :meth:`vrlib.View.orbit`; the views frame the volume.
    fps : float, default 12
        Frames per second.
    progress : bool, default True
        A progress bar on standard error (when it is a terminal).
    **options
        Passed to :func:`vrlib.render` (``method``, ``filter``, ``transfer``, ...).

    Returns
    -------
    list of Image
        The frames.

    Examples
    --------
    >>> import tempfile, pathlib, data_gen
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "blob.gif"
    >>> vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(12)
    >>> images = turntable(vol, out, frames=4, size=8, progress=False)
    >>> len(images), out.read_bytes()[:3]
    (4, b'GIF')
    """
    import imageio.v3 as iio
    from tqdm import tqdm

    path = Path(path)
    suffix = path.suffix.lower()
    validate.choice("path suffix", suffix, (".gif", ".mp4"))
    frames = validate.positive_int("frames", frames)
    if frames > MAX_FRAMES:
        raise ValueError(f"frames must be at most {MAX_FRAMES} (a view every 0.1 degree), "
                         f"got {frames}")
    fps = validate.positive_number("fps", fps)
    if suffix == ".mp4":
        try:
            import imageio_ffmpeg  # noqa: F401
        except ImportError:
            raise ImportError("writing .mp4 needs imageio-ffmpeg (pip install imageio-ffmpeg); "
                              ".gif needs nothing more") from None
    if not path.parent.is_dir():
        raise FileNotFoundError(f"no folder {str(path.parent)!r} to write {path.name} into")
    images, pixels = [], []
    angles = 360.0 * np.arange(frames) / frames
    for azimuth in tqdm(angles, desc="turntable", unit="frame", file=sys.stderr,
                        disable=None if progress else True):
        view = View.orbit(azimuth=float(azimuth), elevation=elevation, size=size, zoom=zoom)
        image = render(volume, view, **options)
        images.append(image)
        pixels.append(image.quantised())
    with atomic_path(path) as tmp:
        if suffix == ".gif":
            iio.imwrite(tmp, np.stack(pixels), extension=".gif", duration=1000.0 / fps,
                        loop=0)
        else:
            iio.imwrite(tmp, np.stack(pixels), extension=".mp4", fps=fps)
    return images
