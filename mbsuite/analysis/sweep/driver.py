"""`run_sweep`: evaluate a function at every point on one executor, in the order of the points, streaming to a store
and resuming from it (claim, submit, collect; wait for points other live writers compute)."""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from ...progress import sweep_progress
from .encoding import StoreError, encode_value, fn_id, record_key
from .executors import Runner
from .grid import take
from .options import SweepOptions, check_executor, check_max_points
from .store import SweepStore

_POLL = 0.1  # s between looks at the store while waiting for points other writers compute


def run_sweep(fn: Callable[[Any], Any], points: Iterable[Any], *, workers: int = 0, progress: bool | None = None,
              desc: str = "sweep", executor: str | None = None, scheduler: Any = None,
              store: str | Path | None = None, max_points: int | None = None,
              options: SweepOptions | None = None) -> list[Any]:
    """Evaluate `fn` at every point and return the results in the order of `points`.

    `workers`: local processes or threads (0 = all cores; 1 = serial in this process). `executor`: "local",
    "threads" or "dask" (then `scheduler` = address or Client). `store`: the file to stream results to, resume from
    and share with other writers (package docstring). `max_points`: the size guard (default `MAX_POINTS`); a larger
    sweep is a `SceneError` before anything runs. With a store, equal points are computed once.

    `options` (`SweepOptions`, e.g. the CLI's `--executor/--scheduler/--store/--max-points`) fills in what the call
    does not pass; `executor` is then the caller's preference (`SweepOptions.executor_for`); by default
    `SweepOptions()`."""
    opts = options if options is not None else SweepOptions()
    executor = opts.executor_for(executor)
    scheduler = scheduler if scheduler is not None else opts.scheduler
    store = store if store is not None else opts.store
    limit = check_max_points(max_points) if max_points is not None else opts.max_points
    check_executor(executor, scheduler)
    points = take(points, limit, desc)
    results: list[Any] = [None] * len(points)
    if not store:
        groups: dict[Any, list[int]] = {i: [i] for i in range(len(points))}
        with sweep_progress(desc, len(points), _parallel(executor, workers, len(points)), progress) as report:
            _drive(fn, points, groups, results, report, None, None, executor, workers, scheduler, desc)
        return results
    db = SweepStore(store)
    fid = fn_id(fn)
    encoded: dict[str, Any] = {}
    groups = {}
    for i, pt in enumerate(points):
        try:
            enc = encode_value(pt)
        except StoreError as exc:
            raise StoreError(f"sweep store {db.path}: point {i} cannot be stored: {exc}") from None
        k = record_key(fid, enc)
        encoded.setdefault(k, enc)
        groups.setdefault(k, []).append(i)
    with sweep_progress(desc, len(points), _parallel(executor, workers, len(groups)), progress) as report, \
            db.session() as owner_fd:
        _drive(fn, points, groups, results, report, db, (fid, encoded, owner_fd), executor, workers, scheduler,
               desc)
    return results


def _parallel(executor: str, workers: int, n: int) -> int:
    """How many points run at a time (a Dask cluster: its own count, said as 'many')."""
    from ...engines.core import n_workers

    return n if executor == "dask" else max(1, min(n_workers(workers), n))


def _drive(fn: Callable, points: list[Any], groups: dict[Any, list[int]], results: list[Any],
           report: Callable[..., None],
           db: SweepStore | None, meta: tuple[str, dict[str, Any], int] | None, executor: str, workers: int,
           scheduler: Any, desc: str) -> None:
    """The loop of `run_sweep`: claim, submit, collect; with a store, wait for points other live writers compute."""
    def deliver(gid: Any, res: Any) -> None:
        for i in groups[gid]:
            results[i] = res
        report(len(groups[gid]), [(points[i], res) for i in groups[gid]], groups[gid])

    queue: deque[Any] = deque(groups)
    waiting: list[Any] = []  # claimed by another live writer
    if db is not None:
        with db.locked(exclusive=False):
            db.read()
        left: deque[Any] = deque()
        for gid in queue:  # finished points are served without starting any executor
            ok, val = db.get(gid)
            if ok:
                deliver(gid, val)
            else:
                left.append(gid)
        queue = left
    if not queue:
        return
    runner = Runner(fn, executor, workers, scheduler, len(queue), desc, db is not None,
                     meta[2] if meta else None)
    failed = True
    try:
        while queue or waiting or runner.busy:
            if db is not None and not queue and waiting and runner.free > 0:
                queue.extend(waiting)  # look again: finished, still claimed, or their writer died
                waiting.clear()
            take: list[Any] = []
            if queue and runner.free > 0:
                if db is None:
                    while queue and len(take) < runner.free:
                        take.append(queue.popleft())
                else:
                    with db.locked():
                        db.read()
                        while queue and len(take) < runner.free:
                            gid = queue.popleft()
                            ok, val = db.get(gid)
                            if ok:
                                deliver(gid, val)
                            elif db.claimed_elsewhere(gid):
                                waiting.append(gid)
                            else:
                                take.append(gid)
                        db.claim(take)
            for gid in take:
                runner.submit(gid, points[groups[gid][0]])
            if runner.busy:
                for gid, res in runner.wait(_POLL if waiting else None):
                    if db is not None and meta is not None:
                        try:
                            db.record(gid, meta[0], meta[1][gid], res)
                        except StoreError as exc:
                            raise StoreError(f"sweep store {db.path}: the result of point {groups[gid][0]} cannot "
                                             f"be stored: {exc}") from None
                    deliver(gid, res)
            elif waiting:
                time.sleep(_POLL)
        failed = False
    finally:
        runner.close(failed)
