"""Output of the benchmark scripts: Markdown tables on stdout, JSON records under build/."""

import json
from pathlib import Path

from vrlib.atomic import atomic_path
from vrlib.cost import measure

ROOT = Path(__file__).resolve().parent.parent


def best_of(fn, repeats=3):
    """``(seconds, result)``: the fastest of ``repeats`` calls of ``fn``, timed by
    :func:`vrlib.cost.measure` (without its warm-up: the scripts warm up where they must)."""
    return measure(fn, repeats=repeats, warmup=False)


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
