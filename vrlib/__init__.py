"""vrlib: volume reconstruction and rendering after Neumann (1993).

Conventions, stated once for the whole package:

* World coordinates are right-handed ``(x, y, z)``; the default volume fills the cube
  [-1, 1]^3.
* Volume samples are stored ``data[z, y, x]`` and are vertex-centred: they sit on the corners
  of the world box and evenly between them, sample ``(i, j, k)`` at
  ``origin + (i, j, k) * spacing``.
* Filters are 1-D kernels in voxel units, applied separably along x, y and z.
* Images are ``[row, col]`` with row 0 at the top; pixel ``(r, c)`` has its centre at
  continuous image coordinates ``(r + 0.5, c + 0.5)`` and one ray through that centre.
* Colours are premultiplied RGBA floats; opacity densities are per world unit.
* Every renderer samples one global lattice anchored in world space, so a volume split into
  bricks renders without seams.

The public API is the list in ``__all__``.
"""

from vrlib import bounds, compositing, cost, filters, metrics, prefilter
from vrlib.animation import turntable
from vrlib.arguments import EmptyImageWarning
from vrlib.classified import ClassifiedVolume, classify
from vrlib.colormapping import auto_transfer, colormap, default_transfer, label_transfer
from vrlib.filters import FILTERS, make_filter
from vrlib.image import Image, RenderStats
from vrlib.reconstruction import ReconstructedField, reconstruct
from vrlib.reference import render_reference
from vrlib.render import METHODS, reference_image, render
from vrlib.transfer import Glow, GradientOpacity, LookupTransfer, Phong, TransferFunction
from vrlib.view import View
from vrlib.volume import Volume

__version__ = "0.1.0"

__all__ = [
    "render",
    "render_reference",
    "turntable",
    "reconstruct",
    "ReconstructedField",
    "reference_image",
    "METHODS",
    "classify",
    "ClassifiedVolume",
    "Volume",
    "View",
    "Glow",
    "LookupTransfer",
    "colormap",
    "auto_transfer",
    "default_transfer",
    "label_transfer",
    "Phong",
    "GradientOpacity",
    "TransferFunction",
    "Image",
    "RenderStats",
    "EmptyImageWarning",
    "make_filter",
    "FILTERS",
    "filters",
    "prefilter",
    "compositing",
    "metrics",
    "bounds",
    "cost",
]
