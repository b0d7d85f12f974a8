"""The scenes of the cost chapter: a dense volume (Marschner-Lobb under the glow function:
every voxel visible) and a sparse one (a few blobs under a ramp that starts at 0.1)."""

import numpy as np

import data_gen
import vrlib


def dense():
    return data_gen.make_field("marschner-lobb"), vrlib.Glow(1.0)


def sparse(count=6, sigma=(0.06, 0.1), threshold=0.1):
    ramp = np.linspace(0.0, 1.0, 11)
    transfer = vrlib.LookupTransfer(6.0 * np.clip((ramp - threshold) / (1 - threshold), 0.0,
                                                  None), value_range=(0.0, 1.0))
    return data_gen.make_field("random-blobs", count=count, seed=4, sigma=sigma), transfer


def visible_fraction(volume, transfer):
    """Share of voxels with non-zero opacity density."""
    return float(np.mean(transfer.opacity_density(volume.data) > 0.0))


def zeroed(volume, transfer):
    """The volume with every voxel of zero opacity density set to exactly zero (as segmented
    data stores empty space): the same images, and zeros a splatter can cull."""
    data = np.where(transfer.opacity_density(volume.data) > 0.0, volume.data, 0.0)
    return vrlib.Volume(data, volume.extent)
