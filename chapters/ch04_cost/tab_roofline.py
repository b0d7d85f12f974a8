"""Table: the ray caster's rate on the cost chapter's scenes as a fraction of this machine's
sampling ceiling (``run_roofline.py``) for its filter and thread count.

The tent filter's ceiling is the trilinear one; every 4-tap filter (the cubics, the Gaussian)
is held to the tricubic one. Writes ``figures/ch04_cost/roofline.csv`` and the fractions the
report quotes to ``build/results/ch04_cost/roofline_fractions.json``.
"""

import vrlib
from chapters.common import figure_path, read_json, result_path, write_csv, write_json


def main():
    limits = read_json(result_path(__file__, "roofline.json"))
    record = read_json(result_path(__file__, f"machines/{limits['machine']['id']}.json"))
    rows, fractions = [], []
    for r in record["rows"]:
        if r["method"] != "raycast" or not r["backend"].startswith("numba"):
            continue
        threads = r["backend"].split()[1]
        if threads not in limits["limits"]:
            continue
        kind = "trilinear" if vrlib.make_filter(r["filter"]).taps <= 2 else "tricubic"
        ceiling = limits["limits"][threads][f"{kind}_float64"]
        rate = r["points"] / r["seconds"]
        fractions.append({"scene": r["scene"], "filter": r["filter"], "threads": int(threads),
                          "rate": rate, "ceiling": ceiling, "fraction": rate / ceiling})
        rows.append([r["scene"], r["filter"], threads, f"{rate / 1e6:.1f}",
                     f"{kind} {ceiling / 1e6:.0f}", f"{rate / ceiling:.2f}"])
    write_csv(figure_path(__file__, "roofline.csv"),
              ["scene", "filter", "threads", "M samples/s", "ceiling (M samples/s)",
               "fraction"], rows)
    values = [f["fraction"] for f in fractions]
    write_json(result_path(__file__, "roofline_fractions.json"), {
        "rows": fractions, "min": min(values), "max": max(values),
        "bandwidth_gb_s": {t: v["bandwidth"] / 1e9 for t, v in limits["limits"].items()},
        "trilinear_m_s": {t: v["trilinear_float64"] / 1e6 for t, v in limits["limits"].items()},
        "tricubic_m_s": {t: v["tricubic_float64"] / 1e6 for t, v in limits["limits"].items()}})


if __name__ == "__main__":
    main()
