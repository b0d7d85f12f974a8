"""The MPI renderer on this machine: equality with the serial render, bytes sent against the
traffic model, load balance on sparse and dense scenes, and timings at 1 and 2 ranks with the
model's prediction for larger machines.

Every run starts ``mpiexec`` from the environment (the MPICH wheel) on
:mod:`chapters.ch07_mpi._frame`, with one numba thread per rank so that two ranks on the two
cores do not compete for them. Writes ``build/results/ch07_mpi/mpi.json``.
"""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import data_gen
from chapters.common import ROOT, by_profile, progress, result_path, write_json
from vrlib import View
from vrlib.parallel import decompose, traffic
from vrlib.parallel.composite import COMPOSITORS

MPIEXEC = Path(sys.executable).parent / "mpiexec"
DENSE = {"field": "marschner-lobb", "params": {}}
SPARSE = {"field": "random-blobs", "params": {"count": 6, "seed": 7}}
ORBIT = {"azimuth": 35.0, "elevation": 25.0}
RAMP = {"threshold": 0.25, "scale": 8.0}
# Every compositor with even bricks, then the other balances and the image partition.
ALL_CASES = [[name, "even"] for name in COMPOSITORS] + [
    ["direct-send", "interleaved"], ["binary-swap", "work"], ["image", None]]
EQUALITY = {"n": by_profile(49, 97), "size": by_profile(96, 192)}
BALANCE = {"n": by_profile(65, 129), "size": by_profile(128, 256), "ranks": [4, 8]}
TIMING = {"n": by_profile(129, 257), "size": by_profile(256, 512), "repeats": 3}
PREDICT = [2, 4, 8, 16, 64, 256, 1024]
PIXEL_BYTES = 32  # float64 RGBA, as the renderer sends them


