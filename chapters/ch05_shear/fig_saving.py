"""Figure: the two-pass saving per rotation (samples, operations, time, memory)."""

import matplotlib.pyplot as plt
import numpy as np

from chapters.ch05_shear._saving import PREDICTED, ratios
from chapters.common import figure_path, read_json, result_path, save_figure


def main():
    data = read_json(result_path(__file__, "saving.json"))
    out, per_n3 = ratios(data)
    fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.8), layout="tight")
    names = list(out)
    left.boxplot([out[n] for n in names], tick_labels=names, widths=0.5)
    for x, (lo, hi) in enumerate((PREDICTED[n] for n in names), start=1):
        left.plot([x - 0.3, x + 0.3], [lo, lo], color="C3", lw=1.5)
        if hi != lo:
            left.plot([x - 0.3, x + 0.3], [hi, hi], color="C3", lw=1.5)
    left.axhline(1.0, color="0.6", lw=0.8, ls=":")
    left.set_ylabel("two-pass / three-pass")
    left.set_title(f"{len(data['rotations'])} random rotations, {data['N']}$^3$ "
                   "(red: derived predictions)", fontsize=10)
    elevation = np.array([r["elevation"] for r in data["rotations"]])
    for method, marker in (("shear3", "o"), ("shear2", "s")):
        right.scatter(np.abs(elevation), per_n3[method], s=14, marker=marker, label=method)
    right.set_xlabel("|elevation| (degrees)")
    right.set_ylabel("samples resampled / N$^3$")
    right.set_title("Work per frame against the view", fontsize=10)
    right.legend()
    save_figure(fig, figure_path(__file__, "saving.png"))


if __name__ == "__main__":
    main()
