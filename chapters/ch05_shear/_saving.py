"""What the ch05 scripts share: the saving ratios and the brief's predictions."""

import numpy as np

# Brief section 8 (derived, not the thesis's numbers): samples 2.71 N^3 -> 1.71 N^3 (0.63),
# frame saving 28-35% (ratio 0.65-0.72), peak memory about a third lower (ratio ~0.67).
PREDICTED = {"samples": "0.63", "operations": "0.65-0.72", "seconds": "0.65-0.72",
             "peak memory": "about 0.67"}


def ratios(data):
    rows = data["rotations"]
    n3 = data["N"] ** 3
    out = {
        "samples": np.array([r["shear2"]["resampled"] / r["shear3"]["resampled"] for r in rows]),
        "operations": np.array([r["shear2"]["operations"] / r["shear3"]["operations"]
                                for r in rows]),
        "seconds": np.array([r["shear2"]["seconds"] / r["shear3"]["seconds"] for r in rows]),
        "peak memory": np.array([r["shear2"]["peak_bytes"] / r["shear3"]["peak_bytes"]
                                 for r in rows]),
    }
    per_n3 = {m: np.array([r[m]["resampled"] / n3 for r in rows]) for m in ("shear3", "shear2")}
    return out, per_n3
