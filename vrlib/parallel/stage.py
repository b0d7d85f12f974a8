"""Failure in a distributed frame: a rank that raises ends the frame on every rank.

A frame runs as a sequence of stages (checking the arguments, reading bricks, rendering,
compositing, ...); at the end of each, the ranks learn whether any of them raised. (Inside a
stage whose ranks wait on each other, compositing, a failure notice also ends the waits:
:mod:`vrlib.parallel.exchange`.) The rank that raised re-raises
its own error and the others raise :class:`RankFailed` naming it, so ``mpiexec`` returns within
seconds instead of hanging in the next collective call.
"""

from __future__ import annotations

__all__ = ["RankFailed", "Stage"]


class RankFailed(RuntimeError):
    """Another rank raised during a distributed render.

    Examples
    --------
    >>> error = RankFailed(2, "reading its bricks", "OSError: disk gone")
    >>> str(error), error.rank
    ('rank 2 failed while reading its bricks: OSError: disk gone', 2)
    """

    def __init__(self, rank, stage, message):
        super().__init__(f"rank {rank} failed while {stage}: {message}")
        self.rank = rank
        self.stage = stage
        self.message = message


class Stage:
    """Ends a stage on every rank together: if any rank raised inside it, the rank that
    raised re-raises its own error and the others raise :class:`RankFailed` naming it.

    Examples
    --------
    >>> from mpi4py import MPI
    >>> with Stage(MPI.COMM_SELF, "counting"):
    ...     total = 1 + 1
    >>> total
    2
    """

    def __init__(self, comm, name):
        self.comm, self.name = comm, name

    def __enter__(self):
        return self

    def __exit__(self, kind, value, traceback):
        if kind is not None and not issubclass(kind, Exception):
            return False
        report = None
        if isinstance(value, RankFailed):  # learnt from another rank: pass its report on
            report = (value.rank, value.stage, value.message)
        elif value is not None:
            report = (self.comm.Get_rank(), self.name, f"{kind.__name__}: {value}")
        failed = [r for r in self.comm.allgather(report) if r is not None]
        if not failed or value is not None:
            return False
        raise RankFailed(*min(failed))
