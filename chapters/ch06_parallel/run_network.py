"""One frame of every class of the taxonomy, routed on 2-D meshes and tori of 4 to 4096
nodes, with the analytic model beside each count.

The image stays 512^2 while the volume grows with the machine (``VOXELS_PER_NODE`` samples per
node, so ``N^3 = P x VOXELS_PER_NODE``). For each node count, network (mesh, torus) and class
(:data:`vrlib.parallel.taxonomy.TAXONOMY`, every row, plus binary swap), the messages of one
frame are built from the real partition and three views (:func:`vrlib.parallel.taxonomy.frame`,
:mod:`vrlib.parallel.traffic`), routed with dimension-order routing
(:mod:`vrlib.parallel.network`), and the busiest, mean and bisection channel loads are
recorded, averaged over the views. Dynamic object partitions re-cut their k-d tree each frame
to follow the work of a scene that moves (six random blobs, translated along the diagonal by
``SHIFT`` of the box's side per frame, work counted on a ``WORK_GRID^3`` lattice). Power laws
``load ~ P^e`` are fitted per class. Writes ``build/results/ch06_parallel/network.json``.
"""

import math
import time

import numpy as np

import data_gen
from chapters.common import by_profile, progress, result_path, write_json
from vrlib import View
from vrlib.parallel import decompose, model, network, taxonomy
from vrlib.parallel.composite import COMPOSITORS

NODES = by_profile([4, 16, 64, 256, 1024, 4096], [4, 16, 64, 256, 1024, 4096])
VOXELS_PER_NODE = by_profile(32**3, 64**3)
WIDTH = 512
PIXEL_BYTES = 4     # 8-bit RGBA, the thesis's era
VOXEL_BYTES = 1     # 8-bit samples
RADIUS = 2.0        # a cubic filter's reach, in samples
INTERLEAVE = 8      # bricks per node for interleaved object partitions
TILES_PER_NODE = 4  # square tiles per node for interleaved image partitions
TURN = 2.0          # degrees per frame for the dynamic image partitions
WORK_GRID = 256     # cells per axis of the work maps the dynamic object partitions follow
SHIFT = 0.02        # how far the scene moves per frame, as a share of the box's side
THRESHOLD = 0.25    # a cell is visible (has work) where the scene exceeds this
VIEWS = [(30.0, 20.0), (-65.0, 40.0), (110.0, -10.0)]


def short_name(p):
    """A class's name in the results: "object blocks interleaved dynamic", "image static"."""
    words = [p.space, p.shape] if p.space == "object" else [p.space, p.schedule]
    if p.layout == "interleaved":
        words.append("interleaved")
    if p.space == "object" and p.schedule == "dynamic":
        words.append("dynamic")
    return " ".join(words)


PARTITIONS = {short_name(p): p for p in taxonomy.TAXONOMY}
CLASSES = {**{name: p.name + (", direct send" if p.space == "object" else "")
              for name, p in PARTITIONS.items()},
           "object blocks binary swap": "object / blocks / contiguous / static, binary swap "
                                        "(bounding rectangles)",
           "binary swap full screen": "object / blocks, binary swap of full-screen images"}


def work_maps():
    """Work per cell of two successive frames of a moving scene: 1 where the scene is
    visible, plus the 1% floor every cell keeps (rays still cross it)."""
    field = data_gen.make_field("random-blobs", count=6, seed=7)
    half = 1.0 / WORK_GRID  # sample the cells' centres
    maps = []
    for shift in (0.0, 2.0 * SHIFT):
        extent = [[-1.0 + half + shift, 1.0 - half + shift]] * 3  # along the diagonal
        values = field.sample(WORK_GRID, extent=extent).data
        maps.append((values > THRESHOLD) + 0.01)
    return maps


