"""Splatting: footprints, agreement with the naive twin, determinism, skips, accuracy."""

import numba
import numpy as np
import pytest
from naive import exact_blob_image, image_mass, random_orbits, splat_naive
from scipy import integrate

import data_gen
import vrlib
from vrlib import Glow, LookupTransfer, Phong, View, Volume, metrics, render
from vrlib.footprint import PLANAR, RADIAL, footprint
from vrlib.view import principal_axis

TABLE = LookupTransfer([0.0, 3.0, 1.0, 5.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])
FILTERS = ["box", "trilinear", "catmull-rom", "bspline", "gaussian", ("gaussian", 0.5, 1.5)]


def exact_line_integral(filt, spacing, point, direction):
    """int K(point + t d) dt for the separable kernel (the ray caster's cube truncation)."""
    h = np.asarray(spacing)

    def kernel(t):
        p = point + t * direction
        return float(np.prod([filt(p[a] / h[a]) for a in range(3)]))

    reach = 3 * filt.radius * float(np.linalg.norm(h))
    return integrate.quad(kernel, -reach, reach, limit=500, points=[0.0])[0]


@pytest.mark.parametrize("name", ["box", "trilinear", "catmull-rom", "bspline", "mitchell",
                                  ("gaussian", 0.6, 2.0)], ids=str)
@pytest.mark.parametrize("spacing", [(1.0, 1.0, 1.0), (0.5, 1.0, 1.5)], ids=["even", "uneven"])
def test_footprint_tables_match_line_integrals(name, spacing):
    """A table entry is the kernel's line integral along the view; between entries it is
    interpolated. Planar tables (every filter but the Gaussian on an even lattice) match the
    separable kernel's integral to 1e-7 at their nodes (the reference quadrature's own accuracy
    across the box's jumps); the radial Gaussian, truncated to a ball, is within 1% of the
    cube-truncated kernel."""
    filt = vrlib.make_filter(name)
    view = View.orbit(azimuth=27, elevation=38)
    radial = filt.name == "gaussian" and spacing[0] == spacing[2]
    fp = footprint(filt, spacing, None if radial else view.basis, resolution=33)
    assert fp.kind == (RADIAL if radial else PLANAR)
    rng = np.random.default_rng(0)
    for _ in range(4):
        if radial:
            u, v = rng.uniform(-0.6, 0.6, 2) * fp.extent
        else:
            u = np.linspace(-fp.extent, fp.extent, 33)[rng.integers(8, 25)]  # table nodes
            v = np.linspace(-fp.extent_v, fp.extent_v, 33)[rng.integers(8, 25)]
        point = u * view.right + v * view.up
        exact = exact_line_integral(filt, spacing, point, view.forward)
        tol = 0.01 * fp(0.0, 0.0) if radial else 1e-7
        assert float(fp(u, v)) == pytest.approx(exact, abs=tol)


@pytest.mark.parametrize("name", ["trilinear", "catmull-rom", "gaussian"])
def test_footprint_mass_and_resolution(name):
    """Each footprint integrates over the plane to the kernel's volume h^3 (the mass a voxel
    carries), and the interpolation error falls as the table grows."""
    view = View.orbit(azimuth=10, elevation=70)
    errors = []
    fine = footprint(name, (0.5, 0.5, 0.5), view.basis if name != "gaussian" else None,
                     resolution=513)
    for resolution in (17, 65, 193):
        fp = footprint(name, (0.5, 0.5, 0.5), view.basis if name != "gaussian" else None,
                       resolution=resolution)
        gu = np.linspace(-fp.extent, fp.extent, 801)
        gv = np.linspace(-(fp.extent_v or fp.extent), fp.extent_v or fp.extent, 801)
        u, v = np.meshgrid(gu, gv)
        values = fp(u, v)
        mass = np.trapezoid(np.trapezoid(values, gu, axis=1), gv)
        assert mass == pytest.approx(0.125, rel=2e-3)
        errors.append(np.abs(values - fine(u, v)).max())
    assert errors[0] > errors[1] > errors[2]


