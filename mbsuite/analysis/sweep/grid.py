"""Sweep sizes and values: the CLI's `--vary` values (`parse_values`), the size of a full grid (`check_grid`) and of a
list of points (`take`), each counted before anything is built and refused above the point limit."""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence, Sized
from typing import Any

from ...errors import SceneError
from .options import MAX_POINTS, check_max_points


def too_many(what: str, count: float | str, limit: int) -> SceneError:
    """The SceneError of a job of `count` items above its `limit`, naming `what` and how to raise the limit."""
    if isinstance(count, str):
        n = count
    else:
        n = f"{count:,}" if isinstance(count, int) and count < 10**15 else f"{float(count):.3g}"
        n = "more than 1e308" if n == "inf" else n
    return SceneError(f"{what}: {n} points exceed the limit of {limit:,} points per sweep; raise it with "
                      "max_points=N (CLI: --max-points N) if the sweep is meant to be that large")


def check_grid(counts: Sequence[int], max_points: int | None = None, what: str = "sweep grid") -> int:
    """The number of points of a full grid over axes of `counts` values, or a `SceneError` if it exceeds
    `max_points` (default `MAX_POINTS`). Call it before building the grid."""
    limit = check_max_points(max_points) if max_points is not None else MAX_POINTS
    total = math.prod(int(c) for c in counts)
    if total > limit:
        raise too_many(f"{what} ({' x '.join(str(int(c)) for c in counts)})", total, limit)
    return total
def _number(text: str, part: str, role: str) -> float:
    try:
        v = float(part)
    except ValueError:
        raise SceneError(f"sweep values {text!r}: range {role} {part!r} is not a number; a range reads "
                         "start:stop:step with numbers (e.g. 1:30:0.5)") from None
    if not math.isfinite(v):
        raise SceneError(f"sweep values {text!r}: range {role} {part!r} is not finite; valid: finite numbers")
    return v


def _range_plan(text: str, item: str) -> tuple[float, float, float, float]:
    """(start, stop, step, count) of `start:stop:step`, stop included; the count is computed, nothing is built."""
    parts = item.split(":")
    if len(parts) != 3:
        raise SceneError(f"sweep values {text!r}: {item!r} has {len(parts)} part(s); a range reads start:stop:step")
    a, b, c = (_number(text, p.strip(), role) for p, role in zip(parts, ("start", "stop", "step"), strict=True))
    if c <= 0:
        raise SceneError(f"sweep values {text!r}: step {c:g} must be > 0")
    if b < a:
        raise SceneError(f"sweep values {text!r}: stop {b:g} is below start {a:g}; need start <= stop")
    q = (b - a) / c
    # stop is included when it lies on the grid up to rounding (e.g. 0:0.3:0.1)
    count = math.floor(q * (1.0 + 1e-12) + 1e-9) + 1 if math.isfinite(q) else math.inf
    return a, b, c, count


def _range_values(text: str, a: float, c: float, n: int) -> list[float]:
    raw = [a + i * c for i in range(n)]
    tidy = [float(f"{v:.12g}") for v in raw]  # 0.30000000000000004 -> 0.3 (12 significant digits)
    if len(set(tidy)) == n:
        return tidy
    if len(set(raw)) == n:
        return raw
    raise SceneError(f"sweep values {text!r}: step {c:g} is below the resolution of the numbers near {a:g}")


def _scalar(text: str, item: str) -> Any:
    if item.lower() in ("true", "false"):
        return item.lower() == "true"
    try:
        v = float(item)
    except ValueError:
        return item  # a word (an effect's setting, an input type)
    if not math.isfinite(v):
        raise SceneError(f"sweep values {text!r}: {item!r} is not finite; valid: finite numbers, true/false, words")
    return v
def parse_values(text: str, max_points: int | None = None) -> list:
    """The values of one sweep axis: `a,b,c` (numbers, true/false or words) or `start:stop:step` (stop included; a
    list may mix both, e.g. `1:5:1,10,20`). Counts the values before building any range and raises `SceneError`
    naming `text` for: an empty item, a non-numeric or non-finite range part, step <= 0, stop < start, a non-finite
    number, more than `max_points` values (default `MAX_POINTS`)."""
    limit = check_max_points(max_points) if max_points is not None else MAX_POINTS
    if not isinstance(text, str) or not text.strip():
        raise SceneError(f"sweep values {text!r}: empty; expected a,b,c or start:stop:step (e.g. 1:30:0.5)")
    plan: list[tuple[str, Any]] = []
    total: float = 0
    for raw in text.split(","):
        item = raw.strip()
        if not item:
            raise SceneError(f"sweep values {text!r}: an empty item between commas")
        if ":" in item:
            a, _b, c, n = _range_plan(text, item)
            total += n
            plan.append(("range", (a, c, n)))
        else:
            total += 1
            plan.append(("value", _scalar(text, item)))
        if total > limit:
            raise too_many(f"sweep values {text!r}", total, limit)
    out: list = []
    for kind, val in plan:
        out.extend(_range_values(text, val[0], val[1], int(val[2])) if kind == "range" else [val])
    return out
def take(points: Iterable[Any], limit: int, desc: str) -> list[Any]:
    """`points` as a list, refusing more than `limit` before building it (a generator is read up to limit + 1)."""
    if isinstance(points, Sized):
        if len(points) > limit:
            raise too_many(desc, len(points), limit)
        return list(points)
    head = list(itertools.islice(points, limit + 1))
    if len(head) > limit:
        raise too_many(desc, f"more than {limit:,}", limit)
    return head
