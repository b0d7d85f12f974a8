"""Output of the benchmark scripts: Markdown tables on stdout, JSON records under build/."""

import json
import time
from pathlib import Path

from vrlib.atomic import atomic_path

ROOT = Path(__file__).resolve().parent.parent


def best_of(fn, repeats=3):
    """``(seconds, result)`` of the fastest of ``repeats`` calls of ``fn``."""
    runs = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        runs.append((time.perf_counter() - start, result))
    return min(runs, key=lambda run: run[0])


def markdown(header, rows):
    """The rows under the header as a Markdown table (one string)."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(cell) for cell in row) + " |" for row in rows]
    return "\n".join(lines)


def write_record(name, record):
    """Write ``build/results/benchmarks/<name>.json`` atomically and say where."""
    out = ROOT / "build" / "results" / "benchmarks" / f"{name}.json"
    with atomic_path(out) as tmp:
        tmp.write_text(json.dumps(record, indent=2) + "\n")
    print(f"\nwritten: {out.relative_to(ROOT)}")