@pytest.mark.parametrize("name", ["trilinear", "catmull-rom",
                                  pytest.param("box", marks=pytest.mark.slow),
                                  pytest.param("bspline", marks=pytest.mark.slow)])
def test_slanted_footprints_match_line_integrals(name):
    """The slanted table (perspective footprints, one per ray) holds the line integral of the
    separable kernel along lines of any slope: exact quadrature between knots matches scipy's
    to 1e-9 on random stretches, and the table's interpolation stays within 0.6% of the
    footprint's peak (offsets every 1/16 voxel, slopes every 0.15)."""
    from vrlib._kernels.footprint import slanted_integral
    from vrlib.footprint import slanted

    filt = vrlib.make_filter(name)
    table = slanted(filt, 0.8)
    nodes, weights = np.polynomial.legendre.leggauss(5)
    rng = np.random.default_rng(1)
    r = filt.radius
    knots = list(np.arange(-r, r + 0.25, 0.5))
    for _ in range(12):
        (bp, bq), (mp, mq) = rng.uniform(-1.5, 1.5, 2), rng.uniform(-0.8, 0.8, 2)
        lo, hi = np.sort(rng.uniform(-r - 0.5, r + 0.5, 2))

        def line(s, bp=bp, bq=bq, mp=mp, mq=mq):
            return float(filt(s) * filt(bp + mp * s) * filt(bq + mq * s))
        cuts = sorted({lo, hi, *[k for k in knots if lo < k < hi],
                       *[(k - b) / m for k in knots for b, m in ((bp, mp), (bq, mq))
                         if m != 0 and lo < (k - b) / m < hi]})
        exact = sum(integrate.quad(line, a, b)[0]
                    for a, b in zip(cuts[:-1], cuts[1:], strict=True))
        assert slanted_integral(*filt.code, float(r), bp, bq, mp, mq, nodes, weights, lo,
                                hi, np.empty(64)) == pytest.approx(exact, abs=1e-9)
        whole = sum(integrate.quad(line, a, b)[0]
                    for a, b in zip(knots[:-1], knots[1:], strict=True))
        assert float(table(bp, bq, mp, mq)) == pytest.approx(whole, abs=6e-3 * float(
            table(0.0, 0.0, 0.0, 0.0)))


@pytest.mark.parametrize("filt", ["trilinear", "catmull-rom"])
def test_wide_perspective_as_accurate_as_ray_casting(filt):
    """Eye just outside the bounding sphere, 100-degree field of view (rays up to 50 degrees
    off the axis): each ray reads its own footprint, so splatting stays within the ray
    caster's error plus 1e-3 in every mode (measured at 32^3, 48^2: Catmull-Rom 7.7e-4
    sheet and direct, 1.2e-4 image-aligned against 3.8e-4 for the ray caster; the view-axis
    table was off by 0.017)."""
    field = data_gen.make_field("gaussian-blob", sigma=0.3, center=(0.05, -0.1, 0.08))
    vol = field.sample(24)
    view = View.orbit(azimuth=30, elevation=20, size=32, projection="perspective",
                      distance=1.05 * np.sqrt(3.0), fov=100)
    exact = exact_blob_image(field, view, 2.0)
    cast = metrics.max_abs_error(render(vol, view, filter=filt, transfer=Glow(2.0)).alpha, exact)
    for mode in vrlib.splat.MODES:
        img = render(vol, view, method="splat", filter=filt, mode=mode, transfer=Glow(2.0))
        assert metrics.max_abs_error(img.alpha, exact) < cast + 1e-3


def small_volume():
    return data_gen.make_field("random-blobs", count=4, seed=2).sample((5, 6, 7))


