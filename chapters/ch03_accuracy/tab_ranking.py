"""Tables: the filters ranked within each method under every metric, and every (method,
filter) pair ranked together."""

from chapters.common import figure_path, read_json, result_path, write_csv


def main():
    data = read_json(result_path(__file__, "accuracy.json"))
    summary, metrics = data["summary"], data["metrics"]
    rows = []
    for method in data["methods"]:
        s = summary[method]
        for filt in s["order"]["rmse"]:
            rows.append([method, filt] + [f"{s['mean_rank'][m][filt]:.2f}" for m in metrics])
    write_csv(figure_path(__file__, "filter_ranking.csv"),
              ["method", "filter"] + [f"mean rank ({m})" for m in metrics], rows)
    rows = []
    for cases, s in [("all", summary), ("vanishing at the faces", data["summary_vanishing"])]:
        rows += [[method, cases, "yes" if s[method]["same_best_every_metric"] else "no",
                  "yes" if s[method]["same_order_every_metric"] else "no",
                  ", ".join(sorted({s[method]["order"][m][0] for m in metrics}))]
                 for method in data["methods"]]
    write_csv(figure_path(__file__, "metric_agreement.csv"),
              ["method", "fields", "same best filter under every metric", "same full order",
               "best filter(s)"], rows)
    fields = data["fields"]
    write_csv(figure_path(__file__, "field_rmse.csv"), ["method"] + fields,
              [[m] + [f"{data['boundary_rmse'][m][f]:.2e}" for f in fields]
               for m in data["methods"]])
    for name, key in [("against_catmull_rom.csv", "against_catmull_rom"),
                      ("against_catmull_rom_vanishing.csv", "against_catmull_rom_vanishing")]:
        table = data[key]
        write_csv(figure_path(__file__, name), ["method"] + data["filters"],
                  [[m] + [f"{table[m][f]['median_ratio']:.2f} ({table[m][f]['lower']:.0%})"
                          for f in data["filters"]] for m in data["methods"]])
    overall = summary["overall"]
    rows = [[c, f"{overall['median_rmse'][c]:.2e}"]
            + [f"{overall['mean_rank'][m][c]:.1f}" for m in metrics]
            for c in overall["order"]["rmse"]]
    write_csv(figure_path(__file__, "overall_ranking.csv"),
              ["method/filter", "median rmse"] + [f"mean rank ({m})" for m in metrics], rows)


if __name__ == "__main__":
    main()
