"""Tables: what each method renders (``figures/ch09_gallery/matrix.csv``: a row per method
and projection, a column per feature, each cell the rmse against the ray caster or a refusal's
letter) and the refusals' own words (``refusals.csv``)."""

import re

from chapters.common import figure_path, read_json, result_path, write_csv

#: Shorter column and row names, so that the table fits the page's column.
SHORT = {"orthographic": "ortho.", "perspective": "persp.", "Phong shading": "shaded",
         "maximum intensity": "MIP", "average intensity": "average",
         "shaded labels (box)": "labels, shaded", "colour table": "colour"}


def main():
    data = read_json(result_path(__file__, "matrix.json"))
    reasons = []  # distinct refusal messages, lettered in order of appearance
    table = {}
    for c in data["cells"]:
        if c["rendered"]:
            # "mode='direct'" -> "direct": the renderers page says which option it is.
            option = c["option"].split("=")[-1].strip("'") if c["option"] else ""
            text = f"{c['rmse']:.4f}" + (f" ({option})" if option else "")
        else:
            reason = re.sub(r" \(not '\w+'\)", "", c["reason"])  # one letter for all methods
            if reason not in reasons:
                reasons.append(reason)
            text = f"refused ({chr(ord('a') + reasons.index(reason))})"
        table[c["projection"], c["method"], c["feature"]] = text
    rows = [[method, SHORT.get(projection, projection),
             *(table[projection, method, f] for f in data["features"])]
            for projection in data["projections"] for method in data["methods"]]
    write_csv(figure_path(__file__, "matrix.csv"),
              ["method", "view", *(SHORT.get(f, f) for f in data["features"])], rows)
    write_csv(figure_path(__file__, "refusals.csv"), ["", "the refusal, as vrlib.render says it"],
              [[chr(ord("a") + i), reason] for i, reason in enumerate(reasons)])


if __name__ == "__main__":
    main()