def twin_cases():
    """(projection, filter, mode) for the twins. Image-aligned twins are slow (every voxel in
    every slab, pixel by pixel): `make test` takes three filters (the tent, a cubic with
    negative lobes, the radial Gaussian) orthographic and the cubic in perspective,
    `make test-all` every one. Perspective sheets and direct splats take the same three
    filters in `make test` (the slanted table of planar footprints, and the radial one's
    closed form), every filter in `make test-all`."""
    for projection in ("orthographic", "perspective"):
        for f in FILTERS:
            three = f in ("trilinear", "catmull-rom", "gaussian")
            for mode in ("sheet", "direct"):
                yield pytest.param(projection, f, mode, marks=() if (
                    projection == "orthographic" or three) else pytest.mark.slow)
            fast = three if projection == "orthographic" else f == "catmull-rom"
            yield pytest.param(projection, f, "image-aligned",
                               marks=() if fast else pytest.mark.slow)


@pytest.mark.parametrize("projection, filt, mode", list(twin_cases()), ids=str)
@pytest.mark.parametrize("transfer", [Glow(3.0), TABLE], ids=["glow", "table"])
def test_kernel_matches_naive_twin(projection, filt, mode, transfer):
    vol = small_volume()
    view = View.orbit(azimuth=33, elevation=-21, size=(7, 9), projection=projection)
    fast = render(vol, view, method="splat", filter=filt, transfer=transfer, mode=mode,
                  early_termination=1.0)
    slow = splat_naive(vol, view, vrlib.make_filter(filt), transfer, mode)
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    assert fast.alpha.max() > 0.1


SHADED = LookupTransfer([0.0, 3.0, 1.0, 5.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]],
                        shading=Phong(specular=0.4),
                        gradient_opacity=vrlib.GradientOpacity([0.0, 2.0], [0.2, 1.0]))


@pytest.mark.parametrize("projection, filt, mode", [
    (projection, filt, mode) if projection == "orthographic" or filt == "catmull-rom" else
    pytest.param(projection, filt, mode, marks=pytest.mark.slow)  # make test-all
    for projection in ("orthographic", "perspective")
    for filt, mode in [("trilinear", "sheet"), ("catmull-rom", "sheet"), ("omoms", "sheet"),
                       ("trilinear", "image-aligned")]])
def test_shaded_sheets_match_naive_twin(projection, filt, mode):
    """Sheet buffers shade: each voxel's central-difference gradient is splatted beside its
    value, and each segment is classified by its mean gradient (gradient opacity) and shaded
    along the pixel's own ray (a headlight), as the twin computes it."""
    vol = small_volume()
    view = View.orbit(azimuth=33, elevation=-21, size=(7, 9), projection=projection)
    fast = render(vol, view, method="splat", filter=filt, transfer=SHADED, mode=mode,
                  early_termination=1.0)
    slow = splat_naive(vol, view, vrlib.make_filter(filt), SHADED, mode)
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    assert fast.alpha.max() > 0.1
    plain = splat_naive(vol, view, vrlib.make_filter(filt), TABLE, mode)
    assert np.abs(fast.rgba - plain).max() > 0.05  # the shading and the ramp show


@pytest.mark.parametrize("projection", ["orthographic",
                                        pytest.param("perspective", marks=pytest.mark.slow)])
def test_shaded_sheets_are_close_to_the_ray_casters(projection):
    """Against the ray caster at a quarter-voxel step: six blobs 48^3 -> 96^2, a shaded
    colour table and a gradient-opacity one, three views. Measured rmse of premultiplied
    RGBA, 2026-11-26: sheets 0.7e-3 to 4.5e-3, image-aligned sheets 0.7e-3 to 3.4e-3, direct
    splatting 4.3e-3 to 6.0e-3 (it classifies before reconstructing). The bound is 2x the
    sheets' measured worst case; the images are the same for 1 and 2 threads."""
    vol = data_gen.make_field("random-blobs", count=6, seed=7).sample(48)
    points = [(0, 0), (0.2, 0), (1, 0.6)]
    transfers = [vrlib.colormap("viridis", points, volume=vol,
                                shading=Phong(specular=0.3)),
                 vrlib.colormap("viridis", points, volume=vol,
                                gradient_opacity=vrlib.GradientOpacity([0.0, 2.0], [0.0, 1.0]))]
    for transfer in transfers:
        for azimuth, elevation in [(35, 25), (0, 0), (120, -40)]:
            view = View.orbit(azimuth=azimuth, elevation=elevation, size=96,
                              projection=projection)
            reference = render(vol, view, transfer=transfer, step=0.25)
            for mode in ("sheet", "image-aligned"):
                image = render(vol, view, method="splat", transfer=transfer, mode=mode)
                assert metrics.rmse(image, reference) < 9e-3
            one = render(vol, view, method="splat", transfer=transfer, threads=1)
            two = render(vol, view, method="splat", transfer=transfer, threads=2)
            assert np.array_equal(one.rgba, two.rgba)


