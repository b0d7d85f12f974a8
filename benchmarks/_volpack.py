"""VolPack (Lacroute and Levoy's shear-warp library, Debian's ``libvolpack1``) through ctypes.

Set up to render the glow model: one 8-bit density field classified by a table
``1 - exp(-density * L)`` with ``L`` the distance between slices along the view (VolPack
composites per-voxel opacities slice by slice and does not correct them for the view), white
colour from a constant lookup shader, luminance + alpha output. VolPack's object space spans the
volume's longest side over [-0.5, 0.5], half our world units; its image rows run bottom-up.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import time

import numpy as np

VP_MIN_VOXEL_OPACITY, VP_MAX_RAY_OPACITY = 1014, 1043
VP_MODEL, VP_PROJECT, VP_PARALLEL, VP_LUMINANCEA = 0, 2, 2400, 5002
VP_NORM_MAX = 7923


def load():
    """The library, or None when it is not installed."""
    try:
        lib = ctypes.CDLL("libvolpack.so.1")
    except OSError:
        return None
    lib.vpCreateContext.restype = ctypes.c_void_p
    lib.vpGetErrorString.restype = ctypes.c_char_p
    lib.vpWindow.argtypes = [ctypes.c_void_p, ctypes.c_int] + [ctypes.c_double] * 6
    lib.vpSetd.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_double]
    lib.vpDestroyContext.argtypes = [ctypes.c_void_p]
    return lib


class VolPack:
    """One classified volume and view, ready to render repeatedly."""

    def __init__(self, lib, volume, view, transfer, *, min_opacity, max_opacity):
        self.lib = lib
        self.ctx = ctypes.c_void_p(lib.vpCreateContext())
        nz, ny, nx = volume.shape
        voxels = np.zeros(volume.shape, dtype=[("normal", "<u2"), ("density", "u1"),
                                               ("pad", "u1")])
        lo, hi = volume.value_range
        voxels["density"] = np.clip(np.round((volume.data - lo) / (hi - lo) * 255), 0, 255)
        self.voxels = voxels  # VolPack keeps a pointer
        axis = int(np.argmax(np.abs(view.forward)))
        length = volume.spacing[axis] / abs(view.forward[axis])
        values = lo + np.arange(256) / 255.0 * (hi - lo)
        self.table = (-np.expm1(-transfer.opacity_density(values) * length)).astype(np.float32)
        self.shade = np.full(VP_NORM_MAX + 1, 255.0, np.float32)
        ctx = self.ctx
        self._ok(lib.vpSetVolumeSize(ctx, nx, ny, nz), "volume size")
        self._ok(lib.vpSetVoxelSize(ctx, 4, 2, 1, 1), "voxel size")
        self._ok(lib.vpSetVoxelField(ctx, 0, 2, 0, VP_NORM_MAX), "normal field")
        self._ok(lib.vpSetVoxelField(ctx, 1, 1, 2, 255), "density field")
        self._ok(lib.vpSetRawVoxels(ctx, voxels.ctypes.data_as(ctypes.c_void_p), voxels.nbytes,
                                    4, 4 * nx, 4 * nx * ny), "voxels")
        self._ok(lib.vpSetClassifierTable(ctx, 0, 1, self.table.ctypes.data_as(ctypes.c_void_p),
                                          self.table.nbytes), "classifier")
        self._ok(lib.vpSetLookupShader(ctx, 1, 1, 0, self.shade.ctypes.data_as(ctypes.c_void_p),
                                       self.shade.nbytes, 0, None, 0), "shader")
        lib.vpSetd(ctx, VP_MIN_VOXEL_OPACITY, min_opacity)
        lib.vpSetd(ctx, VP_MAX_RAY_OPACITY, max_opacity)
        start = time.perf_counter()
        self._ok(lib.vpClassifyVolume(ctx), "classification")
        self.classify_seconds = time.perf_counter() - start
        model = np.eye(4)
        model[:3, :3] = [view.right, view.up, -view.forward]  # eye: x right, y up, z to viewer
        self.model = (ctypes.c_double * 16)(*model.ravel())
        self._ok(lib.vpCurrentMatrix(ctx, VP_MODEL), "model")
        self._ok(lib.vpSetMatrix(ctx, self.model), "model matrix")
        self._ok(lib.vpCurrentMatrix(ctx, VP_PROJECT), "projection")
        self._ok(lib.vpIdentityMatrix(ctx), "projection matrix")
        half_w = view.pixel_size * view.width / 4.0  # our world units / 2
        half_h = view.pixel_size * view.height / 4.0
        self._ok(lib.vpWindow(ctx, VP_PARALLEL, -half_w, half_w, -half_h, half_h, -half_w * 2,
                              half_w * 2), "window")
        self.image = np.zeros((view.height, view.width, 2), np.uint8)
        self._ok(lib.vpSetImage(ctx, self.image.ctypes.data_as(ctypes.POINTER(ctypes.c_ubyte)),
                                view.width, view.height, view.width * 2, VP_LUMINANCEA), "image")

    def _ok(self, result, what):
        if result != 0:
            message = self.lib.vpGetErrorString(self.lib.vpGetError(self.ctx)).decode()
            raise RuntimeError(f"VolPack {what}: {message}")

    def render(self):
        self._ok(self.lib.vpRenderClassifiedVolume(self.ctx), "render")

    def alpha(self):
        """Opacity per pixel, row 0 at the top, from VolPack's 8-bit image."""
        return self.image[::-1, :, 1] / 255.0

    def close(self):
        self.lib.vpDestroyContext(self.ctx)


