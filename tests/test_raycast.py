"""Ray casting: agreement with the naive twin, determinism, skips, accuracy, bad input."""

import inspect
import math

import naive
import numba
import numpy as np
import pytest
from naive import exact_blob_image, image_mass, random_orbits, raycast_naive

import data_gen
import vrlib
from vrlib import Glow, LookupTransfer, Phong, View, Volume, metrics, render, render_reference
from vrlib._kernels import raycast as raycast_kernel
from vrlib._kernels import sampling
from vrlib._kernels._jit import borrowed, readonly
from vrlib._kernels.queue import take
from vrlib._scheduling import on_threads
from vrlib.parallel.sources import ghost as ghost_samples
from vrlib.raycast import cast_rays
from vrlib.value_bounds import reconstructed_range

FILTERS = ["box", "trilinear", "catmull-rom", "bspline", "mitchell", "gaussian",
           ("mitchell-netravali", 0.2, 0.6), ("gaussian", 0.5, 1.5), "omoms"]
TABLE = LookupTransfer([0.0, 3.0, 1.0, 5.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])


def small_volume():
    return data_gen.make_field("random-blobs", count=4, seed=2).sample((9, 11, 10))


@pytest.mark.parametrize("projection, filt", [
    (projection, filt) if projection == "orthographic" or filt in (
        "box", "trilinear", "catmull-rom", "omoms") else
    pytest.param(projection, filt, marks=pytest.mark.slow)
    for projection in ("orthographic", "perspective") for filt in FILTERS], ids=str)
@pytest.mark.parametrize("transfer", [Glow(3.0), TABLE, Glow(2.0, shading=Phong(specular=0.4)),
                                      LookupTransfer([0.0, 2.0], shading=Phong(light=(1, 2, 3)))],
                         ids=["glow", "table", "glow-shaded", "table-shaded"])
def test_kernel_matches_naive_twin(projection, filt, transfer):
    """The optimised kernel (unrolled filters, tiles, threads) equals the by-the-book twin.
    In perspective, ``make test`` takes the box, the tent, Catmull-Rom and O-MOMS (each
    unrolled or general path once); ``make test-all`` every filter."""
    vol = small_volume()
    view = View.orbit(azimuth=33, elevation=-21, size=(7, 9), projection=projection)
    fast = render(vol, view, filter=filt, transfer=transfer, step=0.37, early_termination=1.0)
    slow = raycast_naive(vol, view, vrlib.make_filter(filt), transfer, 0.37)
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    assert fast.alpha.max() > 0.1



@pytest.mark.slow  # 24 s in make test: make test-all runs it (CI's 5 minutes)
def test_box_filter_shades_by_the_sampled_gradient():
    """The box filter's derivative is zero, so shading by it drew the unshaded image,
    silently (the README's ``--labels --shade`` frog). It now takes the samples' gradient at
    the nearest sample (numpy.gradient's differences), as the shear methods do: the shaded
    image differs from the unshaded one, and a light along the view lights the middle of a
    ball more than a light across it (the twin tests above check the gradient itself)."""
    labels = data_gen.make_field("smooth-sphere", radius=0.6).sample(24).data > 0.5
    vol = Volume(labels.astype(float))
    view = View.orbit(azimuth=0, elevation=0, size=32)  # looking along -x, y to the right

    def red(transfer):
        return render(vol, view, filter="box", transfer=transfer).rgba[..., 0]

    along = red(LookupTransfer([0.0, 40.0], shading=Phong(light=(1, 0, 0), ambient=0.1)))
    across = red(LookupTransfer([0.0, 40.0], shading=Phong(light=(0, 1, 0), ambient=0.1)))
    unshaded = red(LookupTransfer([0.0, 40.0]))
    assert np.abs(along - unshaded).max() > 0.1
    middle = (slice(14, 18), slice(14, 18))
    assert along[middle].mean() > 1.5 * across[middle].mean()

@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
@pytest.mark.parametrize("filt", ["box", "trilinear", "catmull-rom", "gaussian"])
@pytest.mark.parametrize("transfer", [Glow(3.0), TABLE, Glow(2.0, shading=Phong(specular=0.4))],
                         ids=["glow", "table", "glow-shaded"])
def test_exact_segment_ends_match_naive_twin(projection, filt, transfer):
    """Exact segment ends (the faces' cut segments sampled at their middle, with their own
    length's opacity) equal the twin that cuts every ray into the lattice's segments, on a
    volume that is not zero at its faces (where the ends matter)."""
    vol = data_gen.make_field("marschner-lobb").sample((9, 11, 10))
    view = View.orbit(azimuth=33, elevation=-21, size=(7, 9), projection=projection)
    fast = render(vol, view, filter=filt, transfer=transfer, step=0.37, early_termination=1.0,
                  segment_ends="exact")
    slow = raycast_naive(vol, view, vrlib.make_filter(filt), transfer, 0.37, "exact")
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    lattice = raycast_naive(vol, view, vrlib.make_filter(filt), transfer, 0.37)
    assert np.abs(fast.rgba - lattice).max() > 1e-4  # the ends do change the image


@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
@pytest.mark.parametrize("filt", ["box", "trilinear", "catmull-rom", ("gaussian", 0.5, 1.5),
                                  "omoms"], ids=str)
