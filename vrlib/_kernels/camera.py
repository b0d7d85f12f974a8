"""The packed camera that kernels read, and the rays through its pixels.

:meth:`vrlib.View.packed` lays a view out as :data:`SIZE` float64 numbers; kernels read them by
the named offsets below, never by bare indices:

==============  =====================================================================
offset          what
==============  =====================================================================
``CENTER``      3 numbers: the scene centre
``RIGHT``       3 numbers: world direction of increasing image column
``UP``          3 numbers: world direction of decreasing image row
``FORWARD``     3 numbers: the viewing direction
``PIXEL``       pixel width on the image plane (orthographic) or at unit distance
``RADIUS``      the scene radius: orthographic rays start this far before the centre
``DISTANCE``    the eye's distance from the centre (perspective), 0 for orthographic
==============  =====================================================================
"""

from __future__ import annotations

import math

from vrlib._kernels._jit import helper_jit, jit

CENTER, RIGHT, UP, FORWARD = 0, 3, 6, 9
PIXEL, RADIUS, DISTANCE = 12, 13, 14
#: Numbers in a packed camera.
SIZE = 15


@jit(inline="always")
def is_perspective(camera):
    """True for a perspective camera (an eye at a finite distance)."""
    return camera[DISTANCE] != 0.0


@jit(inline="always")
def start(camera):
    """Where rays start: the centre of the origin plane, ``RADIUS`` before the scene centre
    (orthographic), or the eye (perspective); as :attr:`vrlib.View.start`."""
    back = camera[DISTANCE] if is_perspective(camera) else camera[RADIUS]
    return (camera[CENTER] - back * camera[FORWARD],
            camera[CENTER + 1] - back * camera[FORWARD + 1],
            camera[CENTER + 2] - back * camera[FORWARD + 2])


@jit(inline="always")
def pixel_ray(camera, height, width, r, c):
    """Origin and unit direction of the ray through pixel ``(r, c)``, as
    :meth:`vrlib.View.rays` computes them."""
    px = camera[PIXEL]
    x = (c + 0.5 - 0.5 * width) * px
    y = (0.5 * height - r - 0.5) * px
    fx, fy, fz = camera[FORWARD], camera[FORWARD + 1], camera[FORWARD + 2]
    sx = y * camera[UP] + x * camera[RIGHT]
    sy = y * camera[UP + 1] + x * camera[RIGHT + 1]
    sz = y * camera[UP + 2] + x * camera[RIGHT + 2]
    o = start(camera)
    if not is_perspective(camera):
        return (o[0] + sx, o[1] + sy, o[2] + sz), (fx, fy, fz)
    dx, dy, dz = fx + sx, fy + sy, fz + sz
    norm = math.sqrt(dx * dx + dy * dy + dz * dz)
    return o, (dx / norm, dy / norm, dz / norm)


@helper_jit
def on_plane(camera, x, y, z):
    """Components of the offset ``(x, y, z)`` along ``RIGHT`` and ``UP``."""
    return (x * camera[RIGHT] + y * camera[RIGHT + 1] + z * camera[RIGHT + 2],
            x * camera[UP] + y * camera[UP + 1] + z * camera[UP + 2])


@helper_jit
def camera_coords(camera, x, y, z):
    """``(right, up, depth)`` of a world point, measured from where rays start."""
    o = start(camera)
    sx = x - o[0]
    sy = y - o[1]
    sz = z - o[2]
    return (sx * camera[RIGHT] + sy * camera[RIGHT + 1] + sz * camera[RIGHT + 2],
            sx * camera[UP] + sy * camera[UP + 1] + sz * camera[UP + 2],
            sx * camera[FORWARD] + sy * camera[FORWARD + 1] + sz * camera[FORWARD + 2])


@helper_jit
def project(camera, height, width, x, y, z):
    """Continuous image position ``(row, col)`` and depth of a world point (as
    :meth:`vrlib.View.project`); NaN position behind a perspective eye."""
    cx, cy, depth = camera_coords(camera, x, y, z)
    if is_perspective(camera):
        if depth <= 0.0:
            return math.nan, math.nan, depth
        cx /= depth
        cy /= depth
    return 0.5 * height - cy / camera[PIXEL], cx / camera[PIXEL] + 0.5 * width, depth


@jit(inline="always")
def ray_box(o, d, lo, hi):
    """Parameters ``(t_in, t_out)`` where the ray ``o + t d`` crosses the box ``[lo, hi]``
    (``t_in >= t_out`` when it misses); ``o`` and ``d`` are 3-tuples."""
    t_in = -math.inf
    t_out = math.inf
    for a in range(3):
        if d[a] == 0.0:
            if o[a] < lo[a] or o[a] > hi[a]:
                return 0.0, 0.0
        else:
            ta = (lo[a] - o[a]) / d[a]
            tb = (hi[a] - o[a]) / d[a]
            if ta > tb:
                ta, tb = tb, ta
            t_in = max(t_in, ta)
            t_out = min(t_out, tb)
    return t_in, t_out
