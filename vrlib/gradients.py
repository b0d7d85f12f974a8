"""Gradients for the renderers that resample values in passes (shearing, shear-warp) or
classify voxels (direct splatting), and the lighting their kernels read.

The ray caster differentiates its reconstruction filter at every sample. The other methods
resample along one or two axes at a time, so they take the *sampled* gradient instead: the
samples' central differences (one-sided on the faces, :func:`numpy.gradient`) in world units,
three volumes resampled by the same filter and passes as the values. Classification then uses
the resampled gradient exactly as the ray caster uses its own (shading, gradient opacity).
"""

from __future__ import annotations

import numpy as np

__all__ = ["gradient_volumes", "kernel_lighting", "no_gradients"]

#: z-slices differenced at a time (bounds the float64 scratch memory).
SLAB = 16


def gradient_volumes(volume):
    """The samples' central-difference gradient in world units, ``(3, nz, ny, nx)`` float32
    (``x``, ``y``, ``z`` components), built once per volume and kept with it. The components
    are stored side by side (``(nz, ny, nx, 3)`` in memory: a sample's three lie together) and
    read-only, so every view a renderer takes of them has one numba type.

    Examples
    --------
    >>> from vrlib import Volume
    >>> ramp = Volume(np.tile(np.linspace(0.0, 1.0, 4), (4, 4, 1)))   # 1 over 2 world units
    >>> g = gradient_volumes(ramp)
    >>> g.shape, float(g[0].mean()), float(abs(g[1:]).max())
    ((3, 4, 4, 4), 0.5, 0.0)
    """
    def build():
        nz = volume.shape[0]
        hx, hy, hz = volume.spacing
        store = np.empty(volume.shape + (3,), np.float32)
        out = np.moveaxis(store, -1, 0)
        for z0 in range(0, nz, SLAB):
            z1 = min(z0 + SLAB, nz)
            lo, hi = max(z0 - 1, 0), min(z1 + 1, nz)  # a neighbour slice each side, where one is
            block = np.asarray(volume.data[lo:hi], np.float64)
            inner = slice(z0 - lo, z1 - lo)
            out[0, z0:z1] = np.gradient(block, hx, axis=2)[inner]
            out[1, z0:z1] = np.gradient(block, hy, axis=1)[inner]
            out[2, z0:z1] = np.gradient(block, hz, axis=0)[inner] if hi - lo > 1 else 0.0
        store.flags.writeable = False
        return np.moveaxis(store, -1, 0)

    return volume.cached(("gradient",), build)


def no_gradients(dtype):
    """A placeholder for a kernel's gradient argument when none is needed: read-only zeros
    ``(3, 2, 2, 2)`` seen through a stride, so that its numba type (a strided read-only array,
    as the gradients are) is the one the kernel was compiled for: no second version compiles."""
    out = np.zeros((2, 2, 2, 3), dtype)
    out.flags.writeable = False
    return np.moveaxis(out, -1, 0)


def kernel_lighting(transfer, direction):
    """What a kernel needs to classify a sample by its gradient, seen along the unit ray
    ``direction`` (from the eye; one direction: orthographic views): ``(lit, ramp_x, ramp_y)``
    with ``lit = [shade, headlight, by_gradient, ambient, diffuse, specular, shininess,
    light (3), direction (3)]`` (flags as 0/1; the light is ``-direction`` for a headlight)
    and the gradient opacity's points (:class:`vrlib.GradientOpacity`).

    Examples
    --------
    >>> from vrlib import Glow, Phong
    >>> lit, _, _ = kernel_lighting(Glow(1.0, shading=Phong()), np.array([0.0, 0.0, 1.0]))
    >>> lit[:3].tolist(), lit[7:10].tolist()      # shaded, headlight, no gradient opacity
    ([1.0, 1.0, 0.0], [-0.0, -0.0, -1.0])
    """
    d = np.asarray(direction, np.float64)
    shading, ramp = transfer.shading, transfer.gradient_opacity
    lit = np.zeros(13)
    lit[10:13] = d
    if shading is not None:
        light = -d if shading.light is None else shading.light
        lit[:2] = 1.0, float(shading.light is None)
        lit[3:7] = shading.ambient, shading.diffuse, shading.specular, shading.shininess
        lit[7:10] = light
    if ramp is None:
        return lit, np.zeros(2), np.zeros(2)
    lit[2] = 1.0
    return lit, ramp.magnitudes, ramp.factors