@pytest.mark.parametrize("transfer", [
    Glow(3.0), TABLE, Glow(2.0, shading=Phong(specular=0.4)),
    LookupTransfer([0.0, 2.0], shading=Phong(light=(1, 2, 3)),
                   gradient_opacity=vrlib.GradientOpacity([0.0, 3.0], [0.2, 1.0]))],
    ids=["glow", "table", "glow-shaded", "table-shaded-ramp"])
def test_preintegration_matches_naive_twin(projection, filt, transfer):
    """Pre-integrated classification equals the twin that integrates the transfer function
    by brute force between each segment's end values (400 pieces a segment): opacity to
    1e-5, colour to 1e-3 (the mean-emission table's bilinear reading between its 256
    entries). The default Gaussian is left out: truncated at 2 voxels, where it is not zero,
    it reconstructs a field that jumps on the lattice planes, and the segments' ends at the
    volume's faces lie on them, where the twin's and the kernel's rounding of a position may
    fall on either side (a difference of 3e-4 measured)."""
    vol = data_gen.make_field("marschner-lobb").sample((9, 11, 10))
    view = View.orbit(azimuth=33, elevation=-21, size=(7, 9), projection=projection)
    fast = render(vol, view, filter=filt, transfer=transfer, step=0.71, early_termination=1.0,
                  classification="preintegrated")
    slow = naive.raycast_preintegrated_naive(vol, view, vrlib.make_filter(filt), transfer,
                                             0.71)
    np.testing.assert_allclose(fast.alpha, slow[..., 3], atol=1e-5)
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-3)
    assert fast.alpha.max() > 0.1


@pytest.mark.parametrize("filt", ["trilinear", "catmull-rom"])
@pytest.mark.parametrize("transfer", [Glow(5.0), TABLE], ids=["glow", "table"])
def test_preintegrated_skipping_changes_nothing(filt, transfer):
    """Empty-space skipping of pre-integrated segments (skipped by their front end, a run
    only while its last segment ends in the same empty block) leaves the image bit for bit,
    on sparse blobs from several views, perspective with the eye inside included."""
    field = data_gen.make_field("random-blobs", count=3, seed=5, sigma=(0.04, 0.06))
    data = field.sample(48).data.copy()
    data[data < 1e-3] = 0.0
    vol = Volume(data)
    views = [View.orbit(azimuth=a, elevation=e, size=40) for a, e in [(0, 0), (37, 23)]]
    views.append(View.orbit(azimuth=10, elevation=5, size=40, projection="perspective",
                            distance=0.5, fov=70))
    for view in views:
        for step in (0.5, 3.0):
            options = dict(filter=filt, transfer=transfer, step=step,
                           classification="preintegrated")
            skipped = render(vol, view, **options)
            full = render(vol, view, empty_space_skipping=False, **options)
            assert np.array_equal(skipped.rgba, full.rgba)
            assert skipped.stats.samples < 0.8 * full.stats.samples  # 0.68 measured


def test_preintegration_is_exact_on_a_linear_field():
    """Along every ray a linear field is linear: pre-integration's opacity is then exact at
    any step, where point sampling misses a narrow opacity peak. Measured (17^3, 48^2, a
    peak 0.03 of the value range wide): pre-integrated rmse 9e-7 at steps 2 to 1/4, point
    sampling 0.43 at step 2 and 0.012 at 1/4."""
    z, y, x = np.meshgrid(*[np.linspace(-1.0, 1.0, 17)] * 3, indexing="ij")
    vol = Volume(0.25 * (x + 1.0) + 0.25 * (y + 1.0))
    view = View.orbit(azimuth=30, elevation=20, size=48)
    grid = np.linspace(0.0, 1.0, 1001)
    peak = LookupTransfer(40.0 * np.clip(1.0 - np.abs(grid - 0.5) / 0.015, 0.0, None),
                          value_range=vol.value_range)
    exact = render_reference(vrlib.ReconstructedField(vol), view, transfer=peak, tol=1e-8)
    for step in (2.0, 0.5):
        pre = render(vol, view, transfer=peak, step=step, early_termination=1.0,
                     classification="preintegrated")
        point = render(vol, view, transfer=peak, step=step, early_termination=1.0,
                       segment_ends="exact")
        assert metrics.rmse(pre, exact) < 1e-5
        assert metrics.rmse(point, exact) > 1e-2


def test_preintegration_refuses_what_it_cannot_do():
    vol = small_volume()
    with pytest.raises(ValueError, match="segment_ends='exact'"):
        render(vol, View.orbit(size=4), classification="preintegrated", segment_ends="lattice")
    with pytest.raises(ValueError, match="classification"):
        render(vol, View.orbit(size=4), classification="pre-integrated")


