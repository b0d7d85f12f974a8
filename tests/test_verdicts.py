"""The report's verdict rule (tests/claim_verdicts.py), on made-up outcomes."""

import claim_verdicts as rules
import pytest


def outcomes_of(*pairs):
    return [{"role": role, "outcome": outcome} for role, outcome in pairs]


@pytest.mark.parametrize("outcomes, expected", [
    (outcomes_of(("supports", "passed"), ("supports", "passed")), "reproduced"),
    (outcomes_of(("supports", "passed"), ("refutes", "passed")), "partly reproduced"),
    (outcomes_of(("supports", "passed"), ("supports", "failed")), "partly reproduced"),
    (outcomes_of(("supports", "failed"), ("refutes", "passed")), "not reproduced"),
    (outcomes_of(("supports", "passed"), ("refutes", "failed")), "reproduced"),
    (outcomes_of(("beyond", "passed"), ("beyond", "passed")), "beyond the thesis"),
    (outcomes_of(("beyond", "failed")), "not reproduced"),
    (outcomes_of(("supports", "passed"), ("supports", "skipped")), "reproduced"),
])
def test_verdict_rule(outcomes, expected):
    assert rules.verdict(outcomes) == expected
