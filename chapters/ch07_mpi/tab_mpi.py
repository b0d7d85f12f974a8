"""Tables: equality and bytes per rank count; timings, speedup and efficiency."""

import numpy as np

from chapters.common import figure_path, read_json, result_path, write_csv


def main():
    data = read_json(result_path(__file__, "mpi.json"))
    rows = []
    for e in data["equality"]:
        for case in e["cases"]:
            field = "voxels" if case["compositing"] == "image" else "composite"
            sent = np.array([r["bytes"][field] for r in case["ranks"]], dtype=float)
            rows.append([e["ranks"], case["compositing"], case["balance"] or "",
                         f"{case['difference']:.1e}", f"{sent.mean() / 1e3:.1f}",
                         f"{sent.max() / 1e3:.1f}"])
    write_csv(figure_path(__file__, "equality.csv"),
              ["ranks", "partition / compositing", "balance", "max difference from serial",
               "mean kB sent per rank", "max kB sent per rank"], rows)
    one = {c["compositing"]: c["seconds"] for c in data["timing"][0]["cases"]}
    rows = []
    for t in data["timing"]:
        for case in t["cases"]:
            speedup = one[case["compositing"]] / case["seconds"]
            rows.append([t["ranks"], case["compositing"], f"{case['seconds']:.3f}",
                         f"{speedup:.2f}", f"{speedup / t['ranks']:.2f}"])
    for r in data["prediction"]["rows"]:
        if r["ranks"] > 2:
            rows.append([r["ranks"], "binary-swap (model)", f"{r['frame_s']:.4f}",
                         f"{r['speedup']:.1f}", f"{r['speedup'] / r['ranks']:.2f}"])
    write_csv(figure_path(__file__, "timing.csv"),
              ["ranks", "compositing", "seconds per frame", "speedup", "efficiency"], rows)


if __name__ == "__main__":
    main()
