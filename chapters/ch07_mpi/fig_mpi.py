"""Figure: bytes each rank sent against the traffic model, and the imbalance of each load
balance on dense and sparse scenes."""

import matplotlib.pyplot as plt
import numpy as np

from chapters.common import figure_path, read_json, result_path, save_figure
from vrlib.parallel.composite import COMPOSITORS


def main():
    data = read_json(result_path(__file__, "mpi.json"))
    fig, (left, middle, right) = plt.subplots(1, 3, figsize=(15, 4.3))
    series = [(name, name.replace("-", " ")) for name in COMPOSITORS]
    series.append(("image", "image partition (voxels)"))
    for (key, label), marker in zip(series, "os^Dv<>", strict=False):
        sim, meas = [], []
        for e in data["equality"]:
            case = next(c for c in e["cases"] if c["compositing"] == key
                        and c["balance"] in ("even", None))
            field = "voxels" if key == "image" else "composite"
            meas += [r["bytes"][field] for r in case["ranks"]]
            sim += e["simulated"][key]
        left.loglog(np.array(sim) / 1e3, np.array(meas) / 1e3, marker, ms=5, alpha=0.7,
                    label=label)
    lims = left.get_xlim()
    left.plot(lims, lims, color="0.5", lw=0.8, ls=":")
    left.set_xlabel("traffic module, kB per rank")
    left.set_ylabel("sent by the MPI renderer, kB per rank")
    left.set_title("Bytes per rank, 2-8 ranks (float64 pixels and voxels)", fontsize=10)
    left.legend(fontsize=8)
    width = 0.25
    groups = [(b["scene"], b["ranks"]) for b in data["balance"]]
    for i, balance in enumerate(("even", "interleaved", "work")):
        values = []
        for b in data["balance"]:
            case = next(c for c in b["cases"] if c["balance"] == balance)
            samples = np.array([r["samples"] for r in case["ranks"]], dtype=float)
            values.append(samples.max() / samples.mean())
        middle.bar(np.arange(len(groups)) + (i - 1) * width, values, width,
                   label="work-sized k-d split (new)" if balance == "work" else balance)
    middle.axhline(1.0, color="0.5", lw=0.8)
    middle.set_xticks(range(len(groups)), [f"{s}\n{p} ranks" for s, p in groups])
    middle.set_ylabel("max / mean ray samples per rank")
    middle.set_title("Load imbalance (1 is perfect)", fontsize=10)
    middle.legend(fontsize=8)
    rows = data["prediction"]["rows"]
    p = [r["ranks"] for r in rows]
    right.loglog(p, [r["frame_s"] for r in rows], "-o", label="model frame time")
    right.loglog(p, [r["composite_s"] for r in rows], "--", label="model compositing")
    measured = [(t["ranks"], c["seconds"]) for t in data["timing"] for c in t["cases"]
                if c["compositing"] == "binary-swap"]
    right.loglog(*zip(*measured, strict=True), "kD", ms=7, label="measured (binary swap)")
    right.set_xlabel("ranks")
    right.set_ylabel("seconds per frame")
    right.set_title("Measured on this machine, predicted beyond it", fontsize=10)
    right.legend(fontsize=8)
    for ax in (left, right):
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    save_figure(fig, figure_path(__file__, "mpi.png"))


if __name__ == "__main__":
    main()
