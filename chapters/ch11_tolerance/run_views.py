"""The promise of ``render(..., tolerance=t)`` seen along and near the lattice, where every
ray samples it at (nearly) the same phase: the chapter's seven analytic scenes from views
along x, y and z, along the diagonal of x and y and the volume's diagonal, and 1, 3 and 8
degrees off x, at tolerances 1e-2 and 1e-3, each against the exact image of the field the
filter reconstructs. Writes ``build/results/ch11_tolerance/views.json``.
"""

import numpy as np

import vrlib
from chapters.ch11_tolerance._cases import analytic_scenes
from chapters.common import by_profile, progress, result_path, write_json

SIZE = by_profile(64, 128)
TOLERANCES = [1e-2, 1e-3]
#: Orthographic views by name: along the lattice's axes and diagonals, and near x.
VIEWS = {"along x": dict(azimuth=0.0, elevation=0.0),
         "along y": dict(azimuth=90.0, elevation=0.0),
         "along z": dict(azimuth=0.0, elevation=90.0),
         "diagonal of x and y": dict(azimuth=45.0, elevation=0.0),
         "diagonal of the volume": dict(azimuth=45.0,
                                        elevation=float(np.degrees(np.arctan(2 ** -0.5)))),
         "1 degree off x": dict(azimuth=1.0, elevation=0.0),
         "3 degrees off x": dict(azimuth=3.0, elevation=0.0),
         "8 degrees off x": dict(azimuth=8.0, elevation=0.0)}


def main():
    cases = []
    for key, label, volume, transfer in progress(analytic_scenes(), "scenes"):
        field = vrlib.ReconstructedField(volume)
        for view_name, orbit in VIEWS.items():
            view = vrlib.View.orbit(size=SIZE, **orbit)
            reference = vrlib.render_reference(field, view, transfer=transfer, tol=1e-8)
            for tolerance in TOLERANCES:
                case = {"scene": key, "label": label, "view": view_name,
                        "tolerance": tolerance}
                try:
                    image = vrlib.render(volume, view, transfer=transfer, tolerance=tolerance)
                except ValueError as refusal:
                    cases.append({**case, "refused": str(refusal)})
                    continue
                choices = image.stats.choices
                cases.append({**case, "rmse": vrlib.metrics.rmse(image, reference),
                              "estimate": choices["estimate"], "step": choices["step"],
                              "phase_checks": len(choices["pilot"]["phase"])})
    rendered = [c for c in cases if "rmse" in c]
    worst = {view: max((c["rmse"] / c["tolerance"] for c in rendered if c["view"] == view),
                       default=None) for view in VIEWS}
    write_json(result_path(__file__, "views.json"), {
        "cases": cases, "size": SIZE, "tolerances": TOLERANCES,
        "views": [[name, orbit] for name, orbit in VIEWS.items()],  # in order
        "summary": {
            "cases": len(cases), "kept": sum(c["rmse"] <= c["tolerance"] for c in rendered),
            "refused": len(cases) - len(rendered),
            "worst_error_over_tolerance": max(c["rmse"] / c["tolerance"] for c in rendered),
            "worst_by_view": worst,
            "halved": sum(c["phase_checks"] > 1 for c in rendered),
            "missed": [f"{c['label']}, {c['view']}, tolerance {c['tolerance']:g} "
                       f"({c['rmse'] / c['tolerance']:.2f} of it)"
                       for c in rendered if c["rmse"] > c["tolerance"]]}})


if __name__ == "__main__":
    main()