@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
def test_prefiltered_sheets_match_naive_twin(projection):
    """A prefiltered filter splats the volume's coefficients (the twin solves for them) with
    its kernel's footprint; direct mode, which classifies voxels, refuses it."""
    vol = small_volume()
    view = View.orbit(azimuth=33, elevation=-21, size=(7, 9), projection=projection)
    fast = render(vol, view, method="splat", filter="omoms", transfer=TABLE,
                  early_termination=1.0)
    slow = splat_naive(vol, view, vrlib.make_filter("omoms"), TABLE, "sheet")
    np.testing.assert_allclose(fast.rgba, slow, atol=1e-6)
    assert fast.alpha.max() > 0.1
    with pytest.raises(ValueError, match="direct splatting classifies each voxel"):
        render(vol, view, method="splat", filter="omoms", mode="direct")


@pytest.mark.parametrize("mode", ["sheet", "image-aligned", "direct"])
def test_bit_identical_for_one_and_two_threads(mode):
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba sees a single CPU: nothing to compare")
    vol = data_gen.make_field("marschner-lobb").sample(24)
    view = View.orbit(azimuth=20, elevation=35, size=70)
    one = render(vol, view, method="splat", filter="catmull-rom", mode=mode, threads=1)
    two = render(vol, view, method="splat", filter="catmull-rom", mode=mode, threads=2)
    assert np.array_equal(one.rgba, two.rgba)


def test_sheet_and_direct_agree_under_glow():
    """All three modes compute 1 - exp(-k sum f_i FP) under Glow for filters without negative
    lobes. Sheets sum the same clipped footprints in another order: equal to 1e-9 (not 1e-12:
    a ray that grazes an edge of the box has an in-box stretch too short to divide a sheet by,
    and its last sheet's length stands in). Image-aligned slabs split each footprint into
    differences of the partial table, interpolated along the line where the whole footprint
    is not: equal to 1e-4."""
    vol = data_gen.make_field("marschner-lobb").sample(20)
    view = View.orbit(azimuth=-30, elevation=15, size=40)
    for filt in ["trilinear", "gaussian", "bspline"]:
        direct = render(vol, view, method="splat", filter=filt, mode="direct")
        sheet = render(vol, view, method="splat", filter=filt, mode="sheet")
        np.testing.assert_allclose(sheet.rgba, direct.rgba, atol=1e-9)
        slabs = render(vol, view, method="splat", filter=filt, mode="image-aligned")
        np.testing.assert_allclose(slabs.rgba, direct.rgba, atol=1e-4)


def test_sheet_and_direct_differ_for_a_sharp_transfer_function():
    """Classifying each voxel before reconstruction (direct) blurs a sharp transfer function:
    the images differ, and sheet buffers are closer to the ray caster, which classifies the
    reconstructed field."""
    field = data_gen.make_field("smooth-sphere", radius=0.6, width=0.15)
    vol = field.sample(32)
    step_tf = LookupTransfer(np.r_[np.zeros(50), np.full(51, 8.0)], value_range=(0, 1))
    view = View.orbit(azimuth=20, elevation=10, size=48)
    sheet = render(vol, view, method="splat", transfer=step_tf, mode="sheet")
    direct = render(vol, view, method="splat", transfer=step_tf, mode="direct")
    cast = render(vol, view, transfer=step_tf, step=0.25)
    assert metrics.rmse(sheet, direct) > 0.01
    assert metrics.rmse(sheet, cast) < metrics.rmse(direct, cast)


