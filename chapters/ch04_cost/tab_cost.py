"""Tables: the operation-count model per reconstructed point, the measured cost per point on
every machine and backend, the fitted model's constants and errors, and the skips."""

import numpy as np

from chapters.ch04_cost import _merged
from chapters.common import figure_path, read_json, result_path, write_csv, write_json


def _config(r):
    step = "" if r["step"] is None else f", step {r['step']:g}"
    return f"{r['method']}, {r['filter']}{step}"


def peer_row(p):
    """One peer point against vrlib's configurations (``run_pareto.dominance``)."""
    name = p["renderer"] + ("" if p["step"] is None else f", step {p['step']:g}")
    if p["seconds"] is None:
        return [name, "-", f"{p['rmse']:.2e}", "-", "-", "-", p.get("note", "not timed")]
    if p.get("dominated_by"):
        r = p["dominated_by"]
        return [name, f"{p['seconds']:.4f}", f"{p['rmse']:.2e}", _config(r),
                f"{r['seconds']:.4f}", f"{r['rmse']:.2e}",
                f"dominated: vrlib's is {p['seconds'] / r['seconds']:.1f}x faster and "
                f"{p['rmse'] / r['rmse']:.1f}x more accurate"]
    if p.get("closest"):
        r = p["closest"]
        return [name, f"{p['seconds']:.4f}", f"{p['rmse']:.2e}", _config(r),
                f"{r['seconds']:.4f}", f"{r['rmse']:.2e}",
                f"not dominated: vrlib's fastest at least as accurate is "
                f"{p['slower_by']:.1f}x slower"]
    return [name, f"{p['seconds']:.4f}", f"{p['rmse']:.2e}", "-", "-", "-",
            "not dominated: no vrlib configuration is as accurate"]


def main():
    records = _merged.machines(__file__)
    first = records[0]
    rows = []
    for r in first["rows"]:
        if r["backend"].startswith("numba") and r["backend"].endswith("1 thread"):
            rows.append([r["scene"], r["method"], r["filter"],
                         f"{r['operations'] / max(r['points'], 1):.0f}"])
    write_csv(figure_path(__file__, "operations_per_point.csv"),
              ["scene", "method", "filter", "operations per point (renderers' count)"], rows)
    rows = []
    for record in records:
        fit, _ = _merged.fitted(record)
        for r in fit:
            ray = next(q for q in record["rows"] if q["scene"] == r["scene"]
                       and q["backend"] == r["backend"] and q["filter"] == r["filter"]
                       and q["method"] == "raycast")
            rows.append([record["machine"]["id"], r["backend"], r["scene"], r["method"],
                         r["filter"], f"{r['ns_per_point']:.1f}",
                         f"{r['ns_per_point'] / ray['ns_per_point']:.2f}",
                         f"{100 * r['model_error']:+.0f}%"])
    write_csv(figure_path(__file__, "cost_per_point.csv"),
              ["machine", "backend", "scene", "method", "filter", "ns per point",
               "over ray casting", "model error"], rows)
    summary = _merged.summary(records)
    rows = [[mid, backend, f"{1e9 * c['c_op']:.3f}", f"{1e9 * c['c_pt']:.1f}",
             f"{1e3 * c['c_0']:.2f}", f"{100 * s['median_model_error']:.0f}%"]
            for mid, s in summary.items() for backend, c in s["constants"].items()]
    write_csv(figure_path(__file__, "model_fit.csv"),
              ["machine", "backend", "ns per operation", "ns per point", "ms per frame",
               "median |model error| (machine)"], rows)
    write_json(result_path(__file__, "model.json"), {
        "machines": summary,
        "splat_cheaper_per_point_than_raycast": {
            mid: float(np.mean([
                r["ns_per_point"] < next(q["ns_per_point"] for q in rec["rows"]
                                         if q["method"] == "raycast" and q["scene"] == r["scene"]
                                         and q["backend"] == r["backend"]
                                         and q["filter"] == r["filter"])
                for r in rec["rows"] if r["method"] == "splat"]))
            for mid, rec in ((rec["machine"]["id"], rec) for rec in records)}})
    pareto = read_json(result_path(__file__, "pareto.json"))
    write_csv(figure_path(__file__, "pareto_front.csv"),
              ["method", "filter", "step", "seconds", "rmse"],
              [[r["method"], r["filter"], "-" if r["step"] is None else f"{r['step']:g}",
                f"{r['seconds']:.4f}", f"{r['rmse']:.2e}"] for r in pareto["front"]]
              + [[p["renderer"], "trilinear" if "VTK" in p["renderer"] else "-",
                  "-" if p["step"] is None else f"{p['step']:g}",
                  "-" if p["seconds"] is None else f"{p['seconds']:.4f}",
                  f"{p['rmse']:.2e}"] for p in pareto["peers"]])
    write_csv(figure_path(__file__, "peers_dominated.csv"),
              ["peer", "seconds", "rmse", "vrlib configuration", "its seconds", "its rmse",
               "verdict"],
              [peer_row(p) for p in pareto["peers"]])
    skips = read_json(result_path(__file__, "skips.json"))
    write_csv(figure_path(__file__, "skips.csv"),
              ["scene", "visible voxels", "method", "skip", "speedup", "largest image change"],
              [[r["scene"], f"{r['visible_fraction']:.1%}", r["method"], r["skip"],
                f"{r['speedup']:.2f}", f"{r['max_change']:.1e}"] for r in skips["rows"]])


if __name__ == "__main__":
    main()
