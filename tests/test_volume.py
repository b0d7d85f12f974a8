"""Volume: validation, lattice geometry and the min-max pyramid."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from vrlib import Volume
from vrlib.volume import DEFAULT_EXTENT


def test_defaults_and_geometry():
    """With no world box given, voxels are cubes and the longest side spans [-1, 1]: a
    non-cubic array is not stretched to the cube."""
    vol = Volume(np.arange(2 * 3 * 5, dtype=float).reshape(2, 3, 5))
    assert vol.shape == (2, 3, 5)
    np.testing.assert_array_equal(vol.extent, [[-1, 1], [-0.5, 0.5], [-0.25, 0.25]])
    np.testing.assert_allclose(vol.spacing, [0.5, 0.5, 0.5])
    np.testing.assert_allclose(vol.center, [0, 0, 0])
    assert vol.bounding_radius == pytest.approx(np.sqrt(1 + 0.25 + 0.0625))
    assert vol.value_range == (0.0, 29.0)
    # Corner samples sit on the corners of the box.
    np.testing.assert_allclose(vol.index_to_world([4, 2, 1]), [1, 0.5, 0.25])
    np.testing.assert_allclose(vol.world_to_index(vol.index_to_world([1.5, 0.25, 0.5])),
                               [1.5, 0.25, 0.5])
    cube = Volume(np.zeros((4, 4, 4)))
    np.testing.assert_array_equal(cube.extent, DEFAULT_EXTENT)
    # The old stretch to the cube stays one argument away.
    stretched = Volume(vol.data, extent=DEFAULT_EXTENT)
    np.testing.assert_allclose(stretched.spacing, [0.5, 1.0, 2.0])


def test_spacing_and_origin():
    """spacing and origin as pyvista's ImageData takes them; each defaults alone."""
    vol = Volume(np.zeros((3, 4, 5)), spacing=(0.5, 1.0, 2.5), origin=(10, 20, 30))
    np.testing.assert_allclose(vol.extent, [[10, 12], [20, 23], [30, 35]])
    np.testing.assert_allclose(vol.spacing, [0.5, 1.0, 2.5])
    np.testing.assert_allclose(Volume(np.zeros((2, 2, 2)), origin=(1, 2, 3)).extent,
                               [[1, 2], [2, 3], [3, 4]])
    np.testing.assert_allclose(Volume(np.zeros((2, 3, 2)), spacing=(2, 2, 2)).extent,
                               [[0, 2], [0, 4], [0, 2]])
    for bad, message in (({"spacing": (1, 0, 1)}, "spacing must be positive"),
                         ({"spacing": (1, 1)}, "spacing must have three"),
                         ({"origin": (0, np.nan, 0)}, "origin must be finite"),
                         ({"extent": DEFAULT_EXTENT, "origin": (0, 0, 0)}, "not both")):
        with pytest.raises(ValueError, match=message):
            Volume(np.zeros((2, 2, 2)), **bad)


def test_anisotropic_extent():
    vol = Volume(np.zeros((3, 3, 3)), extent=[[0, 4], [0, 2], [-1, 0]])
    np.testing.assert_allclose(vol.spacing, [2.0, 1.0, 0.5])
    np.testing.assert_allclose(vol.origin, [0, 0, -1])
    np.testing.assert_allclose(vol.center, [2, 1, -0.5])


@pytest.mark.parametrize(
    "dtype, stored",
    [("uint8", np.float32), ("int16", np.float32), ("float16", np.float32),
     ("float32", np.float32), ("int32", np.float64), ("uint64", np.float64),
     ("float64", np.float64)],
)
def test_storage_type(dtype, stored):
    vol = Volume(np.ones((2, 2, 2), dtype=dtype))
    assert vol.dtype == stored


def test_data_is_read_only_and_copied():
    src = np.zeros((2, 2, 2))
    vol = Volume(src)
    src[0, 0, 0] = 5.0
    assert vol.data[0, 0, 0] == 0.0
    with pytest.raises(ValueError, match="read-only"):
        vol.data[0, 0, 0] = 1.0
    shared = Volume(src, copy=False)
    assert np.shares_memory(shared.data, src)
    assert src.flags.writeable  # the caller's array keeps its own flags


