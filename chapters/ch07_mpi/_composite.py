"""MPI program of chapter 7: time compositing alone against the image size.

Run as ``mpiexec -n P python -m chapters.ch07_mpi._composite CONFIG_JSON``. CONFIG: ``sizes``
(image widths), ``n`` (samples per axis of the volume the bricks cut), ``orbit``,
``compositors`` (names, or ``radix-k:AxB``) and ``repeats``. Each rank holds the local image
its brick would draw: its projected bounding rectangle (the same rectangles the renderer and
the simulation send), filled with a half-transparent colour, so the time is the compositor's
alone, with the real messages' sizes. Rank 0 prints one JSON line: per size and compositor
the median, least and largest seconds over the repeats and the bytes each rank sent.
"""

import json
import sys
import time

import numpy as np
from mpi4py import MPI

from vrlib import View
from vrlib.parallel.composite import compositor
from vrlib.parallel.exchange import Exchange
from vrlib.parallel.traffic import footprint_rect


def main(comm, config):
    rank, size = comm.Get_rank(), comm.Get_size()
    n = config["n"]
    origin, spacing = np.array([-1.0, -1.0, -1.0]), np.full(3, 2.0 / (n - 1))
    out = []
    for width in config["sizes"]:
        view = View.orbit(size=width, **config["orbit"])
        for spec in config["compositors"]:
            comp = compositor(spec)
            tree = comp.split((n - 1,) * 3, size)
            order = tree.order(view, origin, spacing)
            brick = tree.bricks[rank]
            rect = footprint_rect(view, *brick.world_box(origin, spacing))
            local = np.zeros((width, width, 4))
            local[rect[0]:rect[1], rect[2]:rect[3]] = (0.3, 0.2, 0.1, 0.5)
            seconds, sent = [], None
            for _ in range(config["repeats"]):
                held = [(brick, local.copy())]
                sent = {"composite": 0}
                comm.Barrier()
                start = time.perf_counter()
                with Exchange(comm, comp.name, sent) as exchange:
                    comp.composite(exchange, held, tree, np.arange(size), order, view)
                seconds.append(comm.allreduce(time.perf_counter() - start, op=MPI.MAX))
            sent = comm.gather(sent["composite"], root=0)
            if rank == 0:
                out.append({"width": width, "compositing": spec,
                            "seconds": float(np.median(seconds)),
                            "least": float(min(seconds)), "most": float(max(seconds)),
                            "bytes": sent})
    if rank == 0:
        print(json.dumps({"size": size, "cases": out}))


if __name__ == "__main__":
    main(MPI.COMM_WORLD, json.loads(sys.argv[1]))
