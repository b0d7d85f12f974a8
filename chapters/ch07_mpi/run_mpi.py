"""The MPI renderer on this machine: equality with the serial render for 1 to 12 ranks and every
compositor, bytes sent against the traffic model, load balance on sparse and dense scenes,
frame timings at 1, 2, 4 and 8 ranks, compositing time against image size, the model's
prediction for larger machines, and a volume read from a file by 8 ranks whose memory is
measured.

Every run starts ``mpiexec`` from the environment (the MPICH wheel) on
:mod:`chapters.ch07_mpi._frame` or :mod:`chapters.ch07_mpi._composite`, with one numba thread
per rank. This machine has two cores: runs of more than 2 ranks are oversubscribed, so their
counts (bytes, samples, equality, memory) are exact but their times are not speed-ups. Writes
``build/results/ch07_mpi/mpi.json``.
"""

import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import data_gen
import vrlib
from chapters.ch07_mpi._frame import ramp
from chapters.common import ROOT, by_profile, progress, result_path, write_json
from vrlib import View
from vrlib.parallel import decompose, traffic
from vrlib.parallel.composite import COMPOSITORS

MPIEXEC = Path(sys.executable).parent / "mpiexec"
DENSE = {"field": "marschner-lobb", "params": {}}
SPARSE = {"field": "random-blobs", "params": {"count": 6, "seed": 7}}
ORBIT = {"azimuth": 35.0, "elevation": 25.0}
PERSPECTIVE = {"azimuth": -120.0, "elevation": -40.0, "projection": "perspective"}
RAMP = {"threshold": 0.25, "scale": 8.0}
# Every compositor with even bricks, then the other balances and the image partitions.
ALL_CASES = [[name, "even"] for name in COMPOSITORS] + [
    ["direct-send", "interleaved"], ["binary-swap", "work"], ["radix-k", "work"],
    ["image", None], ["image-interleaved", None]]
# Radix-k factorisations besides the default, per rank count.
FACTORS = {4: ["2x2"], 6: ["2x3", "3x2"], 8: ["2x2x2", "2x4"], 9: ["3x3"], 10: ["2x5", "5x2"],
           12: ["3x4", "2x2x3", "2x6"]}
EQUALITY = {"n": by_profile(49, 97), "size": by_profile(96, 192), "ranks": list(range(1, 13))}
BALANCE = {"n": by_profile(65, 129), "size": by_profile(128, 256), "ranks": [4, 8]}
TIMING = {"n": by_profile(129, 257), "size": by_profile(256, 512), "repeats": 5,
          "ranks": [1, 2, 4, 8], "compositors": list(COMPOSITORS)}
COMPOSITING = {"sizes": [256, 512, 1024, 2048], "ranks": [2, 4, 8], "repeats": 5, "n": 129,
               "compositors": list(COMPOSITORS)}
MEMORY = {"n": by_profile(769, 769), "size": 256, "ranks": 8}
PREDICT = [2, 4, 8, 16, 64, 256, 1024]
PIXEL_BYTES = 32  # float64 RGBA, as the renderer sends them


