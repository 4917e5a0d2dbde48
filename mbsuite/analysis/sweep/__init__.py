"""One sweep API for every analysis: evaluate `fn(point)` over points, in parallel on all local cores by default.

    run_sweep(fn, points, workers=0, progress=None, desc="sweep")            # local processes (all cores)
    run_sweep(fn, points, executor="threads")                                # C threads of the native core
    run_sweep(fn, points, executor="dask", scheduler="tcp://host:8786")     # a Dask distributed cluster
    run_sweep(fn, points, store="out/sweep.jsonl")                           # stream to disk; resume; share
    run_sweep(fn, points, options=SweepOptions(executor="dask", scheduler=addr, store=path, max_points=N))
    parse_values("1:30:0.5"), parse_values("1e5,2e5")                        # the CLI's --vary values

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

Results always come back in the order of `points`, whatever the executor and completion order. A sweep holds at most
`max_points` points (default `MAX_POINTS` = 10 000; raise it per call or in `SweepOptions`): a larger one is a
`SceneError` before anything is allocated, and `parse_values` counts a range before it builds it.

The store (`store=PATH`): a JSON-lines file, schema version `SCHEMA_VERSION`, that nothing in it can execute.
- Line 1 is a header record; every later line is one record `{"body": {...}, "sha256": HEX}` where `sha256` is the
  SHA-256 of the body's canonical JSON (sorted keys, no spaces, ASCII). Bodies are `{"type": "result", "key", "fn",
  "point", "result"}` (a finished point, flushed and fsync'ed at once) or `{"type": "claim", "key", "owner", ...}` (a
  writer announces the point it is computing).
- `key` = SHA-256 of the canonical JSON of `{"fn": qualified name of fn (with a partial's arguments), "point":
  encoded point}`; a reader recomputes it from the record's own `fn` and `point`, so a result cannot be served for
  another point or function.
- Values are encoded as plain JSON with tags that keep what JSON cannot hold (`encode_value`): tuples, dicts with
  non-string keys, non-finite and complex numbers, numpy scalars and arrays (dtype, shape and the numbers as a list;
  floats are written with Python's shortest round-trip repr). A resumed result is therefore equal, type for type and
  bit for bit, to the computed one. Lists in JSON rather than a sidecar `.npz`: one file stays the whole store (no
  second file to lose, tear or mismatch), every record is checksummed as one unit, and any JSON tool reads it; the
  price is size (about 20 bytes per float), acceptable for the summaries a sweep returns.
- A record that fails its checksum, does not parse (a line torn by a crash), has a key that does not match its point,
  or holds an unknown tag is reported (`StoreWarning`, and `SweepStore.problems`) and its point recomputed, never
  trusted. Every write starts on a fresh line, so a torn record loses only itself. The checksum detects damage and
  hand edits; it is not a signature: whoever can write the file can also write a record with a valid checksum.
- Writers lock a sidecar file `PATH.lock` (`fcntl.flock`) around each read and append, so any number of processes
  (or threads) can share one store. Before computing points a writer claims them; a point claimed by another live
  writer is not computed again but waited for. A writer is live while it holds `flock` on its own file in
  `PATH.owners/`, which the kernel releases when the process ends however it ends, so the claims of a killed writer
  lapse and its points are computed by whoever needs them. `flock` is reliable on local file systems.
- A file written by the old pickle format, a file that is not a store, a directory, a place that cannot be written and
  a line that is not UTF-8 are each a `StoreError` (an `MbsuiteError`) naming the file (and line).

`SweepOptions` carries `executor`/`scheduler`/`store`/`max_points` from whoever chose them (the CLI's flags) down to
`run_sweep(options=...)`, checked once when made; an analysis that runs sweeps takes `options` and hands it on.

The package: `options.py` (SweepOptions, limits), `grid.py` (values, grid sizes), `encoding.py` (stored values, keys),
`store.py` (SweepStore), `executors.py` (where points run), `driver.py` (run_sweep), `rollout.py` (mujoco.rollout
batches), `points.py` (the generic scene point of `mbsuite sweep`).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .driver import run_sweep
    from .encoding import StoreError, StoreWarning, decode_value, encode_value, point_key
    from .grid import check_grid, parse_values
    from .options import EXECUTORS, MAX_POINTS, SweepOptions
    from .points import scene_point
    from .rollout import get_state, rollout_sweep, state_size
    from .store import FORMAT, SCHEMA_VERSION, SweepStore

# public name -> the module holding it, imported on first use (so the command line's parser, which reads only the
# options' constants, does not load the executors and the engines)
_HOME = {
    "run_sweep": "driver", "StoreError": "encoding", "StoreWarning": "encoding", "decode_value": "encoding",
    "encode_value": "encoding", "point_key": "encoding", "check_grid": "grid", "parse_values": "grid",
    "EXECUTORS": "options", "MAX_POINTS": "options", "SweepOptions": "options", "scene_point": "points",
    "get_state": "rollout", "rollout_sweep": "rollout", "state_size": "rollout", "FORMAT": "store",
    "SCHEMA_VERSION": "store", "SweepStore": "store",
}


def __getattr__(name: str) -> Any:
    """A public name, imported from its module on first use."""
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_HOME[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_HOME})


__all__ = [
    "EXECUTORS", "FORMAT", "MAX_POINTS", "SCHEMA_VERSION", "StoreError", "StoreWarning", "SweepOptions", "SweepStore",
    "check_grid", "decode_value", "encode_value", "get_state", "parse_values",
    "point_key", "rollout_sweep", "run_sweep", "scene_point", "state_size",
]
