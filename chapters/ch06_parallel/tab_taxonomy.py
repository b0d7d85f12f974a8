"""Tables: the taxonomy with each class's per-frame communication, and the fitted scaling
exponents of the simulated classes."""


from chapters.ch06_parallel.run_network import short_name
from chapters.common import figure_path, read_json, result_path, write_csv
from vrlib.parallel.taxonomy import TAXONOMY, communication


def main():
    data = read_json(result_path(__file__, "network.json"))
    counted = []
    for p in TAXONOMY:
        row = data["per_class"][short_name(p)]
        counted.append([p.name, *communication(p), f"{row['total'] / 1e6:.2f} (P={row['nodes']})"])
    write_csv(figure_path(__file__, "taxonomy.csv"), ["class", "what moves each frame",
                                                      "how much", "simulated MB per frame"],
              counted)
    rows = []
    at = 64
    for key, fits in data["exponents"].items():
        name, net = key.rsplit(" (", 1)
        net = net.rstrip(")")
        sel = [r for r in data["rows"] if r["class"] == name and r["torus"] == (net == "torus")
               and r["nodes"] == at]
        kb = f"{sel[0]['total'] / 1e6:.2f}" if sel else ""
        busiest = f"{sel[0]['max'] / 1e3:.0f}" if sel else ""
        rows.append([name, net, kb, busiest] + [
            "" if fits[s] is None else f"{fits[s]:+.2f}" for s in ("total", "max", "mean",
                                                                   "bisection")]
            + [f"{fits['range'][0]}-{fits['range'][1]}"])
    rows.sort(key=lambda r: (r[1], r[0]))
    write_csv(figure_path(__file__, "scaling.csv"),
              ["class", "network", f"MB per frame at P={at}", f"busiest kB at P={at}",
               "exponent total", "exponent busiest", "exponent mean", "exponent bisection",
               "P range"], rows)


if __name__ == "__main__":
    main()
