"""Image-based accuracy: every (method, filter) pair against the reference renderer on
analytic volumes, at several sampling densities and views, under every image metric.

Writes ``build/results/ch03_accuracy/accuracy.json`` (one record per render: case, method,
filter, each metric's value) and ``images.npz`` (the Marschner-Lobb renders and a blob's, with
their references, for the image grids).
"""

import numpy as np

import data_gen
import vrlib
from chapters.common import atomic_path, by_profile, progress, result_path, write_json

METHODS = list(vrlib.METHODS)
FILTERS = list(vrlib.filters.STANDARD)
# Each field with the glow scale that keeps its brightest pixel's optical depth near 1-2, so
# that images are neither faint nor saturated.
FIELDS = {
    "blob s=0.08": (("gaussian-blob", {"sigma": 0.08}), 8.0),
    "blob s=0.2": (("gaussian-blob", {"sigma": 0.2}), 3.0),
    "grating f=2": (("grating", {"frequency": 2.0, "direction": (1.0, 0.6, 0.3)}), 1.0),
    "grating f=5": (("grating", {"frequency": 5.0, "direction": (1.0, 0.6, 0.3)}), 1.0),
    "marschner-lobb": (("marschner-lobb", {}), 1.0),
    "smooth-sphere": (("smooth-sphere", {}), 1.5),
}
SIZES = by_profile([24, 41], [24, 41, 64])
VIEWS = by_profile([(30, 25), (-70, 50)], [(30, 25), (-70, 50), (10, -15), (120, 80)])
IMAGE = by_profile(96, 192)
# Fields that vanish at the volume's faces: no boundary rule enters their images, so the
# filters are compared there without one.
VANISHING = ["blob s=0.08", "blob s=0.2", "smooth-sphere"]
SAVED = {("marschner-lobb", 41, 0), ("blob s=0.08", 24, 0)}  # cases kept for the image grids


def main():
    records, images = [], {}
    cases = [(f, n, v) for f in FIELDS for n in SIZES for v in range(len(VIEWS))]
    references = {}
    for field_name, n, v in progress(cases, "accuracy"):
        (name, params), scale = FIELDS[field_name]
        field = data_gen.make_field(name, **params)
        transfer = vrlib.Glow(scale)
        view = vrlib.View.orbit(azimuth=VIEWS[v][0], elevation=VIEWS[v][1], size=IMAGE)
        if (field_name, v) not in references:
            references[field_name, v] = vrlib.render_reference(field, view, transfer=transfer,
                                                               tol=1e-6).alpha
        ref = references[field_name, v]
        volume = field.sample(n)
        key = f"{field_name}|{n}|{v}"
        if (field_name, n, v) in SAVED:
            images[f"{key}|reference"] = ref
        for method in METHODS:
            for filt in FILTERS:
                img = vrlib.render(volume, view, method=method, filter=filt, transfer=transfer,
                                   step=0.5, early_termination=1.0).alpha
                record = {"field": field_name, "n": n, "view": v, "method": method,
                          "filter": filt}
                for metric, fn in vrlib.metrics.METRICS.items():
                    record[metric] = float(fn(img, ref))
                records.append(record)
                if (field_name, n, v) in SAVED:
                    images[f"{key}|{method}|{filt}"] = img
    write_json(result_path(__file__, "accuracy.json"), {
        "records": records, "fields": list(FIELDS), "sizes": SIZES, "views": VIEWS,
        "image": IMAGE, "methods": METHODS, "filters": FILTERS,
        "metrics": list(vrlib.metrics.METRICS), "summary": summarise(records),
        "vanishing_fields": VANISHING,
        "summary_vanishing": summarise([r for r in records if r["field"] in VANISHING]),
        "boundary_rmse": {m: {f: float(np.median([r["rmse"] for r in records
                                                  if r["method"] == m and r["field"] == f]))
                              for f in FIELDS} for m in METHODS},
        "against_catmull_rom": against("catmull-rom", records),
        "against_catmull_rom_vanishing": against(
            "catmull-rom", [r for r in records if r["field"] in VANISHING])})
    with atomic_path(result_path(__file__, "images.npz")) as tmp:
        np.savez_compressed(tmp, **images)


HIGHER_IS_BETTER = {"psnr", "ssim"}


def against(baseline, records):
    """Per method and filter: the median over cases of the rmse ratio to ``baseline``'s in the
    same case, and the fraction of cases where the filter's rmse is lower."""
    by_case = {(r["field"], r["n"], r["view"], r["method"], r["filter"]): r["rmse"]
               for r in records}
    out = {}
    for method in METHODS:
        out[method] = {}
        for filt in FILTERS:
            ratios = [rmse / by_case[key[:4] + (baseline,)] for key, rmse in by_case.items()
                      if key[3] == method and key[4] == filt]
            out[method][filt] = {"median_ratio": float(np.median(ratios)),
                                 "lower": float(np.mean(np.array(ratios) < 1.0))}
    return out


def mean_ranks(records, label):
    """Mean rank (1: most accurate in a case) of each ``label(record)`` under every metric,
    ranking the records case by case."""
    ranks = {m: {} for m in vrlib.metrics.METRICS}
    for case in sorted({(r["field"], r["n"], r["view"]) for r in records}):
        in_case = [r for r in records if (r["field"], r["n"], r["view"]) == case]
        for m in ranks:
            sign = -1.0 if m in HIGHER_IS_BETTER else 1.0
            for rank, r in enumerate(sorted(in_case, key=lambda r, m=m, s=sign: s * r[m]), 1):
                ranks[m].setdefault(label(r), []).append(rank)
    return {m: {k: float(np.mean(v)) for k, v in by.items()} for m, by in ranks.items()}


def summarise(records):
    """Mean rank of each filter per method under each metric, the order that gives, and
    whether every metric gives the same order; then every (method, filter) pair together."""
    out = {}
    for method in METHODS:  # the filters ranked within each method
        rows = [r for r in records if r["method"] == method]
        mean = mean_ranks(rows, lambda r: r["filter"])
        order = {m: sorted(FILTERS, key=lambda f, m=m: mean[m][f]) for m in mean}
        out[method] = {"mean_rank": mean, "order": order,
                       "same_order_every_metric": len({tuple(o) for o in order.values()}) == 1,
                       "same_best_every_metric": len({o[0] for o in order.values()}) == 1,
                       "cases": len({(r["field"], r["n"], r["view"]) for r in rows})}
    configs = [f"{m}/{f}" for m in METHODS for f in FILTERS]
    mean = mean_ranks(records, lambda r: f"{r['method']}/{r['filter']}")
    out["overall"] = {
        "mean_rank": mean,
        "order": {m: sorted(configs, key=lambda c, m=m: mean[m][c]) for m in mean},
        "median_rmse": {c: float(np.median([r["rmse"] for r in records
                                            if f"{r['method']}/{r['filter']}" == c]))
                        for c in configs},
    }
    return out


if __name__ == "__main__":
    main()
