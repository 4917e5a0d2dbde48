"""One sweep API for every analysis: evaluate `fn(point)` over points, in parallel on all local cores by default.

    run_sweep(fn, points, workers=0, progress=None, desc="sweep")            # local processes (all cores)
    run_sweep(fn, points, executor="threads")                                # C threads of the native core
    run_sweep(fn, points, executor="dask", scheduler="tcp://host:8786")     # a Dask distributed cluster
    run_sweep(fn, points, store="out/sweep.jsonl")                           # stream to disk; resume; share
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
`max_points` points (default `MAX_POINTS` = 10 000; raise it per call or with `sweep_options`): a larger one is a
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

Defaults for calls that do not pass `executor`/`scheduler`/`store`/`max_points` (e.g. an analysis hook called by the
CLI) are set for a block by `sweep_options(executor=..., scheduler=..., store=..., max_points=...)`.
"""

from __future__ import annotations

import contextlib
import fcntl
import functools
import hashlib
import itertools
import json
import math
import multiprocessing as mp
import os
import re
import socket
import time
import uuid
import warnings
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Sequence, Sized
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, ThreadPoolExecutor
from concurrent.futures import wait as futures_wait
from pathlib import Path
from typing import Any

import numpy as np

from ..engines.core import callbacks_installed, n_workers
from ..errors import MbsuiteError, SceneError, SolverError
from ..results import Progress, to_jsonable

EXECUTORS = ("local", "threads", "dask")
MAX_POINTS = 10_000
"""Default upper limit on the number of points of one sweep (raise it with `max_points`)."""
_defaults: dict[str, Any] = {"executor": "local", "scheduler": None, "store": None, "max_points": MAX_POINTS}


@contextlib.contextmanager
def sweep_options(executor: str | None = None, scheduler: Any = None, store: str | Path | None = None,
                  max_points: int | None = None) -> Iterator[None]:
    """Defaults for every `run_sweep` in the block that does not pass its own (the CLI's `--executor/--scheduler/
    --store`, and a raised point limit)."""
    saved = dict(_defaults)
    try:
        if executor is not None:
            _check_executor(executor, scheduler if scheduler is not None else _defaults["scheduler"])
            _defaults["executor"] = executor
        if scheduler is not None:
            _defaults["scheduler"] = scheduler
        if store is not None:
            _defaults["store"] = store
        if max_points is not None:
            _defaults["max_points"] = _check_max_points(max_points)
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


def _check_max_points(max_points: Any) -> int:
    if isinstance(max_points, bool) or not isinstance(max_points, int | np.integer) or max_points < 1:
        raise SceneError(f"max_points = {max_points!r} is invalid; valid: an integer >= 1")
    return int(max_points)


# ------------------------------------------------------------------------------------------------------ sizes, values
def _too_many(what: str, count: float | str, limit: int) -> SceneError:
    if isinstance(count, str):
        n = count
    else:
        n = f"{count:,}" if isinstance(count, int) and count < 10**15 else f"{float(count):.3g}"
        n = "more than 1e308" if n == "inf" else n
    return SceneError(f"{what}: {n} points exceed the limit of {limit:,} points per sweep; raise it with "
                      "max_points=N (CLI: --max-points N) if the sweep is meant to be that large")


