"""One frame of every simulated partition class, routed on 2-D meshes and tori of 4 to 4096
nodes, with the analytic model beside each count.

The image stays 512^2 while the volume grows with the machine (``VOXELS_PER_NODE`` samples per
node, so ``N^3 = P x VOXELS_PER_NODE``). For each node count, network (mesh, torus) and class,
the messages of one frame are built from the real partition and three views
(:mod:`vrlib.parallel.traffic`), routed with dimension-order routing
(:mod:`vrlib.parallel.network`), and the busiest, mean and bisection channel loads are
recorded, averaged over the views. Power laws ``load ~ P^e`` are fitted per class. Writes
``build/results/ch06_parallel/network.json``.
"""

import math
import time

import numpy as np

from chapters.common import by_profile, progress, result_path, write_json
from vrlib import View
from vrlib.parallel import decompose, model, network, traffic
from vrlib.parallel.composite import COMPOSITORS

NODES = by_profile([4, 16, 64, 256, 1024, 4096], [4, 16, 64, 256, 1024, 4096])
VOXELS_PER_NODE = by_profile(32**3, 64**3)
WIDTH = 512
PIXEL_BYTES = 4     # 8-bit RGBA, the thesis's era
VOXEL_BYTES = 1     # 8-bit samples
RADIUS = 2.0        # a cubic filter's reach, in samples
INTERLEAVE = 8      # bricks per node for the interleaved object partition
TURN = 2.0          # degrees per frame for the dynamic image partition
VIEWS = [(30.0, 20.0), (-65.0, 40.0), (110.0, -10.0)]
CLASSES = {
    "object slabs": "object / slabs / contiguous / static, direct send",
    "object shafts": "object / shafts / contiguous / static, direct send",
    "object blocks": "object / blocks / contiguous / static, direct send",
    "object blocks interleaved": f"object / blocks / interleaved (k={INTERLEAVE}) / static, "
                                 "direct send",
    "object blocks binary swap": "object / blocks / contiguous / static, binary swap "
                                 "(bounding rectangles)",
    "binary swap full screen": "object / blocks, binary swap of full-screen images",
    "image static": "image / tiles / contiguous / static (voxels to tiles)",
    "image dynamic": f"image / tiles / contiguous / dynamic ({TURN:g} degrees per frame)",
}


def frame(name, nodes, n, angles, tiles):
    """Messages of one frame seen from ``angles`` (azimuth, elevation) and the model's total
    bytes (Cauchy and view-exact)."""
    view = View.orbit(azimuth=angles[0], elevation=angles[1], size=WIDTH)
    origin = np.array([-1.0, -1.0, -1.0])
    spacing = np.full(3, 2.0 / (n - 1))
    cells = (n - 1,) * 3
    pixel = view.pixel_size
    if name in ("object slabs", "object shafts", "object blocks", "object blocks interleaved"):
        shape = name.split()[1]
        parts = nodes * (INTERLEAVE if name.endswith("interleaved") else 1)
        grid = decompose.grid_shape(parts, shape)
        tree = decompose.split(cells, parts, grid=grid)
        owners = decompose.interleaved_owners(parts, nodes)
        msgs = COMPOSITORS["direct-send"].messages(tree, owners, tiles, view, origin, spacing,
                                                   bytes_per_pixel=PIXEL_BYTES)
        cauchy = model.object_frame(grid, side=2.0, pixel=pixel, bytes_per_pixel=PIXEL_BYTES)
        exact = model.object_frame(grid, side=2.0, pixel=pixel, bytes_per_pixel=PIXEL_BYTES,
                                   view=view)
        return msgs, cauchy[1], exact[1]
    if name in ("object blocks binary swap", "binary swap full screen"):
        tree = decompose.split(cells, nodes)
        msgs = COMPOSITORS["binary-swap"].messages(tree, np.arange(nodes), tiles, view, origin,
                                                   spacing, bytes_per_pixel=PIXEL_BYTES,
                                                   bounded=name.startswith("object"))
        classic = model.binary_swap_frame(nodes, WIDTH, WIDTH, bytes_per_pixel=PIXEL_BYTES)[1]
        return msgs, classic, classic
    tile = WIDTH / math.sqrt(nodes)
    if name == "image static":
        tree = decompose.split(cells, nodes)
        msgs = traffic.image_static(tree, np.arange(nodes), tiles, view, (n,) * 3, origin,
                                    spacing, radius=RADIUS, bytes_per_voxel=VOXEL_BYTES)
        reach = RADIUS * float(np.linalg.norm(spacing)) / pixel
        total = model.image_static_frame(nodes, n**3, tile=tile, reach=reach,
                                         bytes_per_voxel=VOXEL_BYTES)[1]
        return msgs, total, total
    after = View.orbit(azimuth=angles[0] + TURN, elevation=angles[1], size=WIDTH)
    msgs = traffic.image_dynamic(tiles, view, after, (n,) * 3, origin, spacing,
                                 bytes_per_voxel=VOXEL_BYTES)
    total = model.image_dynamic_frame(nodes, n**3, dtheta=math.radians(TURN), depth=2.0,
                                      tile_width=tile, pixel=pixel,
                                      bytes_per_voxel=VOXEL_BYTES)[1]
    return msgs, total, total


