"""One sweep API for every analysis: evaluate `fn(point)` over points, in parallel on all local cores by default.

    run_sweep(fn, points, workers=0, progress=None, desc="sweep")            # local processes (all cores)
    run_sweep(fn, points, executor="threads")                                # C threads of the native core
    run_sweep(fn, points, executor="dask", scheduler="tcp://host:8786")     # a Dask distributed cluster
    run_sweep(fn, points, store="out/sweep.jsonl")                           # stream to disk; resume after a crash

Executors
- `local` (default): a process pool (fork) with `workers` processes (0 = all cores available to this process);
  `workers=1` runs serially in this process. For work that is Python: the hand-derived paths.
- `threads`: a thread pool in this process. For MuJoCo work: the native core (`mbsuite.engines.core`) releases the
  GIL while it steps and keeps no global state, so each thread steps its own MjData in C, with no process start-up
  and nothing pickled (the pantograph's frequency sweep runs its MuJoCo points this way).
- `dask`: `distributed.Client(scheduler)` (an address, or a `Client`/`LocalCluster` object). `fn` and the points
  travel by cloudpickle, results come back pickled: bit-identical to the local executor.
- `rollout_sweep` (below): `mujoco.rollout` steps a batch of open-loop trajectories in C threads; mbsuite's engine
  plugins run under it (a test holds it bitwise equal to the native core).
MuJoCo's Python callbacks (`mujoco.set_mjcb_*`) are process-global: work that installs one (mbsuite's shipped scenes
never do) must not share a process between threads.

Results always come back in the order of `points`, whatever the executor and completion order.

Streaming and resume (`store=PATH`, a JSON-lines file): every finished point is appended as one line
`{"key", "index", "point", "result", "pickle"}` and flushed at once (`pickle` = base64 of the pickled result, so a
resumed result is identical to a computed one; `result` is the JSON view for people and other tools). A later call with
the same store skips every point whose key (a hash of the function's name and the point) is already there, so an
interrupted sweep resumes without recomputing finished points. A truncated last line (the process was killed while
writing) is ignored.

Defaults for calls that do not pass `executor`/`scheduler`/`store` (e.g. an analysis hook called by the CLI) are set
for a block by `sweep_options(executor=..., scheduler=..., store=...)`.
"""

from __future__ import annotations

import base64
import contextlib
import functools
import hashlib
import json
import multiprocessing as mp
import os
import pickle
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np

from ..engines.core import callbacks_installed, n_workers
from ..errors import MbsuiteError, SceneError, SolverError
from ..results import Progress, to_jsonable

EXECUTORS = ("local", "threads", "dask")
_defaults: dict[str, Any] = {"executor": "local", "scheduler": None, "store": None}


@contextlib.contextmanager
def sweep_options(executor: str | None = None, scheduler: Any = None,
                  store: str | Path | None = None) -> Iterator[None]:
    """Defaults for every `run_sweep` in the block that does not pass its own (the CLI's `--executor/--scheduler`)."""
    saved = dict(_defaults)
    try:
        if executor is not None:
            _check_executor(executor, scheduler if scheduler is not None else _defaults["scheduler"])
            _defaults["executor"] = executor
        if scheduler is not None:
            _defaults["scheduler"] = scheduler
        if store is not None:
            _defaults["store"] = store
        yield
    finally:
        _defaults.clear()
        _defaults.update(saved)


def current_executor() -> str:
    """The executor a `run_sweep` call without its own `executor` would use (set by `sweep_options`)."""
    return _defaults["executor"]


def _check_executor(executor: str, scheduler: Any) -> None:
    if executor not in EXECUTORS:
        raise SceneError(f"unknown sweep executor {executor!r}; valid: {list(EXECUTORS)}")
    if executor == "dask" and scheduler is None:
        raise SceneError("the dask executor needs a scheduler address (--scheduler tcp://HOST:PORT)")


# ------------------------------------------------------------------------------------------------------ point keys
def _fn_id(fn: Callable) -> str:
    if isinstance(fn, functools.partial):
        args = json.dumps(to_jsonable([list(fn.args), fn.keywords]), sort_keys=True, default=repr)
        return f"partial({_fn_id(fn.func)}, {args})"
    return f"{getattr(fn, '__module__', '?')}.{getattr(fn, '__qualname__', repr(fn))}"


