"""``method="auto"`` with a tolerance and no filter: the filter chosen by this machine's cost
model (vrlib.auto), and the model's file (vrlib.cost)."""

import json

import numpy as np
import pytest

import data_gen
import vrlib
from vrlib import View, metrics, render, render_reference
from vrlib.cost import load_model, save_model

# Marschner-Lobb at 17^3 -> 24^2 within 1e-3: trilinear's pilots choose a step of 1 voxel,
# Catmull-Rom's too; within 1e-4, 0.29 and 0.52 (its field is smoother along the rays), so
# which filter is cheaper depends on what a sample costs.
TOLERANCE, FINER = 1e-3, 1e-4


@pytest.fixture(scope="module")
def scene():
    return (data_gen.make_field("marschner-lobb").sample(17),
            View.orbit(azimuth=30, elevation=20, size=24))


def model(tmp_path, monkeypatch, c_op, c_pt, c_0=0.0):
    """A cost model for ray casting with these constants, as render() will read it."""
    path = save_model({"raycast": {"c_op": c_op, "c_pt": c_pt, "c_0": c_0}},
                      tmp_path / "cost.json")
    monkeypatch.setenv("VRLIB_COST_MODEL", str(path))
    return path


def candidates(img):
    return {row["filter"]: row for row in img.stats.choices["auto"]["candidates"]}


def test_without_a_cost_model_trilinear_is_taken_and_the_choice_says_why(scene):
    vol, view = scene
    img = render(vol, view, method="auto", tolerance=TOLERANCE)
    auto = img.stats.choices["auto"]
    assert auto["cost_model"] is None and auto["filter"] == "trilinear"
    assert "vrlib bench" in candidates(img)["catmull-rom"]["skipped"]
    np.testing.assert_array_equal(img.rgba, render(vol, view, tolerance=TOLERANCE).rgba)


def test_a_costlier_sample_is_not_planned_where_its_bound_is_no_faster(scene, tmp_path,
                                                                          monkeypatch):
    """Time by operations only: a Catmull-Rom sample costs 306 / 56 as much as a trilinear
    one, so even at the longest step (2 voxels here) it cannot catch up with trilinear's
    1: its pilots are not run."""
    vol, view = scene
    path = model(tmp_path, monkeypatch, c_op=1e-9, c_pt=0.0)
    img = render(vol, view, method="auto", tolerance=TOLERANCE)
    rows = candidates(img)
    assert img.stats.choices["auto"]["filter"] == "trilinear"
    assert img.stats.choices["auto"]["cost_model"] == str(path)
    assert "step" not in rows["catmull-rom"]
    assert rows["catmull-rom"]["bound_seconds"] >= rows["trilinear"]["predicted_seconds"]
    np.testing.assert_array_equal(img.rgba, render(vol, view, tolerance=TOLERANCE).rgba)


def test_a_filter_whose_pilots_alone_cost_more_is_not_planned(scene, tmp_path, monkeypatch):
    """Time by samples only: Catmull-Rom's image at 2 voxels would take half trilinear's
    samples at 1, but its first two pilots (the whole 24^2 view at 2 and 1 voxels) would
    take one and a half times those on top, so planning it cannot pay: dropped before its
    pilots."""
    vol, view = scene
    model(tmp_path, monkeypatch, c_op=0.0, c_pt=1e-8, c_0=1e-4)
    img = render(vol, view, method="auto", tolerance=TOLERANCE)
    rows = candidates(img)
    assert img.stats.choices["auto"]["filter"] == "trilinear"
    assert "step" not in rows["catmull-rom"]
    assert "with its first pilots" in rows["catmull-rom"]["skipped"]
    assert rows["catmull-rom"]["bound_seconds"] >= rows["trilinear"]["predicted_seconds"]


def test_the_filter_predicted_fastest_is_rendered_and_keeps_the_promise(scene, tmp_path,
                                                                        monkeypatch):
    """Time by samples only (every sample costs the same): Catmull-Rom's longer step makes it
    the faster, so it is planned, chosen, and renders as it does when asked for by name,
    within the tolerance of the exact image of its own field."""
    vol, view = scene
    model(tmp_path, monkeypatch, c_op=0.0, c_pt=1e-8, c_0=1e-4)
    img = render(vol, view, method="auto", tolerance=FINER)
    rows = candidates(img)
    assert img.stats.choices["auto"]["filter"] == "catmull-rom"
    assert rows["catmull-rom"]["step"] > rows["trilinear"]["step"]
    assert rows["catmull-rom"]["predicted_seconds"] < rows["trilinear"]["predicted_seconds"]
    by_name = render(vol, view, filter="catmull-rom", tolerance=FINER)
    np.testing.assert_array_equal(img.rgba, by_name.rgba)
    field = vrlib.ReconstructedField(vol, filter="catmull-rom")
    exact = render_reference(field, view, transfer=vrlib.Glow(1.0), tol=1e-8)
    assert metrics.rmse(img, exact) <= FINER