def test_exact_segment_ends_converge_at_second_order():
    """On a field that is not zero at the volume's faces (Marschner-Lobb), the error against
    the exact image of the reconstructed field (vrlib.ReconstructedField integrated by
    render_reference) falls as ds^2 with exact ends and as ds with lattice ends.

    Measured (37^3, 48^2, Glow(1), steps 1 to 1/8): lattice order 1.0; exact order about 2,
    and 10x smaller at step 1. Asserted: exact order >= 1.8 (fit over four steps), lattice
    order below 1.2, exact at least 5x more accurate at step 1.
    """
    vol = data_gen.make_field("marschner-lobb").sample(37)
    view = View.orbit(azimuth=30, elevation=20, size=48)
    exact = render_reference(vrlib.ReconstructedField(vol), view, tol=1e-8)
    steps = np.array([1.0, 0.5, 0.25, 0.125])
    errors = {ends: [metrics.rmse(render(vol, view, step=s, early_termination=1.0,
                                         segment_ends=ends), exact) for s in steps]
              for ends in ("lattice", "exact")}
    order = {ends: np.polyfit(np.log(steps), np.log(e), 1)[0] for ends, e in errors.items()}
    assert order["exact"] >= 1.8
    assert order["lattice"] < 1.2
    assert errors["exact"][0] * 5 < errors["lattice"][0]


@numba.njit(cache=True, nogil=True)
def _take_all(counter, taken):
    while True:
        item = take(counter)
        if item >= taken.shape[0]:
            break
        taken[item] += 1


def test_the_tile_queue_hands_out_every_item_once():
    """The threads share the ray caster's tiles through one counter, each running the
    compiled worker at once without the GIL (``on_threads``, as the renderers do): each
    item is taken by exactly one thread (an increment that is not atomic would hand some
    out twice)."""
    threads = numba.get_num_threads()
    taken = np.zeros(2_000_000, dtype=np.int64)
    counter = np.zeros(1, dtype=np.int64)
    on_threads(lambda i: _take_all(counter, taken), threads)
    assert (taken == 1).all()
    calls = 1 if numba.config.DISABLE_JIT else threads  # without the JIT: one call takes all
    assert counter[0] == taken.size + calls


def test_on_threads_raises_what_a_call_raises():
    if numba.config.DISABLE_JIT:
        pytest.skip("without the JIT one call takes every item")
    calls = []

    def work(i):
        calls.append(i)
        if i == 1:
            raise ValueError("call 1 failed")

    with pytest.raises(ValueError, match="call 1 failed"):
        on_threads(work, 2)
    assert sorted(calls) == [0, 1]


@numba.njit(cache=True)
def _borrowed_sum(values):
    view = borrowed(values)
    return view.sum(), view.shape[0]


def test_a_borrowed_view_reads_the_same_array():
    """``borrowed`` drops only the reference count: the same data, shape and values."""
    values = np.arange(10.0)
    assert _borrowed_sum(values) == (45.0, 10)


@numba.njit(cache=True)
def _tent_and_general_gradients(data, offset, gshape, points, code, scratch):
    out = np.empty((points.shape[0], 2, 3))
    wx, wy, wz, dx, dy, dz = scratch[0], scratch[1], scratch[2], scratch[3], scratch[4], \
        scratch[5]
    for i in range(points.shape[0]):
        ux, uy, uz = points[i, 0], points[i, 1], points[i, 2]
        out[i, 0, 0], out[i, 0, 1], out[i, 0, 2] = sampling.tent_gradient(data, offset, gshape,
                                                                          ux, uy, uz)
        out[i, 1, 0], out[i, 1, 1], out[i, 1, 2] = sampling.gradient(
            data, offset, gshape, ux, uy, uz, code[0], code[1], code[2], code[3], 1.0, 2, wx,
            wy, wz, dx, dy, dz)
    return out


def test_the_tent_gradient_is_the_general_gradient_bit_for_bit():
    """The shaded tent kernels take ``tent_gradient``, the general gradient's sums written
    out for two taps a side: the same numbers bit for bit at random points, on the lattice
    (where the tent's slope jumps), on and beyond the volume's faces (clamped taps), in a
    brick whose samples start past global index 0."""
    rng = np.random.default_rng(11)
    gshape = np.array([9, 10, 11])
    whole = rng.normal(size=tuple(gshape))
    offset = np.array([2, 3, 0])
    brick = readonly(np.ascontiguousarray(whole[2:, 3:, :]))
    top = gshape[::-1] - 1.0  # (x, y, z) of the last sample
    first = offset[::-1].astype(float)  # (x, y, z) of the brick's first sample
    inside = first + rng.uniform(0.0, 1.0, (300, 3)) * (top - first)
    lattice = np.round(inside[:60])
    faces = inside[:60].copy()
    faces[:20, 0], faces[20:40, 1], faces[40:, 2] = top[0], top[1], top[2]
    beyond = inside[:60] + [1.5, 0.7, 2.2]
    points = np.concatenate([inside, lattice, faces, beyond])
    code = np.array(vrlib.make_filter("trilinear").code, dtype=np.float64)
    both = _tent_and_general_gradients(brick, offset, gshape, points, code,
                                       np.zeros((6, 8)))
    np.testing.assert_array_equal(both[:, 0], both[:, 1])
    assert np.abs(both[:, 0]).max() > 0.5 and (both[:, 0] == 0.0).any()


@pytest.mark.parametrize(("transfer", "segment_ends"), [(Glow(3.0), "lattice"),
                                                       (TABLE, "exact")],
                         ids=["glow-lattice", "table-exact"])
