"""Table: two-pass / three-pass ratios over the rotations, beside their derived predictions.

Also writes ``build/results/ch05_shear/summary.json`` for the report's text.
"""

import numpy as np

from chapters.ch05_shear._saving import PREDICTED, SAMPLES_PER_N3, SAVING, predicted_text, ratios
from chapters.common import figure_path, read_json, result_path, write_csv, write_json


def main():
    data = read_json(result_path(__file__, "saving.json"))
    out, per_n3 = ratios(data)
    rows = [[name, f"{v.mean():.3f}", f"{v.min():.3f}", f"{v.max():.3f}",
             predicted_text(name)]
            for name, v in out.items()]
    write_csv(figure_path(__file__, "saving.csv"),
              ["two-pass / three-pass", "mean", "min", "max", "derived"], rows)
    write_json(result_path(__file__, "summary.json"), {
        "rotations": len(data["rotations"]), "N": data["N"], "image": data["image"],
        **{name.replace(" ", "_"): {"mean": float(v.mean()), "min": float(v.min()),
                                    "max": float(v.max()),
                                    "median": float(np.median(v))} for name, v in out.items()},
        "samples_per_n3": {m: float(v.mean()) for m, v in per_n3.items()},
        "derived": {"samples_per_n3": SAMPLES_PER_N3, "saving": list(SAVING),
                    **{name.replace(" ", "_"): list(PREDICTED[name]) for name in PREDICTED}},
    })


if __name__ == "__main__":
    main()