def test_a_filter_given_is_kept(scene, tmp_path, monkeypatch):
    vol, view = scene
    model(tmp_path, monkeypatch, c_op=0.0, c_pt=1e-8)
    img = render(vol, view, method="auto", filter="trilinear", tolerance=TOLERANCE)
    assert "auto" not in img.stats.choices and img.stats.choices["filter"] == "pyramid"


def test_holes_are_wrapped_for_each_filter_s_own_range(tmp_path, monkeypatch):
    """A volume with NaN holes: each candidate renders with the hole transfer function of the
    range its own filter reconstructs, as when asked for by name."""
    data = data_gen.make_field("marschner-lobb").sample(17).data.copy()
    data[8, 8, 8] = np.nan
    vol = vrlib.Volume(data, nan="transparent")
    view = View.orbit(azimuth=30, elevation=20, size=24)
    model(tmp_path, monkeypatch, c_op=0.0, c_pt=1e-8, c_0=1e-4)
    img = render(vol, view, method="auto", tolerance=FINER)
    name = img.stats.choices["auto"]["filter"]
    np.testing.assert_array_equal(img.rgba,
                                  render(vol, view, filter=name, tolerance=FINER).rgba)


@pytest.mark.parametrize("content, why", [
    (b"\xff\xfe not json", "not JSON"),
    (b"[1, 2]", "not a 'vrlib cost model 1' file"),
    (json.dumps({"format": "vrlib cost model 1", "methods": {}}).encode(), "no fitted methods"),
    (json.dumps({"format": "vrlib cost model 1", "methods": {"raycast": {
        "c_op": -1.0, "c_pt": 0.0, "c_0": 0.0}}}).encode(), "raycast c_op is -1.0"),
    (json.dumps({"format": "vrlib cost model 1", "methods": {"raycast": {
        "c_op": 0.0, "c_pt": "1e-8", "c_0": 0.0}}}).encode(), "raycast c_pt is '1e-8'"),
    (b"{" + b" " * 70000 + b"}", "larger than 65536 bytes"),
])
def test_a_file_that_is_not_a_cost_model_is_refused_by_name(tmp_path, monkeypatch, content,
                                                            why, scene):
    path = tmp_path / "cost.json"
    path.write_bytes(content)
    with pytest.raises(ValueError, match="cost model") as caught:
        load_model(path)
    assert why in str(caught.value) and str(path) in str(caught.value)
    monkeypatch.setenv("VRLIB_COST_MODEL", str(path))
    with pytest.raises(ValueError, match="vrlib bench"):
        render(*scene, method="auto", tolerance=TOLERANCE)


def test_a_nan_constant_is_refused(tmp_path):
    path = tmp_path / "cost.json"
    path.write_text('{"format": "vrlib cost model 1", "methods": {"raycast": '
                    '{"c_op": NaN, "c_pt": 0, "c_0": 0}}}')
    with pytest.raises(ValueError, match="raycast c_op is nan, not a finite number"):
        load_model(path)


def test_a_model_fitted_again_is_read_again(tmp_path):
    """The model is read once per version of its file; ``vrlib bench`` writing it again (a
    new file renamed onto the old) is seen at the next read."""
    path = tmp_path / "cost.json"
    save_model({"raycast": {"c_op": 1e-10, "c_pt": 1e-8, "c_0": 1e-3}}, path)
    assert load_model(path)["methods"]["raycast"]["c_0"] == 1e-3
    assert load_model(path) is load_model(path)
    save_model({"raycast": {"c_op": 1e-10, "c_pt": 1e-8, "c_0": 2e-3}}, path)
    assert load_model(path)["methods"]["raycast"]["c_0"] == 2e-3
    path.unlink()
    assert load_model(path) is None


def test_a_model_without_ray_casting_chooses_nothing_and_says_so(scene, tmp_path,
                                                                 monkeypatch):
    vol, view = scene
    path = save_model({"splat": {"c_op": 1e-9, "c_pt": 0.0, "c_0": 0.0}}, tmp_path / "c.json")
    monkeypatch.setenv("VRLIB_COST_MODEL", str(path))
    img = render(vol, view, method="auto", tolerance=TOLERANCE)
    assert img.stats.choices["auto"]["filter"] == "trilinear"
    assert "no ray casting" in candidates(img)["catmull-rom"]["skipped"]
