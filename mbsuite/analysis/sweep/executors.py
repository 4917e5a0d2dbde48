"""Where the points of a sweep run: a process pool, a thread pool, serially in this process or on a Dask cluster
(`Runner`: submit points, collect finished ones, at most `capacity` in flight)."""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import os
import uuid
from collections import deque
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, ThreadPoolExecutor
from concurrent.futures import wait as futures_wait
from typing import Any

from ...engines.core import n_workers
from ...errors import MbsuiteError


def _dask_client(scheduler: Any):
    try:
        from distributed import Client
    except ImportError as exc:  # pragma: no cover - distributed is a declared dependency
        raise MbsuiteError("the dask executor needs the 'distributed' package: pip install distributed") from exc
    if isinstance(scheduler, Client):
        return scheduler, False
    try:
        return Client(scheduler, timeout="10s"), True
    except (OSError, TimeoutError) as exc:
        raise MbsuiteError(f"cannot reach the Dask scheduler at {scheduler!r}: {exc}") from exc


def _close_fd(fd: int) -> None:
    """Pool-worker initialiser: drop the inherited copy of the writer file, so only the writer itself keeps it."""
    with contextlib.suppress(OSError):
        os.close(fd)


class Runner:
    """Submit points to one executor and collect finished ones; `capacity` points in flight at most."""

    def __init__(self, fn: Callable, executor: str, workers: int, scheduler: Any, n: int, desc: str,
                 incremental: bool, owner_fd: int | None):
        self.fn, self.kind, self.desc = fn, executor, desc
        self.inflight: dict[Any, Any] = {}
        self.serial: deque[tuple[Any, Any]] = deque()
        self.client, self.own_client, self.pool = None, False, None
        if executor == "dask":
            self.client, self.own_client = _dask_client(scheduler)
            self.capacity, self.kind = n, "dask"
            self.token = uuid.uuid4().hex[:12]
            return
        nw = min(n_workers(workers), n)
        if nw <= 1:
            self.capacity, self.kind = 1, "serial"
            return
        if executor == "threads":
            self.pool = ThreadPoolExecutor(max_workers=nw)
        else:
            init = (_close_fd, (owner_fd,)) if owner_fd is not None else (None, ())
            self.pool = ProcessPoolExecutor(max_workers=nw, mp_context=mp.get_context("fork"), initializer=init[0],
                                            initargs=init[1])
        self.kind = "pool"
        # with a store, claim a little ahead of the workers so that other writers can take the rest
        self.capacity = 2 * nw if incremental else n

    @property
    def free(self) -> int:
        """How many more points this runner takes now."""
        return self.capacity - len(self.inflight) - len(self.serial)

    @property
    def busy(self) -> bool:
        """True while points are queued or running."""
        return bool(self.inflight or self.serial)

    def submit(self, gid: Any, point: Any) -> None:
        """Queue `point` (group `gid`) on this runner."""
        if self.kind == "serial":
            self.serial.append((gid, point))
        elif self.kind == "dask":
            fut = self.client.submit(self.fn, point, key=f"{self.desc}-{self.token}-{gid}", pure=False)
            self.inflight[fut] = gid
        else:
            self.inflight[self.pool.submit(self.fn, point)] = gid

    def wait(self, timeout: float | None) -> list[tuple[Any, Any]]:
        """Finished (gid, result) pairs: at least one unless `timeout` passed first; re-raises a point's error."""
        if self.kind == "serial":
            gid, point = self.serial.popleft()
            return [(gid, self.fn(point))]
        if self.kind == "dask":
            from distributed import wait as dask_wait

            try:
                done = dask_wait(list(self.inflight), timeout=timeout, return_when="FIRST_COMPLETED").done
            except TimeoutError:
                return []
        else:
            done = futures_wait(list(self.inflight), timeout=timeout, return_when=FIRST_COMPLETED).done
        return [(self.inflight.pop(f), f.result()) for f in done]

    def close(self, failed: bool) -> None:
        """Shut the runner down (cancelling what is in flight if the sweep `failed`)."""
        if failed:
            for f in self.inflight:
                f.cancel()
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=failed)
        if self.own_client:
            self.client.close()