def check_grid(counts: Sequence[int], max_points: int | None = None, what: str = "sweep grid") -> int:
    """The number of points of a full grid over axes of `counts` values, or a `SceneError` if it exceeds
    `max_points` (default: the current limit, `MAX_POINTS`). Call it before building the grid."""
    limit = _check_max_points(max_points) if max_points is not None else _defaults["max_points"]
    total = math.prod(int(c) for c in counts)
    if total > limit:
        raise _too_many(f"{what} ({' x '.join(str(int(c)) for c in counts)})", total, limit)
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
    number, more than `max_points` values (default: the current limit, `MAX_POINTS`)."""
    limit = _check_max_points(max_points) if max_points is not None else _defaults["max_points"]
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
            raise _too_many(f"sweep values {text!r}", total, limit)
    out: list = []
    for kind, val in plan:
        out.extend(_range_values(text, val[0], val[1], int(val[2])) if kind == "range" else [val])
    return out


def _take(points: Iterable[Any], limit: int, desc: str) -> list[Any]:
    """`points` as a list, refusing more than `limit` before building it (a generator is read up to limit + 1)."""
    if isinstance(points, Sized):
        if len(points) > limit:
            raise _too_many(desc, len(points), limit)
        return list(points)
    head = list(itertools.islice(points, limit + 1))
    if len(head) > limit:
        raise _too_many(desc, f"more than {limit:,}", limit)
    return head


# ------------------------------------------------------------------------------------------------------ encoding
class StoreError(MbsuiteError):
    """A sweep store cannot be used (not a store, old pickle format, unwritable, not UTF-8, a value it cannot hold)."""


class StoreWarning(UserWarning):
    """A record of a sweep store was not trusted (damaged, altered, torn); its point is recomputed."""


_TAG = "$"
_NUMERIC_KINDS = "biufcU"


def _enc_float(x: float) -> Any:
    return x if math.isfinite(x) else {_TAG: "float", "v": repr(x)}


def encode_value(obj: Any) -> Any:
    """A JSON value that `decode_value` turns back into `obj`, equal in type and bits (a NaN comes back as the
    plain NaN: its sign and payload are not kept). Holds None, bool, int, float
    (also nan/inf), complex, str, list, tuple, dict, numpy scalars and numeric/str arrays; anything else is a
    `StoreError` naming its type (nothing is ever pickled)."""
    if obj is None or isinstance(obj, bool | str):
        return obj
    if isinstance(obj, np.generic):  # before float: np.float64 is a float subclass
        if obj.dtype.kind not in _NUMERIC_KINDS:
            raise StoreError(f"cannot store a numpy scalar of dtype {obj.dtype}")
        return {_TAG: "scalar", "dtype": obj.dtype.str, "v": encode_value(obj.item())}
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        return _enc_float(float(obj))
    if isinstance(obj, complex):
        return {_TAG: "complex", "re": _enc_float(obj.real), "im": _enc_float(obj.imag)}
    if isinstance(obj, list):
        return [encode_value(v) for v in obj]
    if isinstance(obj, tuple):
        return {_TAG: "tuple", "items": [encode_value(v) for v in obj]}
    if isinstance(obj, dict):
        if all(isinstance(k, str) for k in obj) and _TAG not in obj:
            return {k: encode_value(v) for k, v in obj.items()}
        return {_TAG: "dict", "items": [[encode_value(k), encode_value(v)] for k, v in obj.items()]}
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind not in _NUMERIC_KINDS or obj.dtype.fields is not None:
            raise StoreError(f"cannot store a numpy array of dtype {obj.dtype} (numbers, booleans and str only)")
        return {_TAG: "ndarray", "dtype": obj.dtype.str, "shape": list(obj.shape),
                "data": [encode_value(v) for v in obj.ravel().tolist()]}
    raise StoreError(f"cannot store a value of type {type(obj).__module__}.{type(obj).__qualname__}; a stored "
                     "result or point holds None, bool, int, float, complex, str, list, tuple, dict and numpy "
                     "scalars/arrays of numbers")


def _dec_float(v: Any) -> float:
    if isinstance(v, dict) and v.get(_TAG) == "float" and v.get("v") in ("nan", "inf", "-inf"):
        return float(v["v"])
    if isinstance(v, int | float) and not isinstance(v, bool):
        return float(v)
    raise StoreError(f"bad float {v!r}")


def decode_value(obj: Any) -> Any:
    """The value `encode_value` encoded (a `StoreError` for anything it cannot have written)."""
    if obj is None or isinstance(obj, bool | int | str):
        return obj
    if isinstance(obj, float):
        return obj
    if isinstance(obj, list):
        return [decode_value(v) for v in obj]
    if not isinstance(obj, dict):
        raise StoreError(f"bad value of type {type(obj).__name__}")
    if _TAG not in obj:
        return {k: decode_value(v) for k, v in obj.items()}
    tag = obj[_TAG]
    try:
        if tag == "float":
            return _dec_float(obj)
        if tag == "complex":
            return complex(_dec_float(obj["re"]), _dec_float(obj["im"]))
        if tag == "tuple":
            return tuple(decode_value(v) for v in obj["items"])
        if tag == "dict":
            return {_hashable(decode_value(k)): decode_value(v) for k, v in obj["items"]}
        if tag in ("scalar", "ndarray"):
            dt = np.dtype(obj["dtype"])
            if dt.kind not in _NUMERIC_KINDS or dt.fields is not None:
                raise StoreError(f"bad dtype {obj['dtype']!r}")
            if tag == "scalar":
                return np.array(decode_value(obj["v"]), dtype=dt)[()]
            shape = tuple(int(s) for s in obj["shape"])
            data = [decode_value(v) for v in obj["data"]]
            if math.prod(shape) != len(data):
                raise StoreError(f"array shape {shape} does not hold {len(data)} values")
            return np.array(data, dtype=dt).reshape(shape)
    except (KeyError, TypeError, ValueError) as exc:
        raise StoreError(f"bad {tag!r} value: {exc}") from None
    raise StoreError(f"unknown tag {tag!r}")


def _hashable(k: Any) -> Any:
    try:
        hash(k)
    except TypeError:
        raise StoreError(f"unhashable dict key {k!r}") from None
    return k


def _canonical(obj: Any) -> bytes:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=False).encode()


def _digest(obj: Any) -> str:
    return hashlib.sha256(_canonical(obj)).hexdigest()


# ------------------------------------------------------------------------------------------------------ point keys
def _fn_id(fn: Callable) -> str:
    if isinstance(fn, functools.partial):
        args = _canonical(encode_value([list(fn.args), dict(fn.keywords)])).decode()
        return f"partial({_fn_id(fn.func)}, {args})"
    return f"{getattr(fn, '__module__', '?')}.{getattr(fn, '__qualname__', repr(fn))}"


def _key(fn_id: str, point_enc: Any) -> str:
    return _digest({"fn": fn_id, "point": point_enc})


def point_key(fn: Callable, point: Any) -> str:
    """The store key of (function, point): SHA-256 of the canonical JSON of the function's qualified name (with a
    partial's arguments) and the encoded point. A closure's captured variables are not part of it: one store per
    study. `StoreError` for a point `encode_value` cannot hold."""
    return _key(_fn_id(fn), encode_value(point))


# ------------------------------------------------------------------------------------------------------ the store
FORMAT = "mbsuite-sweep-store"
SCHEMA_VERSION = 1
_OWNER = re.compile(r"[0-9a-f]{32}")


def _no_duplicate_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out = dict(pairs)
    if len(out) != len(pairs):
        raise ValueError("duplicate key in a JSON object")
    return out


def _record_line(body: dict[str, Any]) -> bytes:
    return (json.dumps({"body": body, "sha256": _digest(body)}, separators=(",", ":"), ensure_ascii=True,
                       allow_nan=False) + "\n").encode("ascii")


class SweepStore:
    """One store file shared by any number of writers (see the module docstring for the format and the guarantees).

    `load()` returns the trusted results by key. `run_sweep(store=...)` uses the rest: `locked`, `read`, `get`,
    `claimed_elsewhere`, `claim`, `record`, `session`."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        if self.path.is_dir():
            raise StoreError(f"sweep store {self.path}: is a directory; give a file path "
                             f"(e.g. {self.path / 'sweep.jsonl'})")
        if self.path.exists() and not self.path.is_file():
            raise StoreError(f"sweep store {self.path}: is not a regular file")
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise StoreError(f"sweep store {self.path}: cannot create its folder ({exc.strerror or exc})") from None
        self.lock_path = self.path.with_name(self.path.name + ".lock")
        self.owners_dir = self.path.with_name(self.path.name + ".owners")
        self.owner = uuid.uuid4().hex
        self.problems: list[str] = []
        self._offset = 0
        self._lineno = 0
        self._results: dict[str, tuple[int, dict[str, Any]]] = {}
        self._claims: dict[str, str] = {}
        self._reported: set[int] = set()
        self._alive: dict[str, bool] = {}
        self._owner_fd: int | None = None
        self._held = False

    # ---- locking
    def _oserror(self, what: str, exc: OSError, path: Path | None = None) -> StoreError:
        return StoreError(f"sweep store {path or self.path}: cannot {what} ({exc.strerror or exc})")

    @contextlib.contextmanager
    def locked(self, exclusive: bool = True) -> Iterator[None]:
        """Hold the sidecar lock `PATH.lock` (exclusive for writing, shared for reading)."""
        try:
            fd = os.open(self.lock_path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        except OSError as exc:
            raise self._oserror("create or open its lock file", exc, self.lock_path) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH)
            self._alive.clear()
            self._held = True
            yield
        finally:
            self._held = False
            os.close(fd)  # releases the lock

    @contextlib.contextmanager
    def session(self) -> Iterator[int]:
        """Be a live writer: hold `flock` on `PATH.owners/<owner>` while the block runs (the kernel releases it when
        the process dies, which is how other writers tell that this one's claims lapsed). Yields the file's fd."""
        path = self.owners_dir / self.owner
        with self.locked():
            try:
                self.owners_dir.mkdir(exist_ok=True)
                fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
            except OSError as exc:
                raise self._oserror("create its writer file", exc, path) from None
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            os.write(fd, f"pid {os.getpid()} host {socket.gethostname()}\n".encode())
            self._owner_fd = fd
        try:
            yield fd
        finally:
            with self.locked():
                with contextlib.suppress(OSError):
                    path.unlink()
                os.close(fd)
                self._owner_fd = None
                with contextlib.suppress(OSError):
                    self.owners_dir.rmdir()  # only when no other writer is registered

    def _is_alive(self, owner: str) -> bool:
        """Whether writer `owner` still holds its file (lock held by the caller)."""
        if owner == self.owner:
            return True
        if owner not in self._alive:
            path = self.owners_dir / owner
            try:
                fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
            except OSError:
                self._alive[owner] = False
            else:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except BlockingIOError:
                    self._alive[owner] = True
                else:  # nobody holds it: that writer ended without cleaning up (killed)
                    self._alive[owner] = False
                    with contextlib.suppress(OSError):
                        path.unlink()
                finally:
                    os.close(fd)
        return self._alive[owner]

    # ---- reading
    def _report(self, lineno: int, offset: int, msg: str) -> None:
        self._reported.add(offset)
        text = f"sweep store {self.path}, line {lineno}: {msg}; not trusted (its point is recomputed if needed)"
        self.problems.append(text)
        warnings.warn(text, StoreWarning, stacklevel=4)

    def read(self) -> None:
        """Read the records appended since the last call (lock held by the caller)."""
        try:
            with self.path.open("rb") as fh:
                size = os.fstat(fh.fileno()).st_size
                if size < self._offset:
                    raise StoreError(f"sweep store {self.path}: the file shrank while in use (replaced or truncated "
                                     "by another program)")
                fh.seek(self._offset)
                data = fh.read()
        except FileNotFoundError:
            if self._offset:
                raise StoreError(f"sweep store {self.path}: the file was removed while in use") from None
            return
        except OSError as exc:
            raise self._oserror("read it", exc) from None
        pos = 0
        while (nl := data.find(b"\n", pos)) >= 0:
            self._lineno += 1
            self._parse(data[pos:nl], self._lineno, self._offset + pos)
            pos = nl + 1
        if pos < len(data) and (self._offset + pos) not in self._reported:
            # no writer is mid-write while we hold the lock: an unterminated line is a record torn by a crash
            if self._lineno == 0:
                self._lineno += 1  # a torn first line: see whether it is a store at all
                self._parse(data[pos:], self._lineno, self._offset + pos)
                self._lineno -= 1
            else:
                self._report(self._lineno + 1, self._offset + pos, "a truncated record (the writer was interrupted)")
        self._offset += pos

    def _parse(self, raw: bytes, n: int, offset: int) -> None:
        if offset in self._reported or not raw.strip():
            return
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise StoreError(f"sweep store {self.path}, line {n}: not UTF-8 text (byte {exc.start + 1} of the "
                             "line); the file was not written by mbsuite or is damaged") from None
        try:
            rec = json.loads(text, object_pairs_hook=_no_duplicate_keys)
        except (ValueError, RecursionError):
            rec = None
        well_formed = (isinstance(rec, dict) and set(rec) == {"body", "sha256"} and isinstance(rec["body"], dict)
                       and isinstance(rec["sha256"], str))
        if n == 1:
            self._header(rec, well_formed)
            return
        if not well_formed:
            if isinstance(rec, dict) and "pickle" in rec:
                self._report(n, offset, "a record of the old pickle format (never unpickled: a pickle can execute "
                                        "code)")
            elif rec is None:
                self._report(n, offset, "not valid JSON (a truncated or damaged record)")
            else:
                self._report(n, offset, "not a sweep-store record")
            return
        body = rec["body"]
        if _digest(body) != rec["sha256"]:
            self._report(n, offset, "checksum mismatch (the record was altered or damaged)")
            return
        kind = body.get("type")
        if kind == "result":
            key, fn, point = body.get("key"), body.get("fn"), body.get("point")
            if not (isinstance(key, str) and isinstance(fn, str) and "point" in body and "result" in body):
                self._report(n, offset, "a result record without key, fn, point and result")
            elif _key(fn, point) != key:
                self._report(n, offset, "its key is not the hash of its function and point")
            else:
                self._results.setdefault(key, (n, body))  # the first trusted result of a point wins
        elif kind == "claim":
            key, owner = body.get("key"), body.get("owner")
            if isinstance(key, str) and isinstance(owner, str) and _OWNER.fullmatch(owner):
                self._claims[key] = owner
            else:
                self._report(n, offset, "a claim record without key and owner")
        else:
            self._report(n, offset, f"unknown record type {kind!r}")

    def _header(self, rec: Any, well_formed: bool) -> None:
        if isinstance(rec, dict) and ("pickle" in rec or {"key", "index"} <= set(rec)):
            raise StoreError(f"sweep store {self.path}: written in the old pickle format, which is not read any more "
                             "(a pickle can execute code); move or delete the file and run again to recompute")
        body = rec["body"] if well_formed else None
        if not (well_formed and isinstance(body, dict) and body.get("type") == "header"
                and body.get("format") == FORMAT):
            raise StoreError(f"sweep store {self.path}, line 1: not a sweep-store header; the file is not an "
                             f"mbsuite sweep store (left untouched; give another --store path)")
        if _digest(body) != rec["sha256"]:
            raise StoreError(f"sweep store {self.path}, line 1: the header fails its checksum (damaged)")
        if body.get("version") != SCHEMA_VERSION:
            raise StoreError(f"sweep store {self.path}: schema version {body.get('version')!r}; this mbsuite reads "
                             f"version {SCHEMA_VERSION}")

    def get(self, key: str) -> tuple[bool, Any]:
        """(True, result) for a trusted record of `key`, else (False, None)."""
        hit = self._results.get(key)
        if hit is None:
            return False, None
        n, body = hit
        try:
            return True, decode_value(body["result"])
        except (StoreError, RecursionError) as exc:
            del self._results[key]
            self._report(n, -n, f"its result cannot be decoded ({exc})")
            return False, None

    def claimed_elsewhere(self, key: str) -> bool:
        """Whether another live writer has claimed `key` (lock held by the caller)."""
        owner = self._claims.get(key)
        return owner is not None and owner != self.owner and self._is_alive(owner)

    def load(self) -> dict[str, Any]:
        """All trusted results by key (reading under a shared lock)."""
        with self.locked(exclusive=False):
            self.read()
        out = {}
        for key in list(self._results):
            ok, val = self.get(key)
            if ok:
                out[key] = val
        return out

    # ---- writing
    def _ensure_header(self) -> None:
        try:
            if self.path.is_file() and self.path.stat().st_size > 0:
                return
            tmp = self.path.with_name(f".{self.path.name}.{self.owner}.tmp")
            tmp.write_bytes(_record_line({"type": "header", "format": FORMAT, "version": SCHEMA_VERSION}))
            os.replace(tmp, self.path)  # atomic: a store never holds a torn header
        except OSError as exc:
            raise self._oserror("write it", exc) from None

    def _append(self, bodies: list[dict[str, Any]], sync: bool) -> None:
        """Append records (exclusive lock held), each on a fresh line."""
        if not self._held:
            raise RuntimeError("SweepStore._append without the lock")
        self._ensure_header()
        data = b"".join(_record_line(b) for b in bodies)
        try:
            fd = os.open(self.path, os.O_RDWR | os.O_APPEND | os.O_CLOEXEC)
            try:
                size = os.fstat(fd).st_size
                if size and os.pread(fd, 1, size - 1) != b"\n":
                    data = b"\n" + data  # a torn last record stays one bad line; this one starts fresh
                view = memoryview(data)
                while view:
                    view = view[os.write(fd, view):]
                if sync:
                    os.fsync(fd)
            finally:
                os.close(fd)
        except OSError as exc:
            raise self._oserror("append to it", exc) from None

    def claim(self, keys: list[str]) -> None:
        """Announce that this writer computes `keys` (exclusive lock held)."""
        if not keys:
            return
        host, pid = socket.gethostname(), os.getpid()
        self._append([{"type": "claim", "key": k, "owner": self.owner, "pid": pid, "host": host} for k in keys],
                     sync=False)
        for k in keys:
            self._claims[k] = self.owner

    def record(self, key: str, fn_id: str, point_enc: Any, result: Any) -> None:
        """Append the finished point `key` (takes the lock; flushed to disk before it returns)."""
        body = {"type": "result", "key": key, "fn": fn_id, "point": point_enc, "result": encode_value(result)}
        with self.locked():
            self._append([body], sync=True)


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


