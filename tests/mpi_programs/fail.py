"""MPI test program: one rank fails; the frame must end on every rank.

Run as ``mpiexec -n P python fail.py FAILING_RANK [COMPOSITING ROUND WHEN] [OUTPUT]``.

Without COMPOSITING the failing rank's data source raises while reading its brick. With it
(a name, or ``radix-k:2x2`` for radix-k with factors 2, 2) the failing rank raises inside
compositing round ROUND, ``before`` posting its messages of that round or ``after`` the
round's exchange completed; WHEN ``kill`` sends the rank SIGKILL there instead. Every rank
that survives prints its outcome as one JSON line and exits 1 on error, so ``mpiexec`` returns
promptly; rank 0 writes the image to OUTPUT (when given) if the frame completes.
"""

import json
import os
import signal
import sys

from mpi4py import MPI

import data_gen
import vrlib
from vrlib.parallel import exchange, mpi


class Flaky:
    """A field that cannot produce one rank's samples (a broken disk, say)."""

    def __init__(self, failing):
        self.field = data_gen.make_field("gaussian-blob")
        self.bounds = self.field.bounds
        self.failing = failing

    def sample_region(self, shape, region, *, extent=None):
        if self.failing:
            raise OSError("cannot read the samples of this brick")
        return self.field.sample_region(shape, region, extent=extent)


def inject(failing_round, when):
    """Make this rank fail in compositing round ``failing_round``."""
    swap = exchange.Exchange.swap

    def failing_swap(self, round, sends, receives):
        if round == failing_round and when == "kill":
            os.kill(os.getpid(), signal.SIGKILL)
        if round == failing_round and when == "before":
            self.round = round
            raise RuntimeError(f"injected failure before round {round}")
        out = swap(self, round, sends, receives)
        if round == failing_round and when == "after":
            raise RuntimeError(f"injected failure after round {round}")
        return out

    exchange.Exchange.swap = failing_swap


def main(comm, failing_rank, spec=None, failing_round=0, when="before", output=None):
    failing = failing_rank == comm.Get_rank()
    if spec is not None and failing:
        inject(failing_round, when)
    view = vrlib.View.orbit(azimuth=20, elevation=10, size=32)
    source = Flaky(failing and spec is None)
    try:
        frame = mpi.render_object(comm, source, view, shape=17,
                                  compositing=spec or "binary-swap")
    except Exception as error:  # report it, then end this rank with an error status
        print(json.dumps({"rank": comm.Get_rank(), "error": type(error).__name__,
                          "message": str(error)}), flush=True)
        sys.exit(1)
    if frame.image is not None and output:
        frame.image.save(output)
    print(json.dumps({"rank": comm.Get_rank(), "error": None}), flush=True)


if __name__ == "__main__":
    args = sys.argv[1:]
    main(MPI.COMM_WORLD, int(args[0]), *(args[1:2]), *(int(a) for a in args[2:3]),
         *args[3:5])
