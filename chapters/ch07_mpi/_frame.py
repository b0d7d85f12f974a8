"""MPI program of chapter 7: render distributed frames and report from rank 0.

Run as ``mpiexec -n P python -m chapters.ch07_mpi._frame CONFIG_JSON``. CONFIG: ``field`` and
``params`` (data_gen), ``n`` (samples per axis), ``size`` (image), ``orbit`` (View.orbit
keywords), ``threshold`` and ``scale`` of a ramp transfer function (transparent below the
threshold), ``cases`` (``[compositing, balance]``, or ``["image", null]``), ``repeats`` (best
time kept) and ``check`` (compare with the serial render on rank 0). Prints one JSON line.
"""

import json
import sys
import time

import numpy as np
from mpi4py import MPI

import data_gen
import vrlib
from vrlib.parallel import mpi


def ramp(threshold, scale):
    """Opacity density 0 below ``threshold``, rising linearly to ``scale`` at 1."""
    values = np.linspace(0.0, 1.0, 257)
    return vrlib.LookupTransfer(scale * np.clip((values - threshold) / (1 - threshold), 0, 1))


def main(comm, config):
    field = data_gen.make_field(config["field"], **config.get("params", {}))
    transfer = ramp(config["threshold"], config["scale"])
    view = vrlib.View.orbit(size=config["size"], **config["orbit"])
    serial = None
    if config.get("check") and comm.Get_rank() == 0:
        serial = vrlib.render(field.sample(config["n"]), view, transfer=transfer,
                              early_termination=1.0).rgba
    out = []
    for compositing, balance in config["cases"]:
        best = None
        for _ in range(config.get("repeats", 1)):
            comm.Barrier()
            start = time.perf_counter()
            if compositing == "image":
                frame = mpi.render_image(comm, field, view, shape=config["n"],
                                         transfer=transfer)
            else:
                frame = mpi.render_object(comm, field, view, shape=config["n"],
                                          transfer=transfer, compositing=compositing,
                                          balance=balance)
            seconds = comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
            if best is None or seconds < best[0]:
                best = (seconds, frame)
        seconds, frame = best
        if comm.Get_rank() == 0:
            out.append({"compositing": compositing, "balance": balance, "seconds": seconds,
                        "ranks": frame.ranks,
                        "difference": None if serial is None else
                        float(np.abs(frame.image.rgba - serial).max())})
    if comm.Get_rank() == 0:
        print(json.dumps({"size": comm.Get_size(), "cases": out}))


if __name__ == "__main__":
    main(MPI.COMM_WORLD, json.loads(sys.argv[1]))
