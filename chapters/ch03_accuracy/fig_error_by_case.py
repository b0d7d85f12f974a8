"""Figure: rmse against the reference for every filter, per field and sampling density
(ray casting and shear-warp; the other methods in the tables)."""

import matplotlib.pyplot as plt
import numpy as np

from chapters.common import figure_path, read_json, result_path, save_figure


def main():
    data = read_json(result_path(__file__, "accuracy.json"))
    records, fields, filters = data["records"], data["fields"], data["filters"]
    methods = ["raycast", "splat", "shearwarp"]
    fig, axes = plt.subplots(1, len(methods), figsize=(5 * len(methods), 4.2), sharey=True)
    cases = [(f, n) for f in fields for n in data["sizes"]]
    x = np.arange(len(cases))
    width = 0.8 / len(filters)
    for ax, method in zip(axes, methods, strict=True):
        for i, filt in enumerate(filters):
            values = [np.mean([r["rmse"] for r in records if r["method"] == method
                               and r["filter"] == filt and (r["field"], r["n"]) == case])
                      for case in cases]
            ax.bar(x + (i - len(filters) / 2 + 0.5) * width, values, width, label=filt)
        ax.set_yscale("log")
        ax.set_xticks(x, [f"{f} {n}^3" for f, n in cases], rotation=70, fontsize=7)
        ax.set_title(method)
    axes[0].set_ylabel("rmse against the reference (mean over views)")
    axes[0].legend(fontsize=7, ncol=2)
    fig.tight_layout()
    save_figure(fig, figure_path(__file__, "error_by_case.png"))


if __name__ == "__main__":
    main()
