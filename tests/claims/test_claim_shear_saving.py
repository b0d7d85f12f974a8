"""Claim 6 (thesis abstract and chapter 1): "the third pass of the three-pass volume-shear method
is unnecessary; dropping it saves about 30% of computation and memory".

Chapter ch05 measured it over 50 random rotations at 128^3. Checked here over 6 seeded random
rotations at 48^3 (one pixel and one ray sample per voxel, Catmull-Rom): the two-pass method
resamples at least 25% fewer samples and is as accurate on average: its rmse over the
three-pass rmse, averaged over the rotations, is below 1.1 (view by view the ratio varies,
measured 0.75 to 1.30 at these rotations, because the two methods sample different points
along each ray). The memory saving holds only against a three-pass method that stores its
third volume, which vrlib's does not: that half of the claim is not reproduced here, so the
verdict is "partly reproduced".
"""

import numpy as np
import pytest

import data_gen
import vrlib


@pytest.fixture(scope="module")
def renders():
    field = data_gen.make_field("marschner-lobb")
    vol = field.sample(48)
    size = int(round(np.sqrt(3) * 47))
    rng = np.random.default_rng(1993)
    out = []
    for _ in range(6):
        azimuth = rng.uniform(-180, 180)
        elevation = np.degrees(np.arcsin(rng.uniform(-1, 1)))
        view = vrlib.View.orbit(azimuth=azimuth, elevation=elevation, size=size)
        ref = vrlib.render_reference(field, view, tol=1e-5)
        pair = {m: vrlib.render(vol, view, method=m, filter="catmull-rom", step=1.0)
                for m in ("shear3", "shear2")}
        out.append((pair, ref))
    return out


@pytest.mark.claim(6, "supports")
def test_two_pass_saves_a_quarter_or_more_of_the_resampling(renders):
    ratios = [p["shear2"].stats.voxels / p["shear3"].stats.voxels for p, _ in renders]
    assert np.mean(ratios) < 0.75


@pytest.mark.claim(6, "refutes")
def test_dropping_the_pass_saves_no_memory_here(renders):
    """The memory half of the claim does not hold in vrlib. It assumes a three-pass method
    that stores its third volume before compositing; vrlib's runs its last pass along the
    rays, fused with the compositing, so it holds the same two intermediate volumes as the
    two-pass method: dropping the pass saves no memory (ratio 1; ch05 measures the peak),
    while the computation saved stays (above)."""
    ratios = [p["shear2"].stats.bytes / p["shear3"].stats.bytes for p, _ in renders]
    np.testing.assert_allclose(ratios, 1.0)


@pytest.mark.claim(6, "supports")
def test_two_pass_is_as_accurate(renders):
    ratios = [vrlib.metrics.rmse(pair["shear2"], ref) / vrlib.metrics.rmse(pair["shear3"], ref)
              for pair, ref in renders]
    assert np.mean(ratios) < 1.1
