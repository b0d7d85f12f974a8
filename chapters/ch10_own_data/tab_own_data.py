"""Tables of the "Your own data" page: formats read back, and the renders' costs."""

from chapters.common import figure_path, read_json, result_path, write_csv


def main():
    info = read_json(result_path(__file__, "own_data.json"))
    write_csv(figure_path(__file__, "formats.csv"),
              ["format", "shape (z, y, x)", "spacing (mm)", "load (s)",
               "largest sample difference", "largest image difference"],
              [[r["format"], "x".join(map(str, r["shape"])),
                ", ".join(f"{s:g}" for s in r["spacing"]), f"{r['load_seconds']:.2f}",
                f"{r['samples_difference']:.1e}", f"{r['image_difference']:.1e}"]
               for r in info["formats"]])
    write_csv(figure_path(__file__, "transfer_functions.csv"),
              ["image", "kind", "volume (z, y, x)", "render (s)", "mean opacity"],
              [[r["name"], r["kind"], "x".join(map(str, r["shape"])), f"{r['seconds']:.2f}",
                f"{r['mean_alpha']:.3f}"] for r in info["transfer_functions"]])
    write_csv(figure_path(__file__, "anisotropic.csv"),
              ["method", "rmse against ray casting at step 1/8", "render (s)"],
              [[m, f"{r['rmse']:.1e}", f"{r['seconds']:.2f}"]
               for m, r in info["anisotropic"]["methods"].items()])


if __name__ == "__main__":
    main()