def fit(nodes, values):
    """Exponent ``e`` of ``values ~ nodes^e`` (least squares in log-log)."""
    nodes, values = np.asarray(nodes, float), np.asarray(values, float)
    keep = values > 0
    if keep.sum() < 2:
        return None
    return float(np.polyfit(np.log(nodes[keep]), np.log(values[keep]), 1)[0])


def main():
    rows = []
    jobs = [(p, name) for p in NODES for name in CLASSES]
    for nodes, name in progress(jobs, "frames"):
        n = round((nodes * VOXELS_PER_NODE) ** (1.0 / 3.0)) + 1
        if name == "object slabs" and nodes > n - 1:
            continue  # fewer slices than nodes: slabs cannot be cut
        tiles = decompose.screen_tiles(WIDTH, WIDTH, nodes)
        for torus in (False, True):
            net = network.Network.square(nodes, torus=torus)
            sums = {"total": 0.0, "max": 0.0, "mean": 0.0, "bisection": 0.0, "cauchy": 0.0,
                    "exact": 0.0, "model_mean": 0.0, "model_bisection": 0.0,
                    "max_sent": 0.0, "seconds": 0.0}
            for angles in VIEWS:
                start = time.perf_counter()
                msgs, cauchy, exact = frame(name, nodes, n, angles, tiles)
                load = net.route(msgs.src, msgs.dst, msgs.bytes)
                sums["seconds"] += time.perf_counter() - start
                predicted = model.channel_loads(msgs.total, nodes, torus=torus)
                for key, value in (("total", msgs.total), ("max", load.max),
                                   ("mean", load.mean), ("bisection", load.bisection()),
                                   ("cauchy", cauchy), ("exact", exact),
                                   ("model_mean", predicted["mean"]),
                                   ("model_bisection", predicted["bisection"]),
                                   ("max_sent", float(msgs.sent_per_node(nodes).max()))):
                    sums[key] += value / len(VIEWS)
            sums["seconds"] *= len(VIEWS)  # a total, not a mean
            rows.append({"class": name, "nodes": nodes, "N": n, "torus": torus, **sums})
    exponents = {}
    for name in CLASSES:
        for torus in (False, True):
            sel = [r for r in rows if r["class"] == name and r["torus"] == torus]
            key = f"{name} ({'torus' if torus else 'mesh'})"
            exponents[key] = {stat: fit([r["nodes"] for r in sel], [r[stat] for r in sel])
                              for stat in ("total", "max", "mean", "bisection")}
            exponents[key]["range"] = [sel[0]["nodes"], sel[-1]["nodes"]]
    slowest = max(r["seconds"] for r in rows) / len(VIEWS)
    largest = [r for r in rows if r["nodes"] == max(NODES) and not r["torus"]]
    lowest = min(largest, key=lambda r: r["max"])["class"]
    timing = {r["class"]: r["seconds"] / len(VIEWS) for r in largest}

    def total(name, nodes):
        return next(r["total"] for r in rows if r["class"] == name and r["nodes"] == nodes
                    and not r["torus"])

    crossover = next((p for p in NODES if total("image static", p) > total("object blocks", p)),
                     None)
    interleave_ratio = total("object blocks interleaved", 64) / total("object blocks", 64)
    write_json(result_path(__file__, "network.json"), {
        "width": WIDTH, "voxels_per_node": VOXELS_PER_NODE, "pixel_bytes": PIXEL_BYTES,
        "voxel_bytes": VOXEL_BYTES, "radius": RADIUS, "interleave": INTERLEAVE, "turn": TURN,
        "views": VIEWS, "classes": CLASSES, "rows": rows, "exponents": exponents,
        "slowest_frame_seconds": slowest, "seconds_at_largest": timing,
        "lowest_busiest_at_largest": lowest, "image_static_exceeds_blocks_at": crossover,
        "interleave_ratio": interleave_ratio,
        "largest": max(NODES),
    })


if __name__ == "__main__":
    main()
