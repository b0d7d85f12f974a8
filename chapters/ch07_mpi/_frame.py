"""MPI program of chapter 7: render distributed frames and report from rank 0.

Run as ``mpiexec -n P python -m chapters.ch07_mpi._frame CONFIG_JSON``. CONFIG: ``field`` and
``params`` (data_gen) with ``n`` (samples per axis), or ``file`` (a volume file each rank reads
its brick of); ``size`` (image); ``orbits`` (a list of View.orbit keywords); ``threshold`` and
``scale`` of a ramp transfer function (transparent below the threshold); ``cases``
(``[compositing, balance]``: a compositor name or ``radix-k:AxB`` for radix-k with those
factors, or ``["image", null]`` / ``["image-interleaved", null]``); ``repeats`` (every time is
kept; the frame reported is the last) and ``check`` (compare with the serial render on rank
0); ``save``: a path where rank 0 writes the last frame's RGBA (.npy). With ``memory`` each
rank first renders a small field (so that the kernels are loaded),
then resets its peak resident memory (Linux's ``/proc/self/clear_refs``) and reports its
resident memory before the frames (``resident``) and its peak during them (``peak``). Prints
one JSON line.
"""

import json
import sys
import time

import numpy as np
from mpi4py import MPI

import data_gen
import vrlib
from vrlib.parallel import mpi


def status(key):
    """A memory figure of this process from /proc/self/status (VmRSS, VmHWM), bytes."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024
    raise KeyError(key)


def reset_peak():
    """Start measuring the peak resident memory afresh (Linux 4.0 and later)."""
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")


def ramp(threshold, scale):
    """Opacity density 0 below ``threshold``, rising linearly to ``scale`` at 1."""
    values = np.linspace(0.0, 1.0, 257)
    return vrlib.LookupTransfer(scale * np.clip((values - threshold) / (1 - threshold), 0, 1))


def render(comm, source, shape, view, transfer, compositing, balance):
    if compositing.startswith("image"):
        layout = "interleaved" if compositing == "image-interleaved" else "contiguous"
        return mpi.render_image(comm, source, view, shape=shape, transfer=transfer,
                                layout=layout)
    return mpi.render_object(comm, source, view, shape=shape, transfer=transfer,
                             compositing=compositing, balance=balance)


def main(comm, config):
    if "file" in config:
        source, shape = config["file"], None
    else:
        source = data_gen.make_field(config["field"], **config.get("params", {}))
        shape = config["n"]
    transfer = ramp(config["threshold"], config["scale"])
    memory = None
    if config.get("memory"):
        small = data_gen.make_field("gaussian-blob")
        for compositing, balance in config["cases"]:
            render(comm, small, 17, vrlib.View.orbit(size=16), transfer, compositing, balance)
        comm.Barrier()
        reset_peak()
        memory = {"resident": status("VmRSS")}
    out = []
    for orbit in config["orbits"]:
        view = vrlib.View.orbit(size=config["size"], **orbit)
        serial = None
        if config.get("check") and comm.Get_rank() == 0:
            volume = data_gen.load(source) if shape is None else source.sample(shape)
            serial = vrlib.render(volume, view, transfer=transfer, early_termination=1.0).rgba
            del volume
        for compositing, balance in config["cases"]:
            seconds = []
            for _ in range(config.get("repeats", 1)):
                comm.Barrier()
                start = time.perf_counter()
                frame = render(comm, source, shape, view, transfer, compositing, balance)
                seconds.append(comm.allreduce(time.perf_counter() - start, op=MPI.MAX))
            if comm.Get_rank() == 0:
                out.append({"orbit": orbit, "compositing": compositing, "balance": balance,
                            "seconds": float(np.median(seconds)), "all_seconds": seconds,
                            "ranks": frame.ranks,
                            "difference": None if serial is None else
                            float(np.abs(frame.image.rgba - serial).max())})
    if memory is not None:
        memory["peak"] = status("VmHWM")
    if config.get("save") and comm.Get_rank() == 0:
        np.save(config["save"], frame.image.rgba)
    memory = comm.gather(memory, root=0)
    if comm.Get_rank() == 0:
        print(json.dumps({"size": comm.Get_size(), "memory": memory, "cases": out}))


if __name__ == "__main__":
    main(MPI.COMM_WORLD, json.loads(sys.argv[1]))
