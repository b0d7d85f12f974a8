"""Table: each filter's response at DC, half Nyquist, Nyquist, its sidelobe peak and 2 pi (a
prefiltered filter's effective response: prefilter and kernel together)."""

from chapters.common import figure_path, read_json, result_path, write_csv


def main():
    summary = read_json(result_path(__file__, "responses.json"))
    rows = [
        [label, f"{s['dc']:.4f}", f"{s['half_nyquist']:.4f}", f"{s['nyquist']:.4f}",
         f"{s['sidelobe_peak']:.4f}", f"{s['at_2pi']:.2e}",
         "yes" if s["partition_of_unity"] else "no", "yes" if s["interpolating"] else "no",
         "yes" if s["prefiltered"] else "no"]
        for label, s in summary.items()
    ]
    write_csv(figure_path(__file__, "nyquist.csv"),
              ["filter", "K(0)", "K(pi/2)", "K(pi)", "max |K| past 1.5 pi", "K(2 pi)",
               "partition of unity", "interpolates samples", "prefiltered"], rows)


if __name__ == "__main__":
    main()