def test_a_quick_start_gives_the_packets_image(monkeypatch, transfer, segment_ends):
    """A quick start (a one-off render of few samples inside
    :func:`vrlib.raycast.quick_starts`, while the kernel with packets is not compiled) takes
    its own kernel (rays one at a time), then, once the kernel with packets is compiled,
    that one: the same image bit for bit and the same samples counted, grey or coloured,
    with the volume's faces cutting segments or not. A quick start's kernel that lost the
    cut segments' lengths, or a packet that took a sample more or less than the scalar
    loop, would differ; so would a quick start that took the packets after all (the
    kernels' signatures tell which ran). The quick start's kernel takes lattice ends as
    None (compiled without the cut segments' code) and exact ends as True; the kernel with
    packets takes a flag."""
    vol = data_gen.make_field("marschner-lobb").sample(24)
    view = View.orbit(azimuth=20, elevation=35, size=70)
    monkeypatch.setenv("VRLIB_QUICK_START", "1")
    monkeypatch.setattr(vrlib.raycast, "_quick_start", {"on": 0, "ready": set()})
    images = []
    for compiled in (False, True):  # the packets' kernel not compiled, then compiled
        monkeypatch.setattr(vrlib.raycast, "compiled_or_cached", lambda d, a, c=compiled: c)
        with vrlib.raycast.quick_starts():
            images.append(render(vol, view, transfer=transfer, segment_ends=segment_ends))
    quick, with_packets = images
    assert np.array_equal(quick.rgba, with_packets.rgba)
    assert quick.stats.samples == with_packets.stats.samples
    assert quick.rgba[..., 3].max() > 0.5  # rays that take many samples
    if not numba.config.DISABLE_JIT:  # which kernels ran, by their signatures
        def kinds(kernel, flags):
            names = list(inspect.signature(kernel.py_func).parameters)
            return {tuple(str(s[names.index(n)]) for n in flags) for s in kernel.signatures}

        quick_ends = "none" if segment_ends == "lattice" else "bool"
        assert ("none", "none", "bool", "bool") in kinds(
            raycast_kernel.raycast, ("filtering", "lighting", "packets", "exact"))
        assert (quick_ends,) in kinds(raycast_kernel.raycast_quick, ("exact",))


def test_quick_starts_only_where_asked(monkeypatch, tmp_path):
    """A render asks whether the kernel with packets is ready (and takes the quick start if
    not) only inside :func:`vrlib.raycast.quick_starts`, for one render (not the renders of
    a tolerance's pilots, which share a memo), of few samples, unless
    ``VRLIB_QUICK_START=0``; a yes is kept. ``vrlib render`` renders inside it."""
    vol = data_gen.make_field("gaussian-blob").sample(12)
    view = View.orbit(size=16)
    asked = []
    monkeypatch.setenv("VRLIB_QUICK_START", "1")
    state = {"on": 0, "ready": set()}
    monkeypatch.setattr(vrlib.raycast, "_quick_start", state)
    answer = [False]
    monkeypatch.setattr(vrlib.raycast, "compiled_or_cached",
                        lambda d, a: asked.append(a[-7] is True) or answer[0])
    render(vol, view)
    assert asked == []  # outside quick_starts()
    with vrlib.raycast.quick_starts():
        render(vol, view)
        assert asked == [True] and not state["ready"]  # asked about the packets' kernel
        render(vol, view, tolerance=1e-2)  # pilots and the render share a memo
        assert len(asked) == 1
        bound = vrlib.raycast.QUICK_START_SAMPLES
        monkeypatch.setattr(vrlib.raycast, "QUICK_START_SAMPLES", 1)
        render(vol, view)
        assert len(asked) == 1  # many samples
        monkeypatch.setattr(vrlib.raycast, "QUICK_START_SAMPLES", bound)
        monkeypatch.setenv("VRLIB_QUICK_START", "0")
        render(vol, view)
        assert len(asked) == 1  # turned off
        monkeypatch.setenv("VRLIB_QUICK_START", "1")
        answer[0] = True
        render(vol, view)
        render(vol, view)
        assert len(asked) == 2 and len(state["ready"]) == 1  # ready, and kept
    assert state["on"] == 0
    from vrlib import cli

    state["ready"].clear()
    out = tmp_path / "blob.npy"
    assert cli.main(["render", "gaussian-blob:12", "--size", "16", "-o", str(out)]) == 0
    assert len(asked) == 3 and out.exists() and state["on"] == 0


