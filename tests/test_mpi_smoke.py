"""Real MPI under the environment's own mpiexec (the MPICH wheel in .venv)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

PROGRAM = Path(__file__).parent / "mpi_programs" / "exchange.py"
MPIEXEC = Path(sys.executable).parent / "mpiexec"


@pytest.mark.mpi
@pytest.mark.parametrize("ranks", [2, 4])
def test_ranks_exchange_an_image_sized_buffer(ranks):
    """Each rank receives its ring neighbour's 512 x 512 RGBA float64 image intact."""
    assert MPIEXEC.exists(), f"mpiexec missing from the environment: {MPIEXEC}"
    done = subprocess.run(
        [str(MPIEXEC), "-n", str(ranks), sys.executable, str(PROGRAM), "512", "512"],
        capture_output=True, text=True, timeout=120, env=os.environ.copy(), check=False,
    )
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report["size"] == ranks
    assert "MPICH" in report["library"]
    for entry in report["ranks"]:
        assert entry["got"] == (entry["rank"] - 1) % ranks
        assert entry["uniform"]
        assert entry["bytes"] == 512 * 512 * 4 * 8
