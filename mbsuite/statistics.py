"""Declared statistics: the numbers a run states about its physics, declared like its output signals.

A model declares each statistic once on its spec (`ModelSpec.statistics`, name -> `Statistic`): its unit, how it
is computed (with the source of the definition) and the window it is taken over. A run's `SimResult.statistics`
holds their values, checked against the declaration when the result is assembled (`mbsuite.results.assemble`):
a value without a declaration is an error, as a signal without a unit is. Solver counters and timings (steps,
function evaluations, wall time) are not statistics: they stay in `SimResult.stats`.

A statistic taken once per member of a group (the catenary's pantographs of a train) declares `per`: the name
pattern of a member's copy, with `{k}` for the member's number (1, 2, ...) and `{name}` for the statistic's
name, e.g. `per="p{k}_{name}"` gives `p1_Fm`, `p2_Fm`.

The headline outputs (`mbsuite.trust.estimate.Headline`: the numbers the error estimate, the design studies and the
perturbation check read) are statistics or signal features with a tolerance; a statistic need not be a headline.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

#: the kinds of value a statistic may have: a number, a list of numbers of one unit (one per part, e.g. per link), or
#: a verdict (True/False, unit "-")
KINDS = ("number", "numbers", "verdict")


@dataclass(frozen=True)
class Statistic:
    """One statistic of a run: `unit` (SI, or the unit its standard states it in, e.g. mm or %), `definition` (how it
    is computed, citing the source), `window` (what part of the run it is taken over), `kind` ("number" or
    "verdict"), `per` (the name pattern of a member's copy, module docstring; "" = one per run)."""

    unit: str
    definition: str
    window: str
    kind: str = "number"
    per: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"statistic kind {self.kind!r}; valid: {KINDS}")
        if self.per and not ("{k}" in self.per and "{name}" in self.per):
            raise ValueError(f"statistic per = {self.per!r} must hold {{k}} and {{name}}")


def _pattern(per: str) -> re.Pattern[str]:
    return re.compile(re.escape(per).replace(r"\{k\}", r"(?P<k>[1-9][0-9]*)").replace(r"\{name\}", r"(?P<name>.+)"))


def lookup(table: Mapping[str, Statistic], name: str) -> Statistic | None:
    """The declaration of `name` in `table`: the statistic itself, or a member's copy of one declared `per` member."""
    if name in table:
        return table[name]
    for stat_name, stat in table.items():
        if stat.per:
            m = _pattern(stat.per).fullmatch(name)
            if m and m.group("name") == stat_name:
                return stat
    return None


def checked(values: Mapping[str, Any], table: Mapping[str, Statistic], model: str) -> dict[str, Any]:
    """`values` as plain floats (verdicts as bools, lists as lists of floats), each name declared in `table`; a
    KeyError naming the undeclared ones, a TypeError naming a value of the wrong kind."""
    missing = sorted(k for k in values if lookup(table, k) is None)
    if missing:
        raise KeyError(f"model '{model}' declares no statistic {missing}; add them to its statistics")
    out: dict[str, float | bool] = {}
    for k, v in values.items():
        stat = lookup(table, k)
        if stat.kind == "verdict":
            if not isinstance(v, bool | np.bool_):
                raise TypeError(f"statistic {k} of model '{model}' is a verdict; got {v!r}")
            out[k] = bool(v)
        elif stat.kind == "numbers":
            if not isinstance(v, list | tuple | np.ndarray) or not all(
                    isinstance(x, int | float | np.integer | np.floating) and not isinstance(x, bool) for x in v):
                raise TypeError(f"statistic {k} of model '{model}' is a list of numbers; got {v!r}")
            out[k] = [float(x) for x in v]
        else:
            if isinstance(v, bool | np.bool_) or not isinstance(v, int | float | np.integer | np.floating):
                raise TypeError(f"statistic {k} of model '{model}' is a number; got {v!r}")
            out[k] = float(v)
    return out


def unit_of(table: Mapping[str, Statistic], name: str) -> str:
    """The unit of a declared statistic (or of a member's copy)."""
    stat = lookup(table, name)
    return "" if stat is None else stat.unit


def describe(table: Mapping[str, Statistic]) -> list[str]:
    """One line per declared statistic (`mbsuite list --json`: each model's `statistics`)."""
    lines = []
    for name, s in table.items():
        shown = f"{name} (per member: {s.per.format(k='<k>', name=name)})" if s.per else name
        value = "true/false" if s.kind == "verdict" else f"[{s.unit}]" if s.unit else "[-]"
        lines.append(f"{shown} {value}: {s.definition}; over {s.window}")
    return lines
