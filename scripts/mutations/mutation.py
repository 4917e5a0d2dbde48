"""One seeded defect: a text edit of one file and the tests that should catch it."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Mutation:
    """Replace the one occurrence of `old` in `path` by `new`; `tests` is the mutated model's own test folder/file."""

    name: str
    path: str
    old: str
    new: str
    doc: str
    tests: str