def test_culling_zero_voxels_changes_nothing():
    """Voxels of value zero (and, in direct mode, of zero density) are never drawn; drawing
    them would add exactly nothing."""
    data = data_gen.make_field("random-blobs", count=3, seed=5, sigma=(0.05, 0.08)).sample(
        32).data.copy()
    data[data < 0.05] = 0.0
    vol = Volume(data)
    threshold_tf = LookupTransfer(np.r_[0.0, 0.0, np.linspace(1, 6, 9)], value_range=(0, 1))
    view = View.orbit(azimuth=40, elevation=25, size=40)
    for mode, transfer in [("sheet", Glow(2.0)), ("direct", Glow(2.0)),
                           ("direct", threshold_tf)]:
        culled = render(vol, view, method="splat", mode=mode, transfer=transfer)
        full = render(vol, view, method="splat", mode=mode, transfer=transfer,
                      empty_space_skipping=False)
        assert np.array_equal(culled.rgba, full.rgba)
        assert culled.stats.voxels < 0.5 * full.stats.voxels


@pytest.mark.parametrize("mode", ["sheet", "image-aligned"])
@pytest.mark.parametrize("filt", ["trilinear", "catmull-rom", "bspline"])
def test_transfer_function_culling(mode, filt):
    """Sheet modes leave out the voxels whose neighbourhood the transfer function makes
    transparent (no exact zeros needed): far fewer voxels are drawn on a sparse scene whose
    background is a small nonzero value, and the image changes by under 1e-5 (a sheet
    classifies a mean over a stretch of the ray, so leaving voxels out is not exact to the
    bit; the neighbourhood's widening keeps the change at rounding level)."""
    data = data_gen.make_field("random-blobs", count=4, seed=3).sample(40).data + 0.01
    vol = Volume(data)
    step = LookupTransfer([0.0, 0.0, 0.0, 40.0, 40.0], value_range=(0.0, 1.0))
    view = View.orbit(azimuth=30, elevation=20, size=48)
    culled = render(vol, view, method="splat", filter=filt, mode=mode, transfer=step)
    full = render(vol, view, method="splat", filter=filt, mode=mode, transfer=step,
                  empty_space_skipping=False)
    assert full.alpha.max() > 0.5
    assert np.abs(culled.rgba - full.rgba).max() < 1e-5
    assert culled.stats.voxels < 0.5 * full.stats.voxels


def test_opaque_pixels_take_nothing_more():
    vol = data_gen.make_field("smooth-sphere", radius=0.7).sample(24)
    view = View.orbit(azimuth=10, elevation=10, size=40)
    for mode in ("sheet", "direct"):
        full = render(vol, view, method="splat", mode=mode, transfer=Glow(40.0),
                      early_termination=1.0)
        assert full.alpha.max() > 0.999
        for threshold in [0.9, 0.99]:
            early = render(vol, view, method="splat", mode=mode, transfer=Glow(40.0),
                           early_termination=threshold)
            assert np.abs(early.rgba - full.rgba).max() <= 1.0 - threshold + 1e-12
            assert early.stats.samples < full.stats.samples


@pytest.mark.parametrize("filt", ["box", "trilinear", "catmull-rom", "bspline", "mitchell",
                                  "gaussian"])
def test_glow_blob_against_closed_form(filt):
    """A Gaussian blob sampled at 64^3 against its closed-form image (docs/model.md), both
    modes. Measured rmse (96^2, Glow(2)): box 1.5e-4, trilinear 2.0e-4, Catmull-Rom 1.2e-4,
    B-spline 3.2e-4, Mitchell 1.7e-4, Gaussian 3.3e-4: the sampling and the footprint tables
    set the floor."""
    field = data_gen.make_field("gaussian-blob", sigma=0.3, center=(0.05, -0.1, 0.08))
    vol = field.sample(64)
    view = View.orbit(azimuth=30, elevation=20, size=96)
    exact = exact_blob_image(field, view, 2.0)
    for mode in ("sheet", "direct"):
        img = render(vol, view, method="splat", filter=filt, transfer=Glow(2.0), mode=mode)
        assert metrics.rmse(img.alpha, exact) < 5e-4


