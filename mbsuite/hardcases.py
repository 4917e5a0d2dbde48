"""The hard-case harness: situations that break naive multibody codes, each with the scene that provokes it and what
must hold (no NaN/inf, bounded work in steps or RHS calls, bounded closure residual, bounded energy drift, correct
detection and reporting).

Each model declares its own cases (`HARD_CASES` in the module named by its `ModelSpec.cases`); this module names no
model: it holds the `HardCase`/`Checker` machinery, collects the registry from the models and runs cases.
`mbsuite hardcases` lists the registry; `mbsuite hardcases --run` runs it and prints what was measured against each
bound; `tests/suite/test_hardcases.py` runs every entry (entries marked slow only under `pytest -m slow`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import MbsuiteError


@dataclass
class Check:
    """One assertion of a hard case: what, whether it held, the measured value and its bound."""
    what: str
    ok: bool
    value: Any = None
    bound: Any = None

    def line(self) -> str:
        """The assertion as one report line."""
        v = "" if self.value is None else f" = {_fmt(self.value)}"
        b = "" if self.bound is None else f" (bound {_fmt(self.bound)})"
        return f"[{'ok' if self.ok else 'FAIL'}] {self.what}{v}{b}"


def _fmt(x: Any) -> str:
    if isinstance(x, float | np.floating):
        return f"{float(x):.4g}"
    return str(x)


class Checker:
    """Collects the assertions of one hard case (all are evaluated; the case fails if any fails)."""

    def __init__(self) -> None:
        self.checks: list[Check] = []
        self.measured: dict[str, Any] = {}

    def le(self, what: str, value: float, bound: float) -> None:
        """Assert `value <= bound` (a NaN fails)."""
        value = float(value)
        self.checks.append(Check(what, bool(math.isfinite(value) and value <= bound), value, f"<= {bound:g}"))

    def ge(self, what: str, value: float, bound: float) -> None:
        """Assert `value >= bound` (a NaN fails)."""
        value = float(value)
        self.checks.append(Check(what, bool(math.isfinite(value) and value >= bound), value, f">= {bound:g}"))

    def true(self, what: str, cond: bool, value: Any = None) -> None:
        """Assert a condition, recording `value` beside it."""
        self.checks.append(Check(what, bool(cond), value))

    def finite(self, what: str, *arrays: Any) -> None:
        """Assert every value of every array is finite."""
        ok = all(np.all(np.isfinite(np.asarray(a, float))) for a in arrays)
        self.checks.append(Check(f"{what}: no NaN/inf", ok))

    def raises(self, what: str, fn: Callable[[], Any], exc: type[BaseException] | tuple, match: str) -> None:
        """Assert that `fn()` raises `exc` with `match` in its message (any other outcome fails)."""
        try:
            fn()
        except exc as e:  # noqa: B030 - exc is a class or tuple of classes
            self.checks.append(Check(what, match.lower() in str(e).lower(), f"{type(e).__name__}: {str(e)[:90]}"))
            return
        except Exception as e:  # noqa: BLE001 - a different error is a failed check, reported
            self.checks.append(Check(what, False, f"unexpected {type(e).__name__}: {str(e)[:90]}"))
            return
        self.checks.append(Check(what, False, "no error raised"))


@dataclass(frozen=True)
class HardCase:
    """A situation that breaks naive multibody codes: what makes it hard, the scene, what is asserted, the check."""
    name: str
    model: str
    hard: str  # what makes it hard
    scene: str  # the scene (or machinery) that provokes it
    asserts: str  # what is asserted, in words
    check: Callable[[Checker], None] = field(repr=False, compare=False)
    slow: bool = False
    known: str = ""  # a limitation found by this case and left to the model's owner
    expected_failure: str = ""  # non-empty: the case fails today for this reason (tests: strict xfail)


@dataclass
class Outcome:
    """The result of running one hard case: its checks, what was measured, an unexpected error if any."""
    case: HardCase
    checks: list[Check]
    measured: dict[str, Any]
    error: str | None = None

    @property
    def passed(self) -> bool:
        """True when no unexpected error occurred and every check (at least one) held."""
        return self.error is None and bool(self.checks) and all(c.ok for c in self.checks)

    def text(self) -> str:
        """The outcome as report lines."""
        lines = [f"{self.case.name}: {'PASS' if self.passed else 'FAIL'}"]
        if self.error:
            lines.append(f"  error: {self.error}")
        lines += ["  " + c.line() for c in self.checks]
        return "\n".join(lines)


def run_case(case: HardCase) -> Outcome:
    """Run one case. Every warning raised inside is recorded in `measured["warnings"]`; a RuntimeWarning (overflow,
    invalid value, a solver's complaint) is a failed check: a hard case must stay numerically clean."""
    ck = Checker()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            case.check(ck)
    except Exception as e:  # noqa: BLE001 - an unexpected error is a failed hard case, reported with its message
        return Outcome(case, ck.checks, ck.measured, f"{type(e).__name__}: {e}")
    if caught:
        ck.measured["warnings"] = sorted({f"{w.category.__name__}: {w.message}" for w in caught})
    runtime = sorted({str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)})
    if runtime:
        ck.true("no RuntimeWarning", False, "; ".join(runtime)[:200])
    return Outcome(case, ck.checks, ck.measured)


def registry() -> tuple[HardCase, ...]:
    """Every model's hard cases (`HARD_CASES` of the module named by its `ModelSpec.cases`), in model order."""
    from .registry import models

    out: list[HardCase] = []
    for name, spec in sorted(models().items()):
        suite = spec.suite()
        for c in getattr(suite, "HARD_CASES", ()):
            if c.model != name:
                raise MbsuiteError(f"hard case {c.name!r} is declared by model {name!r} but names model {c.model!r}")
            out.append(c)
    names = [c.name for c in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise MbsuiteError(f"hard case names must be unique; repeated: {dup}")
    return tuple(out)


def cases(model: str | None = None, include_slow: bool = True) -> list[HardCase]:
    """The hard cases of one model (or all), optionally without the slow ones."""
    out = [c for c in registry() if (model is None or c.model == model) and (include_slow or not c.slow)]
    if model is not None and not out:
        raise MbsuiteError(f"no hard cases for model {model!r}; models: {sorted({c.model for c in registry()})}")
    return out


def get(name: str) -> HardCase:
    """The hard case called `name` (an MbsuiteError listing the valid names if unknown)."""
    for c in registry():
        if c.name == name:
            return c
    raise MbsuiteError(f"unknown hard case {name!r}; valid: {[c.name for c in registry()]}")