@pytest.mark.parametrize("classification", ["point", "preintegrated"])
def test_a_quick_start_of_a_sparse_volume_skips_nothing(monkeypatch, classification):
    """A quick start of a volume with empty space, while the kernels that skip are not
    compiled, gives the image of a render that skips, bit for bit: point classification
    samples the visible box through (more samples, the kernel without skipping, which a
    render that skips had not taken), pre-integration keeps skipping but casts every pixel's
    ray instead of compiling the footprint mask's kernel (not called). A quick start that
    dropped a sample that counts, or lost the visible box's samples, would differ."""
    field = data_gen.make_field("random-blobs", count=3, seed=5, sigma=(0.04, 0.06))
    data = field.sample(40).data.copy()
    data[data < 1e-3] = 0.0
    vol = Volume(data)
    view = View.orbit(azimuth=37, elevation=23, size=36)
    # Glow and float64: the kernels other tests compile (a test of its own kind of kernel
    # costs make test seconds of compiling).
    options = dict(transfer=Glow(12.0), classification=classification, step=0.7)
    skipped = render(vol, view, **options)
    monkeypatch.setenv("VRLIB_QUICK_START", "1")
    monkeypatch.setattr(vrlib.raycast, "_quick_start", {"on": 0, "ready": set()})
    monkeypatch.setattr(vrlib.raycast, "compiled_or_cached", lambda d, a: False)
    monkeypatch.setattr(vrlib.skipping, "compiled_or_cached", lambda d, a: False)

    def no_mask(*args):
        raise AssertionError("the footprint mask's kernel was called")

    monkeypatch.setattr(vrlib.raycast, "footprint_mask", no_mask)
    with vrlib.raycast.quick_starts():
        quick = render(vol, view, **options)
    assert np.array_equal(quick.rgba, skipped.rgba)
    assert quick.rgba[..., 3].max() > 0.3
    if classification == "point":
        assert quick.stats.samples > 1.5 * skipped.stats.samples  # sampled through


def test_compiled_or_cached_loads_without_compiling(tmp_path):
    """:func:`vrlib._kernels._jit.compiled_or_cached` answers from this process's compiled
    signatures and numba's disk cache, and never compiles: False for a signature neither
    holds, True once compiled, and True for a new dispatcher of the same function whose
    signature only the disk holds, which it then runs without compiling."""
    if numba.config.DISABLE_JIT:
        pytest.skip("no dispatchers without the JIT")
    import importlib.util

    from vrlib._kernels._jit import compiled_or_cached

    # A function in a file of this test's own: numba's cache of it starts empty.
    (tmp_path / "doubling.py").write_text("def twice(x):\n    return 2 * x\n")
    spec = importlib.util.spec_from_file_location("doubling", tmp_path / "doubling.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    first = numba.njit(cache=True)(module.twice)
    assert not compiled_or_cached(first, (1.5,)) and not first.overloads
    assert first(1.5) == 3.0 and compiled_or_cached(first, (1.5,))
    assert not compiled_or_cached(first, (1,)) and len(first.overloads) == 1  # another
    second = numba.njit(cache=True)(module.twice)
    assert compiled_or_cached(second, (1.5,)) and len(second.overloads) == 1
    assert second(1.5) == 3.0 and second.stats.cache_misses == {}


@pytest.mark.parametrize("options", [{}, {"segment_ends": "exact"},
                                     {"classification": "preintegrated"},
                                     {"skip_budget": 1e-2}, {"tolerance": 1e-3}], ids=str)
@pytest.mark.parametrize("filt", ["trilinear", "catmull-rom", "gaussian"])
def test_bit_identical_for_one_and_two_threads(filt, options, monkeypatch):
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba sees a single CPU: nothing to compare")
    monkeypatch.setattr(vrlib.raycast, "ONE_THREAD_SAMPLES", 0)  # small renders on two too
    vol = data_gen.make_field("marschner-lobb").sample(24)
    view = View.orbit(azimuth=20, elevation=35, size=70)
    one = render(vol, view, filter=filt, threads=1, **options)
    two = render(vol, view, filter=filt, threads=2, **options)
    assert np.array_equal(one.rgba, two.rgba)
    assert one.stats.samples == two.stats.samples


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="a single CPU")
def test_a_small_unlit_tent_render_runs_on_one_thread(monkeypatch):
    """Below ONE_THREAD_SAMPLES (by the bound on samples) the tent filter's unlit render
    takes one thread whatever the thread count, the other filters the thread count; the
    image is the same either way."""
    calls = []
    launch = vrlib.raycast.on_threads
    monkeypatch.setattr(vrlib.raycast, "on_threads",
                        lambda work, threads: calls.append(threads) or launch(work, threads))
    vol = data_gen.make_field("marschner-lobb").sample(24)
    small, large = View.orbit(azimuth=20, elevation=35, size=32), View.orbit(size=160)
    alone = render(vol, small, threads=2)
    render(vol, large, threads=2)  # 25600 rays of about 80 samples by the bound
    render(vol, small, filter="catmull-rom", threads=2)
    monkeypatch.setattr(vrlib.raycast, "ONE_THREAD_SAMPLES", 0)
    both = render(vol, small, threads=2)
    assert calls == [1, 2, 2, 2]
    assert np.array_equal(alone.rgba, both.rgba)


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="a single CPU")
def test_many_rays_of_few_samples_take_two_threads(monkeypatch):
    """A ray costs ``RAY_SAMPLES`` samples in the work that picks the threads: 4096 rays at a
    step of 16 voxels (18 thousand samples by the bound, 281 thousand with the rays) take
    two threads, as they would not by their samples alone; the image is the same."""
    calls = []
    launch = vrlib.raycast.on_threads
    monkeypatch.setattr(vrlib.raycast, "on_threads",
                        lambda work, threads: calls.append(threads) or launch(work, threads))
    vol = data_gen.make_field("marschner-lobb").sample(24)
    view = View.orbit(azimuth=20, elevation=35, size=64)
    two = render(vol, view, step=16.0, threads=2)
    monkeypatch.setattr(vrlib.raycast, "RAY_SAMPLES", 0)
    one = render(vol, view, step=16.0, threads=2)
    assert calls == [2, 1]
    assert np.array_equal(one.rgba, two.rgba)


