"""Every machine's cost measurements, merged, with the cost model fitted per machine and
backend (``vrlib.cost.fit_model``)."""

import json

import numpy as np

from chapters.common import ROOT, result_path
from vrlib.cost import fit_model


def machines(script):
    """Records of every machine: measured here (``build/results``) or committed from elsewhere
    (``chapters/ch04_cost/machines``); one per machine id, the build's own first."""
    paths = sorted(result_path(script, "machines").glob("*.json"))
    paths += sorted((ROOT / "chapters" / "ch04_cost" / "machines").glob("*.json"))
    records = {}
    for path in paths:
        record = json.loads(path.read_text())
        records.setdefault(record["machine"]["id"], record)
    return list(records.values())


def fitted(record):
    """Rows of one machine with the model's prediction, and the constants per backend."""
    rows, constants = [], {}
    for backend in sorted({r["backend"] for r in record["rows"]}):
        here = [r for r in record["rows"] if r["backend"] == backend]
        c, predicted = fit_model([r["operations"] for r in here], [r["points"] for r in here],
                                 [r["seconds"] for r in here])
        constants[backend] = c
        for r, p in zip(here, predicted, strict=True):
            rows.append({**r, "predicted": float(p),
                         "model_error": float(p / r["seconds"] - 1.0)})
    return rows, constants


def summary(records):
    out = {}
    for record in records:
        rows, constants = fitted(record)
        errors = np.abs([r["model_error"] for r in rows])
        out[record["machine"]["id"]] = {
            "cpu": record["machine"]["cpu"], "cores": record["machine"]["cores"],
            "constants": constants, "median_model_error": float(np.median(errors)),
            "max_model_error": float(errors.max())}
    return out
