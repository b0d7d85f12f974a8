"""Speed of the foundation's building blocks (``make bench``).

Each group compares variants measured in the same run; read the table's ratios, not the
absolute times, which depend on the machine.
"""

import numpy as np
import pytest

import data_gen
from vrlib import Volume, make_filter
from vrlib._kernels import filters as kernels
from vrlib._kernels._jit import jit

OFFSETS = np.random.default_rng(0).uniform(-2.5, 2.5, 1_000_000)


@jit
def _weights(kind, p0, p1, p2, x, out):
    for i in range(x.shape[0]):
        out[i] = kernels.weight(kind, p0, p1, p2, x[i])


@pytest.mark.parametrize("name", ["pyramid", "gaussian", "catmull-rom"])
@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_filter_weights(benchmark, name, backend):
    """10^6 filter weights: NumPy vectorised vs the numba kernel function."""
    benchmark.group = f"filter weights ({name})"
    f = make_filter(name)
    if backend == "numpy":
        benchmark(f, OFFSETS)
    else:
        out = np.empty_like(OFFSETS)
        _weights(*f.code, OFFSETS, out)  # compile outside the timing
        benchmark(_weights, *f.code, OFFSETS, out)


@pytest.mark.parametrize("n", [64, 128])
def test_sample_marschner_lobb(benchmark, n):
    benchmark.group = "sample an analytic field"
    field = data_gen.make_field("marschner-lobb")
    benchmark(field.sample, n)


@pytest.mark.parametrize("margin", [0, 1])
def test_minmax_pyramid_256(benchmark, margin):
    benchmark.group = "min-max pyramid of 256^3"
    data = data_gen.make_field("random-blobs", count=16, seed=0).sample(256).data
    benchmark(lambda: Volume(data, copy=False).minmax_pyramid(8, margin=margin))
