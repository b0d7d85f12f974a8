"""What the ch05 scripts share: the saving ratios and their derived predictions."""

import numpy as np

# Derived, not the thesis's numbers (docs/derivations.md, "The two-pass shear"): averaged over
# random rotations, samples resampled fall from 2.71 N^3 to 1.71 N^3; with compositing counted
# the frame saving is 28-35%; one volume-sized buffer of three goes (peak memory about 2/3).
SAMPLES_PER_N3 = {"shear3": 2.71, "shear2": 1.71}
SAVING = (0.28, 0.35)
PREDICTED = {  # (low, high) of the ratio two-pass / three-pass
    "samples": (SAMPLES_PER_N3["shear2"] / SAMPLES_PER_N3["shear3"],) * 2,
    "operations": (1 - SAVING[1], 1 - SAVING[0]),
    "seconds": (1 - SAVING[1], 1 - SAVING[0]),
    "peak memory": (2 / 3, 2 / 3),
}


def predicted_text(name):
    """A prediction as the table prints it: one value or a range."""
    low, high = PREDICTED[name]
    return f"{low:.2f}" if low == high else f"{low:.2f}-{high:.2f}"


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
