"""Tables: splatting's defects measured (faces, popping, perspective, aliasing, culling)."""

from chapters.common import figure_path, read_json, result_path, write_csv


def main():
    data = read_json(result_path(__file__, "splatting.json"))
    modes = ["sheet", "image-aligned", "direct"]
    write_csv(figure_path(__file__, "splat_faces.csv"),
              ["filter", *[f"splat {m}" for m in modes], "ray caster (step 0.5)",
               "splat - ray caster, steps 0.2 / 0.1 / 0.05 (rmse)"],
              [[r["filter"], *[f"{r[m]:.5f}" for m in modes], f"{r['raycast']:.5f}",
                " / ".join(f"{a['rmse']:.1e}" for a in r["against_raycast"])]
               for r in data["faces"]])
    write_csv(figure_path(__file__, "splat_popping.csv"),
              ["method", "largest change across 45 degrees (44.9 to 45.1)",
               "largest change before it (44.7 to 44.9)", "ratio"],
              [[r["method"], f"{r['across']:.3f}", f"{r['before']:.3f}",
                f"{r['across'] / r['before']:.2f}"] for r in data["popping"]])
    write_csv(figure_path(__file__, "splat_perspective.csv"),
              ["filter", *[f"splat {m}" for m in modes], "ray caster"],
              [[r["filter"], *[f"{r[m]:.4f}" for m in modes], f"{r['raycast']:.4f}"]
               for r in data["perspective"]["rows"]])
    angles = sorted({a["angle"] for a in data["perspective"]["angles"]})
    filters = list(dict.fromkeys(a["filter"] for a in data["perspective"]["angles"]))
    write_csv(figure_path(__file__, "splat_angles.csv"),
              ["filter", *[f"{a} degrees" for a in angles]],
              [[f, *[f"{a['relative_error']:.3f}" for a in data["perspective"]["angles"]
                     if a["filter"] == f]] for f in filters])
    write_csv(figure_path(__file__, "splat_aliasing.csv"),
              ["renderer (trilinear)", "rmse against pixel centres", "rmse against pixel means"],
              [[r["method"], f"{r['rmse_centres']:.5f}", f"{r['rmse_area']:.5f}"]
               for r in data["aliasing"]["rows"]])
    write_csv(figure_path(__file__, "splat_culling.csv"),
              ["mode", "filter", "footprints drawn without culling", "with culling",
               "frame speed-up", "largest image change"],
              [[r["mode"], r["filter"], r["footprints"][0], r["footprints"][1],
                f"{r['speedup']:.1f}", f"{r['change']:.1e}"]
               for r in data["culling"]["rows"]])


if __name__ == "__main__":
    main()
