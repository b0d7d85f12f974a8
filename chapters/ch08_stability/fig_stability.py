"""Figures: precision of accumulation, segment-opacity models across optical depth, glow scale
extremes, and convergence in step and resolution."""

import matplotlib.pyplot as plt
import numpy as np

from chapters.common import figure_path, read_json, result_path, save_figure


def precision_figure():
    data = read_json(result_path(__file__, "precision.json"))
    opacity = read_json(result_path(__file__, "opacity.json"))
    fig, axes = plt.subplots(1, 3, figsize=(12, 4.2), layout="tight")
    ax = axes[0]
    rows = data["accumulation"]
    for mean, ls in zip(sorted({r["mean_alpha"] for r in rows}), ("-", "--", ":"), strict=True):
        sel = [r for r in rows if r["mean_alpha"] == mean]
        n = [r["samples"] for r in sel]
        for name, colour in (("float32", "C3"), ("float32 compensated", "C1"),
                             ("float64", "C0")):
            ax.loglog(n, [max(r[name], 1e-20) for r in sel], ls, color=colour, marker="o",
                      ms=3, label=f"{name}" if mean == 1e-4 else None)
    ax.set_xlabel("samples per ray")
    ax.set_ylabel("largest error in accumulated colour")
    ax.set_title("Front-to-back accumulation (mean alpha 1e-4 solid,\n1e-3 dashed, 1e-2 "
                 "dotted) against extended precision", fontsize=9)
    ax.legend(fontsize=8)
    ax = axes[1]
    seg = opacity["segment_models"]
    depth = np.array(seg["depth"])
    for name, value in seg.items():
        if name == "depth":
            continue
        ax.loglog(depth, np.maximum(value["relative"], 1e-18), label=name)
    ax.set_xlabel("optical depth x of one segment")
    ax.set_ylabel("relative error of segment opacity")
    ax.set_title("1 - exp(-x): models and ways of computing it", fontsize=9)
    ax.legend(fontsize=7)
    ax = axes[2]
    glow = opacity["glow"]
    for method in dict.fromkeys(r["method"] for r in glow):
        sel = [r for r in glow if r["method"] == method]
        ax.loglog([r["scale"] for r in sel], [r["relative_error"] for r in sel], "-o", ms=3,
                  label=method)
    ax.set_xlabel("glow scale k (opacity per world unit per unit value)")
    ax.set_ylabel("largest error / brightest exact pixel")
    ax.set_title("Glow scale from 1e-6 to 1e6 (Gaussian blob, closed form)", fontsize=9)
    ax.legend(fontsize=8)
    for a in axes:
        a.grid(True, which="both", alpha=0.3)
    save_figure(fig, figure_path(__file__, "precision.png"))


def convergence_figure():
    data = read_json(result_path(__file__, "convergence.json"))
    fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.8), layout="tight")
    for filt, entry in data["steps"].items():
        rows = entry["rows"]
        left.loglog([r["step"] for r in rows], [r["max_error"] for r in rows], "-o", ms=4,
                    label=f"{filt} (order {entry['order_large_steps']:.2f} at steps >= 0.5)")
    left.set_xlabel("ray step (voxels)")
    left.set_ylabel("largest error")
    left.set_title(f"Ray casting against the closed form, {data['volume']}$^3$", fontsize=10)
    left.legend(fontsize=8)
    for (method, entry), style in zip(data["resolution"].items(),
                                      ("-o", "--s", ":^", "-.v", "-D"), strict=False):
        rows = entry["rows"]
        right.loglog([r["N"] for r in rows], [r["rmse"] for r in rows], style, ms=4,
                     label=f"{method} (order {entry['order']:.2f})")
    right.set_xlabel("samples per axis N")
    right.set_ylabel("rmse")
    right.set_title("Every method, Catmull-Rom, as the resolution grows", fontsize=10)
    right.legend(fontsize=8)
    for a in (left, right):
        a.grid(True, which="both", alpha=0.3)
    save_figure(fig, figure_path(__file__, "convergence.png"))


def segment_ends_figure():
    data = read_json(result_path(__file__, "segment_ends.json"))
    scenes = list(dict.fromkeys(r["scene"] for r in data["rows"]))
    fig, axes = plt.subplots(1, len(scenes), figsize=(11, 3.6), sharey=True, layout="tight")
    styles = {("trilinear", "lattice"): "--o", ("trilinear", "exact"): "-o",
              ("catmull-rom", "lattice"): "--s", ("catmull-rom", "exact"): "-s"}
    for ax, scene in zip(axes, scenes, strict=True):
        for r in (r for r in data["rows"] if r["scene"] == scene):
            ax.loglog(r["steps"], r["rmse"], styles[r["filter"], r["ends"]], ms=4,
                      label=f"{r['filter']}, {r['ends']} ends (order {r['order']:.2f})")
        ax.set_title(scene, fontsize=10)
        ax.set_xlabel("ray step (voxels)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    axes[0].set_ylabel("rmse against the reconstructed field's exact image")
    save_figure(fig, figure_path(__file__, "segment_ends.png"))


def main():
    precision_figure()
    convergence_figure()
    segment_ends_figure()


if __name__ == "__main__":
    main()