def frame(name, nodes, n, angles, work):
    """Messages of one frame seen from ``angles`` (azimuth, elevation) and the model's total
    bytes (Cauchy and view-exact; None where no model is derived)."""
    view = View.orbit(azimuth=angles[0], elevation=angles[1], size=WIDTH)
    origin = np.array([-1.0, -1.0, -1.0])
    spacing = np.full(3, 2.0 / (n - 1))
    cells = (n - 1,) * 3
    pixel = view.pixel_size
    if name in ("object blocks binary swap", "binary swap full screen"):
        tree = decompose.split(cells, nodes)
        msgs = COMPOSITORS["binary-swap"].messages(tree, np.arange(nodes), None, view, origin,
                                                   spacing, bytes_per_pixel=PIXEL_BYTES,
                                                   bounded=name.startswith("object"))
        classic = model.binary_swap_frame(nodes, WIDTH, WIDTH, bytes_per_pixel=PIXEL_BYTES)[1]
        return msgs, classic, classic
    p = PARTITIONS[name]
    after = View.orbit(azimuth=angles[0] + TURN, elevation=angles[1], size=WIDTH)
    msgs = taxonomy.frame(p, nodes, n, view, after=after, work=work, interleave=INTERLEAVE,
                          tiles_per_node=TILES_PER_NODE, radius=RADIUS,
                          pixel_bytes=PIXEL_BYTES, voxel_bytes=VOXEL_BYTES)
    if p.space == "object":
        if p.layout == "interleaved" or p.schedule == "dynamic":
            return msgs, None, None
        grid = decompose.grid_shape(nodes, p.shape)
        cauchy = model.object_frame(grid, side=2.0, pixel=pixel, bytes_per_pixel=PIXEL_BYTES)
        exact = model.object_frame(grid, side=2.0, pixel=pixel, bytes_per_pixel=PIXEL_BYTES,
                                   view=view)
        return msgs, cauchy[1], exact[1]
    if p.layout == "interleaved":
        return msgs, None, None
    tile = WIDTH / math.sqrt(nodes)
    if p.schedule == "static":
        reach = RADIUS * float(np.linalg.norm(spacing)) / pixel
        total = model.image_static_frame(nodes, n**3, tile=tile, reach=reach,
                                         bytes_per_voxel=VOXEL_BYTES)[1]
        return msgs, total, total
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
    rows, skipped = [], []
    work = work_maps()
    jobs = [(p, name) for p in NODES for name in CLASSES]
    for nodes, name in progress(jobs, "frames"):
        n = round((nodes * VOXELS_PER_NODE) ** (1.0 / 3.0)) + 1
        frames = []
        try:
            for angles in VIEWS:
                start = time.perf_counter()
                frames.append((*frame(name, nodes, n, angles, work),
                               time.perf_counter() - start))
        except ValueError as error:  # e.g. fewer slices than nodes: slabs cannot be cut
            skipped.append({"class": name, "nodes": nodes, "why": str(error)})
            continue
        for torus in (False, True):
            net = network.Network.square(nodes, torus=torus)
            sums = {"total": 0.0, "max": 0.0, "mean": 0.0, "bisection": 0.0, "cauchy": 0.0,
                    "exact": 0.0, "model_mean": 0.0, "model_bisection": 0.0,
                    "max_sent": 0.0, "seconds": 0.0}
            for msgs, cauchy, exact, seconds in frames:
                start = time.perf_counter()
                load = net.route(msgs.src, msgs.dst, msgs.bytes)
                sums["seconds"] += seconds + time.perf_counter() - start
                predicted = model.channel_loads(msgs.total, nodes, torus=torus)
                for key, value in (("total", msgs.total), ("max", load.max),
                                   ("mean", load.mean), ("bisection", load.bisection()),
                                   ("cauchy", cauchy), ("exact", exact),
                                   ("model_mean", predicted["mean"]),
                                   ("model_bisection", predicted["bisection"]),
                                   ("max_sent", float(msgs.sent_per_node(nodes).max()))):
                    sums[key] = None if value is None else sums[key] + value / len(VIEWS)
            rows.append({"class": name, "nodes": nodes, "N": n, "torus": torus, **sums})
    def total(name, nodes):
        return next(r["total"] for r in rows if r["class"] == name and r["nodes"] == nodes
                    and not r["torus"])

    exponents = {}
    for name in CLASSES:
        for torus in (False, True):
            sel = [r for r in rows if r["class"] == name and r["torus"] == torus]
            key = f"{name} ({'torus' if torus else 'mesh'})"
            exponents[key] = {stat: fit([r["nodes"] for r in sel], [r[stat] for r in sel])
                              for stat in ("total", "max", "mean", "bisection")}
            exponents[key]["range"] = [sel[0]["nodes"], sel[-1]["nodes"]]
    slowest = max(r["seconds"] for r in rows) / len(VIEWS)
    # Every class counted at 64 nodes, or at the largest count below it that can cut it.
    at = 64
    per_class = {}
    for name in CLASSES:
        counts = [r["nodes"] for r in rows if r["class"] == name and r["nodes"] <= at]
        per_class[name] = {"nodes": max(counts), "total": total(name, max(counts))}
    largest = [r for r in rows if r["nodes"] == max(NODES) and not r["torus"]]
    lowest = min(largest, key=lambda r: r["max"])["class"]
    timing = {r["class"]: r["seconds"] / len(VIEWS) for r in largest}

    crossover = next((p for p in NODES if total("image static", p) > total("object blocks", p)),
                     None)
    interleave_ratio = total("object blocks interleaved", 64) / total("object blocks", 64)
    write_json(result_path(__file__, "network.json"), {
        "width": WIDTH, "voxels_per_node": VOXELS_PER_NODE, "pixel_bytes": PIXEL_BYTES,
        "voxel_bytes": VOXEL_BYTES, "radius": RADIUS, "interleave": INTERLEAVE, "turn": TURN,
        "tiles_per_node": TILES_PER_NODE, "work_grid": WORK_GRID, "shift": SHIFT,
        "threshold": THRESHOLD, "views": VIEWS, "classes": CLASSES, "rows": rows,
        "skipped": skipped, "exponents": exponents, "at": at, "per_class": per_class,
        "slowest_frame_seconds": slowest, "seconds_at_largest": timing,
        "lowest_busiest_at_largest": lowest, "image_static_exceeds_blocks_at": crossover,
        "interleave_ratio": interleave_ratio,
        "largest": max(NODES),
    })


if __name__ == "__main__":
    main()