def launch(ranks, config):
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    done = subprocess.run([str(MPIEXEC), "-n", str(ranks), sys.executable, "-m",
                           "chapters.ch07_mpi._frame", json.dumps(config)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=900, check=False)
    if done.returncode != 0:
        raise SystemExit(f"mpiexec -n {ranks} failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def simulated_bytes(ranks, n, size):
    """The traffic module's bytes per rank for direct send and bounded binary swap (float64
    pixels), and for the image partition (float64 voxels, the trilinear filter's reach)."""
    view = View.orbit(size=size, **ORBIT)
    origin, spacing = np.array([-1.0, -1.0, -1.0]), np.full(3, 2.0 / (n - 1))
    tree = decompose.split((n - 1,) * 3, ranks)
    tiles = decompose.screen_tiles(size, size, ranks)
    owners = np.arange(ranks)
    sent = {name: compositor.messages(tree, owners, tiles, view, origin, spacing,
                                      bytes_per_pixel=PIXEL_BYTES).sent_per_node(ranks).tolist()
            for name, compositor in COMPOSITORS.items()}
    image = traffic.image_static(tree, owners, tiles, view, (n,) * 3, origin, spacing,
                                 radius=1.0, bytes_per_voxel=8)
    return {**sent, "image": image.sent_per_node(ranks).tolist()}


def main():
    if not MPIEXEC.exists():
        raise SystemExit(f"mpiexec missing from the environment: {MPIEXEC}")
    equality = []
    for ranks in progress(range(1, 9), "ranks 1-8"):
        report = launch(ranks, {**DENSE, **RAMP, "n": EQUALITY["n"], "size": EQUALITY["size"],
                                "orbit": ORBIT, "cases": ALL_CASES, "check": True})
        equality.append({"ranks": ranks, "cases": report["cases"],
                         "simulated": simulated_bytes(ranks, EQUALITY["n"], EQUALITY["size"])})
    balance = []
    for name, field in progress([("dense", DENSE), ("sparse", SPARSE)], "balance"):
        for ranks in BALANCE["ranks"]:
            report = launch(ranks, {**field, **RAMP, "n": BALANCE["n"],
                                    "size": BALANCE["size"], "orbit": ORBIT, "repeats": 2,
                                    "cases": [["direct-send", "even"],
                                              ["direct-send", "interleaved"],
                                              ["direct-send", "work"]]})
            balance.append({"scene": name, "ranks": ranks, "cases": report["cases"]})
    timing = []
    for ranks in progress([1, 2], "timing"):
        report = launch(ranks, {**DENSE, **RAMP, "n": TIMING["n"], "size": TIMING["size"],
                                "orbit": ORBIT, "repeats": TIMING["repeats"],
                                "cases": [[name, "even"] for name in COMPOSITORS]})
        timing.append({"ranks": ranks, "cases": report["cases"]})
    prediction = predict(timing)
    write_json(result_path(__file__, "mpi.json"), {
        "equality": equality, "balance": balance, "timing": timing,
        "prediction": prediction, "summary": summarise(equality, balance, timing, prediction),
        "settings": {
            "equality": EQUALITY, "balance": BALANCE, "timing": TIMING, "orbit": ORBIT,
            "ramp": RAMP, "dense": DENSE, "sparse": SPARSE}})


def summarise(equality, balance, timing, prediction):
    """The numbers the report quotes."""
    worst = max(c["difference"] for e in equality for c in e["cases"])
    ratios = []
    for e in equality[1:]:
        for key in COMPOSITORS:
            case = next(c for c in e["cases"] if c["compositing"] == key
                        and c["balance"] == "even")
            sent = np.array([r["bytes"]["composite"] for r in case["ranks"]], dtype=float)
            simulated = np.array(e["simulated"][key])
            ratios.append(float(sent.sum() / simulated.sum()))
    imbalance = {}
    for b in balance:
        for case in b["cases"]:
            samples = np.array([r["samples"] for r in case["ranks"]], dtype=float)
            imbalance[f"{b['scene']} {b['ranks']} {case['balance']}"] = float(
                samples.max() / samples.mean())
    visible = {}
    for name, scene in (("dense", DENSE), ("sparse", SPARSE)):
        samples = data_gen.make_field(scene["field"], **scene["params"]).sample(BALANCE["n"])
        visible[name] = float((samples.data > RAMP["threshold"]).mean())
    t1, t2 = (_swap(t)["seconds"] for t in timing)
    two = next(r for r in prediction["rows"] if r["ranks"] == 2)
    return {"max_difference": worst, "sent_over_simulated": [min(ratios), max(ratios)],
            "imbalance": imbalance, "t1": t1, "t2": t2, "speedup": t1 / t2,
            "efficiency": t1 / t2 / 2, "model_t2": two["frame_s"],
            "rate_mb_s": prediction["bytes_per_second"] / 1e6, "visible": visible}


def _swap(run):
    """The binary-swap case of a timing run (the case the speedup and the model quote)."""
    return next(c for c in run["cases"] if c["compositing"] == "binary-swap")


def predict(timing):
    """Frame time at larger P from the measured costs: the 1-rank frame (sampling the field,
    ray casting, everything but communication) divided evenly over P ranks, plus binary swap's
    bounded bytes for the busiest rank at that P (traffic module) at the compositing rate
    measured with 2 ranks (bytes sent over seconds spent compositing)."""
    single = _swap(timing[0])["seconds"]
    two = _swap(timing[1])["ranks"]
    moved = sum(r["bytes"]["composite"] for r in two)
    spent = sum(r["composite_s"] for r in two)
    rate = moved / spent if spent > 0 else math.inf
    n, size = TIMING["n"], TIMING["size"]
    view = View.orbit(size=size, **ORBIT)
    origin, spacing = np.array([-1.0, -1.0, -1.0]), np.full(3, 2.0 / (n - 1))
    rows = []
    for p in PREDICT:
        tree = decompose.split((n - 1,) * 3, p)
        swap = COMPOSITORS["binary-swap"].messages(tree, np.arange(p), None, view, origin,
                                                   spacing, bytes_per_pixel=PIXEL_BYTES)
        busiest = float(swap.sent_per_node(p).max())
        work = single / p
        rows.append({"ranks": p, "work_s": work, "composite_s": busiest / rate,
                     "frame_s": work + busiest / rate,
                     "speedup": single / (work + busiest / rate)})
    return {"single_rank_s": single, "bytes_per_second": rate, "rows": rows}


if __name__ == "__main__":
    main()
