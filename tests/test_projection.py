"""Maximum- and average-intensity projections (blend="maximum" / "average")."""

import numpy as np
import pytest

import data_gen
import vrlib
from vrlib._scheduling import thread_count

FIELD = data_gen.make_field("marschner-lobb")


def projected(volume, view, filt, blend, step=0.5):
    """The projection computed from the public pieces: each ray's samples at (k + 1/2) ds
    inside the volume's box, reconstructed by vrlib.reconstruct, then max or mean."""
    origins, directions = view.rays()
    ds = step * float(volume.spacing.min())
    lo, hi = volume.extent[:, 0], volume.extent[:, 1]
    out = np.zeros(view.shape)
    hit = np.zeros(view.shape, dtype=bool)
    for r in range(view.height):
        for c in range(view.width):
            o, d = origins[r, c], directions[r, c]
            with np.errstate(divide="ignore", invalid="ignore"):
                ta, tb = (lo - o) / d, (hi - o) / d
            t_in = max(np.nanmax(np.minimum(ta, tb)), 0.0)
            t_out = np.nanmin(np.maximum(ta, tb))
            k = np.arange(np.ceil(t_in / ds - 0.5), np.ceil(t_out / ds - 0.5))
            t = (k + 0.5) * ds
            t = t[(t >= t_in) & (t < t_out)]
            if t.size:
                values = vrlib.reconstruct(volume, o + t[:, None] * d, filter=filt)
                out[r, c] = values.max() if blend == "maximum" else values.mean()
                hit[r, c] = True
    return out, hit


@pytest.mark.parametrize("blend", ["maximum", "average"])
@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
def test_projection_equals_its_definition(blend, projection):
    """Every pixel equals the max (mean) of the reconstructed samples of its ray, classified
    by the transfer function with its unit distance."""
    vol = FIELD.sample(12)
    view = vrlib.View.orbit(azimuth=25, elevation=15, size=10, projection=projection)
    tf = vrlib.colormap("viridis", [(0, 0.1), (1, 0.9)], clim=(0, 1), volume=vol)
    img = vrlib.render(vol, view, filter="catmull-rom", transfer=tf, blend=blend)
    value, hit = projected(vol, view, "catmull-rom", blend)
    alpha = np.where(hit, -np.expm1(-tf.opacity_density(value) * tf.unit_distance), 0.0)
    np.testing.assert_allclose(img.alpha, alpha, atol=1e-12)
    np.testing.assert_allclose(img.rgba[..., :3], tf.emission(value) * alpha[..., None],
                               atol=1e-12)
    assert hit.sum() > 30 and img.stats.samples > 0


@pytest.mark.parametrize("filt", sorted(set(vrlib.FILTERS) - {"gaussian", "mitchell-netravali"}))
def test_every_filter_projects_a_constant_exactly(filt):
    """A constant volume's maximum and average are the constant, with every filter whose
    weights sum to 1 (prefiltered filters reproduce constants too; the truncated Gaussian's
    weights sum to 1 within 0.5% only, and mitchell-netravali is "mitchell" with parameters)."""
    vol = vrlib.Volume(np.full((6, 7, 8), 0.4))
    tf = vrlib.colormap("gray", [(0, 1), (1, 1)], clim=(0, 0.5))
    for blend in ("maximum", "average"):
        img = vrlib.render(vol, vrlib.View.orbit(azimuth=10, elevation=5, size=6), filter=filt,
                           transfer=tf, blend=blend)
        inside = img.alpha > 0
        assert inside.sum() > 10
        np.testing.assert_allclose(img.rgba[..., 0][inside], 0.8 * img.alpha[inside],
                                   atol=1e-9)


def test_maximum_bounds_average_on_a_real_volume():
    """The MNI brain: on every ray the maximum is at least the mean, and the images do not
    depend on the thread count."""
    mni = data_gen.load("mni152")
    view = vrlib.View.orbit(azimuth=90, size=24)
    tf = vrlib.colormap("gray", [(0, 1), (1, 1)], volume=mni)
    with thread_count(1):
        one = vrlib.render(mni, view, transfer=tf, blend="maximum")
    top = vrlib.render(mni, view, transfer=tf, blend="maximum")
    mean = vrlib.render(mni, view, transfer=tf, blend="average")
    np.testing.assert_array_equal(one.rgba, top.rgba)
    assert np.all(top.rgba[..., 0] >= mean.rgba[..., 0] - 1e-12)
    assert top.rgba[..., 0].max() > 0.8 and mean.rgba[..., 0].max() < top.rgba[..., 0].max()


def test_projections_refuse_what_they_cannot_do():
    vol = FIELD.sample(8)
    view = vrlib.View.orbit(size=4)
    with pytest.raises(ValueError, match="use method='raycast'"):
        vrlib.render(vol, view, method="splat", blend="maximum")
    with pytest.raises(ValueError, match="does not shade"):
        vrlib.render(vol, view, blend="average", transfer=vrlib.Glow(1, shading=vrlib.Phong()))
    with pytest.raises(ValueError, match="unknown blend 'mip'"):
        vrlib.render(vol, view, blend="mip")
