"""The report's verdict rule (tests/claims/conftest.py), on made-up outcomes."""

import importlib.util
from pathlib import Path

import pytest

spec = importlib.util.spec_from_file_location(
    "claims_conftest", Path(__file__).parent / "claims" / "conftest.py")
rules = importlib.util.module_from_spec(spec)
spec.loader.exec_module(rules)


def tests(*pairs):
    return [{"role": role, "outcome": outcome} for role, outcome in pairs]


@pytest.mark.parametrize("outcomes, expected", [
    (tests(("supports", "passed"), ("supports", "passed")), "reproduced"),
    (tests(("supports", "passed"), ("refutes", "passed")), "partly reproduced"),
    (tests(("supports", "passed"), ("supports", "failed")), "partly reproduced"),
    (tests(("supports", "failed"), ("refutes", "passed")), "not reproduced"),
    (tests(("supports", "passed"), ("refutes", "failed")), "reproduced"),
    (tests(("beyond", "passed"), ("beyond", "passed")), "beyond the thesis"),
    (tests(("beyond", "failed")), "not reproduced"),
    (tests(("supports", "passed"), ("supports", "skipped")), "reproduced"),
])
def test_verdict_rule(outcomes, expected):
    assert rules.verdict(outcomes) == expected
