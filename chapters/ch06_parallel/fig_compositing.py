"""Figure and table: modelled compositing time and bytes per frame against the node count for
direct send, binary swap, radix-k with the default factorisation (k at most 8) and the best k
per node count."""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import NullFormatter

from chapters.common import figure_path, read_json, result_path, save_figure, write_csv
from vrlib.parallel.composite import radix_factors


def curve(rows, nodes, pick, key):
    out = []
    for p in nodes:
        row = pick([r for r in rows if r["nodes"] == p])
        out.append(key(row))
    return np.array(out, dtype=float)


def default(sel):
    """Radix-k's default factorisation (factors of at most 8)."""
    return next(r for r in sel if r["factors"] == radix_factors(r["nodes"], 8))


def main():
    data = read_json(result_path(__file__, "compositing.json"))
    rows, nodes = data["rows"], data["nodes"]
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.9), layout="tight")
    for ax, kind in zip(axes[:2], ("torus", "mesh"), strict=True):
        best = {b["nodes"]: b for b in data["best"][kind]}
        for label, pick, style in (
                ("direct send", lambda s: next(r for r in s if r["label"] == "direct send"),
                 "C3s-"),
                ("binary swap", lambda s: next(r for r in s if r["label"] == "binary swap"),
                 "C0o-"),
                ("radix-k, k <= 8", default, "C2^-"),
                ("radix-k, best k", lambda s, best=best: next(
                    r for r in s if r["label"] == best[s[0]["nodes"]]["label"]), "C1D--")):
            ax.loglog(nodes, 1e3 * curve(rows, nodes, pick, lambda r, kind=kind:
                                         r[kind]["seconds"]), style, ms=4, label=label)
        ax.set_xlabel("nodes P")
        ax.set_ylabel("modelled ms per frame")
        ax.set_title(f"{kind}: {data['width']}$^2$ image, latency "
                     f"{data['alpha'] * 1e6:g} $\\mu$s, {data['beta'] / 1e9:g} GB/s", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    ax = axes[2]
    for label, style in (("direct send", "C3s-"), ("binary swap", "C0o-")):
        ax.loglog(nodes, curve(rows, nodes, lambda s, label=label: next(
            r for r in s if r["label"] == label), lambda r: r["total"]) / 1e6, style, ms=4,
            label=label)
    ax.loglog(nodes, curve(rows, nodes, default, lambda r: r["total"]) / 1e6, "C2^-", ms=4,
              label="radix-k, k <= 8")
    ax.set_xlabel("nodes P")
    ax.set_ylabel("MB sent per frame (all nodes)")
    ax.set_title("Bytes: bounding rectangles of what each node holds", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    for ax in axes:
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_minor_formatter(NullFormatter())
    save_figure(fig, figure_path(__file__, "compositing.png"))
    table = []
    for torus, mesh in zip(data["best"]["torus"], data["best"]["mesh"], strict=True):
        table.append([torus["nodes"], " x ".join(map(str, torus["factors"])), torus["rounds"],
                      f"{torus['seconds'] * 1e3:.3f}",
                      f"{torus['binary_swap_seconds'] * 1e3:.3f}",
                      f"{torus['direct_send_seconds'] * 1e3:.3f}",
                      f"{torus['speedup_over_binary_swap']:.2f}",
                      " x ".join(map(str, mesh["factors"])),
                      f"{mesh['speedup_over_binary_swap']:.2f}"])
    write_csv(figure_path(__file__, "compositing.csv"),
              ["P", "best k (torus)", "rounds", "ms", "binary swap ms", "direct send ms",
               "vs binary swap", "best k (mesh)", "vs binary swap (mesh)"], table)


if __name__ == "__main__":
    main()
