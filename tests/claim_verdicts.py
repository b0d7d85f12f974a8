"""Records each claim test's outcome, so that the report's verdicts come from the tests
(a pytest plugin, loaded by ``tests/conftest.py``).

Every test in ``tests/claims/`` carries ``@pytest.mark.claim(number, role)``:
``"supports"`` (it checks a part of the thesis's claim that holds), ``"refutes"`` (it checks a
part that does not hold: its passing means that part is not reproduced) or ``"beyond"`` (it
checks something the package adds where the thesis's own version is unknown). With
``VRLIB_VERDICTS=path`` set, the outcomes and each claim's verdict are written there as JSON
when the session ends.
"""

import json
import os
from pathlib import Path

import pytest

from vrlib.atomic import atomic_path

CLAIMS_DIR = Path(__file__).resolve().parent / "claims"

CLAIMS = {
    1: "A separable cubic filter reconstructs more accurately than a pyramid or a Gaussian "
       "filter (error bound and image metrics)",
    2: "Splatting is more efficient per reconstructed point than ray casting or shearing",
    3: "Object partitions have the lowest communication; at constant image size the bandwidth "
       "per channel falls as the machine and volume grow",
    4: "A taxonomy of partitions with their communication costs",
    5: "A new load-balancing method for object partitions",
    6: "The third shear pass is unnecessary, saving about 30%",
}
ROLES = ("supports", "refutes", "beyond")
_OUTCOMES = []


def verdict(tests):
    """``reproduced``, ``partly reproduced``, ``not reproduced`` or ``beyond the thesis``."""
    ran = [t for t in tests if t["outcome"] in ("passed", "failed")]
    supports = [t for t in ran if t["role"] == "supports"]
    beyond = [t for t in ran if t["role"] == "beyond"]
    refuted = [t for t in ran if t["role"] == "refutes" and t["outcome"] == "passed"]
    held = [t for t in supports if t["outcome"] == "passed"]
    if not supports and beyond:
        return "beyond the thesis" if all(t["outcome"] == "passed" for t in beyond) \
            else "not reproduced"
    if not held:
        return "not reproduced"
    if len(held) < len(supports) or refuted:
        return "partly reproduced"
    return "reproduced"


def pytest_collection_modifyitems(items):
    for item in items:
        if Path(str(item.fspath)).resolve().parent != CLAIMS_DIR:
            continue
        mark = item.get_closest_marker("claim")
        if mark is None or mark.args[0] not in CLAIMS or mark.args[1] not in ROLES:
            raise pytest.UsageError(f"{item.nodeid} needs @pytest.mark.claim(number, role) "
                                    f"with number in {sorted(CLAIMS)} and role in {ROLES}")


def pytest_runtest_logreport(report):
    if report.when != "call" and not (report.when == "setup" and report.outcome != "passed"):
        return
    path = Path(report.fspath).resolve()
    if path.parent != CLAIMS_DIR:
        return
    _OUTCOMES.append({"nodeid": report.nodeid, "outcome": report.outcome})


def pytest_sessionfinish(session):
    target = os.environ.get("VRLIB_VERDICTS")
    if not target:
        return
    marks, docs = {}, {}
    for item in session.items:
        mark = item.get_closest_marker("claim")
        if mark is not None:
            marks[item.nodeid] = mark.args
            docs[item.nodeid] = " ".join((item.function.__doc__ or "").split("\n\n")[0].split())
    claims = {str(n): {"claim": text, "tests": []} for n, text in CLAIMS.items()}
    for entry in _OUTCOMES:
        if entry["nodeid"] not in marks:
            continue
        number, role = marks[entry["nodeid"]]
        claims[str(number)]["tests"].append({"test": entry["nodeid"], "role": role,
                                             "outcome": entry["outcome"],
                                             "checks": docs[entry["nodeid"]]})
    for entry in claims.values():
        entry["verdict"] = verdict(entry["tests"])
        tests = entry["tests"]
        # Checks whose outcome says the claim (or vrlib's own version of it) holds, and
        # checks whose outcome says a part of it does not (named, for the report).
        for t in tests:
            t["holds"] = (t["role"] != "refutes") == (t["outcome"] == "passed")
        ran = [t for t in tests if t["outcome"] in ("passed", "failed")]
        entry["hold"] = sum(t["holds"] for t in ran)
        entry["fail"] = len(ran) - entry["hold"]
        entry["failing"] = [t["test"] for t in ran if not t["holds"]]
    with atomic_path(target) as tmp:
        tmp.write_text(json.dumps({"claims": claims}, indent=2, sort_keys=True) + "\n")
