"""Output of the benchmark scripts: Markdown tables on stdout, JSON records under build/."""

import json
import time
from pathlib import Path

from vrlib.atomic import atomic_path
from vrlib.cost import measure

ROOT = Path(__file__).resolve().parent.parent


def best_of(fn, repeats=3, seconds=0.5):
    """``(seconds, result)``: the fastest of at least ``repeats`` calls of ``fn``, and of as
    many more as fit in about ``seconds`` (at most 100), timed by :func:`vrlib.cost.measure`
    (without its warm-up: the scripts warm up where they must). A short render is timed
    more often: on a machine whose timings drift by 10-20%, three runs of a 10 ms render
    gave thread ratios 0.4 apart from one bench to the next."""
    best, result = measure(fn, repeats=repeats, warmup=False)
    more = min(int(seconds / best) - repeats, 100) if best > 0.0 else 0
    if more > 0:
        again, result = measure(fn, repeats=more, warmup=False)
        best = min(best, again)
    return best, result


def best_of_each(fns, repeats=3, seconds=0.5):
    """``{name: (seconds, result)}`` for callables ``fns`` (``{name: fn}``) to be compared:
    timed in turn, one call of each per round, for at least ``repeats`` rounds and as many
    more as fit in about ``seconds`` per callable (at most 100), the fastest call of each
    kept. Rounds in turn see the same machine: timed one after the other (:func:`best_of`
    each), a ratio of two 10 ms renders drifted by 0.1 to 0.2 from one bench to the next. A
    round starts one callable further along than the last: a render right after another of a
    different kind finds the caches cold (``method="auto"`` timed always after Catmull-Rom
    came out 1.1 to 1.2 times trilinear at 128^2, 1.05 in a loop of its own)."""
    best = {name: (float("inf"), None) for name in fns}
    names, spent = list(fns), 0.0
    for done in range(100):
        if done >= repeats and spent >= seconds * len(fns):
            break
        # each round starts one further along, so that none always follows the same one
        for name in names[done % len(names):] + names[:done % len(names)]:
            start = time.perf_counter()
            result = fns[name]()
            took = time.perf_counter() - start
            spent += took
            if took < best[name][0]:
                best[name] = (took, result)
    return best


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
