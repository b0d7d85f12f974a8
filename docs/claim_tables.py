"""The report's claim tables, from the verdicts of the claim tests:
``python -m docs.claim_tables build/results/claims/verdicts.json figures/claims``.

Writes ``claims.csv`` (the front page's table: each claim, its verdict with the checks that do
not hold named, and links to its chapters, figures and tests) and ``claim_<n>.csv`` (every test
of claim n with what it checks and its outcome, for the *Claim tests* page). Cells are MyST
Markdown, so the links work in the report. Then compares the README's verdict table with the
verdicts and says which rows differ (a warning: the README is updated by hand, at a commit).
"""

import json
import re
import sys
from pathlib import Path

from chapters.common import write_csv

ROOT = Path(__file__).resolve().parent.parent

#: Each claim as the front page states it, with its evidence: (text, chapters, figures).
#: Chapters are (title, page); figures are paths under figures/.
CLAIMS = {
    "1": ("A separable cubic filter reconstructs more accurately than a pyramid (trilinear) or "
          "a Gaussian filter, by image comparison and by an analytic scale-space error bound.",
          [("Filters", "chapters/ch02_filters.md"),
           ("Image accuracy", "chapters/ch03_accuracy.md")],
          ["ch02_filters/error_bound.png", "ch03_accuracy/filter_ranking.csv"]),
    "2": ("Splatting is the most efficient reconstruction method per reconstructed point.",
          [("Cost", "chapters/ch04_cost.md")],
          ["ch04_cost/regimes.png", "ch04_cost/cost_per_point.csv"]),
    "3": ("Object partitions have the lowest communication cost, scale on 2-D meshes at "
          "constant image size, and need less bandwidth per channel as system and volume grow.",
          [("Parallel rendering", "chapters/ch06_parallel.md")],
          ["ch06_parallel/channel_load.png", "ch06_parallel/scaling.csv"]),
    "4": ("A taxonomy of partitions (image or object; slabs, shafts, blocks; contiguous or "
          "interleaved; static or dynamic) with their communication costs.",
          [("Parallel rendering", "chapters/ch06_parallel.md")],
          ["ch06_parallel/taxonomy.csv"]),
    "5": ("A new load-balancing method for object partitions (the thesis's is unknown: "
          "vrlib's work-sized k-d split).",
          [("MPI renderer", "chapters/ch07_mpi.md")],
          ["ch07_mpi/mpi.png"]),
    "6": ("The third pass of three-pass volume shearing is unnecessary, saving about 30%.",
          [("The third shear pass", "chapters/ch05_shear.md")],
          ["ch05_shear/saving.png"]),
}


def test_name(nodeid):
    """``tests/claims/test_x.py::test_y[p]`` -> ``test_y[p]``."""
    return nodeid.split("::")[-1]


def verdict_cell(number, claim):
    ran = claim["hold"] + claim["fail"]
    cell = f"**{claim['verdict']}**: {claim['hold']} of {ran} checks hold"
    if claim["failing"]:
        names = ", ".join(f"`{test_name(t)}`" for t in claim["failing"])
        cell += f". Does not hold: {names} ([why](claim_tests.md#claim-{number}))"
    return cell


def evidence_cell(number, chapters, figures):
    pages = ", ".join(f"[{title}]({page})" for title, page in chapters)
    files = ", ".join(f"[{Path(f).name}](../figures/{f})" for f in figures)
    return f"{pages}; {files}; [the tests](claim_tests.md#claim-{number})"


def readme_differences(claims, readme):
    """Rows of the README's verdict table (``| n | verdict | ...``) that disagree."""
    found = dict(re.findall(r"^\| (\d) \| \*\*([a-z ]+)\*\*", readme, flags=re.M))
    return [f"claim {n}: README says {found.get(n)!r}, the tests say {c['verdict']!r}"
            for n, c in claims.items() if found.get(n) != c["verdict"]]


def main(verdicts, out):
    claims = json.loads(Path(verdicts).read_text())["claims"]
    out = Path(out)
    rows = [[text, verdict_cell(n, claims[n]), evidence_cell(n, chapters, figures)]
            for n, (text, chapters, figures) in CLAIMS.items()]
    write_csv(out / "claims.csv", ["claim (paraphrased)", "verdict", "evidence"], rows)
    for n, claim in claims.items():
        rows = [[f"`{test_name(t['test'])}`", t["role"], t["outcome"],
                 "holds" if t["holds"] else "**does not hold**", t["checks"]]
                for t in claim["tests"]]
        write_csv(out / f"claim_{n}.csv", ["test", "role", "outcome", "the claim", "checks"],
                  rows)
    for line in readme_differences(claims, (ROOT / "README.md").read_text()):
        print(f"warning: README verdict table is out of date: {line}")


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
