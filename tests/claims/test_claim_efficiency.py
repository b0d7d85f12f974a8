"""Claim 2 (thesis abstract and chapter 1): "splatting (a 2-D footprint filter) is more efficient
per reconstructed point than ray casting or volume shearing; cost is modelled and measured on
several workstations".

Tests may not check wall time (that is measured in chapter ch04 and reported there, with the
machine). What they check is the operation-count model the renderers keep: per reconstructed
point, splatting does fewer operations than ray casting with every filter, because a footprint
pixel is one table lookup while a ray sample gathers n^3 voxels. Chapter ch04 found the
measured time per point agrees on this machine in most regimes but not all: at one pixel per
voxel or fewer on dense volumes, shear-warp is cheaper per point; and per *frame* splatting was
never the fastest, because it reconstructs many more points.
"""

import pytest

import data_gen
import vrlib
from vrlib.cost import points


def per_point(method, filt, *, m=2.0, n=32):
    vol = data_gen.make_field("marschner-lobb").sample(n)
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=int(m * n))
    stats = vrlib.render(vol, view, method=method, filter=filt, step=0.5,
                         early_termination=1.0).stats
    return stats.operations / points(stats), points(stats)


@pytest.mark.claim(2, "supports")
@pytest.mark.parametrize("filt", ["pyramid", "gaussian", "catmull-rom", "bspline"])
def test_splatting_does_fewer_operations_per_point_than_ray_casting(filt):
    splat, _ = per_point("splat", filt)
    ray, _ = per_point("raycast", filt)
    assert splat < ray


@pytest.mark.claim(2, "refutes")
@pytest.mark.parametrize("filt", ["pyramid", "catmull-rom"])
def test_splatting_reconstructs_more_points_per_frame(filt):
    """Why cheaper points do not make a cheaper frame: at two pixels per voxel a footprint
    covers many pixels, so splatting reconstructs more points than ray casting at half-voxel
    steps."""
    _, splat = per_point("splat", filt)
    _, ray = per_point("raycast", filt)
    assert splat > ray
