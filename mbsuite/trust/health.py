"""Health figures: numbers a run reports about its own accuracy, each with the bound past which the result is not
trusted.

A model's run attaches figures to its `SimResult` (`results.assemble(..., health=[...])`); `judge` then turns a figure
past its bound into an `AccuracyError` naming the figure, its value, its bound and what to change — or, when the
caller allows inaccurate results (`--allow-inaccurate`, `solver.allow_inaccurate = true`), into a warning carried in
the result's `warnings`, its summary and its JSON. A result is never quietly wrong.

An error estimate above its tolerance (`judge_estimate`) does not discard the result: it is kept and flagged. Without
`allow_inaccurate` the analysis raises `InaccurateResult` carrying its result (an `AccuracyError`, so a caller that
catches those still does); the command line prints that result, writes its files and exits with status 3
(`EXIT_INACCURATE`) instead of 0; with `allow_inaccurate` the result is accepted with the warnings, as above.

Figures every time-domain model can report (names are shared so tables line up across models):
- `stability_margin`: h * omega_max, the step times the highest natural frequency of the linearised model; explicit
  RK4 is stable below 2.79, Euler below 2, the implicit integrators are stable but inaccurate above ~0.5;
- `nyquist_ratio`: input frequency / (1 / (2 h)), must be well below 1 (bound 0.1 gives >= 10 steps per half period);
- `energy_residual`: |energy in - energy stored - energy dissipated| / energy in, where a balance is defined;
- `closure_residual`: the largest loop-closure error of a closed chain (m);
- `excursion`: the largest coordinate excursion relative to the model's plausible range.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from typing import Any

from ..errors import SolverError


class AccuracyError(SolverError):
    """A run finished but a health figure is past its bound: its numbers are not to be trusted."""


class InaccurateResultWarning(UserWarning):
    """A health figure past its bound, accepted because the caller allowed inaccurate results."""


#: the command line's exit status of a result kept and reported although an error estimate exceeds its tolerance
#: (0: success, 2: any error, 130: interrupted)
EXIT_INACCURATE = 3


class InaccurateResult(AccuracyError):
    """An error estimate above its tolerance, the caller not allowing inaccurate results: the result is kept, not
    discarded. `result` is it (a `SimResult`, a `Report`), `messages` the `INACCURATE: ...` lines (`judge_estimate`)
    it carries in its warnings. The command line prints it, writes its files and exits `EXIT_INACCURATE`."""

    def __init__(self, messages: Iterable[str], result: Any = None):
        self.messages = list(messages)
        self.result = result
        self.shown = False  # set by the command line once it has printed the result
        n = len(self.messages)
        first = self.messages[0].removeprefix("INACCURATE: ") if n else "an error estimate exceeds its tolerance"
        super().__init__(first + (f" (and {n - 1} more)" if n > 1 else "") + "; the result is kept, flagged "
                         "inaccurate; rerun with --allow-inaccurate (solver.allow_inaccurate = true) to accept it")

    def __reduce__(self):  # across processes: the messages (a result may hold what does not pickle)
        return (type(self), (self.messages,))

    def report(self) -> Any:
        """The kept result as a `Report` flagged inaccurate (`Report.flag_inaccurate`)."""
        from ..results import Report

        rep = self.result if isinstance(self.result, Report) else self.result.report()
        rep.flag_inaccurate(self.messages)
        return rep


@dataclass(frozen=True)
class Figure:
    """One health figure: `value` must be <= `bound` (both in `unit`). `fix` says what to change when it is not."""

    name: str
    value: float
    bound: float
    unit: str = ""
    doc: str = ""
    fix: str = ""

    @property
    def ok(self) -> bool:
        """True when the value is finite and within its bound."""
        return math.isfinite(self.value) and self.value <= self.bound

    def message(self, what: str = "") -> str:
        """The figure past its bound, in words, with what to change."""
        where = f"{what}: " if what else ""
        unit = f" {self.unit}" if self.unit else ""
        fix = f"; {self.fix}" if self.fix else ""
        return (f"{where}{self.name} = {self.value:.4g}{unit} exceeds its bound {self.bound:.4g}{unit} "
                f"({self.doc}){fix}")

    def to_dict(self) -> dict[str, Any]:
        """The figure as a JSON-able dictionary (with `ok`)."""
        return {**asdict(self), "ok": self.ok}


# explicit-stability limits of h * |lambda| on the imaginary axis (undamped modes)
STABILITY_LIMIT = {"rk4": 2.8, "euler": 2.0, "discrete": 2.0, "implicit": 1.0, "implicitfast": 1.0}


def stability_margin(h: float, omega_max: float, integrator: str, *, fraction: float = 0.5) -> Figure:
    """h * omega_max against `fraction` of the integrator's limit (the accuracy, not only stability, is at stake:
    at half the RK4 limit the per-step amplitude error of the fastest mode is below 1 %)."""
    limit = STABILITY_LIMIT.get(integrator, 1.0)
    return Figure("stability_margin", h * omega_max, fraction * limit, "",
                  f"timestep x highest natural frequency for {integrator}",
                  f"lower solver.timestep below {fraction * limit / omega_max:.3g} s")


def nyquist_ratio(h: float, f_input: float, *, bound: float = 0.1) -> Figure:
    """The input frequency against the step's Nyquist rate 1/(2h)."""
    return Figure("nyquist_ratio", f_input * 2.0 * h, bound, "", "input frequency / Nyquist rate of the step",
                  f"lower solver.timestep below {bound / (2.0 * f_input):.3g} s" if f_input > 0 else "")


def judge(figures: Iterable[Figure], *, allow_inaccurate: bool = False, what: str = "") -> list[str]:
    """Raise `AccuracyError` for the first figure past its bound, or (allowed) return the warnings and emit them."""
    msgs = [f.message(what) for f in figures if not f.ok]
    if not msgs:
        return []
    if not allow_inaccurate:
        raise AccuracyError(msgs[0] + (f" (and {len(msgs) - 1} more)" if len(msgs) > 1 else "")
                            + "; rerun with --allow-inaccurate (solver.allow_inaccurate = true) to keep the result")
    for m in msgs:
        warnings.warn("INACCURATE: " + m, InaccurateResultWarning, stacklevel=2)
    return ["INACCURATE: " + m for m in msgs]


def judge_estimate(figures: Iterable[Figure], *, allow_inaccurate: bool = False, what: str = "") -> list[str]:
    """The `INACCURATE: ...` lines of an error estimate's figures past their tolerance (`ErrorEstimate.figures`),
    emitted as warnings when the caller allows inaccurate results. It never raises: the caller keeps its result with
    these lines in its warnings and, unless allowed and if there are any, raises `InaccurateResult` carrying it."""
    msgs = ["INACCURATE: " + f.message(what) for f in figures if not f.ok]
    if allow_inaccurate:
        for m in msgs:
            warnings.warn(m, InaccurateResultWarning, stacklevel=2)
    return msgs
