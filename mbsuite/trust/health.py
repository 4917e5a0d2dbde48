"""Health figures: numbers a run reports about its own accuracy, each with the bound past which the result is not
trusted.

A model's run attaches figures to its `SimResult` (`results.assemble(..., health=[...])`); `judge` then turns a figure
past its bound into an `AccuracyError` naming the figure, its value, its bound and what to change — or, when the
caller allows inaccurate results (`--allow-inaccurate`, `solver.allow_inaccurate = true`), into a warning carried in
the result's `warnings`, its summary and its JSON. A result is never quietly wrong.

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
