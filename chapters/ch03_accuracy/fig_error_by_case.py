"""Figure: rmse against the reference for every filter, per field and sampling density
(ray casting, splatting and shear-warp, one above the other; the other methods in the
tables)."""

import matplotlib.pyplot as plt
import numpy as np

from chapters.common import figure_path, read_json, result_path, save_figure


def main():
    data = read_json(result_path(__file__, "accuracy.json"))
    records, fields, filters = data["records"], data["fields"], data["filters"]
    methods = ["raycast", "splat", "shearwarp"]
    fig, axes = plt.subplots(len(methods), 1, figsize=(7.5, 2.4 * len(methods) + 1.2),
                             sharex=True, sharey=True, layout="constrained")
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
        ax.set_title(method, fontsize=9)
        ax.set_ylabel("rmse (mean over views)", fontsize=8)
    axes[-1].set_xticks(x, [f"{f} {n}^3" for f, n in cases], rotation=60, ha="right",
                        fontsize=7)
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside upper center",
               ncol=(len(filters) + 1) // 2, fontsize=7)
    save_figure(fig, figure_path(__file__, "error_by_case.png"))


if __name__ == "__main__":
    main()