@pytest.mark.parametrize("sigma", [0.4, 0.5, 0.6, 0.7])
def test_gaussian_ripple_floor(sigma):
    """A Gaussian kernel does not sum to one over the lattice (docs/chapters/ch02_filters.md):
    splatting a constant volume along an axis gives an image that ripples with the lattice, by
    2 exp(-2 pi^2 sigma^2) per axis (1.4% at sigma 0.5, 0.16% at 0.6), so by twice that
    over the two axes of the image. Measured (ptp / 2 / mean): 16.6%, 2.82%, 0.322%, 0.022%
    against predicted 17.0%, 2.88%, 0.328%, 0.025%. This floor does not fall with finer
    images; only a wider kernel (more blur) lowers it."""
    vol = Volume(np.ones((16, 16, 16)))
    view = View.orbit(azimuth=0, elevation=0, size=128)
    k = 1e-3  # optically thin: alpha ~ k tau
    img = render(vol, view, method="splat", filter=("gaussian", sigma, 3.0), transfer=Glow(k))
    tau = -np.log1p(-img.alpha)[40:88, 40:88] / k  # away from the volume's edges
    ripple = (tau.max() - tau.min()) / 2 / tau.mean()
    per_axis = 2 * np.exp(-2 * np.pi**2 * sigma**2)
    assert ripple == pytest.approx((1 + per_axis) ** 2 - 1, rel=0.15)


def test_mass_invariant_over_random_orbits():
    """Sum of -ln(1 - alpha) * pixel area = k * integral of F, to 1%, for 8 random orbits."""
    field = data_gen.make_field("gaussian-blob", sigma=0.25, center=(0.1, 0.0, -0.1))
    vol = field.sample(48)
    k = 1.5
    expected = k * field.integral(field.bounds)
    for view in random_orbits(8, seed=11, size=96):
        for filt in ("trilinear", "gaussian"):
            img = render(vol, view, method="splat", filter=filt, transfer=Glow(k))
            assert image_mass(img, view) == pytest.approx(expected, rel=1e-2)


def test_splat_and_raycast_agree():
    """Same volume, same filter: splatting integrates the reconstructed field exactly along
    each ray, ray casting sums samples every quarter voxel. For a blob well inside the volume
    (so that the border kernels carry nothing) they agree to 3e-4 (measured: trilinear 1.3e-4,
    Catmull-Rom 1.0e-4, worst pixel), the size of the footprint tables' interpolation error."""
    field = data_gen.make_field("gaussian-blob", sigma=0.2)
    vol = field.sample(40)
    view = View.orbit(azimuth=25, elevation=35, size=64)
    for filt in ("trilinear", "catmull-rom"):
        splat = render(vol, view, method="splat", filter=filt, transfer=Glow(2.0))
        cast = render(vol, view, filter=filt, transfer=Glow(2.0), step=0.25)
        assert metrics.max_abs_error(splat.alpha, cast.alpha) < 3e-4


@pytest.mark.parametrize("filt", ["trilinear", "catmull-rom", "gaussian"])
def test_splat_converges_to_ray_casting_on_a_field_live_at_the_faces(filt):
    """Marschner-Lobb is far from zero at the volume's faces: border kernels are clipped to the
    box and the lattice extended by its border samples, as the ray caster reconstructs, so the
    splat image is the line integral the ray caster converges to. Their difference falls in
    proportion to the ray caster's step (its error, first order at the box's entry and exit):
    rmse 1.0e-3, 5.2e-4, 2.6e-4 at steps 0.2, 0.1, 0.05 for each filter (41^3, 96^2)."""
    vol = data_gen.make_field("marschner-lobb").sample(24)
    view = View.orbit(azimuth=30, elevation=25, size=48)
    splat = render(vol, view, method="splat", filter=filt, mode="direct", early_termination=1.0)
    gaps = [metrics.rmse(splat.alpha, render(vol, view, filter=filt, step=step,
                                             early_termination=1.0).alpha)
            for step in (0.2, 0.1)]
    assert gaps[1] < 0.6 * gaps[0]
    assert gaps[1] < 2e-3


