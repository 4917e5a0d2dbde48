"""The lock-ups of a rotor-system run and how far two runs' lock-ups lie apart: the physics metric the work-precision
studies of rotor models read (an engineer reads when a clutch or brake locks)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any


def lock_ups(events: Sequence[dict[str, Any]], t0: float = 0.0) -> list[tuple[str, float]]:
    """(element, time) of every transition into `stuck` at or after `t0`."""
    return [(e.get("element", "?"), float(e["t"])) for e in events
            if e.get("to") == "stuck" and e.get("t") is not None and e["t"] >= t0]


def lock_time_error(run: Sequence[tuple[str, float]], ref: Sequence[tuple[str, float]], period: float) -> float:
    """The largest time difference of matched lock-ups (element by element, in order) over `period`; a lock-up one
    run has and the other lacks counts as a whole period (1.0). 0.0 when neither run locks."""
    by_el: dict[str, tuple[list[float], list[float]]] = {}
    for el, t in ref:
        by_el.setdefault(el, ([], []))[1].append(t)
    for el, t in run:
        by_el.setdefault(el, ([], []))[0].append(t)
    errs = []
    for a, b in by_el.values():
        k = min(len(a), len(b))
        errs += [abs(x - y) for x, y in zip(a[:k], b[:k], strict=True)]
        if len(a) != len(b):
            errs.append(period)
    return (max(errs) if errs else 0.0) / period
