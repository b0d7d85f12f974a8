"""Tables: the worst-case error at the derived predictions' feature sizes (measured 1-D and
3-D, the Fourier bound, the derived prediction), and the feature size each filter needs for
10%, 5% and 1% error."""

import math

from chapters.common import figure_path, read_json, result_path, write_csv


def _ratio(value):
    return "> 8" if math.isinf(value) else f"{value:.2f}"  # beyond the searched range


def main():
    data = read_json(result_path(__file__, "error_bound.json"))
    ratios = data["derived_ratios"]
    rows = []
    for label, s in data["at_derived"].items():
        derived = s["derived_1d"] or [None] * len(ratios)
        for q, m1, m3, b1, p in zip(ratios, s["measured_1d"], s["measured_3d"], s["bound_1d"],
                                    derived, strict=True):
            rows.append([label, f"{q:g}", f"{m1:.3f}", "-" if p is None else f"{p:.3f}",
                         "inf" if math.isinf(b1) else f"{b1:.3f}", f"{m3:.3f}"])
    write_csv(figure_path(__file__, "error_bound.csv"),
              ["filter", "sigma/h", "E 1-D measured", "E 1-D derived", "Fourier bound 1-D",
               "E 3-D measured"], rows)
    targets = [f"{t:g}" for t in data["targets"]]
    rows = [[label] + [_ratio(r[t][dims]) for t in targets for dims in ("1d", "3d")]
            for label, r in data["required"].items()]
    write_csv(figure_path(__file__, "feature_size.csv"),
              ["filter"] + [f"{float(t):.0%} {d}" for t in targets for d in ("1-D", "3-D")],
              rows)


if __name__ == "__main__":
    main()