# VolPack's own example (Debian's libvolpack1-dev: examples/volume.h, classifyvolume.c,
# rendervolume.c): the MRI head, its classification ramps, its material and light.
EXAMPLES = "/usr/share/doc/libvolpack1-dev/examples"
BRAIN_FILE, BRAIN_HEADER, BRAIN_SHAPE = "brainsmall.den", 62, (84, 128, 128)  # [z, y, x]
DENSITY_RAMP = ([0, 24, 255], [0.0, 1.0, 1.0])
GRADIENT_RAMP = ([0, 5, 20, 221], [0.0, 0.0, 1.0, 1.0])
MATERIAL = {"ambient": 0.18, "diffuse": 0.35, "specular": 0.39, "shininess": 10.0}
LIGHT = (0.3, 0.3, 1.0)  # eye coordinates, towards the light
MIN_VOXEL_OPACITY, MAX_RAY_OPACITY, IMAGE_SIZE = 0.05, 0.95, 256
VP_LIGHT_BOTH_SIDES, VP_DEPTH_CUE, VP_CONCAT_MODE, VP_CONCAT_LEFT = 1029, 1031, 1038, 2601
VP_LUMINANCE, VP_LIGHT0, VP_COLOR, VP_DIRECTION = 5001, 2000, 2100, 2101
VP_MATERIAL0, VP_BOTH_SIDES = 2200, 3
VP_AMBIENT, VP_DIFFUSE, VP_SPECULAR, VP_SHINYNESS = 2300, 2301, 2302, 2303
VP_X_AXIS, VP_Y_AXIS = 0, 1


def brain_density():
    """The example's 8-bit MRI head ``[z, y, x]``, or None when libvolpack1-dev is missing."""
    import os

    path = os.path.join(EXAMPLES, BRAIN_FILE)
    if not os.path.exists(path):
        return None
    raw = np.fromfile(path, dtype=np.uint8)
    expected = BRAIN_HEADER + int(np.prod(BRAIN_SHAPE))
    if raw.size != expected:
        raise ValueError(f"{path}: {raw.size} bytes, expected {expected}")
    return raw[BRAIN_HEADER:].reshape(BRAIN_SHAPE).copy()


def _ramp(points, size):
    """``vpRamp``: the piecewise-linear table through integer ``points`` over 0 .. size - 1."""
    xs, ys = points
    return np.interp(np.arange(size), xs, ys).astype(np.float32)


