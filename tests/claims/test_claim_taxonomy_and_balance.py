"""Claims 4 and 5 (thesis abstract and chapter 1): "a taxonomy of task/data partitions (image
vs object; slabs, shafts, blocks; contiguous vs interleaved; static vs dynamic) with three
optimal algorithms and their communication costs", and "a new load-balancing method for
object partitions".

Which three algorithms the thesis found optimal, and its balancing method, are not known (only
its Chapter 1 survives). What is checked: every class of the taxonomy is a partition vrlib can
build, with its communication derived and (for the simulated classes) counted, and the costs
order as derived; and vrlib's own method, the work-sized k-d split (explained in chapter ch07),
balances a sparse scene far better than equal bricks or interleaving, serially and under MPI.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import data_gen
from vrlib import LookupTransfer, View
from vrlib.parallel import decompose, model, mpi, taxonomy
from vrlib.parallel.composite import COMPOSITORS

RAMP = LookupTransfer(8.0 * np.clip((np.linspace(0, 1, 257) - 0.25) / 0.75, 0.0, 1.0))
PROGRAM = Path(__file__).parent.parent / "mpi_programs" / "render.py"
MPIEXEC = Path(sys.executable).parent / "mpiexec"


@pytest.mark.claim(4, "supports")
def test_every_class_of_the_taxonomy_can_be_built():
    """Each class maps to a decomposition: object shapes to k-d trees of bricks (interleaved:
    k bricks per node dealt round-robin), image classes to screen tiles."""
    nodes = 8
    for p in taxonomy.TAXONOMY:
        what, grows = taxonomy.communication(p)
        assert what and grows
        if p.space == "object":
            parts = nodes * (4 if p.layout == "interleaved" else 1)
            tree = decompose.split((32, 32, 32), parts,
                                   grid=decompose.grid_shape(parts, p.shape))
            owners = decompose.interleaved_owners(parts, nodes)
            assert sorted(set(owners.tolist())) == list(range(nodes))
            cut = {a for b in tree.bricks for a in range(3) if b.cells[a] != 32}
            assert cut <= set(decompose.SHAPES[p.shape])
        else:
            tiles = decompose.screen_tiles(64, 64, nodes, layout=p.layout, tile=8)
            assert tiles.nodes == nodes


@pytest.mark.claim(4, "supports")
def test_object_partition_costs_order_as_derived():
    """At 64 nodes: blocks < shafts < slabs per frame, and interleaving 8 blocks per node
    multiplies the blocks' traffic by about 8^(1/3) = 2 (within 15%)."""
    n, nodes, width = 129, 64, 512
    view = View.orbit(azimuth=30, elevation=20, size=width)
    origin, spacing = np.array([-1.0, -1.0, -1.0]), np.full(3, 2.0 / (n - 1))
    tiles = decompose.screen_tiles(width, width, nodes)
    totals = {}
    for shape, per_node in (("slabs", 1), ("shafts", 1), ("blocks", 1), ("blocks", 8)):
        parts = nodes * per_node
        tree = decompose.split((n - 1,) * 3, parts, grid=decompose.grid_shape(parts, shape))
        msgs = COMPOSITORS["direct-send"].messages(
            tree, decompose.interleaved_owners(parts, nodes), tiles, view, origin, spacing)
        totals[(shape, per_node)] = msgs.total
    assert totals[("blocks", 1)] < totals[("shafts", 1)] < totals[("slabs", 1)]
    assert totals[("blocks", 8)] / totals[("blocks", 1)] == pytest.approx(2.0, rel=0.15)
    # The Cauchy model orders them the same way.
    cauchy = [model.object_frame(decompose.grid_shape(nodes, s), side=2.0, pixel=1.0)[1]
              for s in ("blocks", "shafts", "slabs")]
    assert cauchy == sorted(cauchy)


