"""One sweep API for every analysis: evaluate `fn(point)` over points, in parallel processes by default.

Processes (not threads) because MuJoCo's Python callbacks are process-global and hold the GIL. Results come back in the
order of `points`. `fn` must be picklable (a module-level function or functools.partial of one).
"""

from __future__ import annotations

import multiprocessing as mp
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

from ..results import Progress


def n_workers(workers: int = 0) -> int:
    """0 = all cores available to this process."""
    if workers and workers > 0:
        return workers
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - non-Linux
        return os.cpu_count() or 1


def run_sweep(fn: Callable[[Any], Any], points: Sequence[Any], *, workers: int = 0, progress: bool | None = None,
              desc: str = "sweep") -> list[Any]:
    """Evaluate `fn` at every point; `workers=1` runs serially in this process."""
    nw = min(n_workers(workers), max(len(points), 1))
    results: list[Any] = [None] * len(points)
    with Progress(len(points), desc, enabled=progress) as bar:
        if nw <= 1:
            for i, pt in enumerate(points):
                results[i] = fn(pt)
                bar.update()
            return results
        with ProcessPoolExecutor(max_workers=nw, mp_context=mp.get_context("fork")) as ex:
            futs = {ex.submit(fn, pt): i for i, pt in enumerate(points)}
            for fut in as_completed(futs):
                results[futs[fut]] = fut.result()
                bar.update()
    return results