class BrainExample:
    """VolPack's example scene, classified by VolPack itself (``vpVolumeNormals``,
    ``vpClassifyVolume`` with the density and gradient ramps) and shaded by its lookup shader.

    Two changes from the example, so that vrlib renders the same scene: lighting is two-sided
    (``VP_LIGHT_BOTH_SIDES``, as vrlib's Phong) and depth cueing is off (vrlib has none).
    ``opacity_cap`` replaces opacity 1 (infinite density in vrlib's model), and the gradient
    table is ``g'(x) = (1 - (1 - cap)^g(x)) / cap``, so that VolPack's product of per-voxel
    opacities equals vrlib's product of densities at full density (VolPack multiplies
    opacities, vrlib multiplies densities: they agree where a factor is 0 or 1).
    """

    def __init__(self, lib, density, *, opacity_cap):
        self.lib = lib
        lib.vpSetMaterial.argtypes = [ctypes.c_void_p] + [ctypes.c_int] * 3 + [ctypes.c_double] * 3
        lib.vpSetLight.argtypes = [ctypes.c_void_p] + [ctypes.c_int] * 2 + [ctypes.c_double] * 3
        lib.vpRotate.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_double]
        lib.vpGetMatrix.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_void_p]
        self.ctx = ctx = ctypes.c_void_p(lib.vpCreateContext())
        nz, ny, nx = density.shape
        self.density = np.ascontiguousarray(density, dtype=np.uint8)
        self.voxels = np.zeros(density.shape, dtype=[("normal", "<u2"), ("density", "u1"),
                                                     ("gradient", "u1")])
        self._ok(lib.vpSetVolumeSize(ctx, nx, ny, nz), "volume size")
        self._ok(lib.vpSetVoxelSize(ctx, 4, 3, 2, 2), "voxel size")
        self._ok(lib.vpSetVoxelField(ctx, 0, 2, 0, VP_NORM_MAX), "normal field")
        self._ok(lib.vpSetVoxelField(ctx, 1, 1, 2, 255), "density field")
        self._ok(lib.vpSetVoxelField(ctx, 2, 1, 3, 221), "gradient field")
        self._ok(lib.vpSetRawVoxels(ctx, self.voxels.ctypes.data_as(ctypes.c_void_p),
                                    self.voxels.nbytes, 4, 4 * nx, 4 * nx * ny), "voxels")
        start = time.perf_counter()
        self._ok(lib.vpVolumeNormals(ctx, self.density.ctypes.data_as(ctypes.c_void_p),
                                     self.density.size, 1, 2, 0), "normals")
        cap = float(opacity_cap)
        self.density_table = np.minimum(_ramp(DENSITY_RAMP, 256), cap).astype(np.float32)
        g = _ramp(GRADIENT_RAMP, 222).astype(np.float64)
        self.gradient_table = (-np.expm1(g * np.log1p(-cap)) / cap).astype(np.float32)
        self._ok(lib.vpSetClassifierTable(ctx, 0, 1, self.density_table.ctypes.data_as(
            ctypes.c_void_p), self.density_table.nbytes), "density table")
        self._ok(lib.vpSetClassifierTable(ctx, 1, 2, self.gradient_table.ctypes.data_as(
            ctypes.c_void_p), self.gradient_table.nbytes), "gradient table")
        lib.vpSetd(ctx, VP_MIN_VOXEL_OPACITY, MIN_VOXEL_OPACITY)
        self._ok(lib.vpClassifyVolume(ctx), "classification")
        self.classify_seconds = time.perf_counter() - start
        self.shade = np.zeros(VP_NORM_MAX + 1, np.float32)
        self._ok(lib.vpSetLookupShader(ctx, 1, 1, 0, self.shade.ctypes.data_as(ctypes.c_void_p),
                                       self.shade.nbytes, 0, None, 0), "shader")
        for prop, key in [(VP_AMBIENT, "ambient"), (VP_DIFFUSE, "diffuse"),
                          (VP_SPECULAR, "specular")]:
            value = MATERIAL[key]
            lib.vpSetMaterial(ctx, VP_MATERIAL0, prop, VP_BOTH_SIDES, value, value, value)
        lib.vpSetMaterial(ctx, VP_MATERIAL0, VP_SHINYNESS, VP_BOTH_SIDES,
                          MATERIAL["shininess"], 0.0, 0.0)
        lib.vpSetLight(ctx, VP_LIGHT0, VP_DIRECTION, *LIGHT)
        lib.vpSetLight(ctx, VP_LIGHT0, VP_COLOR, 1.0, 1.0, 1.0)
        lib.vpEnable(ctx, VP_LIGHT0, 1)
        lib.vpEnable(ctx, VP_LIGHT_BOTH_SIDES, 1)
        lib.vpEnable(ctx, VP_DEPTH_CUE, 0)
        lib.vpSeti(ctx, VP_CONCAT_MODE, VP_CONCAT_LEFT)
        self._ok(lib.vpCurrentMatrix(ctx, VP_PROJECT), "projection")
        self._ok(lib.vpIdentityMatrix(ctx), "projection matrix")
        self._ok(lib.vpWindow(ctx, VP_PARALLEL, -0.5, 0.5, -0.5, 0.5, -0.5, 0.5), "window")
        self._ok(lib.vpCurrentMatrix(ctx, VP_MODEL), "model")
        self.image = np.zeros((IMAGE_SIZE, IMAGE_SIZE), np.uint8)
        self._ok(lib.vpSetImage(ctx, self.image.ctypes.data_as(ctypes.c_void_p), IMAGE_SIZE,
                                IMAGE_SIZE, IMAGE_SIZE, VP_LUMINANCE), "image")
        lib.vpSetd(ctx, VP_MAX_RAY_OPACITY, MAX_RAY_OPACITY)

    _ok = VolPack._ok

    def orient(self, turn):
        """The example's view turned by ``turn`` degrees about the vertical: its rotations
        (y by 130, x by -15, concatenated on the left) and then y by ``turn``."""
        self._ok(self.lib.vpIdentityMatrix(self.ctx), "model identity")
        for axis, degrees in [(VP_Y_AXIS, 130.0), (VP_X_AXIS, -15.0), (VP_Y_AXIS, turn)]:
            self._ok(self.lib.vpRotate(self.ctx, axis, degrees), "rotate")

    def model(self):
        """The current model matrix (object to eye), 4 x 4."""
        matrix = np.zeros(16)
        self._ok(self.lib.vpGetMatrix(self.ctx, VP_MODEL, matrix.ctypes.data_as(
            ctypes.c_void_p)), "get matrix")
        return matrix.reshape(4, 4)

    def render(self):
        """One frame as the example draws it: the shading table, then the render."""
        self._ok(self.lib.vpShadeTable(self.ctx), "shade table")
        self._ok(self.lib.vpRenderClassifiedVolume(self.ctx), "render")

    def luminance(self):
        """The image in [0, 1] (rows as :func:`bench_volpack_example.brain_scene` frames it)."""
        return self.image / 255.0

    close = VolPack.close