@pytest.mark.claim(4, "supports")
def test_every_row_of_the_taxonomy_is_counted_and_orders_as_derived():
    """Every class of the taxonomy, simulated for one frame on 16 nodes (dynamic object
    partitions re-cut for a moving scene, dynamic image partitions for a 2 degree turn): each
    sends something, interleaving costs more than the contiguous layout in every class (image
    tiles: every node's tiles see nearly the whole volume; object bricks: more, smaller
    fragments), and a re-cut object partition moves voxels on top of its fragments."""
    nodes, n = 16, 65
    view = View.orbit(azimuth=30, elevation=20, size=128)
    after = View.orbit(azimuth=32, elevation=20, size=128)
    field = data_gen.make_field("random-blobs", count=6, seed=7)
    work = [(field.sample(64, extent=[[-1 + s, 1 + s]] * 3).data > 0.25) + 0.01
            for s in (0.0, 0.1)]  # the scene moves along the diagonal
    totals = {}
    for p in taxonomy.TAXONOMY:
        msgs = taxonomy.frame(p, nodes, n, view, after=after, work=work, interleave=4)
        assert msgs.total > 0, p.name
        totals[(p.space, p.shape, p.layout, p.schedule)] = msgs
    for (space, shape, layout, schedule), msgs in totals.items():
        if layout == "interleaved":
            assert msgs.total > totals[(space, shape, "contiguous", schedule)].total
    # The static image partition's interleaved tiles need most of the volume on every node.
    per_node = totals[("image", "tiles", "interleaved", "static")].sent_per_node(nodes)
    assert per_node.sum() > 0.5 * (nodes - 1) * n**3 / nodes
    for shape in ("slabs", "shafts", "blocks"):
        p = taxonomy.Partition("object", shape, "contiguous", "dynamic")
        still = taxonomy.frame(p, nodes, n, view, work=[work[1], work[1]]).total
        assert totals[("object", shape, "contiguous", "dynamic")].total > still  # migration


def imbalance(work):
    work = np.asarray(work, dtype=float)
    return float(work.max() / work.mean())


@pytest.mark.claim(5, "beyond")
def test_work_sized_split_balances_a_sparse_scene_serially():
    """The serial twin of the work map: visible cells per brick, equal bricks against the
    work-sized split, on six random blobs (about 1% visible) for 8 ranks."""
    vol = data_gen.make_field("random-blobs", count=6, seed=7).sample(65)
    cells = tuple(n - 1 for n in vol.shape)
    work = mpi.visible_cells(vol.data, (0, 0, 0), (0, 0, 0), cells, vol.shape,
                             transfer=RAMP)

    def per_brick(tree):
        shares = []
        for b in tree.bricks:
            mask = np.zeros(cells)
            mask[b.lo[0]:b.hi[0], b.lo[1]:b.hi[1], b.lo[2]:b.hi[2]] = 1.0
            blocks = mask.reshape(8, 8, 8, 8, 8, 8).mean(axis=(1, 3, 5))
            shares.append(float((work * blocks).sum()))
        return shares

    even = imbalance(per_brick(decompose.split(cells, 8)))
    balanced = imbalance(per_brick(mpi.work_split(work, cells, 8)))
    assert even > 2.0
    assert balanced < 1.3


@pytest.mark.claim(5, "beyond")
@pytest.mark.mpi
@pytest.mark.slow
def test_work_sized_split_balances_ray_samples_under_mpi():
    """Under mpiexec with 8 ranks on the sparse scene: max / mean ray samples per rank is
    under 1.3 with the work-sized split, over 2 with equal bricks, and below interleaving's;
    every image equals the serial render. (Slow: 8 ranks on 2 cores take 12-20 s; the
    serial twin above checks the same split in `make test`, and `make all`'s verdicts and
    `make test-all` run this one.)"""
    config = {"field": "random-blobs", "params": {"count": 6, "seed": 7}, "n": 65, "size": 96,
              "threshold": 0.25, "filters": ["trilinear"],
              "views": [{"azimuth": 35, "elevation": 25}],
              "cases": [["direct-send", "even"], ["direct-send", "interleaved"],
                        ["direct-send", "work"]]}
    done = subprocess.run([str(MPIEXEC), "-n", "8", sys.executable, str(PROGRAM),
                           json.dumps(config)], capture_output=True, text=True, timeout=120,
                          env=os.environ.copy(), check=False)
    assert done.returncode == 0, done.stderr
    even, interleaved, work = json.loads(done.stdout.strip().splitlines()[-1])["results"]
    for r in (even, interleaved, work):
        assert r["difference"] < 1e-6
    assert imbalance(work["samples"]) < 1.3
    assert imbalance(even["samples"]) > 2.0
    assert imbalance(work["samples"]) < imbalance(interleaved["samples"])