def launch(ranks, config, program="_frame"):
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    done = subprocess.run([str(MPIEXEC), "-n", str(ranks), sys.executable, "-m",
                           f"chapters.ch07_mpi.{program}", json.dumps(config)], cwd=ROOT,
                          env=env, capture_output=True, text=True, timeout=1800, check=False)
    if done.returncode != 0:
        raise SystemExit(f"mpiexec -n {ranks} failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def lattice(n):
    return np.array([-1.0, -1.0, -1.0]), np.full(3, 2.0 / (n - 1))


def simulated_bytes(ranks, n, size, orbit):
    """The traffic module's bytes per rank for each compositor (float64 pixels, each
    compositor's own k-d tree) and for the image partitions (float64 voxels, the trilinear
    filter's reach)."""
    view = View.orbit(size=size, **orbit)
    origin, spacing = lattice(n)
    tiles = decompose.screen_tiles(size, size, ranks)
    owners = np.arange(ranks)
    sent = {}
    for name, compositor in COMPOSITORS.items():
        tree = compositor.split((n - 1,) * 3, ranks)
        sent[name] = compositor.messages(tree, owners, tiles, view, origin, spacing,
                                         bytes_per_pixel=PIXEL_BYTES).sent_per_node(ranks)
    tree = decompose.split((n - 1,) * 3, ranks)
    for key, layout in (("image", "contiguous"), ("image-interleaved", "interleaved")):
        tiles = decompose.screen_tiles(size, size, ranks, layout=layout)
        sent[key] = traffic.image_static(tree, owners, tiles, view, (n,) * 3, origin, spacing,
                                         radius=1.0, bytes_per_voxel=8).sent_per_node(ranks)
    return {k: v.tolist() for k, v in sent.items()}


def main():
    if not MPIEXEC.exists():
        raise SystemExit(f"mpiexec missing from the environment: {MPIEXEC}")
    equality = []
    for ranks in progress(EQUALITY["ranks"], "ranks 1-12"):
        cases = ALL_CASES + [[f"radix-k:{f}", "even"] for f in FACTORS.get(ranks, [])]
        report = launch(ranks, {**DENSE, **RAMP, "n": EQUALITY["n"], "size": EQUALITY["size"],
                                "orbits": [ORBIT, PERSPECTIVE], "cases": cases,
                                "check": True})
        equality.append({"ranks": ranks, "cases": report["cases"],
                         "simulated": simulated_bytes(ranks, EQUALITY["n"], EQUALITY["size"],
                                                      ORBIT)})
    balance = []
    for name, field in progress([("dense", DENSE), ("sparse", SPARSE)], "balance"):
        for ranks in BALANCE["ranks"]:
            report = launch(ranks, {**field, **RAMP, "n": BALANCE["n"],
                                    "size": BALANCE["size"], "orbits": [ORBIT],
                                    "cases": [["direct-send", "even"],
                                              ["direct-send", "interleaved"],
                                              ["direct-send", "work"],
                                              ["image", None], ["image-interleaved", None]]})
            balance.append({"scene": name, "ranks": ranks, "cases": report["cases"]})
    timing = []
    for ranks in progress(TIMING["ranks"], "timing"):
        report = launch(ranks, {**DENSE, **RAMP, "n": TIMING["n"], "size": TIMING["size"],
                                "orbits": [ORBIT], "repeats": TIMING["repeats"],
                                "cases": [[name, "even"] for name in TIMING["compositors"]]})
        timing.append({"ranks": ranks, "cases": report["cases"]})
    compositing = []
    for ranks in progress(COMPOSITING["ranks"], "compositing"):
        report = launch(ranks, {**COMPOSITING, "orbit": ORBIT}, program="_composite")
        compositing.append({"ranks": ranks, "cases": report["cases"]})
    memory = measure_memory()
    prediction = predict(timing, compositing)
    write_json(result_path(__file__, "mpi.json"), {
        "equality": equality, "balance": balance, "timing": timing,
        "compositing": compositing, "memory": memory, "prediction": prediction,
        "summary": summarise(equality, balance, timing, compositing, prediction),
        "settings": {
            "equality": EQUALITY, "balance": BALANCE, "timing": TIMING,
            "compositing": COMPOSITING, "memory": MEMORY, "orbit": ORBIT,
            "perspective": PERSPECTIVE, "ramp": RAMP, "dense": DENSE, "sparse": SPARSE,
            "factors": FACTORS}})


def measure_memory():
    """A volume larger than any rank should hold, written to a .npy file slab by slab, rendered
    by ``MEMORY["ranks"]`` ranks that each map the file and read only their brick; each rank's
    peak resident memory during the frame against the volume's size, and the image against
    the serial render of the whole file (in this process)."""
    n = MEMORY["n"]
    field = data_gen.make_field(DENSE["field"], **DENSE["params"])
    with tempfile.TemporaryDirectory(dir=ROOT / "build") as folder:
        path = Path(folder) / "volume.npy"
        array = np.lib.format.open_memmap(path, mode="w+", dtype=np.float32, shape=(n,) * 3)
        for z0 in range(0, n, 64):
            region = [(z0, min(z0 + 64, n)), (0, n), (0, n)]
            array[z0:region[0][1]] = field.sample_region((n,) * 3, region,
                                                         extent=field.bounds)
        array.flush()
        del array
        # The file is in voxel units (as data_gen.load reads a .npy), the field spans 2: the
        # same optical depth needs the density per voxel.
        per_voxel = {**RAMP, "scale": RAMP["scale"] * 2.0 / (n - 1)}
        report = launch(MEMORY["ranks"], {**per_voxel, "file": str(path), "size": MEMORY["size"],
                                          "orbits": [ORBIT], "memory": True,
                                          "cases": [["radix-k", "even"]],
                                          "save": str(Path(folder) / "frame.npy")})
        frame = np.load(Path(folder) / "frame.npy")
        volume = data_gen.load(path)
        view = View.orbit(size=MEMORY["size"], **ORBIT)
        serial = vrlib.render(volume, view, transfer=ramp(per_voxel["threshold"],
                                                          per_voxel["scale"]),
                              early_termination=1.0)
        size_bytes = volume.data.nbytes
        del volume
    peaks = [m["peak"] for m in report["memory"]]
    return {"samples": n, "volume_bytes": size_bytes, "ranks": MEMORY["ranks"],
            "peak": peaks, "resident": [m["resident"] for m in report["memory"]],
            "peak_over_volume": max(peaks) / size_bytes,
            "alpha_max": float(serial.alpha.max()),
            "difference": float(np.abs(frame - serial.rgba).max())}


def median_case(run, name):
    return next(c for c in run["cases"] if c["compositing"] == name)


def fit_round_cost(compositing):
    """Cost of one compositing round at 2 ranks (one core each, one message each):
    ``seconds = a + b x bytes``
    fitted over image sizes and compositors (least squares), the bytes being the most any
    rank sent."""
    two = next(c for c in compositing if c["ranks"] == 2)["cases"]
    sent = np.array([max(c["bytes"]) for c in two], dtype=float)
    seconds = np.array([c["seconds"] for c in two])
    b, a = np.polyfit(sent, seconds, 1)
    return float(max(a, 0.0)), float(b)


def predict(timing, compositing):
    """Frame time at larger P from the measured costs: the 1-rank frame (sampling, ray casting,
    everything but communication) divided evenly over P ranks, plus each compositor's rounds
    (the traffic module's, for the same view), each costing the fitted ``a`` per message the
    busiest sender posts plus ``b`` per byte the busiest sender sends (at two ranks a round
    is one message, so ``a`` is a message's cost). The model assumes one core per rank, the
    measured per-round cost at any P, and no network contention."""
    a, b = fit_round_cost(compositing)
    n, size = TIMING["n"], TIMING["size"]
    view = View.orbit(size=size, **ORBIT)
    origin, spacing = lattice(n)
    out = {}
    for name in TIMING["compositors"]:
        single = median_case(timing[0], name)["seconds"]
        compositor = COMPOSITORS[name]
        rows = []
        for p in PREDICT:
            tree = compositor.split((n - 1,) * 3, p)
            tiles = decompose.screen_tiles(size, size, p)
            rounds = [m for m in compositor.rounds(tree, np.arange(p), tiles, view, origin,
                                                   spacing, bytes_per_pixel=PIXEL_BYTES)
                      if m.bytes.size]
            composite_s = sum(a * int(np.bincount(m.src, minlength=p).max()) +
                              b * float(m.sent_per_node(p).max()) for m in rounds)
            work = single / p
            rows.append({"ranks": p, "work_s": work, "composite_s": composite_s,
                         "rounds": len(rounds), "frame_s": work + composite_s,
                         "speedup": single / (work + composite_s)})
        out[name] = rows
    return {"round_seconds": a, "seconds_per_byte": b, "rows": out}


def summarise(equality, balance, timing, compositing, prediction):
    """The numbers the report quotes."""
    worst = max(c["difference"] for e in equality for c in e["cases"])
    counted = sum(len(e["cases"]) for e in equality)
    ratios = {}
    for e in equality[1:]:
        for key in [*COMPOSITORS, "image", "image-interleaved"]:
            case = next(c for c in e["cases"] if c["compositing"] == key
                        and c["balance"] in ("even", None) and c["orbit"] == ORBIT)
            field = "voxels" if key.startswith("image") else "composite"
            sent = np.array([r["bytes"][field] for r in case["ranks"]], dtype=float)
            ratios.setdefault(key, []).append(float(sent.sum() / np.sum(e["simulated"][key])))
    imbalance = {}
    for b in balance:
        for case in b["cases"]:
            samples = np.array([r["samples"] for r in case["ranks"]], dtype=float)
            key = case["balance"] or case["compositing"]
            imbalance[f"{b['scene']} {b['ranks']} {key}"] = float(samples.max() /
                                                                 samples.mean())
    visible = {}
    for name, scene in (("dense", DENSE), ("sparse", SPARSE)):
        samples = data_gen.make_field(scene["field"], **scene["params"]).sample(BALANCE["n"])
        visible[name] = float((samples.data > RAMP["threshold"]).mean())
    times = {}
    for t in timing:
        for case in t["cases"]:
            runs = case["all_seconds"]
            times[f"{case['compositing']} {t['ranks']}"] = {
                "median": case["seconds"], "least": min(runs), "most": max(runs)}
    one = {name: times[f"{name} 1"]["median"] for name in TIMING["compositors"]}
    speedup = {name: one[name] / times[f"{name} 2"]["median"] for name in one}
    spread_1 = {name: times[f"{name} 1"]["most"] / times[f"{name} 1"]["least"] - 1
                for name in one}
    at = {c["ranks"]: {(x["width"], x["compositing"]): x for x in c["cases"]}
          for c in compositing}
    radix_vs_swap = {f"{r} {w}": {
        "time": at[r][(w, "radix-k")]["seconds"] / at[r][(w, "binary-swap")]["seconds"],
        "bytes": max(at[r][(w, "radix-k")]["bytes"]) / max(at[r][(w, "binary-swap")]["bytes"])}
        for r in at for w in COMPOSITING["sizes"]}
    return {"max_difference": worst, "cases_checked": counted,
            "sent_over_simulated": {k: [min(v), max(v)] for k, v in ratios.items()},
            "imbalance": imbalance, "visible": visible, "times": times,
            "speedup_2": speedup, "efficiency_2": {k: v / 2 for k, v in speedup.items()},
            "spread_1": spread_1, "radix_vs_swap": radix_vs_swap,
            "round_ms": prediction["round_seconds"] * 1e3,
            "rate_mb_s": 1e-6 / prediction["seconds_per_byte"]
            if prediction["seconds_per_byte"] > 0 else math.inf}


if __name__ == "__main__":
    main()
