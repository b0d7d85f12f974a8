"""Test-suite configuration.

Hypothesis profiles: ``default`` (``make test``: bounded examples, no per-example deadline,
since a first call may include a JIT compile) and ``thorough`` (``make test-all``), chosen with
``HYPOTHESIS_PROFILE``.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

pytest_plugins = ["claim_verdicts"]  # the report's claim verdicts, from tests/claims

settings.register_profile("default", max_examples=60, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("thorough", max_examples=500, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


@pytest.fixture(scope="session")
def mpi_kernels_compiled():
    """The renderers' kernels compiled once, by one rank, before any test starts many: eight
    ranks compiling the ray caster at once on two cores take minutes, where loading it from
    numba's on-disk cache takes a second."""
    mpiexec = Path(sys.executable).parent / "mpiexec"
    program = Path(__file__).parent / "mpi_programs" / "render.py"
    config = {"field": "gaussian-blob", "n": 9, "size": 8, "views": [{"azimuth": 30}],
              "filters": ["trilinear"],
              "cases": [["direct-send", "even"], ["binary-swap", "work"], ["image", None]]}
    subprocess.run([str(mpiexec), "-n", "1", sys.executable, str(program), json.dumps(config)],
                   capture_output=True, timeout=600, check=True)


@pytest.fixture(autouse=True)
def _kernels_before_ranks(request):
    if request.node.get_closest_marker("mpi") is not None:
        request.getfixturevalue("mpi_kernels_compiled")