@pytest.mark.parametrize(
    "data, extent, error, message",
    [
        (np.zeros((2, 2)), None, ValueError, "must be 3-dimensional .* got 2 dimension"),
        (np.zeros((2, 2, 2, 2)), None, ValueError, "got 4 dimension"),
        (np.zeros((2, 1, 2)), None, ValueError, "at least 2 samples along every axis"),
        (np.zeros((0, 2, 2)), None, ValueError, "at least 2 samples"),
        (np.full((2, 2, 2), np.nan), None, ValueError, "found 8 NaN or infinite"),
        (np.array([[[0.0, np.inf], [0, 0]], [[0, 0], [0, 0]]]), None, ValueError,
         "found 1 NaN or infinite"),
        (np.zeros((2, 2, 2), dtype=bool), None, TypeError, "got dtype bool"),
        (np.zeros((2, 2, 2), dtype=complex), None, TypeError, "got dtype complex128"),
        (np.array([[["a", "b"]] * 2] * 2), None, TypeError, "must be real numbers"),
        (np.zeros((2, 2, 2)), [[0, 1], [0, 1]], ValueError, r"extent must have shape \(3, 2\)"),
        (np.zeros((2, 2, 2)), [[0, 1], [1, 1], [0, 1]], ValueError, "extent along y is empty"),
        (np.zeros((2, 2, 2)), [[0, 1], [0, 1], [2, 1]], ValueError, "extent along z is inverted"),
        (np.zeros((2, 2, 2)), [[0, np.inf], [0, 1], [0, 1]], ValueError, "extent must be finite"),
        (np.zeros((2, 2, 2)), "cube", TypeError, "extent must be 3 pairs"),
    ],
)
def test_rejects_bad_input(data, extent, error, message):
    with pytest.raises(error, match=message):
        Volume(data, extent)


def naive_block_range(data, block, margin, reduce):
    """Reference: reduce over each block's index box, directly."""
    nz, ny, nx = data.shape
    counts = [-(-(n - 1) // block) for n in data.shape]
    out = np.empty(counts)
    for bz in range(counts[0]):
        for by in range(counts[1]):
            for bx in range(counts[2]):
                sl = tuple(
                    slice(max(0, b * block - margin), min(n, (b + 1) * block + margin + 1))
                    for b, n in zip((bz, by, bx), (nz, ny, nx), strict=True)
                )
                out[bz, by, bx] = reduce(data[sl])
    return out


@settings(max_examples=25)
@given(
    data=hnp.arrays(np.float64, hnp.array_shapes(min_dims=3, max_dims=3, min_side=2,
                                                 max_side=11),
                    elements=st.floats(-10, 10)),
    block=st.integers(1, 5),
    margin=st.integers(0, 2),
)
def test_pyramid_matches_naive(data, block, margin):
    pyr = Volume(data).minmax_pyramid(block, margin=margin)
    np.testing.assert_array_equal(pyr.minimum[0], naive_block_range(data, block, margin, np.min))
    np.testing.assert_array_equal(pyr.maximum[0], naive_block_range(data, block, margin, np.max))
    # Each coarser level bounds the level below; the top is one block holding the global range.
    for level in range(1, pyr.levels):
        lo, hi = pyr.minimum[level], pyr.maximum[level]
        fine_lo, fine_hi = pyr.minimum[level - 1], pyr.maximum[level - 1]
        for idx in np.ndindex(fine_lo.shape):
            parent = tuple(i // 2 for i in idx)
            assert lo[parent] <= fine_lo[idx] and hi[parent] >= fine_hi[idx]
    assert pyr.minimum[-1].shape == (1, 1, 1)
    assert pyr.minimum[-1].item() == data.min() and pyr.maximum[-1].item() == data.max()


def test_pyramid_is_cached_and_validated():
    vol = Volume(np.zeros((5, 5, 5)))
    assert vol.minmax_pyramid(2) is vol.minmax_pyramid(2)
    assert vol.minmax_pyramid(2).cells_per_block(1) == 4
    with pytest.raises(ValueError, match="block must be an integer >= 1"):
        vol.minmax_pyramid(0)
    with pytest.raises(ValueError, match="margin must be an integer >= 0"):
        vol.minmax_pyramid(4, margin=-1)


def test_repr():
    assert repr(Volume(np.zeros((2, 3, 4)))) == (
        "Volume(shape=(2, 3, 4), dtype=float64, extent=[[-1, 1], [-0.666667, 0.666667], "
        "[-0.333333, 0.333333]])"
    )


def test_pyvista_round_trip_keeps_samples_and_extent():
    """Volume -> pyvista.ImageData -> Volume is exact, for an anisotropic, offset volume."""
    pytest.importorskip("pyvista")
    data = np.random.default_rng(4).uniform(size=(3, 5, 7))
    vol = Volume(data, extent=[[-2.0, 1.0], [0.5, 1.5], [10.0, 10.2]])
    back = Volume.from_pyvista(vol.to_pyvista("density"), scalars="density")
    np.testing.assert_array_equal(back.data, vol.data)
    np.testing.assert_allclose(back.extent, vol.extent, rtol=1e-15)


def test_from_pyvista_refuses_what_it_cannot_read():
    pv = pytest.importorskip("pyvista")
    with pytest.raises(TypeError, match="grid must be a pyvista.ImageData"):
        Volume.from_pyvista(np.zeros((3, 3, 3)))
    grid = pv.ImageData(dimensions=(3, 3, 3))
    grid.point_data["a"] = np.zeros(27)
    grid.point_data["b"] = np.ones(27)
    with pytest.raises(ValueError, match="scalars 'c' is not a point array"):
        Volume.from_pyvista(grid, scalars="c")
