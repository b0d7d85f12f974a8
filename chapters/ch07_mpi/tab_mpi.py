"""Tables: equality and bytes per rank count; frame timings with the model's prediction; and
compositing time against image size."""

import numpy as np

from chapters.common import figure_path, read_json, result_path, write_csv

OBJECT = ("direct-send", "binary-swap", "radix-k")
IMAGE = ("image", "image-interleaved")


def main():
    data = read_json(result_path(__file__, "mpi.json"))
    ortho = data["settings"]["orbit"]
    rows = []
    for e in data["equality"]:
        worst = max(c["difference"] for c in e["cases"])
        kb = []
        for key in OBJECT + IMAGE:
            case = next(c for c in e["cases"] if c["compositing"] == key and
                        c["balance"] in ("even", None) and c["orbit"] == ortho)
            field = "voxels" if key in IMAGE else "composite"
            kb.append(np.mean([r["bytes"][field] for r in case["ranks"]]) / 1e3)
        rows.append([e["ranks"], len(e["cases"]), f"{worst:.1e}",
                     *(f"{v:.1f}" for v in kb)])
    write_csv(figure_path(__file__, "equality.csv"),
              ["ranks", "images compared", "max difference from serial",
               *(f"{k} kB/rank" for k in OBJECT), "image kB/rank",
               "image interleaved kB/rank"], rows)
    times = data["summary"]["times"]
    rows = []
    for t in data["timing"]:
        for case in t["cases"]:
            name, ranks = case["compositing"], t["ranks"]
            one = times[f"{name} 1"]["median"]
            spread = times[f"{name} {ranks}"]
            rows.append([ranks, name, f"{case['seconds']:.3f}",
                         f"{spread['least']:.3f}-{spread['most']:.3f}",
                         f"{one / case['seconds']:.2f}",
                         f"{one / case['seconds'] / ranks:.2f}",
                         "" if ranks <= 2 else "oversubscribed"])
    for name, model in data["prediction"]["rows"].items():
        for r in model:
            if r["ranks"] > 8:
                rows.append([r["ranks"], f"{name} (model)", f"{r['frame_s']:.4f}", "",
                             f"{r['speedup']:.1f}", f"{r['speedup'] / r['ranks']:.2f}",
                             f"{r['rounds']} rounds"])
    write_csv(figure_path(__file__, "timing.csv"),
              ["ranks", "compositing", "median seconds per frame", "least-most",
               "speedup", "efficiency", "note"], rows)
    summary = data["summary"]
    write_csv(figure_path(__file__, "sent.csv"),
              ["compositing", "sent / simulated, least", "most"],
              [[k, f"{v[0]:.2f}", f"{v[1]:.2f}"]
               for k, v in summary["sent_over_simulated"].items()])
    keys = ("even", "interleaved", "work", "image", "image-interleaved")
    rows = []
    for b in data["balance"]:
        group = f"{b['scene']} {b['ranks']}"
        rows.append([f"{b['scene']}, {b['ranks']}",
                     *(f"{summary['imbalance'][f'{group} {k}']:.2f}" for k in keys)])
    write_csv(figure_path(__file__, "balance.csv"),
              ["scene, ranks", "equal bricks", "interleaved bricks (4 per rank)",
               "work-sized split", "image tiles", "image, interleaved tiles"], rows)
    write_csv(figure_path(__file__, "radix_vs_swap.csv"),
              ["ranks", "image width", "time, radix-k / binary swap",
               "most bytes sent by a rank, radix-k / binary swap"],
              [[*key.split(" "), f"{r['time']:.2f}", f"{r['bytes']:.2f}"]
               for key, r in summary["radix_vs_swap"].items()])
    rows = []
    for run in data["compositing"]:
        for case in run["cases"]:
            rows.append([run["ranks"], case["width"], case["compositing"],
                         f"{case['seconds'] * 1e3:.1f}",
                         f"{case['least'] * 1e3:.1f}-{case['most'] * 1e3:.1f}",
                         f"{max(case['bytes']) / 1e6:.2f}"])
    write_csv(figure_path(__file__, "compositing.csv"),
              ["ranks", "image width", "compositing", "median ms", "least-most ms",
               "most MB sent by a rank"], rows)


if __name__ == "__main__":
    main()