def point_key(fn: Callable, point: Any) -> str:
    """A stable key of (function, point): sha256 of the function's qualified name and the point as sorted JSON."""
    text = json.dumps({"fn": _fn_id(fn), "point": to_jsonable(point)}, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


# ------------------------------------------------------------------------------------------------------ the store
class SweepStore:
    """An append-only JSON-lines file of finished points (see the module docstring)."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)

    def load(self) -> dict[str, Any]:
        """Finished results by key; a malformed (truncated) line is skipped."""
        done: dict[str, Any] = {}
        if not self.path.is_file():
            return done
        with self.path.open() as fh:
            for line in fh:
                try:
                    rec = json.loads(line)
                    done[rec["key"]] = pickle.loads(base64.b64decode(rec["pickle"]))
                except (ValueError, KeyError, pickle.UnpicklingError, EOFError, TypeError):
                    continue
        return done

    def append(self, key: str, index: int, point: Any, result: Any) -> None:
        rec = {"key": key, "index": index, "point": to_jsonable(point), "result": _json_view(result),
               "pickle": base64.b64encode(pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL)).decode()}
        line = json.dumps(rec, default=repr) + "\n"
        with self.path.open("a") as fh:
            fh.write(line)
            fh.flush()
            os.fsync(fh.fileno())


def _json_view(result: Any) -> Any:
    try:
        return to_jsonable(result)
    except Exception:  # noqa: BLE001 - the pickle is authoritative; the JSON view is a courtesy
        return repr(result)


# ------------------------------------------------------------------------------------------------------ executors
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


def run_sweep(fn: Callable[[Any], Any], points: Sequence[Any], *, workers: int = 0, progress: bool | None = None,
              desc: str = "sweep", executor: str | None = None, scheduler: Any = None,
              store: str | Path | None = None) -> list[Any]:
    """Evaluate `fn` at every point and return the results in the order of `points`.

    `workers`: local processes (0 = all cores; 1 = serial in this process). `executor`: "local" or "dask" (then
    `scheduler` = address or Client). `store`: JSON-lines file to stream results to and resume from."""
    executor = executor or _defaults["executor"]
    if executor == "threads" and _defaults["executor"] == "dask":
        executor = "dask"  # a cluster was asked for: it wins over a caller's local preference
    scheduler = scheduler if scheduler is not None else _defaults["scheduler"]
    store = store if store is not None else _defaults["store"]
    _check_executor(executor, scheduler)
    points = list(points)
    keys = [point_key(fn, pt) for pt in points]
    results: list[Any] = [None] * len(points)
    db = SweepStore(store) if store else None
    done = db.load() if db else {}
    todo = []
    for i, k in enumerate(keys):
        if k in done:
            results[i] = done[k]
        else:
            todo.append(i)

    def finish(i: int, res: Any) -> None:
        results[i] = res
        if db is not None:
            db.append(keys[i], i, points[i], res)
        bar.update()

    with Progress(len(points), desc, enabled=progress) as bar:
        bar.update(len(points) - len(todo))
        if not todo:
            return results
        if executor == "dask":
            client, own = _dask_client(scheduler)
            try:
                from distributed import as_completed as dask_completed

                futs = {client.submit(fn, points[i], key=f"{desc}-{keys[i]}", pure=False): i for i in todo}
                for fut in dask_completed(list(futs)):
                    finish(futs[fut], fut.result())
            finally:
                if own:
                    client.close()
            return results
        nw = min(n_workers(workers), len(todo))
        if nw <= 1:
            for i in todo:
                finish(i, fn(points[i]))
            return results
        pool = (ThreadPoolExecutor(max_workers=nw) if executor == "threads"
                else ProcessPoolExecutor(max_workers=nw, mp_context=mp.get_context("fork")))
        with pool as ex:
            futs = {ex.submit(fn, points[i]): i for i in todo}
            try:
                for fut in as_completed(futs):
                    finish(futs[fut], fut.result())
            except BaseException:
                for f in futs:
                    f.cancel()
                raise
    return results


# ------------------------------------------------------------------------------------------------------ rollout
def rollout_sweep(models: Any, initial_states: np.ndarray, controls: np.ndarray, *, workers: int = 0,
                  nstep: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Open-loop trajectories of a batch in MuJoCo's C threads (`mujoco.rollout`), `workers` threads (0 = all cores).

    `models`: one MjModel or a sequence (one per trajectory, same sizes); `initial_states` (B, nstate) in
    mjSTATE_FULLPHYSICS; `controls` (B, nstep, nu) (or singleton dimensions). Returns (state (B, nstep, nstate),
    sensordata). Refuses to run while a Python callback is installed: rollout's threads would call it without the GIL
    serialising the model's state, and a scene with callbacks must go through `run_sweep` instead."""
    import mujoco
    from mujoco import rollout

    installed = callbacks_installed()
    if installed:
        raise SceneError(f"rollout_sweep needs a scene without Python callbacks; installed: {installed}. "
                         "Use run_sweep (processes) for such scenes.")
    m0 = models if isinstance(models, mujoco.MjModel) else models[0]
    nt = max(1, min(n_workers(workers), np.shape(initial_states)[0]))
    datas = [mujoco.MjData(m0) for _ in range(nt)]
    state, sens = rollout.rollout(models, datas, np.asarray(initial_states, float), np.asarray(controls, float),
                                  nstep=nstep)
    from ..engines.core import check_plugin_faults

    for d in datas:  # a fault of an mbsuite plugin in any trajectory stays recorded in the data that ran it
        check_plugin_faults(m0, d, "mujoco.rollout batch")
    if not np.all(np.isfinite(state)):
        raise SolverError("mujoco.rollout batch: a trajectory became non-finite (NaN/inf); reduce the timestep")
    return state, sens


def state_size(model: Any) -> int:
    import mujoco

    return mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)


def get_state(model: Any, data: Any) -> np.ndarray:
    """The full physics state of `data` (the initial-state format of `rollout_sweep`)."""
    import mujoco

    s = np.zeros(state_size(model))
    mujoco.mj_getState(model, data, s, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    return s


# ------------------------------------------------------------------------------------------------------ scene points
def scene_point(job: tuple[dict, dict]) -> dict[str, Any]:
    """A generic parameter-study point: `job = (scene_dict, sections)`; runs `scene.replace(**sections)` and returns
    per-signal statistics (min, max, mean, final) and the solver stats. Module-level, so it pickles to any executor."""
    from .. import run
    from ..scenes import scene_from_dict

    scene_d, sections = job
    scene = scene_from_dict(scene_d)
    if sections:
        scene = scene.replace(**sections)
    res = run(scene)
    sig = getattr(res, "signals", {}) or {}
    return {"signals": {k: {"min": float(np.min(v)), "max": float(np.max(v)), "mean": float(np.mean(v)),
                            "final": float(v[-1])} for k, v in sig.items()},
            "stats": to_jsonable(getattr(res, "stats", {}) or {})}
