"""The view: camera placement, projection and the image lattice.

A view looks along ``forward`` at ``center``; ``right`` and ``up`` span the image plane, with
image columns increasing along ``right`` and rows increasing *down* (row 0 at the top). Pixel
``(row, col)`` has its centre at continuous image coordinates ``(row + 0.5, col + 0.5)``.
The basis is right-handed: ``right x up = -forward`` (the camera looks down its own -z axis,
as in OpenGL).

At ``zoom = 1`` the shorter image side spans the diameter of the scene sphere (``center``,
``radius``), so every orbit sees the whole volume. A view given neither ``center`` nor
``radius`` frames whatever it renders: :func:`vrlib.render` replaces its sphere by the
volume's bounding sphere (:meth:`View.fitted`), so a volume in its own units (millimetres, a
grid of 0..499) renders without knowing where it lies. Orthographic rays start on the plane
tangent to that sphere nearest the viewer; perspective rays start at the eye.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from vrlib import validate
from vrlib._kernels import camera as _camera

__all__ = ["View", "PROJECTIONS", "principal_axis"]

#: Projections accepted by :class:`View`.
PROJECTIONS = ("orthographic", "perspective")

_MAX_SIZE = 16384
_DEFAULT_RADIUS = math.sqrt(3.0)


def _image_size(size):
    if isinstance(size, tuple | list):
        if len(size) != 2:
            raise ValueError(f"size must be an int or a (height, width) pair, got {size!r}")
        h = validate.positive_int("size[0] (height)", size[0])
        w = validate.positive_int("size[1] (width)", size[1])
    else:
        h = w = validate.positive_int("size", size)
    if max(h, w) > _MAX_SIZE:
        raise ValueError(f"size must be at most {_MAX_SIZE} pixels per side, got ({h}, {w})")
    return h, w


class View:
    """A camera: direction, image size, projection and framing of a scene sphere.

    Most users build one with :meth:`orbit`; this constructor takes the direction directly.

    Parameters
    ----------
    forward : array_like of 3 floats
        Viewing direction (from the eye towards the scene); normalised here.
    up : array_like of 3 floats, default (0, 0, 1)
        A world direction that appears upward in the image; must not be parallel to
        ``forward``.
    size : int or (int, int), default 256
        Image size in pixels: ``n`` for ``n x n`` or ``(height, width)``.
    center : array_like of 3 floats, optional
        The point looked at; the centre of the scene sphere.
    radius : float, optional
        Radius of the scene sphere. Give neither ``center`` nor ``radius`` to frame the volume
        rendered (its bounding sphere, :meth:`fitted`); until then the view frames the cube
        [-1, 1]^3 (centre 0, radius ``sqrt(3)``).
    projection : {"orthographic", "perspective"}
    zoom : float, default 1.0
        Magnification (> 0): at 1 the shorter image side spans the sphere's diameter.
    fov : float, optional
        Perspective only: full angle in degrees, in (0, 180), seen by the shorter image side at
        ``zoom = 1``. Default: the angle the scene sphere subtends from the eye.
    distance : float, optional
        Perspective only: distance from the eye to ``center``; default ``4 * radius``. Without
        ``fov`` the eye must be outside the scene sphere.

    Raises
    ------
    ValueError
        Zero or non-finite vectors, ``up`` parallel to ``forward``, a non-positive size, zoom,
        radius or distance, an unknown projection, ``fov`` outside (0, 180), or a perspective
        eye inside the scene sphere with no ``fov`` to frame it.

    Examples
    --------
    >>> view = View([0, 0, -1], up=[0, 1, 0], size=4)
    >>> view.basis.tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]
    >>> round(view.pixel_size, 6)          # 2 sqrt(3) / 4
    0.866025
    """

    def __init__(self, forward, up=(0.0, 0.0, 1.0), *, size=256, center=None, radius=None,
                 projection="orthographic", zoom=1.0, fov=None, distance=None):
        #: Whether the scene sphere was given (False: :meth:`fitted` frames the volume).
        self.framed = center is not None or radius is not None
        self._given = {"up": up, "fov": fov, "distance": distance}
        self._fitted = None  # (box, view): the last framing fitted() made (it reuses it)
        self._seen = None  # (box, answer): the last box sees() was asked about
        self._lines = None  # the view moved back from (orthographic: the same ray lines)
        center = (0.0, 0.0, 0.0) if center is None else center
        radius = _DEFAULT_RADIUS if radius is None else radius
        f = validate.vector3("forward", forward, unit=True)
        up = validate.vector3("up", up, unit=True)
        right = np.cross(f, up)
        if np.linalg.norm(right) < 1e-9:
            raise ValueError(
                f"up {up.tolist()} is parallel to the view direction {f.tolist()}; "
                "give an up vector across the view"
            )
        right /= np.linalg.norm(right)
        self._basis = np.array([right, np.cross(right, f), f])
        self._basis.flags.writeable = False
        self.center = validate.vector3("center", center).copy()  # not the caller's array
        self.center.flags.writeable = False  # shared with the resized views
        self.radius = validate.positive_number("radius", radius)
        self.projection = validate.choice("projection", projection, PROJECTIONS)
        self.zoom = validate.positive_number("zoom", zoom)
        if self.projection == "orthographic":
            if fov is not None or distance is not None:
                raise ValueError("fov and distance apply to the perspective projection only")
            self.fov = self.distance = None
        else:
            if distance is None:
                distance = 4.0 * self.radius
            self.distance = validate.positive_number("distance", distance)
            if fov is None:
                if self.distance <= self.radius:
                    raise ValueError(
                        f"the eye (distance {self.distance:g}) is inside the scene sphere "
                        f"(radius {self.radius:g}): give fov explicitly or move the eye out"
                    )
                fov = 2.0 * math.degrees(math.asin(self.radius / self.distance))
            self.fov = validate.finite_number("fov", fov, low=0.0, high=180.0,
                                               low_open=True, high_open=True)
        self._set_size(size)

    @classmethod
    def orbit(cls, *, azimuth=0.0, elevation=0.0, size=256, projection="orthographic",
              zoom=1.0, fov=None, distance=None, center=None, radius=None):
        """A view from a point on a sphere around ``center``, world z up.

        The eye lies in direction ``(cos e cos a, cos e sin a, sin e)`` from the centre
        (``a`` azimuth about z from +x, ``e`` elevation above the xy plane, in degrees) and
        looks at the centre. Image right is ``(-sin a, cos a, 0)`` at every elevation, so views
        straight down (``e = 90``) are well defined. Other parameters as for :class:`View`.

        Examples
        --------
        >>> view = View.orbit(azimuth=0, elevation=0, size=8)
        >>> view.basis.round(12).tolist()     # right, up, forward
        [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]]
        >>> View.orbit(elevation=90, size=8).forward.round(12).tolist()
        [-0.0, -0.0, -1.0]
        """
        a = math.radians(validate.finite_number("azimuth", azimuth))
        e = math.radians(validate.finite_number("elevation", elevation))
        eye_dir = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
        right = np.array([-math.sin(a), math.cos(a), 0.0])
        up = np.cross(right, -eye_dir)
        return cls(-eye_dir, up, size=size, center=center, radius=radius,
                   projection=projection, zoom=zoom, fov=fov, distance=distance)

    @classmethod
    def fit(cls, volume, **orbit):
        """An orbit view (:meth:`orbit`'s keywords) framing ``volume``'s bounding sphere.

        Examples
        --------
        >>> from vrlib import Volume
        >>> vol = Volume(np.zeros((2, 2, 2)), spacing=(499, 469, 135))
        >>> view = View.fit(vol, azimuth=30, size=8)
        >>> view.center.tolist(), round(view.radius, 1)
        ([249.5, 234.5, 67.5], 349.0)
        """
        box = extent_of(volume)
        return cls.orbit(center=box.mean(axis=1), radius=_radius_of(box), **orbit)

    def fitted(self, volume):
        """This view framing ``volume`` (a :class:`vrlib.Volume`, a field or a world box
        ``(3, 2)``), unless it was given its own ``center`` or ``radius``: then itself.

        :func:`vrlib.render` and the other renderers' entry points call it, so a view built
        from angles alone sees the whole volume, in any units.

        Examples
        --------
        >>> box = [[0, 499], [0, 469], [0, 135]]
        >>> View.orbit(azimuth=30, size=8).fitted(box).center.tolist()
        [249.5, 234.5, 67.5]
        >>> View.orbit(size=8, radius=1.0).fitted(box).center.tolist()   # framed by the user
        [0.0, 0.0, 0.0]
        """
        if self.framed:
            return self
        box = extent_of(volume)
        # The last box's view is kept: renders of one view (another step, transfer function
        # or volume of the same box) ask again (0.1-0.3 ms of a render's Python each time).
        kept = self._fitted
        if kept is not None and kept[0] == box.tobytes():
            return kept[1]
        view = View(self.forward, self._given["up"], size=self.shape, center=box.mean(axis=1),
                    radius=_radius_of(box), projection=self.projection, zoom=self.zoom,
                    fov=self._given["fov"], distance=self._given["distance"])
        self._fitted = (box.tobytes(), view)
        return view

    def resized(self, size):
        """This view with ``size`` pixels (``n`` or ``(height, width)``) over the same image:
        the same framing, larger or smaller pixels (a preview, a pilot render).

        Examples
        --------
        >>> view = View.orbit(azimuth=30, size=64, radius=1.0)
        >>> small = view.resized(16)
        >>> small.shape, round(small.pixel_size / view.pixel_size, 6)
        ((16, 16), 4.0)
        """
        view = copy.copy(self)  # the same camera (its arrays are read-only), other pixels
        view._fitted = view._seen = view._lines = None
        view._set_size(size)
        return view

    def moved_back(self, distance):
        """This view with its camera moved ``distance`` world units back along its direction.
        An orthographic view's rays stay on their lines, so it sees the same image of
        everything in front of it, while each ray's samples, spaced from where it starts,
        move ``distance`` along it (:mod:`vrlib.tolerance` checks the sampling's phase so).

        Examples
        --------
        >>> view = View.orbit(azimuth=30, size=8, radius=1.0)
        >>> back = view.moved_back(0.25)
        >>> bool(np.allclose(view.start - back.start, 0.25 * view.forward)), back.shape
        (True, (8, 8))
        """
        view = copy.copy(self)
        view._fitted = view._seen = None
        view._lines = None if self.is_perspective else self.lines
        view.center = self.center - distance * self.forward
        view.center.flags.writeable = False
        return view

    def _set_size(self, size):
        """The image's ``size`` and the pixels' pitch that follows from it."""
        self.height, self.width = _image_size(size)
        if self.projection == "orthographic":
            # Width of one pixel on the image plane, in world units.
            self._pixel = 2.0 * self.radius / (self.zoom * min(self.height, self.width))
        else:
            half = math.tan(math.radians(self.fov) / 2.0) / self.zoom
            # Width of one pixel on the plane one world unit in front of the eye.
            self._pixel = 2.0 * half / min(self.height, self.width)
        self._pixel_size = self._pixel if self.distance is None else self._pixel * self.distance

    def sees(self, extent):
        """Whether any part of the world box ``extent`` projects into the image.

        Examples
        --------
        >>> view = View.orbit(size=8, radius=1.0)
        >>> inside, outside = [[-1, 1], [-1, 1], [-1, 1]], [[0, 1], [50, 60], [0, 1]]
        >>> view.sees(inside), view.sees(outside), view.sees(inside)
        (True, False, True)
        """
        box = np.asarray(extent, dtype=np.float64)
        # The last answer is kept: every frame of an animation asks again about one box.
        key = (box.shape, box.tobytes())
        if self._seen is None or self._seen[0] != key:
            self._seen = (key, self._projects_into_image(box))
        return self._seen[1]

    def _projects_into_image(self, box):
        """:meth:`sees`, computed."""
        corners = box[_AXES, BOX_CORNERS]  # (8, 3): x, y, z each at its low or high end
        if self.is_perspective:
            depth = self.to_camera(corners)[:, 2]
            if np.all(depth <= 0.0):
                return False
            if np.any(depth <= 0.0):
                return True  # the eye is inside or beside the box: it may fill the view
        rows, cols = self.project(corners)[:, :2].T
        return bool(rows.min() < self.height and rows.max() > 0.0
                    and cols.min() < self.width and cols.max() > 0.0)

    # -- geometry --------------------------------------------------------------------------

    @property
    def basis(self):
        """Rows ``right, up, forward`` (world unit vectors)."""
        return self._basis

    @property
    def right(self):
        """World direction of increasing image column."""
        return self._basis[0]

    @property
    def up(self):
        """World direction of decreasing image row."""
        return self._basis[1]

    @property
    def forward(self):
        """Viewing direction (towards the scene)."""
        return self._basis[2]

    @property
    def shape(self):
        """``(height, width)`` of the image in pixels."""
        return (self.height, self.width)

    @property
    def lines(self):
        """The view whose rays lie on the same lines as this one's, pixel for pixel: this
        view, or for an orthographic view :meth:`moved_back`, the view it was moved from.
        What depends on the rays' lines alone (which pixels' rays can meet a block) is kept
        for both under it.

        Examples
        --------
        >>> view = View.orbit(azimuth=30, size=8, radius=1.0)
        >>> view.moved_back(0.25).lines is view, view.resized(4).lines is view
        (True, False)
        """
        return self if self._lines is None else self._lines

    @property
    def is_perspective(self):
        """True for the perspective projection."""
        return self.projection == "perspective"

    @property
    def start(self):
        """Where rays start: the eye (perspective), or the centre of the origin plane,
        ``radius`` before ``center`` along ``forward`` (orthographic), from which each ray is
        offset by its pixel's position on the plane.

        Examples
        --------
        >>> View([0, 0, -1], up=[0, 1, 0], radius=1.0).start.tolist()
        [0.0, 0.0, 1.0]
        """
        if self.is_perspective:
            return self.eye
        return self.center - self.radius * self.forward

    @property
    def eye(self):
        """Eye position (perspective) or ``None`` (orthographic: the eye is at infinity)."""
        if self.distance is None:
            return None
        return self.center - self.distance * self.forward

    @property
    def pixel_size(self):
        """World units per pixel: on the image plane (orthographic), or at ``center``
        (perspective)."""
        return self._pixel_size

    @property
    def plane_pixel(self):
        """Pixel width on the image plane (orthographic), or at unit distance from the eye
        (perspective): the pitch of the pixels' offsets from :attr:`start`."""
        return self._pixel

    def _plane_offsets(self):
        """Offsets of pixel centres along ``right`` (per column) and ``up`` (per row)."""
        cols = (np.arange(self.width) + 0.5 - 0.5 * self.width) * self._pixel
        rows = (0.5 * self.height - np.arange(self.height) - 0.5) * self._pixel
        return rows, cols

    def packed(self):
        """The view as numbers for the numba kernels, laid out as the named offsets of
        :mod:`vrlib._kernels.camera` say: centre, right, up, forward (3 each), pixel width on
        the image plane (orthographic) or at unit distance (perspective), radius, and the eye
        distance (0 for orthographic).

        Examples
        --------
        >>> from vrlib._kernels.camera import DISTANCE, PIXEL, RADIUS
        >>> camera = View([0, 0, -1], up=[0, 1, 0], size=2, radius=1.0).packed()
        >>> camera[[PIXEL, RADIUS, DISTANCE]].tolist()
        [1.0, 1.0, 0.0]
        """
        camera = np.empty(_camera.SIZE)
        camera[_camera.CENTER:_camera.CENTER + 3] = self.center
        camera[_camera.RIGHT:_camera.RIGHT + 3] = self.right
        camera[_camera.UP:_camera.UP + 3] = self.up
        camera[_camera.FORWARD:_camera.FORWARD + 3] = self.forward
        camera[_camera.PIXEL] = self._pixel
        camera[_camera.RADIUS] = self.radius
        camera[_camera.DISTANCE] = self.distance if self.is_perspective else 0.0
        return camera

    def rays(self):
        """One ray per pixel centre: ``(origins, directions)``, each ``(height, width, 3)``.

        Directions are unit vectors. Orthographic origins lie on the plane tangent to the scene
        sphere nearest the viewer, so the sphere spans ray parameters ``[0, 2 * radius]``;
        perspective origins are the eye.

        Examples
        --------
        >>> o, d = View([0, 0, -1], up=[0, 1, 0], size=2, radius=1.0).rays()
        >>> o[0, 0].tolist(), d[0, 0].tolist()
        ([-0.5, 0.5, 1.0], [0.0, 0.0, -1.0])
        """
        rows, cols = self._plane_offsets()
        r, u, f = self._basis
        offsets = rows[:, None, None] * u + cols[None, :, None] * r
        if not self.is_perspective:
            origins = self.start + offsets
            directions = np.broadcast_to(f, origins.shape).copy()
        else:
            directions = f + offsets
            directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
            origins = np.broadcast_to(self.start, directions.shape).copy()
        return origins, directions

    def to_camera(self, points):
        """World points ``(..., 3)`` to camera coordinates ``(right, up, depth)``.

        Depth is measured along ``forward`` from the ray-origin plane (orthographic) or from
        the eye (perspective).

        Examples
        --------
        >>> View([0, 0, -1], up=[0, 1, 0], radius=1.0).to_camera([0.5, 0.25, 0.0]).tolist()
        [0.5, 0.25, 1.0]
        """
        p = np.asarray(points, dtype=np.float64)
        return (p - self.start) @ self._basis.T

    def project(self, points):
        """World points ``(..., 3)`` to continuous image coordinates ``(row, col, depth)``.

        Pixel ``(r, c)`` covers ``[r, r + 1) x [c, c + 1)``; points behind a perspective eye
        get ``nan`` image coordinates.

        Examples
        --------
        >>> view = View([0, 0, -1], up=[0, 1, 0], size=2, radius=1.0)
        >>> view.project([[0.0, 0.0, 0.0], [-0.5, 0.5, 0.0]]).tolist()
        [[1.0, 1.0, 1.0], [0.5, 0.5, 1.0]]
        """
        cam = self.to_camera(points)
        x, y, depth = cam[..., 0], cam[..., 1], cam[..., 2]
        if self.is_perspective:
            with np.errstate(divide="ignore", invalid="ignore"):
                scale = np.where(depth > 0.0, 1.0 / depth, np.nan)
            x, y = x * scale, y * scale
        col = x / self._pixel + 0.5 * self.width
        row = 0.5 * self.height - y / self._pixel
        return np.stack([row, col, depth], axis=-1)

    def __repr__(self):
        f = ", ".join(f"{v:.4g}" for v in self.forward)
        extra = ""
        if self.distance is not None:
            extra = f", fov={self.fov:.4g}, distance={self.distance:g}"
        return (
            f"View(forward=[{f}], size=({self.height}, {self.width}), "
            f"projection={self.projection!r}, zoom={self.zoom:g}{extra})"
        )


#: The eight corners of a box, ``(8, 3)``: the end (0 low, 1 high) each axis takes.
BOX_CORNERS = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
_AXES = np.arange(3)


def extent_of(scene):
    """The world box of a volume, a field (its ``bounds``) or a ``(3, 2)`` array."""
    for name in ("extent", "bounds"):
        if hasattr(scene, name):
            return np.asarray(getattr(scene, name), dtype=np.float64)
    box = np.asarray(scene, dtype=np.float64)
    if box.shape != (3, 2):
        raise ValueError(f"a view frames a Volume, a field or a (3, 2) world box, got {scene!r}")
    return box


def _radius_of(box):
    return float(0.5 * np.linalg.norm(box[:, 1] - box[:, 0]))


def principal_axis(view, volume):
    """The volume axis (0, 1, 2 for x, y, z) most parallel to the view, and whether slices
    run front to back in increasing index order: the slicing axis of splatting and
    shear-warp.

    Orthographic views use the view direction; perspective views the direction from the eye
    to the volume's centre. Ties (views at exactly 45 degrees) go to the lower axis.

    Examples
    --------
    >>> from vrlib import Volume
    >>> principal_axis(View.orbit(azimuth=45, elevation=0), Volume(np.zeros((2, 2, 2))))
    (0, False)
    """
    direction = (volume.center - view.eye if view.is_perspective else view.forward).tolist()
    strength = [abs(d) for d in direction]  # plain floats: 4 -> 2 us a frame
    top = max(strength) - 1e-12
    axis = next(a for a in range(3) if strength[a] >= top)
    return axis, direction[axis] > 0