@pytest.mark.parametrize("filt", ["box", "trilinear", "catmull-rom", "gaussian"])
@pytest.mark.parametrize("transfer", [Glow(5.0), TABLE], ids=["glow", "table"])
def test_empty_space_skipping_changes_nothing(filt, transfer):
    """Skipping is exact: bit-identical images, and fewer samples on a sparse scene."""
    field = data_gen.make_field("random-blobs", count=3, seed=5, sigma=(0.04, 0.06))
    data = field.sample(48).data.copy()
    data[data < 1e-3] = 0.0  # true empty space around the blobs
    vol = Volume(data)
    views = [View.orbit(azimuth=a, elevation=e, size=40)
             for a, e in [(0, 0), (90, 0), (0, 90), (37, 23), (45, 45)]]
    views += [View.orbit(azimuth=-50, elevation=15, size=40, projection="perspective"),
              View.orbit(azimuth=10, elevation=5, size=40, projection="perspective",
                         distance=0.5, fov=70)]  # eye inside: blocks behind it
    for view in views:
        skipped = render(vol, view, filter=filt, transfer=transfer)
        full = render(vol, view, filter=filt, transfer=transfer, empty_space_skipping=False)
        assert np.array_equal(skipped.rgba, full.rgba)
        assert skipped.stats.samples < 0.5 * full.stats.samples


@pytest.mark.parametrize("classification", ["point", "preintegrated"])
@pytest.mark.parametrize("transfer", [Glow(4.0), TABLE, Glow(3.0, shading=Phong(specular=0.5))],
                         ids=["glow", "table", "glow-shaded"])
def test_skipping_by_a_budget_stays_within_it(classification, transfer):
    """Leaving out blocks that are not empty, while the bounds of those a ray leaves out add
    up to at most the budget, changes no channel of any pixel by more than the budget, and
    leaves out samples (a blob with long low tails)."""
    vol = data_gen.make_field("gaussian-blob", sigma=0.3).sample(40)
    view = View.orbit(azimuth=25, elevation=35, size=48)
    full = render(vol, view, transfer=transfer, classification=classification, step=0.5)
    for budget in (1e-3, 1e-2, 0.1):
        part = render(vol, view, transfer=transfer, classification=classification, step=0.5,
                      skip_budget=budget)
        assert np.abs(part.rgba - full.rgba).max() <= budget
    assert part.stats.samples < 0.9 * full.stats.samples


def test_early_termination_stays_within_its_bound():
    """Stopping at opacity 1 - e changes no channel by more than e (emission <= 1)."""
    vol = data_gen.make_field("smooth-sphere", radius=0.7).sample(32)
    view = View.orbit(azimuth=10, elevation=10, size=48)
    full = render(vol, view, transfer=Glow(20.0), early_termination=1.0)
    assert full.alpha.max() > 0.999
    for threshold in [0.9, 0.99, 0.999]:
        early = render(vol, view, transfer=Glow(20.0), early_termination=threshold)
        assert np.abs(early.rgba - full.rgba).max() <= 1.0 - threshold + 1e-12
        assert early.stats.samples < full.stats.samples


@pytest.mark.parametrize("ends", ["lattice", "exact"])
@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
@pytest.mark.parametrize("brick", [False, True], ids=["whole", "brick"])
def test_runs_inside_the_volume_equal_the_general_loop(ends, projection, brick):
    """The common case (tent filter, grey, nothing to skip) samples its runs of cells inside
    the volume without a test per sample, eight rays' runs at once in vector form, each run
    as long as the ray stays inside: its image and sample count equal, bit for bit, those of
    the same render whose runs are cut at every block face by skip checks (a skip grid whose
    blocks are all visible: lanes that leave and rejoin the packet), over rays that stop by
    early termination inside a run, rays cut by the volume's faces, a perspective eye and a
    brick's own box. (Both take the runs; the naive
    twins check the runs' arithmetic against a loop that samples each segment on its own:
    a run that ends one sample late fails five of ``test_exact_segment_ends_match_naive_twin``
    and none here.)"""
    vol = data_gen.make_field("marschner-lobb").sample((23, 20, 21))
    view = View.orbit(azimuth=33, elevation=21, size=37, projection=projection)
    filt, transfer = vrlib.make_filter("trilinear"), Glow(40.0)
    ext = vol.extent
    first, box = 0, (ext[:, 0].copy(), ext[:, 1].copy())
    data = vol.data
    if brick:  # the upper half along z, with one ghost sample below
        first = 10
        data = np.ascontiguousarray(vol.data[first - 1:])
        first -= 1
        box[0][2] = ext[2, 0] + 10 * vol.spacing[2]
    visible = np.zeros((3, 3, 3), bool)
    grid = (visible, vrlib.skipping.clearance(visible), 8, np.ones(view.shape, bool))
    images = []
    for skip in (None, grid):
        rgba, samples = cast_rays(
            data, offset=(first, 0, 0), global_shape=vol.shape, origin=vol.origin,
            spacing=vol.spacing, box=box, view=view, filt=filt, transfer=transfer,
            ds=0.7 * vol.spacing.min(), value_range=reconstructed_range(vol, filt),
            early_termination=0.95, skip=skip, exact_ends=ends == "exact")
        images.append((rgba, samples))
    (runs, taken_runs), (general, taken_general) = images
    assert np.array_equal(runs, general)
    assert taken_runs == taken_general
    assert (runs[..., 3] >= 0.95).mean() > 0.2  # rays do stop early
    assert 0.0 < (runs[..., 3] > 0.0).mean() < 1.0


