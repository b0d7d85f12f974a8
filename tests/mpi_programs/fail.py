"""MPI test program: one rank's data source raises; the frame must end on every rank.

Run as ``mpiexec -n P python fail.py FAILING_RANK``. The field raises when asked for the
brick of ``FAILING_RANK``; every rank prints its outcome as one JSON line and exits 1 on
error, so ``mpiexec`` returns promptly.
"""

import json
import sys

from mpi4py import MPI

import data_gen
import vrlib
from vrlib.parallel import mpi


class Flaky:
    """A field that cannot produce one rank's samples (a broken disk, say)."""

    def __init__(self, failing_rank, comm):
        self.field = data_gen.make_field("gaussian-blob")
        self.bounds = self.field.bounds
        self.failing = failing_rank == comm.Get_rank()

    def sample_region(self, shape, region, *, extent=None):
        if self.failing:
            raise OSError("cannot read the samples of this brick")
        return self.field.sample_region(shape, region, extent=extent)


def main(comm, failing_rank):
    view = vrlib.View.orbit(azimuth=20, elevation=10, size=32)
    try:
        mpi.render_object(comm, Flaky(failing_rank, comm), view, shape=17)
    except Exception as error:  # report it, then end this rank with an error status
        print(json.dumps({"rank": comm.Get_rank(), "error": type(error).__name__,
                          "message": str(error)}), flush=True)
        sys.exit(1)
    print(json.dumps({"rank": comm.Get_rank(), "error": None}), flush=True)


if __name__ == "__main__":
    main(MPI.COMM_WORLD, int(sys.argv[1]))
