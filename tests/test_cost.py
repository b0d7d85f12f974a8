"""The cost model's plumbing (vrlib.cost): point counts, machine record, model fit."""

import numpy as np
import pytest

import data_gen
import vrlib
from vrlib.cost import fit_model, machine, points


@pytest.mark.parametrize("method", list(vrlib.METHODS))
def test_points_count_what_each_renderer_composites(method):
    """Ray casting: one point per ray sample; shear3/shear2: the composited samples (the
    resampled ones counted apart); splat: footprint pixels; shear-warp: slice samples."""
    vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(12)
    view = vrlib.View.orbit(azimuth=20, elevation=10, size=16)
    stats = vrlib.render(vol, view, method=method, early_termination=1.0).stats
    count = points(stats)
    assert 0 < count <= stats.samples
    if method in ("shear3", "shear2"):
        assert count == stats.samples - sum(v for k, v in stats.passes.items()
                                            if k.startswith("pass"))


def test_fit_recovers_known_constants_and_rejects_bad_input():
    rng = np.random.default_rng(1)
    ops, pts = rng.uniform(1e5, 1e7, 12), rng.uniform(1e3, 1e6, 12)
    t = 3e-10 * ops + 2e-8 * pts + 5e-4
    constants, predicted = fit_model(ops, pts, t)
    assert constants["c_op"] == pytest.approx(3e-10, rel=1e-6)
    assert constants["c_pt"] == pytest.approx(2e-8, rel=1e-6)
    np.testing.assert_allclose(predicted, t, rtol=1e-9)
    with pytest.raises(ValueError, match="at least 3 frames"):
        fit_model([1, 2], [1, 2], [1, 2])
    with pytest.raises(ValueError, match="seconds must all be > 0"):
        fit_model([1, 2, 3], [1, 2, 3], [1, 0, 3])
    with pytest.raises(ValueError, match="one length"):
        fit_model([1, 2, 3], [1, 2], [1, 2, 3])


def test_machine_record_names_the_cpu_and_cores():
    record = machine()
    assert record["cores"] >= 1 and record["cpu"]
    assert record["id"].endswith(f"{record['cores']}c")