@pytest.mark.parametrize("ends", ["lattice", "exact"])
@pytest.mark.parametrize("filt,transfer", [("catmull-rom", Glow(1.0)),
                                           ("box", Glow(1.0, shading=Phong()))],
                         ids=["catmull-rom", "box-shaded"])
def test_bricks_share_the_global_lattice(ends, filt, transfer):
    """Two bricks (with the ghost samples an MPI rank reads), each rendered over its own box
    and composited with the over operator, give the whole volume's image: no sample is taken
    twice or missed (with exact ends, only the whole volume's faces cut a segment, never the
    bricks'); the box filter's sampled gradient needs its one ghost sample."""
    vol = data_gen.make_field("marschner-lobb").sample((20, 21, 22))
    view = View.orbit(azimuth=-70, elevation=25, size=30)
    filt = vrlib.make_filter(filt)
    whole = render(vol, view, filter=filt, transfer=transfer, step=0.41,
                   early_termination=1.0, empty_space_skipping=False, segment_ends=ends)
    split, ghost = 10, ghost_samples(filt)
    ext = vol.extent
    z_cut = ext[2, 0] + split * vol.spacing[2]
    parts = []
    for first, stop, (z_lo, z_hi) in [(0, split + ghost + 1, (ext[2, 0], z_cut)),
                                      (split - ghost, vol.shape[0], (z_cut, ext[2, 1]))]:
        rgba, _ = cast_rays(
            np.ascontiguousarray(vol.data[first:stop]), offset=(first, 0, 0),
            global_shape=vol.shape, origin=vol.origin, spacing=vol.spacing,
            box=([ext[0, 0], ext[1, 0], z_lo], [ext[0, 1], ext[1, 1], z_hi]), view=view,
            filt=filt, transfer=transfer, ds=0.41 * vol.spacing.min(),
            value_range=reconstructed_range(vol, filt), early_termination=1.0,
            exact_ends=ends == "exact")
        parts.append(rgba)
    # The view looks down (elevation 25): the upper brick (larger z) is in front.
    composited = vrlib.compositing.over(parts[1], parts[0])
    np.testing.assert_allclose(composited, whole.rgba, atol=1e-14)


@pytest.mark.parametrize("filt", ["box", "trilinear", "catmull-rom", "bspline", "mitchell",
                                  "gaussian"])
def test_glow_blob_against_closed_form(filt):
    """A Gaussian blob sampled at 64^3 against its closed-form image (docs/model.md).

    Measured rmse at steps 1, 0.5, 0.25 (64^3, 96^2, Glow(2), sigma 0.3, azimuth 30,
    elevation 20): box 2.0e-4 / 9.3e-5 / 8.4e-5, trilinear 9.2e-5 at every step, Catmull-Rom
    9.3e-6 / 4.8e-6 / 2.5e-6, B-spline 1.8e-4, Mitchell 6.1e-5, Gaussian 2.0e-4. The bound
    asserted is the issue's (trilinear at step 0.5 under 2e-3) for every filter, and the
    interpolating cubic must beat the tent.
    """
    field = data_gen.make_field("gaussian-blob", sigma=0.3, center=(0.05, -0.1, 0.08))
    vol = field.sample(64)
    view = View.orbit(azimuth=30, elevation=20, size=96)
    exact = exact_blob_image(field, view, 2.0)
    errors = [metrics.rmse(render(vol, view, filter=filt, transfer=Glow(2.0), step=s).alpha,
                           exact) for s in (1.0, 0.5, 0.25)]
    assert errors[1] < 2e-3
    if filt == "catmull-rom":
        tent = metrics.rmse(render(vol, view, transfer=Glow(2.0)).alpha, exact)
        assert errors[1] < tent / 5
        assert errors[2] < errors[1] < errors[0]  # converges as the step shrinks


def test_mass_invariant_over_random_orbits():
    """Sum of -ln(1 - alpha) * pixel area = k * integral of F (docs/model.md), to 0.5%, for
    8 random orbits, orthographic."""
    field = data_gen.make_field("gaussian-blob", sigma=0.25, center=(0.1, 0.0, -0.1))
    vol = field.sample(48)
    k = 1.5
    expected = k * field.integral(field.bounds)
    for view in random_orbits(8, seed=11, size=96):
        img = render(vol, view, transfer=Glow(k))
        assert image_mass(img, view) == pytest.approx(expected, rel=5e-3)


