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