@pytest.mark.parametrize("mode", ["sheet", "image-aligned", "direct"])
@pytest.mark.parametrize("n", [2, 9])
def test_constant_volume_gives_the_exact_chord_image(mode, n):
    """A constant volume reconstructs to the constant everywhere in its box (border samples
    repeated beyond the faces), so the image is 1 - exp(-k c chord) exactly, to the partial
    tables' interpolation: within 1e-2 for Catmull-Rom on a 2^3 volume (one kernel spans the
    box; measured 6.6e-3) and 1e-3 on 9^3. Before the kernels were clipped at the faces the 2^3
    volume was off by 1.0 and a 33^3 one by 0.2."""
    vol = Volume(np.full((n, n, n), 0.7))
    view = View.orbit(azimuth=30, elevation=20, size=32, radius=vol.bounding_radius)
    origins, directions = view.rays()
    from vrlib.reference import _clip_to_box

    t_in, t_out = _clip_to_box(origins, directions, -1.0, 1.0)
    exact = -np.expm1(-2.0 * 0.7 * (t_out - t_in))
    img = render(vol, view, method="splat", filter="catmull-rom", transfer=Glow(2.0), mode=mode,
                 early_termination=1.0)
    assert metrics.max_abs_error(img.alpha, exact) < (1e-2 if n == 2 else 1e-3)


@pytest.mark.parametrize("azimuth, elevation", [(0, 0), (90, 0), (0, 90), (45, 0), (45, 35.264),
                                                (-135, -45)])
def test_axis_aligned_and_tied_views(azimuth, elevation):
    """Views along an axis and exactly between axes (ties in the slice order) render like
    their neighbours a hair away."""
    vol = data_gen.make_field("marschner-lobb").sample(20)
    at = render(vol, View.orbit(azimuth=azimuth, elevation=elevation, size=32), method="splat")
    near = render(vol, View.orbit(azimuth=azimuth + 1e-6, elevation=elevation - 1e-6, size=32),
                  method="splat")
    assert np.all(np.isfinite(at.rgba))
    assert metrics.max_abs_error(at, near) < 1e-5


def test_principal_axis_and_order():
    vol = Volume(np.zeros((4, 4, 4)))
    assert principal_axis(View.orbit(azimuth=0, elevation=0), vol) == (0, False)
    assert principal_axis(View.orbit(azimuth=180, elevation=10), vol) == (0, True)
    assert principal_axis(View.orbit(azimuth=0, elevation=-80), vol) == (2, True)
    assert principal_axis(View.orbit(azimuth=45, elevation=0), vol)[0] == 0  # tie -> lower axis


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        ({"mode": "fast"}, ValueError,
             "unknown mode 'fast'; known: 'sheet', 'image-aligned', 'direct'"),
            ({"slab_width": 0.01}, ValueError, "slab_width must be >= 0.1"),
        ({"footprint_resolution": 4}, ValueError, "footprint resolution must be an integer >= 8"),
        ({"footprint_resolution": 5000}, ValueError, "at most 1024"),
        ({"filter": ("gaussian", -0.5, 2.0)}, ValueError, "sigma must be > 0"),
        ({"filter": ("gaussian", 0.5, 0.0)}, ValueError, "radius must be > 0"),
        ({"filter": ("gaussian", 0.5, 6.0)}, ValueError, "radius 6 is out of range"),
        ({"table": 3}, TypeError, "method 'splat' takes no option 'table'; its options: mode"),
    ],
)
def test_bad_input(kwargs, error, message):
    with pytest.raises(error, match=message):
        render(small_volume(), View.orbit(size=4), method="splat", **kwargs)


def test_eye_inside_is_refused():
    vol = small_volume()
    inside = View.orbit(size=8, projection="perspective", distance=0.3, fov=60)
    with pytest.raises(ValueError, match="splatting needs the eye outside the volume"):
        render(vol, inside, method="splat")