@pytest.mark.parametrize("azimuth, elevation", [(0, 30), (30, 60), (45, 10)])
def test_catmull_rom_beats_trilinear_on_marschner_lobb(azimuth, elevation):
    """On Marschner-Lobb sampled at 41^3 (just under Nyquist), against the reference.

    Measured rmse (64^2, Glow(2), step 0.25), trilinear / Catmull-Rom: 3.6e-3 / 3.2e-3 at
    (0, 30), 5.4e-3 / 4.0e-3 at (30, 60), 7.6e-3 / 4.5e-3 at (45, 10): the cubic wins by 11% to
    41% depending on the view (the projection along rays averages errors out most when the
    rings are seen from above). The B-spline, which blurs, loses to trilinear everywhere.
    """
    field = data_gen.make_field("marschner-lobb")
    vol = field.sample(41)
    view = View.orbit(azimuth=azimuth, elevation=elevation, size=64)
    ref = render_reference(field, view, transfer=Glow(2.0), tol=1e-6)

    def error(filt):
        return metrics.rmse(render(vol, view, filter=filt, transfer=Glow(2.0), step=0.25).alpha,
                            ref.alpha)

    tent, cubic, bspline = error("trilinear"), error("catmull-rom"), error("bspline")
    assert cubic < 0.95 * tent
    assert bspline > tent


def test_images_converge_as_the_step_shrinks():
    vol = data_gen.make_field("marschner-lobb").sample(24)
    view = View.orbit(azimuth=15, elevation=40, size=32)
    images = [render(vol, view, step=s, transfer=Glow(3.0)).rgba for s in (2.0, 1.0, 0.5, 0.25,
                                                                          0.125)]
    diffs = [np.abs(a - b).max() for a, b in zip(images, images[1:], strict=False)]
    assert all(later < earlier for earlier, later in zip(diffs, diffs[1:], strict=False))


def test_views_that_miss_give_a_transparent_image():
    vol = small_volume()
    off = View.orbit(size=8, center=(10, 10, 10), radius=0.5)
    with pytest.warns(vrlib.EmptyImageWarning, match="lies outside the view"):
        img = render(vol, off)
    assert np.array_equal(img.rgba, np.zeros((8, 8, 4)))
    assert img.stats.samples == 0


def test_perspective_eye_inside_the_volume():
    vol = data_gen.make_field("marschner-lobb").sample(16)
    view = View.orbit(size=16, projection="perspective", distance=0.3, fov=60)
    img = render(vol, view)
    assert np.all(np.isfinite(img.rgba)) and img.alpha.max() > 0


def test_stats_are_counted():
    vol = small_volume()
    img = render(vol, View.orbit(size=8), step=0.5)
    assert img.stats.samples > 0
    assert img.stats.operations > img.stats.samples
    assert img.stats.bytes >= vol.data.nbytes
    assert img.stats.seconds > 0


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        ({"method": "raytrace"}, ValueError, "unknown method 'raytrace'; known: 'raycast'"),
        ({"filter": "cubic"}, ValueError, "unknown filter 'cubic'; known:"),
        ({"filter": ("gaussian", 0.6, 5.0)}, ValueError, "radius 5 is out of range"),
        ({"step": 0.0}, ValueError, "step must be > 0"),
        ({"step": -1.0}, ValueError, "step must be > 0"),
        ({"step": math.nan}, ValueError, "step must be finite"),
        ({"step": "fine"}, TypeError, "step must be a real number"),
        ({"early_termination": 0.0}, ValueError, "early_termination must be > 0"),
        ({"early_termination": 1.5}, ValueError, "early_termination must be <= 1"),
        ({"transfer": "glow"}, TypeError, "transfer must be a vrlib transfer function"),
        ({"empty_space_skipping": 1}, TypeError, "empty_space_skipping must be True or False"),
        ({"threads": 0}, ValueError, "threads must be between 1 and"),
        ({"threads": 1.5}, TypeError, "threads must be an integer"),
    ],
)
def test_bad_input(kwargs, error, message):
    with pytest.raises(error, match=message):
        render(small_volume(), View.orbit(size=4), **kwargs)


def test_bad_volume_or_view():
    with pytest.raises(TypeError, match="volume must be a vrlib.Volume, got ndarray"):
        render(np.zeros((4, 4, 4)), View.orbit(size=4))
    with pytest.raises(TypeError, match="view must be a vrlib.View"):
        render(small_volume(), (30, 20))


def test_kernel_without_skipping_equals_the_kernel_with_it():
    """The kernel compiled without skipping (``skipping=None``: nothing to skip) does the
    arithmetic of the one that skips: with skipping on (jumping empty blocks, runs cut at
    each skip check) and off the image is bit for bit the same."""
    vol = data_gen.make_field("random-blobs", count=4, seed=2, sigma=(0.08, 0.12)).sample(33)
    ramp = vrlib.LookupTransfer(np.where(np.linspace(0, 1, 33) > 0.2, 20.0, 0.0),
                                value_range=(0.0, 1.0))
    view = vrlib.View.orbit(azimuth=25, elevation=35, size=40)
    on = vrlib.render(vol, view, transfer=ramp, empty_space_skipping=True)
    off = vrlib.render(vol, view, transfer=ramp, empty_space_skipping=False)
    assert on.stats.samples < off.stats.samples  # the general loop really skipped
    np.testing.assert_array_equal(on.rgba, off.rgba)