def _close_fd(fd: int) -> None:
    """Pool-worker initialiser: drop the inherited copy of the writer file, so only the writer itself keeps it."""
    with contextlib.suppress(OSError):
        os.close(fd)


class _Runner:
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
        return self.capacity - len(self.inflight) - len(self.serial)

    @property
    def busy(self) -> bool:
        return bool(self.inflight or self.serial)

    def submit(self, gid: Any, point: Any) -> None:
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
        if failed:
            for f in self.inflight:
                f.cancel()
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=failed)
        if self.own_client:
            self.client.close()


_POLL = 0.1  # s between looks at the store while waiting for points other writers compute


def run_sweep(fn: Callable[[Any], Any], points: Iterable[Any], *, workers: int = 0, progress: bool | None = None,
              desc: str = "sweep", executor: str | None = None, scheduler: Any = None,
              store: str | Path | None = None, max_points: int | None = None) -> list[Any]:
    """Evaluate `fn` at every point and return the results in the order of `points`.

    `workers`: local processes or threads (0 = all cores; 1 = serial in this process). `executor`: "local",
    "threads" or "dask" (then `scheduler` = address or Client). `store`: the file to stream results to, resume from
    and share with other writers (module docstring). `max_points`: the size guard (default `MAX_POINTS`); a larger
    sweep is a `SceneError` before anything runs. With a store, equal points are computed once."""
    executor = executor or _defaults["executor"]
    if executor == "threads" and _defaults["executor"] == "dask":
        executor = "dask"  # a cluster was asked for: it wins over a caller's local preference
    scheduler = scheduler if scheduler is not None else _defaults["scheduler"]
    store = store if store is not None else _defaults["store"]
    limit = _check_max_points(max_points) if max_points is not None else _defaults["max_points"]
    _check_executor(executor, scheduler)
    points = _take(points, limit, desc)
    results: list[Any] = [None] * len(points)
    if not store:
        groups: dict[Any, list[int]] = {i: [i] for i in range(len(points))}
        with Progress(len(points), desc, enabled=progress) as bar:
            _drive(fn, points, groups, results, bar, None, None, executor, workers, scheduler, desc)
        return results
    db = SweepStore(store)
    fn_id = _fn_id(fn)
    encoded: dict[str, Any] = {}
    groups = {}
    for i, pt in enumerate(points):
        try:
            enc = encode_value(pt)
        except StoreError as exc:
            raise StoreError(f"sweep store {db.path}: point {i} cannot be stored: {exc}") from None
        k = _key(fn_id, enc)
        encoded.setdefault(k, enc)
        groups.setdefault(k, []).append(i)
    with Progress(len(points), desc, enabled=progress) as bar, db.session() as owner_fd:
        _drive(fn, points, groups, results, bar, db, (fn_id, encoded, owner_fd), executor, workers, scheduler,
               desc)
    return results


def _drive(fn: Callable, points: list[Any], groups: dict[Any, list[int]], results: list[Any], bar: Progress,
           db: SweepStore | None, meta: tuple[str, dict[str, Any], int] | None, executor: str, workers: int,
           scheduler: Any, desc: str) -> None:
    """The loop of `run_sweep`: claim, submit, collect; with a store, wait for points other live writers compute."""
    def deliver(gid: Any, res: Any) -> None:
        for i in groups[gid]:
            results[i] = res
        bar.update(len(groups[gid]))

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
    runner = _Runner(fn, executor, workers, scheduler, len(queue), desc, db is not None,
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
    """The length of MuJoCo's full physics state of `model` (`mj_stateSize`, `mjSTATE_FULLPHYSICS`)."""
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
