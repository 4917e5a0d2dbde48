"""Progress and cost of long work: what a command will run, said before it starts, a bar while it runs, an estimate of
its time from the first finished run, a budget, and the finished runs kept when it is interrupted.

A command line opens one `Study` around its work (`mbsuite.cli.main`). Inside it, the work declares its plan, once:

- an analysis that knows its whole size declares it (`planned`: optimise's generations x designs x operating points,
  sensitivity's sample x operating points, work-precision's settings); the sweeps it runs report into that plan;
- otherwise the first sweep that runs (`mbsuite.analysis.sweep.run_sweep`: `mbsuite sweep`, a `--vary` study, an
  error estimate's companions) declares its own points as the plan. A sweep run inside a point of another sweep
  (a frequency response at each point of a `--vary` study) is not a run of the plan: it runs silently.

Stated before the work starts (stderr, one line): how many runs, how many in parallel. After the first finished run:
its time and the estimated time of all (`first run x ceil(runs / parallel)`, wall clock). With a budget (the command
line's `--budget`, default `BUDGET` s) an estimate above it stops the study there with an `OverBudget` error naming
`--yes` and, where the analysis knows one, a cheaper setting that fits; the finished runs are kept as on Ctrl-C.
The lines and the bar (tqdm) are shown on a terminal only (the lines also with `MBSUITE_PROGRESS=1`, e.g. in a
log); `--quiet` silences both. Outside a command line (the
API) there is no study: sweeps draw their own bar as before (`Progress`).

Ctrl-C: a sweep with a store has its finished points in the store (a rerun resumes); otherwise the finished runs of
the plan are written as a partial summary (`partial_summary.json` under `--out`, else in the current directory) and
the command says where.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

from .errors import MbsuiteError

#: default budget of a command's long work (s of wall time), above which it asks for --yes
BUDGET = 300.0


class OverBudget(MbsuiteError):
    """The estimated time of a study exceeds its budget (the command line's --budget) and --yes was not given.
    `result`: what was finished before the study and is kept (an error estimate's run: the command prints and writes
    it, then stops with this error); None where nothing was."""

    result: Any = None


class Progress:
    """A progress bar on stderr (tqdm): shown when stderr is a terminal, when `MBSUITE_PROGRESS=1`, or with
    `enabled=True`, never under the command line's --quiet; on a non-terminal it prints a line at most every 5 s
    instead of redrawing."""

    def __init__(self, total: int, desc: str = "", enabled: bool | None = None):
        from tqdm import tqdm

        tty = sys.stderr.isatty()
        if enabled is None:
            quiet = _ACTIVE is not None and _ACTIVE.quiet  # the command line's --quiet
            enabled = not quiet and (tty or os.environ.get("MBSUITE_PROGRESS", "") not in ("", "0"))
        self.enabled = bool(enabled)
        self.total = max(int(total), 1)
        self._bar = tqdm(total=self.total, desc=desc, disable=not self.enabled, file=sys.stderr, ncols=100,
                         mininterval=0.2 if tty else 5.0, leave=True)

    @property
    def n(self) -> int:
        """How many units are done."""
        return int(self._bar.n)

    def update(self, k: int = 1) -> None:
        """Advance by `k` units."""
        self._bar.update(k)

    def write(self, text: str, stream: TextIO) -> None:
        """A line on `stream` above the bar (the bar redrawn below it)."""
        self._bar.write(text, file=stream)

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self._bar.close()


def duration(seconds: float) -> str:
    """A duration in words a reader takes in at once: 42 s, 3.5 min, 1.2 h."""
    if seconds < 90:
        return f"{seconds:.0f} s" if seconds >= 10 else f"{seconds:.1f} s"
    if seconds < 5400:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


@dataclass
class Plan:
    """What a piece of long work will run: `runs` (an upper bound when `upto`: an optimiser may stop early),
    `parallel` at a time, `detail` in words; `cheaper(runs)` names a setting of the analysis that fits in `runs`
    runs (None: the analysis knows none); `weights`: the runs' relative costs where they differ (an error estimate's
    companions), in the order of the sweep that runs them; `unit`: the wall time (s) of work of weight 1 when it is
    known before the work starts (an error estimate's run, timed before its companions): then the estimate, and the
    budget's check, come before the first run."""

    what: str
    runs: int
    parallel: int
    upto: bool = False
    detail: str = ""
    cheaper: Callable[[int], str | None] | None = None
    weights: tuple[float, ...] = ()
    unit: float | None = None
    done: int = 0
    started: float = field(default_factory=time.perf_counter)
    finished: list[Any] = field(default_factory=list)

    def statement(self) -> str:
        """The line said before the work starts."""
        n = f"up to {self.runs}" if self.upto else str(self.runs)
        detail = f" ({self.detail})" if self.detail else ""
        par = "one at a time" if self.parallel <= 1 else f"{self.parallel} in parallel"
        ahead = self.ahead()
        when = ("time estimate after the first" if ahead is None else
                f"about {duration(ahead)} (the run took {duration(self.unit)})")
        return f"{self.what}: {n} run{'s' if self.runs != 1 else ''}{detail}, {par}; {when}"

    def ahead(self) -> float | None:
        """The wall time of all runs estimated before any has run, from `unit` and `weights`; None without them."""
        if self.unit is None or not self.weights or self.unit <= 0:
            return None
        return self.unit * max(sum(self.weights) / max(self.parallel, 1), max(self.weights))

    def estimate(self, first: float, index: int | None = None) -> float:
        """The wall time of all runs from the first finished run's (s; `index`: which run it was, with `weights`:
        the work of all over the parallel runs, at least the largest run's)."""
        if self.weights and index is not None and 0 <= index < len(self.weights) and self.weights[index] > 0:
            unit = first / self.weights[index]
            return unit * max(sum(self.weights) / max(self.parallel, 1), max(self.weights))
        return first * math.ceil(self.runs / max(self.parallel, 1))


class Study:
    """A command's long work (module docstring): its plan, bar, estimate, budget and the finished runs."""

    def __init__(self, command: str, *, quiet: bool = False, budget: float | None = None, confirmed: bool = False,
                 out: str | None = None, store: str | None = None, stream: TextIO | None = None,
                 bar: bool | None = None):
        self.command, self.quiet, self.budget, self.confirmed = command, quiet, budget, confirmed
        self.out, self.store = out, store
        self.stream = stream if stream is not None else sys.stderr
        shown = stream is not None or self.stream.isatty() or os.environ.get("MBSUITE_PROGRESS", "") not in ("", "0")
        self.quiet = quiet or not shown  # on a terminal (or MBSUITE_PROGRESS=1, or a given stream) unless --quiet
        self.bar_wanted = (not self.quiet and self.stream.isatty()) if bar is None else bar
        self.plan: Plan | None = None
        self.last: Plan | None = None  # the latest plan, kept for the partial summary
        self.depth = 0  # sweeps running inside the plan (a nested one is silent)
        self.pid = os.getpid()
        self._bar: Progress | None = None
        self.saved = ""

    def say(self, text: str) -> None:
        """One line on the stream unless quiet, after the command's name (the work's name where it differs)."""
        text = f"mbsuite {self.command}: {text.removeprefix(self.command + ': ')}"
        if not self.quiet:
            if self._bar is not None:
                self._bar.write(text, self.stream)
            else:
                print(text, file=self.stream, flush=True)

    def start(self, plan: Plan) -> None:
        """Declare `plan` (say it; open the bar); a plan whose time is known before it starts (`Plan.ahead`) is
        checked against the budget here, before any of its runs."""
        self.plan = self.last = plan
        self.say(plan.statement())
        ahead = plan.ahead()
        if ahead is not None and self.budget is not None and ahead > self.budget and not self.confirmed:
            self.plan = None
            raise OverBudget(f"{plan.what}: about {duration(ahead)} for {plan.runs} runs ({plan.detail}; the run "
                             f"took {duration(plan.unit)}, {plan.parallel} in parallel), above the budget of "
                             f"{duration(self.budget)} (--budget SECONDS): run it with --yes or --budget "
                             f"{math.ceil(ahead * 1.2 / 60) * 60}, or without it")
        if self.bar_wanted:
            self._bar = Progress(plan.runs, plan.what, enabled=True)

    def end(self) -> None:
        """The plan is over (finished, stopped or failed)."""
        if self._bar is not None:
            self._bar.__exit__()
            self._bar = None
        self.plan = None

    def update(self, k: int = 1, results: list[Any] | None = None, indices: list[int] | None = None) -> None:
        """`k` more runs of the plan finished (`results`: their (point, result) pairs, kept for a partial summary;
        `indices`: their places in the sweep, for the plan's weights); after the first, the estimate, checked
        against the budget."""
        plan = self.plan
        if plan is None:
            return
        first = plan.done == 0
        plan.done += k
        if results:
            plan.finished.extend(results)
        if self._bar is not None:
            self._bar.update(k)
        if first and (plan.runs > plan.parallel or len(set(plan.weights)) > 1):
            took = time.perf_counter() - plan.started
            if plan.parallel == 1:  # one at a time: k runs took that long together
                took /= k
            total = plan.estimate(took, indices[0] if indices else None)
            self.say(f"{plan.what}: first run finished after {duration(took)}: about {duration(total)} for "
                     f"{'up to ' if plan.upto else ''}{plan.runs} runs")
            if self.budget is not None and total > self.budget and not self.confirmed:
                raise OverBudget(self.over_budget(plan, took, total))

    def nested(self, n: int, parallel: int) -> Callable[..., None]:
        """What a sweep of `n` points run inside a run of the plan (a frequency response at a point of a `--vary`
        study) reports to: not runs of the plan, but while the plan's first run is not finished, the first of its
        own points gives the estimate of the whole (`n` points `parallel` at a time per run of the plan), said and
        judged against the budget then, not only after the plan's first run."""
        plan, started, said = self.plan, time.perf_counter(), []

        def report(k: int, results: list[Any] | None = None, indices: list[int] | None = None) -> None:
            if said or plan is None or plan is not self.plan or plan.done > 0:
                return
            said.append(True)
            took = time.perf_counter() - started
            if parallel <= 1:
                took /= max(k, 1)
            one = took * math.ceil(n / max(parallel, 1))
            total = one * math.ceil(plan.runs / max(plan.parallel, 1))
            self.say(f"{plan.what}: each run is {n} runs of its own; the first of them finished after "
                     f"{duration(took)}: about {duration(one)} a run, {duration(total)} for {plan.runs} runs")
            if self.budget is not None and total > self.budget and not self.confirmed:
                raise OverBudget(self.over_budget(plan, one, total))

        return report

    def over_budget(self, plan: Plan, took: float, total: float) -> str:
        """The `OverBudget` message: the estimate, the budget, --yes and a cheaper setting where known."""
        fits = max(int(self.budget / took) * max(plan.parallel, 1), 1) if took > 0 else plan.runs
        hint = plan.cheaper(fits) if plan.cheaper is not None else None
        cheaper = f", or a cheaper study: {hint}" if hint else ""
        return (f"{plan.what}: about {duration(total)} for {'up to ' if plan.upto else ''}{plan.runs} runs (the first "
                f"took {duration(took)}, {plan.parallel} in parallel), above the budget of {duration(self.budget)} "
                f"(--budget SECONDS): run it with --yes{cheaper}")

    def keep_partial(self) -> str:
        """On an interrupt: where the finished runs are (the store, or a partial summary written now)."""
        plan = self.last
        if self.store:
            return f"finished points are kept in {self.store} (rerun the command to resume)"
        if plan is None or not plan.finished:
            return "no run had finished; nothing was saved"
        from .results import to_jsonable

        where = Path(self.out) if self.out else Path.cwd()
        path = where / "partial_summary.json"
        try:
            where.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(to_jsonable({
                "interrupted": True, "command": self.command, "work": plan.what, "planned_runs": plan.runs,
                "finished_runs": len(plan.finished),
                "runs": [{"point": p, "result": r} for p, r in plan.finished]}), indent=1, default=str) + "\n")
        except OSError as exc:
            return f"the {len(plan.finished)} finished runs could not be saved ({exc})"
        return f"the {len(plan.finished)} finished runs of {plan.runs} are in {path}"


