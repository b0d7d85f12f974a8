"""Pre-integrated classification against point sampling on steep transfer functions: the
error against the exact image of the reconstructed field as the step shrinks, for point
sampling as it was (lattice ends), point sampling with exact ends, and pre-integration; and
how many samples pre-integration takes for the error point sampling reaches at each step.
Empty-space skipping is off, so that samples count the method, not the scene. Writes
``build/results/ch11_tolerance/preintegration.json``.
"""

import numpy as np

import data_gen
import vrlib
from chapters.ch11_tolerance._cases import peak
from chapters.common import by_profile, progress, result_path, write_json

SIZE = by_profile(96, 192)
STEPS = [float(2.0**-k) for k in range(-1, 6)]  # 2 down to 1/32 voxel
SETTINGS = {"point, lattice ends": ("point", "lattice"),
            "point, exact ends": ("point", "exact"),
            "pre-integrated": ("preintegrated", "exact")}


def scenes():
    ml = data_gen.make_field("marschner-lobb").sample(41)
    blob = data_gen.make_field("gaussian-blob", sigma=0.3).sample(48)
    z, y, x = np.meshgrid(*[np.linspace(-1.0, 1.0, 17)] * 3, indexing="ij")
    ramp = vrlib.Volume(0.25 * (x + 1.0) + 0.25 * (y + 1.0))
    return [("Marschner-Lobb 41^3, peak 3% wide", ml, peak(ml)),
            ("Marschner-Lobb 41^3, peak 10% wide", ml, peak(ml, width=0.1, density=10.0)),
            ("blob 48^3, peak 3% wide", blob, peak(blob)),
            ("blob 48^3, peak 10% wide", blob, peak(blob, width=0.1, density=10.0)),
            ("linear field 17^3, peak 3% wide", ramp, peak(ramp, centre=0.5))]


def samples_for(errors, samples, target):
    """Samples needed to reach ``target``, interpolated in log-log between the steps (on the
    running minimum of the errors); None when no step reaches it."""
    envelope = np.minimum.accumulate(errors)
    if envelope[-1] > target:
        return None
    i = int(np.argmax(envelope <= target))
    if i == 0:
        return float(samples[0])
    f = (np.log(target) - np.log(envelope[i - 1])) / (np.log(envelope[i])
                                                       - np.log(envelope[i - 1]))
    return float(np.exp(np.log(samples[i - 1]) + f * (np.log(samples[i])
                                                      - np.log(samples[i - 1]))))


def main():
    view = vrlib.View.orbit(azimuth=30, elevation=20, size=SIZE)
    rows = []
    for label, volume, transfer in progress(scenes(), "scenes"):
        exact = vrlib.render_reference(vrlib.ReconstructedField(volume), view,
                                       transfer=transfer, tol=1e-8)
        curves = {}
        for name, (classification, ends) in SETTINGS.items():
            images = [vrlib.render(volume, view, transfer=transfer, step=s,
                                   early_termination=1.0, empty_space_skipping=False,
                                   classification=classification, segment_ends=ends)
                      for s in STEPS]
            curves[name] = {"rmse": [vrlib.metrics.rmse(i, exact) for i in images],
                            "samples": [i.stats.samples for i in images]}
        before, pre = curves["point, lattice ends"], curves["pre-integrated"]
        ratios = []
        for error, samples in zip(before["rmse"], before["samples"], strict=True):
            needed = samples_for(np.array(pre["rmse"]), np.array(pre["samples"]), error)
            ratios.append(None if needed is None else samples / needed)
        rows.append({"scene": label, "curves": curves, "sample_ratio": ratios})
    found = [r for row in rows for r in row["sample_ratio"][1:] if r is not None]
    write_json(result_path(__file__, "preintegration.json"),
               {"rows": rows, "steps": STEPS, "size": SIZE,
                "ratio_min": min(found), "ratio_median": float(np.median(found)),
                "ratio_max": max(found)})


if __name__ == "__main__":
    main()
