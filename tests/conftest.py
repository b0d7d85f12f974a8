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

# The ray caster's quick starts (a one-off small render takes its own small kernel
# while the one with them is not compiled: vrlib.raycast.QUICK_START_SAMPLES) off, here and
# in the processes the tests start: the suite's renders would otherwise compile both kernels
# of most kinds. tests/test_raycast.py checks the quick start's image against the packets'.
os.environ.setdefault("VRLIB_QUICK_START", "0")

settings.register_profile("default", max_examples=60, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("thorough", max_examples=500, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


#: A session of at least this many tests is a full run, worth compiling kernels beside.
_FULL_RUN = 300


def pytest_collection_finish(session):
    """Compile the renderers' kernels in a second process while a full session runs
    (``tests/warm_kernels.py`` says why); not when numba's JIT is off."""
    if len(session.items) < _FULL_RUN or os.environ.get("NUMBA_DISABLE_JIT") == "1":
        return
    if os.environ.get("PYTEST_XDIST_WORKER", "gw0") != "gw0":
        return  # under xdist every worker collects the session: one compiling beside is enough
    session.config.warm_kernels = subprocess.Popen(
        [sys.executable, str(Path(__file__).parent / "warm_kernels.py")],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def pytest_sessionfinish(session):
    warm = getattr(session.config, "warm_kernels", None)
    if warm is not None and warm.poll() is None:
        warm.terminate()
        warm.wait(timeout=30)


@pytest.fixture(autouse=True, scope="session")
def no_cost_model(tmp_path_factory):
    """The tests' cost model file (``VRLIB_COST_MODEL``): none, unless a test writes one
    there or points the variable elsewhere. The user's own, fitted by ``vrlib bench``, would
    make ``method="auto"`` choose by this machine's timings, and ``vrlib bench`` in a test
    would overwrite it."""
    path = tmp_path_factory.mktemp("cost") / "cost.json"
    held = os.environ.get("VRLIB_COST_MODEL")
    os.environ["VRLIB_COST_MODEL"] = str(path)
    yield path
    path.unlink(missing_ok=True)
    if held is None:
        os.environ.pop("VRLIB_COST_MODEL", None)
    else:
        os.environ["VRLIB_COST_MODEL"] = held


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
