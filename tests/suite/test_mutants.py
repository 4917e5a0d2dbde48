"""The mutation check (`scripts/mutants.py`): its table applies to the code as it is, its classifier cannot flatter."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import mutants  # noqa: E402
from mutations import MUTATIONS  # noqa: E402


def test_names_are_unique_and_each_names_an_existing_file_and_tests() -> None:
    names = [m.name for m in MUTATIONS]
    assert len(names) == len(set(names)), sorted(n for n in names if names.count(n) > 1)
    for m in MUTATIONS:
        assert (ROOT / m.path).is_file() and m.path.startswith("mbsuite/"), m
        assert (ROOT / m.tests).exists() and m.tests.startswith("tests/"), m
        assert m.old != m.new and m.doc, m


@pytest.mark.parametrize("m", MUTATIONS, ids=lambda m: m.name)
def test_each_mutation_applies_exactly_once_to_the_code_as_it_is(m) -> None:
    """The code has moved on when this fails: update the mutation's text (the check refuses to run otherwise)."""
    assert mutants.check_applies(ROOT, m).count(m.old) == 1


def _row(**kw) -> dict:
    return {"nodeid": "tests/x/test_a.py::test_b", "when": "call", "type": "AssertionError", "assertion": True,
            "origin": "tests/x/test_a.py", "message": "assert 1 == 2", **kw}


def test_only_an_assertion_raised_in_a_test_counts_as_a_physics_catch() -> None:
    assert mutants.classify(_row()).kind == "physics"
    # an AssertionError raised inside the package is a crash, not a catch
    assert mutants.classify(_row(origin="mbsuite/models/x.py")).kind == "raised"
    assert mutants.classify(_row(type="ValueError", assertion=False, message="bad")).kind == "raised"
    assert mutants.classify(_row(when="collect", assertion=False)).kind == "broken"
    path, _ = mutants.NON_PHYSICS[0]
    assert mutants.classify(_row(nodeid=path + "[a]")).kind == "non-physics"
    # a test whose name merely starts like a listed one is not on the list
    assert mutants.classify(_row(nodeid=path + "_other")).kind == "physics"


def test_verdict_needs_a_physics_failure() -> None:
    def run(*kinds: str, status: str = "failed") -> mutants.Run:
        return mutants.Run("m.own", ["tests"], [], status, 1, 3, 1.0, "log",
                           [mutants.Failure(f"t{i}", "call", k, "") for i, k in enumerate(kinds)])

    assert mutants.verdict([run("raised", "physics")]) == "caught"
    assert mutants.verdict([run("non-physics", "raised"), run("non-physics")]) == "NOT CAUGHT"
    assert mutants.verdict([run("broken", status="broken")]) == "broken"
    assert mutants.verdict([run(status="hung")]) == "hung"


def test_overlapping_paths_are_passed_once() -> None:
    """pytest >= 9 merges overlapping path arguments; the check passes each folder once, none inside another."""
    assert mutants._without_nested(["tests/a", "tests/a/test_x.py", "tests/b", "tests/a"]) == ["tests/a", "tests/b"]
    assert mutants._without_nested(["tests/ab", "tests/a"]) == ["tests/a", "tests/ab"]
