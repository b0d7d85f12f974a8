"""MPI test program: distributed renders against the serial render; rank 0 reports.

Run as ``mpiexec -n P python render.py CONFIG_JSON``. CONFIG holds ``field`` (a data_gen name),
``params``, ``n`` (samples per axis) or ``file`` (a .npy or .nii file read brick by brick
instead), ``size`` (image), ``views`` (orbit keyword dicts), ``filters`` (every view with
each, unless a view names its own ``filter``) and ``cases`` (``[compositing, balance]`` pairs,
or ``["image", null]``, ``["image-interleaved", null]`` for 8-pixel tiles dealt round-robin;
``radix-k:2x3`` is radix-k with factors 2, 3); the transfer function
is ``Glow(glow)``, or with ``threshold`` a ramp that is transparent below it; ``shade`` adds
Phong shading and ``gradient_opacity`` (``[magnitudes, factors]``) a gradient ramp;
``step``, ``segment_ends`` and ``classification`` are passed to every render.
Rank 0 prints one JSON line: per case, the largest difference from the serial render, the
bytes each rank sent per phase, the rectangles it sent while compositing, the samples and the
peak resident memory per rank.
"""

import json
import sys

import numpy as np
from mpi4py import MPI

import data_gen
import vrlib
from vrlib.parallel import mpi


def main(comm, config):
    field = data_gen.make_field(config["field"], **config.get("params", {}))
    extras = {"shading": vrlib.Phong(specular=0.3) if config.get("shade") else None,
              "gradient_opacity": (vrlib.GradientOpacity(*config["gradient_opacity"])
                                   if "gradient_opacity" in config else None)}
    transfer = vrlib.Glow(config.get("glow", 2.0), **extras)
    if "threshold" in config:
        values = np.linspace(0.0, 1.0, 257)
        t = config["threshold"]
        transfer = vrlib.LookupTransfer(8.0 * np.clip((values - t) / (1 - t), 0.0, 1.0),
                                        **extras)
    # The source: the field sampled on n^3, or a file (``file``) read brick by brick.
    source, shape = field, config.get("n")
    if "file" in config:
        source, shape = config["file"], None
    options = {key: config[key] for key in ("step", "segment_ends", "classification")
               if key in config}
    results = []
    for orbit in config["views"]:
        orbit = dict(orbit)
        filters = [orbit.pop("filter")] if "filter" in orbit else config["filters"]
        view = vrlib.View.orbit(size=config["size"], **orbit)
        for filt in filters:
            serial = None
            if comm.Get_rank() == 0:
                volume = field.sample(shape) if shape else data_gen.load(source)
                serial = vrlib.render(volume, view, filter=filt,
                                      transfer=transfer, early_termination=1.0,
                                      **options).rgba
            for compositing, balance in config["cases"]:
                if compositing.startswith("image"):
                    layout = "interleaved" if compositing == "image-interleaved" else \
                        "contiguous"
                    frame = mpi.render_image(comm, source, view, shape=shape, filter=filt,
                                             transfer=transfer, layout=layout, tile=8,
                                             **options)
                else:
                    frame = mpi.render_object(comm, source, view, shape=shape,
                                              filter=filt, transfer=transfer,
                                              compositing=compositing,
                                              balance=balance, **options)
                if comm.Get_rank() == 0:
                    results.append({
                        "view": orbit, "filter": filt, "compositing": compositing,
                        "balance": balance,
                        "difference": float(np.abs(frame.image.rgba - serial).max()),
                        "alpha_max": float(serial[..., 3].max()),
                        "bytes": [r["bytes"] for r in frame.ranks],
                        "messages": [r.get("messages", []) for r in frame.ranks],
                        "samples": [r["samples"] for r in frame.ranks],
                        "peak_rss": [r["peak_rss"] for r in frame.ranks],
                    })
    if comm.Get_rank() == 0:
        print(json.dumps({"size": comm.Get_size(), "results": results}))


if __name__ == "__main__":
    main(MPI.COMM_WORLD, json.loads(sys.argv[1]))
