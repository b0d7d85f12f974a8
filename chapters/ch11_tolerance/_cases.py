"""The scenes of the time-against-error chapter: analytic volumes whose exact image (of the
field the filter reconstructs) the reference renderer gives, from two views, and a real
volume against a fine render."""

import numpy as np

import data_gen
import vrlib

#: Requested tolerances (rmse of premultiplied RGBA).
TOLERANCES = [1e-2, 1e-3, 1e-4]
#: Three views: orthographic across the lattice, orthographic along its x axis (where every
#: ray samples the lattice at the same phase: the pilots can agree while all miss what lies
#: between their samples), and in perspective from another side.
VIEWS = {"orthographic": dict(azimuth=30, elevation=20),
         "along x": dict(azimuth=0, elevation=0),
         "perspective": dict(azimuth=-60, elevation=35, projection="perspective")}


def peak(volume, centre=0.6, width=0.03, density=40.0):
    """A narrow opacity peak, ``width`` of the value range wide: a steep transfer function."""
    grid = np.linspace(0.0, 1.0, 1001)
    return vrlib.LookupTransfer(density * np.clip(1.0 - np.abs(grid - centre) / (width / 2),
                                                  0.0, None), value_range=volume.value_range)


def colour_ramp(volume):
    """Opacity rising with the value, colour from blue through green to red."""
    return vrlib.LookupTransfer([0.0, 1.0, 3.0, 6.0],
                                [[0.1, 0.2, 1.0], [0.1, 1.0, 0.3], [1.0, 0.6, 0.1],
                                 [1.0, 0.1, 0.1]], value_range=volume.value_range)


def analytic_scenes():
    """``(key, label, volume, transfer)`` for every analytic scene."""
    ml = data_gen.make_field("marschner-lobb").sample(41)
    blob = data_gen.make_field("gaussian-blob", sigma=0.3).sample(48)
    narrow = data_gen.make_field("gaussian-blob", sigma=0.25).sample(41)
    floor = vrlib.Volume(narrow.data + 0.3, narrow.extent)
    blobs = data_gen.make_field("random-blobs", count=6, seed=4, sigma=(0.06, 0.1)).sample(64)
    return [
        ("ml", "Marschner-Lobb 41^3, Glow(1)", ml, vrlib.Glow(1.0)),
        ("ml-peak", "Marschner-Lobb 41^3, narrow peak", ml, peak(ml)),
        ("ml-colour", "Marschner-Lobb 41^3, colour ramp", ml, colour_ramp(ml)),
        ("ml-shaded", "Marschner-Lobb 41^3, Glow(2) shaded", ml,
         vrlib.Glow(2.0, shading=vrlib.Phong(specular=0.3))),
        ("blob", "blob 48^3, Glow(2)", blob, vrlib.Glow(2.0)),
        ("floor", "blob on a floor of 0.3, 41^3", floor, vrlib.Glow(1.0)),
        ("blobs", "six sparse blobs 64^3, Glow(8)", blobs, vrlib.Glow(8.0)),
    ]


def real_scene():
    """The MNI152 template under a bone colormap ramp, against a fine render."""
    head = data_gen.load("mni152")
    transfer = vrlib.colormap("bone", [(0.0, 0.0), (0.3, 0.0), (1.0, 0.8)], volume=head)
    return "mni152", "MNI152 197x233x189, bone colormap", head, transfer
