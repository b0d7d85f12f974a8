"""MPI smoke program: ranks pass an image-sized buffer around a ring; rank 0 reports.

Run as ``mpiexec -n P python exchange.py HEIGHT WIDTH``. Each rank fills a premultiplied-RGBA
float64 image with its rank number, sends it to the next rank and receives from the previous
one; rank 0 gathers what every rank received and prints it as one JSON line.
"""

import json
import sys

import numpy as np
from mpi4py import MPI


def main(comm, height, width):
    rank, size = comm.Get_rank(), comm.Get_size()
    mine = np.full((height, width, 4), float(rank))
    received = np.empty_like(mine)
    comm.Sendrecv(mine, dest=(rank + 1) % size, recvbuf=received, source=(rank - 1) % size)
    uniform = bool(np.all(received == received[0, 0, 0]))
    report = comm.gather({"rank": rank, "got": float(received[0, 0, 0]), "uniform": uniform,
                          "bytes": int(received.nbytes)}, root=0)
    if rank == 0:
        print(json.dumps({"size": size, "library": MPI.Get_library_version().split("\n")[0],
                          "ranks": report}))


if __name__ == "__main__":
    main(MPI.COMM_WORLD, int(sys.argv[1]), int(sys.argv[2]))