_ACTIVE: Study | None = None
_LAST: Study | None = None


def last_study() -> Study | None:
    """The latest study opened in this process (after an interrupt: where its finished runs are)."""
    return _LAST


def active() -> Study | None:
    """The command's study, in the process that opened it (a worker process has none)."""
    s = _ACTIVE
    return s if s is not None and s.pid == os.getpid() else None


@contextmanager
def study(command: str, **kw: Any) -> Iterator[Study]:
    """Open the command's `Study` (keywords: `Study`'s) for the duration of its work."""
    global _ACTIVE, _LAST
    s, before = Study(command, **kw), _ACTIVE
    _ACTIVE = _LAST = s
    try:
        yield s
    finally:
        s.end()
        _ACTIVE = before


@contextmanager
def planned(what: str, runs: int, parallel: int, *, upto: bool = False, detail: str = "",
            cheaper: Callable[[int], str | None] | None = None, weights: tuple[float, ...] = (),
            unit: float | None = None) -> Iterator[Study | None]:
    """Declare the plan of an analysis that knows its whole size (module docstring); the sweeps it runs report into
    it (`unit`: `Plan.unit`, its time known ahead). Yields the study, or None outside a command line or inside
    another plan."""
    s = active()
    if s is None or s.plan is not None:
        yield None
        return
    s.start(Plan(what, max(int(runs), 1), max(int(parallel), 1), upto, detail, cheaper, tuple(weights), unit))
    try:
        yield s
    finally:
        s.end()


@contextmanager
def sweep_progress(desc: str, n: int, parallel: int, enabled: bool | None) -> Iterator[Callable[..., None]]:
    """What a sweep of `n` points reports its finished points to: `report(k, results)` (module docstring: the
    plan of the command's study, a plan of its own, nothing when nested; outside a study its own `Progress` bar,
    `enabled` as `Progress`)."""
    s = active()
    if s is None:
        with Progress(n, desc, enabled=enabled) as bar:
            yield lambda k, results=None, indices=None: bar.update(k)
        return
    if s.depth > 0:
        yield s.nested(n, parallel)
        return
    own = s.plan is None
    if own:
        s.start(Plan(desc, max(n, 1), max(min(parallel, n), 1)))
    s.depth += 1
    try:
        yield s.update
    finally:
        s.depth -= 1
        if own:
            s.end()
