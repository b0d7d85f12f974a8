"""Tables: every stress case with its verdict per method, and the precision of storage."""

import vrlib
from chapters.common import figure_path, read_json, result_path, write_csv

METHODS = list(vrlib.METHODS)


def cell(result):
    if result["refusal"] is not None and result["passed"]:
        return "refuses"
    value = result["max_error"]
    number = "" if value is None else f" ({value:.2g})"
    return ("pass" if result["passed"] else "FAIL") + number


def main():
    data = read_json(result_path(__file__, "cases.json"))
    write_csv(figure_path(__file__, "stress.csv"),
              ["case", "what must hold", *METHODS, "verdict"],
              [[f"{c['group']}: {c['case']}", c["expectation"],
                *[cell(c["results"][m]) if m in c["results"] else "" for m in METHODS],
                "holds" if c["passed"] else "fails"]
               for c in data["cases"] if set(c["results"]) == set(METHODS)])
    write_csv(figure_path(__file__, "ringing.csv"),
              ["filter", "overshoot of a unit step", "bound (lattice sums)", "within"],
              [[name, f"{r['max_error']:.4f}", f"{r['bound']:.4f}",
                "yes" if r["passed"] else "no"] for c in data["cases"]
               if c["case"] == "step-edge ringing" for name, r in c["results"].items()])
    precision = read_json(result_path(__file__, "precision.json"))
    write_csv(figure_path(__file__, "storage.csv"),
              ["method", "largest change float32 vs float64 storage", "rmse float32",
               "rmse float64"],
              [[r["method"], f"{r['difference']:.1e}", f"{r['rmse_float32']:.6f}",
                f"{r['rmse_float64']:.6f}"] for r in precision["storage"]["rows"]])


if __name__ == "__main__":
    main()
