"""How and where a sweep runs: `SweepOptions` (executor, scheduler, store, point limit), checked once when made and
handed to `run_sweep(options=...)` by whoever runs the sweep (the CLI builds one from `--executor/--scheduler/--store/
--max-points`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...errors import SceneError

EXECUTORS = ("local", "threads", "dask")
MAX_POINTS = 10_000
"""Default upper limit on the number of points of one sweep (raise it with `max_points`)."""


def check_executor(executor: str, scheduler: Any) -> None:
    """A `SceneError` for an unknown executor, or for "dask" without a scheduler."""
    if executor not in EXECUTORS:
        raise SceneError(f"unknown sweep executor {executor!r}; valid: {list(EXECUTORS)}")
    if executor == "dask" and scheduler is None:
        raise SceneError("the dask executor needs a scheduler address (--scheduler tcp://HOST:PORT)")


def check_max_points(max_points: Any, name: str = "max_points") -> int:
    """`max_points` as an int, or a `SceneError` naming `name` (the CLI: `--max-points`) unless it is an integer >= 1
    (`mbsuite.limits`: numpy integers too; 2.5, bools, NaN and inf refused)."""
    from ...limits import Limit  # not at import: the light command-line parser reads this module

    return Limit(lo=1, kind=int, doc="most points of one sweep").check(name, max_points, SceneError)


@dataclass(frozen=True, kw_only=True)
class SweepOptions:
    """Where the points of a sweep run and how large it may be; a `SceneError` on construction for a bad value.

    `executor`: "local", "threads" or "dask", or None to leave it to the caller of `run_sweep` (else "local");
    `scheduler`: a Dask scheduler address or `Client` (needed by "dask"); `store`: the file to stream results to and
    resume from; `max_points`: the size guard (default `MAX_POINTS`)."""

    executor: str | None = None
    scheduler: Any = None
    store: str | Path | None = None
    max_points: int = MAX_POINTS

    def __post_init__(self) -> None:
        if self.executor is not None:
            check_executor(self.executor, self.scheduler)
        object.__setattr__(self, "max_points", check_max_points(self.max_points))

    def executor_for(self, preferred: str | None) -> str:
        """The executor of a sweep whose caller prefers `preferred` (None: no preference): the caller's preference,
        else these options' executor, else "local"; a preferred "threads" yields to "dask" (a cluster was asked for
        and wins over a local preference)."""
        executor = preferred or self.executor or "local"
        return "dask" if executor == "threads" and self.executor == "dask" else executor
