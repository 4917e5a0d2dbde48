"""The sweep store: nothing in it executes, altered or torn records are never trusted, writers share it safely."""

from __future__ import annotations

import base64
import hashlib
import json
import math
import os
import pickle
import re
import subprocess
import sys
import tempfile
import textwrap
import threading
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from mbsuite.analysis.sweep import (
    StoreError,
    StoreWarning,
    SweepStore,
    decode_value,
    encode_value,
    point_key,
    run_sweep,
)
from mbsuite.errors import MbsuiteError

ROOT = Path(__file__).resolve().parents[2]


def _double(x):
    return {"x": x, "y": 2.0 * x}


def _bodies(path: Path) -> list[dict]:
    return [json.loads(line)["body"] for line in path.read_text().splitlines() if line.strip()]


def _sha(body: dict) -> str:
    """The checksum as the format defines it, computed here independently of the module."""
    canon = json.dumps(body, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=False)
    return hashlib.sha256(canon.encode()).hexdigest()


class _Boom:
    """Unpickling this runs `open(marker, "w")`: the proof that a store never unpickles."""

    def __init__(self, marker: str):
        self.marker = marker

    def __reduce__(self):
        return (open, (self.marker, "w"))


def _pickle_line(marker: Path, key: str = "k", point: object = 0) -> str:
    payload = base64.b64encode(pickle.dumps(_Boom(str(marker)))).decode()
    return json.dumps({"key": key, "index": 0, "point": point, "result": 0, "pickle": payload}) + "\n"


# ------------------------------------------------------------------------------------------------ nothing executes
def test_old_pickle_store_is_refused_naming_the_file_and_never_unpickled(tmp_path):
    marker, store = tmp_path / "executed", tmp_path / "old.jsonl"
    store.write_text(_pickle_line(marker, point_key(_double, 0), 0))
    with pytest.raises(StoreError, match="old pickle format") as err:
        run_sweep(_double, [0, 1], workers=1, store=store)
    assert str(store) in str(err.value)
    assert not marker.exists()
    assert store.read_text() == _pickle_line(marker, point_key(_double, 0), 0)  # left untouched


def test_crafted_pickle_line_inside_a_store_is_reported_and_not_executed(tmp_path):
    marker, store = tmp_path / "executed", tmp_path / "s.jsonl"
    assert run_sweep(_double, [0, 1], workers=1, store=store) == [_double(0), _double(1)]
    with store.open("a") as fh:
        fh.write(_pickle_line(marker, point_key(_double, 2), 2))
    with pytest.warns(StoreWarning, match="old pickle format"):
        assert run_sweep(_double, [0, 1, 2], workers=1, store=store) == [_double(x) for x in range(3)]
    assert not marker.exists()


# ------------------------------------------------------------------------------------------------ forged records
def _rewrite(store: Path, edit) -> None:
    lines = store.read_text().splitlines(keepends=True)
    store.write_text("".join(edit(i, line) for i, line in enumerate(lines)))


def test_altered_result_fails_its_checksum_and_is_recomputed(tmp_path):
    store, calls = tmp_path / "s.jsonl", []

    def f(x):
        calls.append(x)
        return x * 10

    assert run_sweep(f, [1, 2, 3], workers=1, store=store) == [10, 20, 30]

    def forge(_i, line):  # the result of point 2 becomes 999, the checksum left as it was
        rec = json.loads(line)
        if rec["body"].get("type") == "result" and rec["body"]["point"] == 2:
            rec["body"]["result"] = 999
        return json.dumps(rec) + "\n"

    _rewrite(store, forge)
    calls.clear()
    with pytest.warns(StoreWarning, match=r"line \d+: checksum mismatch"):
        assert run_sweep(f, [1, 2, 3], workers=1, store=store) == [10, 20, 30]
    assert calls == [2]


def test_result_moved_to_another_point_is_detected_even_with_a_valid_checksum(tmp_path):
    """A forger who recomputes the checksum but serves point 3's result under point 2's key is caught by the key,
    which is the hash of the function and the point the record itself holds."""
    store, calls = tmp_path / "s.jsonl", []

    def f(x):
        calls.append(x)
        return x * 10

    run_sweep(f, [2, 3], workers=1, store=store)
    key2 = point_key(f, 2)

    def forge(_i, line):
        body = json.loads(line)["body"]
        if body.get("type") == "result" and body["point"] == 3:
            body["key"] = key2  # claims to be point 2, holds point 3 and its result
            return json.dumps({"body": body, "sha256": _sha(body)}) + "\n"
        if body.get("type") == "result" and body["point"] == 2:
            return ""  # the genuine record of point 2 removed
        return line

    _rewrite(store, forge)
    calls.clear()
    with pytest.warns(StoreWarning, match="key is not the hash"):
        assert run_sweep(f, [2, 3], workers=1, store=store) == [20, 30]
    assert calls == [2, 3]  # the forged record serves neither point


def test_truncated_record_loses_only_itself_and_the_next_append_starts_a_fresh_line(tmp_path):
    store = tmp_path / "s.jsonl"
    run_sweep(_double, [0, 1, 2], workers=1, store=store)
    data = store.read_bytes()
    store.write_bytes(data[:-25])  # the record of point 2 torn by a crash
    calls = []

    def f(x):
        calls.append(x)
        return _double(x)

    f.__qualname__ = _double.__qualname__  # the same function for the store's key
    with pytest.warns(StoreWarning, match="truncated record"):
        assert run_sweep(f, [0, 1, 2, 3], workers=1, store=store) == [_double(x) for x in range(4)]
    assert calls == [2, 3]  # only the torn record's point and the new one
    lines = store.read_bytes().split(b"\n")
    torn = [i for i, ln in enumerate(lines) if ln and not ln.endswith(b"}")]
    assert len(torn) == 1  # the torn record stays one bad line: the append did not glue itself onto it
    with pytest.warns(StoreWarning) as rec:
        fresh = SweepStore(store).load()
    assert len(rec) == 1 and f"line {torn[0] + 1}:" in str(rec[0].message)
    assert sorted(fresh.values(), key=lambda r: r["x"]) == [_double(x) for x in range(4)]


# ------------------------------------------------------------------------------------------------ bad places
def test_directory_unwritable_place_foreign_file_and_non_utf8_line_are_clear_errors(tmp_path):
    with pytest.raises(StoreError, match="is a directory") as err:
        run_sweep(_double, [1], workers=1, store=tmp_path)
    assert str(tmp_path) in str(err.value)
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    with pytest.raises(StoreError, match="cannot create its folder"):
        run_sweep(_double, [1], workers=1, store=blocker / "sub" / "s.jsonl")
    csv = tmp_path / "data.csv"
    csv.write_text("a,b\n1,2\n")
    with pytest.raises(StoreError, match=r"line 1: not a sweep-store header"):
        run_sweep(_double, [1], workers=1, store=csv)
    assert csv.read_text() == "a,b\n1,2\n"
    store = tmp_path / "s.jsonl"
    run_sweep(_double, [1], workers=1, store=store)
    with store.open("ab") as fh:
        fh.write(b'{"body": "caf\xe9"}\n')
    n = len(store.read_bytes().splitlines())
    with pytest.raises(StoreError, match=rf"s\.jsonl, line {n}: not UTF-8") as err:
        run_sweep(_double, [1, 2], workers=1, store=store)
    assert isinstance(err.value, MbsuiteError)


def test_newer_schema_version_is_refused(tmp_path):
    store = tmp_path / "s.jsonl"
    body = {"type": "header", "format": "mbsuite-sweep-store", "version": 2}
    store.write_text(json.dumps({"body": body, "sha256": _sha(body)}) + "\n")
    with pytest.raises(StoreError, match="schema version 2"):
        SweepStore(store).load()


def _read_only_folder(folder: Path) -> None:
    folder.chmod(0o500)


def _lock_place_taken_by_a_folder(folder: Path) -> None:
    (folder / "s.jsonl.lock").mkdir()  # no file can be opened for writing there, not even by root


def _writers_place_taken_by_a_file(folder: Path) -> None:
    (folder / "s.jsonl.owners").write_text("x")  # the writers' folder cannot be made, not even by root


@pytest.mark.parametrize("spoil", [
    pytest.param(_read_only_folder, marks=pytest.mark.skipif(os.geteuid() == 0, reason="root writes anywhere")),
    _lock_place_taken_by_a_folder,
    _writers_place_taken_by_a_file,
])
def test_folder_where_the_store_cannot_write_is_a_clear_error(tmp_path, spoil):
    """A store whose folder refuses its files is a StoreError naming the file, before any point is computed."""
    folder = tmp_path / "place"
    folder.mkdir()
    spoil(folder)
    calls = []
    try:
        with pytest.raises(StoreError, match=rf"sweep store {re.escape(str(folder))}/s\.jsonl\S*: cannot "):
            run_sweep(calls.append, [1], workers=1, store=folder / "s.jsonl")
    finally:
        folder.chmod(0o700)
    assert calls == []


def test_unstorable_result_is_a_store_error_naming_the_point(tmp_path):
    with pytest.raises(StoreError, match=r"point 1 cannot be stored: cannot store a value of type .*object"):
        run_sweep(lambda x: object() if x else 0, [0, 1], workers=1, store=tmp_path / "s.jsonl")


# ------------------------------------------------------------------------------------------------ concurrent writers
WRITER = textwrap.dedent("""
    import os, sys, time
    from mbsuite.analysis.sweep import run_sweep

    def slow(x):
        fd = os.open(os.environ["CALLS"], os.O_WRONLY | os.O_APPEND | os.O_CREAT)
        os.write(fd, f"{x} {os.getpid()}\\n".encode())
        os.close(fd)
        time.sleep(0.15)
        return [x, x * x]

    print(repr(run_sweep(slow, list(range(10)), workers=int(sys.argv[2]), store=sys.argv[1])))
""")


@pytest.mark.parametrize("workers", [1, 2])
def test_two_writer_processes_compute_each_point_once(tmp_path, workers):
    script, store, calls = tmp_path / "w.py", tmp_path / "s.jsonl", tmp_path / "calls.txt"
    script.write_text(WRITER)
    env = {**os.environ, "CALLS": str(calls)}
    procs = [subprocess.Popen([sys.executable, str(script), str(store), str(workers)], env=env, cwd=ROOT,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outs = [p.communicate(timeout=120) for p in procs]
    for p, (_out, err) in zip(procs, outs, strict=True):
        assert p.returncode == 0, err
    expect = [[x, x * x] for x in range(10)]
    assert [eval(out) for out, _ in outs] == [expect, expect]  # noqa: S307 - our own repr of plain data
    done = [line.split() for line in calls.read_text().splitlines()]
    assert sorted(int(x) for x, _pid in done) == list(range(10))  # each point exactly once
    assert not (tmp_path / "s.jsonl.owners").exists()  # both writers deregistered


def test_two_writer_threads_compute_each_point_once(tmp_path):
    store, calls, lock = tmp_path / "s.jsonl", [], threading.Lock()
    out: list = [None, None]
    gate = threading.Barrier(2)

    def slow(x):
        with lock:
            calls.append((x, threading.current_thread().name))
        threading.Event().wait(0.05)
        return x + 0.5

    def writer(j):
        gate.wait()
        out[j] = run_sweep(slow, list(range(12)), workers=1, store=store)

    ts = [threading.Thread(target=writer, args=(j,), name=f"writer{j}") for j in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join(60)
    assert out == [[x + 0.5 for x in range(12)]] * 2
    assert sorted(x for x, _ in calls) == list(range(12))
    assert {name for _, name in calls} == {"writer0", "writer1"}  # started together, both took points


def test_claims_of_a_killed_writer_lapse(tmp_path):
    """A writer that dies holding claims does not block the others: they compute its points."""
    store = SweepStore(tmp_path / "s.jsonl")
    ghost = "0" * 32  # a writer that registered no live file: as after SIGKILL
    with store.locked():
        store.read()
        store.owner, real = ghost, store.owner
        store.claim([point_key(_double, 1)])
        store.owner = real
    calls = []

    def f(x):
        calls.append(x)
        return _double(x)

    f.__qualname__ = _double.__qualname__
    assert run_sweep(f, [1, 2], workers=1, store=tmp_path / "s.jsonl") == [_double(1), _double(2)]
    assert calls == [1, 2]


# ------------------------------------------------------------------------------------------------ round trip
def _same(a, b) -> bool:
    """Equal in type and bits, recursively (-0.0 != 0.0; any NaN equals any NaN: JSON keeps no NaN payload)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, float):
        if math.isnan(a) or math.isnan(b):
            return math.isnan(a) and math.isnan(b)
        return a == b and math.copysign(1, a) == math.copysign(1, b)
    if isinstance(a, complex):
        return _same(a.real, b.real) and _same(a.imag, b.imag)
    if isinstance(a, list | tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict):
        return list(a) == list(b) and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, np.ndarray | np.generic):
        return a.dtype == b.dtype and a.shape == b.shape and _same(a.tolist(), b.tolist())
    return a == b


_arrays = hnp.arrays(st.sampled_from([np.float64, np.float32, np.int64, np.int8, np.uint16, np.bool_,
                                      np.complex128]),
                     hnp.array_shapes(min_dims=0, max_dims=3, max_side=4))
_scalars = _arrays.map(lambda a: a.ravel()[0] if a.size else np.float64(0.0))
_leaves = (st.none() | st.booleans() | st.integers() | st.floats(allow_nan=True, allow_infinity=True) | st.text()
           | st.complex_numbers(allow_nan=True, allow_infinity=True) | _arrays | _scalars)
_values = st.recursive(
    _leaves,
    lambda kids: (st.lists(kids, max_size=4) | st.lists(kids, max_size=4).map(tuple)
                  | st.dictionaries(st.text(max_size=5) | st.just("$"), kids, max_size=4)
                  | st.dictionaries(st.integers() | st.floats(allow_nan=False), kids, max_size=3)),
    max_leaves=12)


@settings(max_examples=300, deadline=None)
@given(_values)
def test_encoding_round_trips_any_storable_value_exactly(value):
    line = json.dumps(encode_value(value), allow_nan=False)  # plain JSON: no NaN tokens, nothing executable
    assert _same(decode_value(json.loads(line)), value)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(_values, min_size=1, max_size=3))
def test_store_round_trips_results_exactly(results):
    calls: list[int] = []

    def f(i: int):
        calls.append(i)
        return results[i]

    with tempfile.TemporaryDirectory() as d, warnings.catch_warnings():
        warnings.simplefilter("error", StoreWarning)  # nothing written by us may be reported
        store = Path(d) / "s.jsonl"
        computed = run_sweep(f, list(range(len(results))), workers=1, store=store)
        assert calls == list(range(len(results)))
        resumed = run_sweep(f, list(range(len(results))), workers=1, store=store)
        assert calls == list(range(len(results)))  # every result came from the store: none computed again
        assert all(_same(a, b) for a, b in zip(computed, results, strict=True))
        assert all(_same(a, b) for a, b in zip(resumed, results, strict=True))


# ------------------------------------------------------------------------------------------------ keys and codec
def _typed(x):
    """A result that names the point's type and value: two points served the same result are told apart."""
    return f"{type(x).__module__}.{type(x).__qualname__} {x!r}"


# points equal under ==, or with the same plain JSON, that are different points of a study
_LOOKALIKES = [1, 1.0, True, "1", (1,), [1], {"1": 1}, {1: 1}, np.int64(1), np.int32(1), np.float32(1.0),
               np.float64(1.0), np.array([1.0]), np.array([1.0], dtype=np.float32), np.array([[1.0]]),
               0.0, -0.0, complex(1.0, 0.0), np.str_("1"), np.bool_(True)]


def test_points_that_look_alike_never_share_a_key_and_each_gets_its_own_result(tmp_path):
    """Every pair of different points has its own key (equal under == or in plain JSON is not the same point), so a
    sweep computes each of them and a resumed one serves each its own result."""
    keys = [point_key(_typed, p) for p in _LOOKALIKES]
    assert len(set(keys)) == len(_LOOKALIKES)
    assert point_key(_typed, 1) != point_key(_double, 1)  # the function is part of the key
    store, calls = tmp_path / "s.jsonl", []

    def f(x):
        calls.append(x)
        return _typed(x)

    f.__qualname__ = "typed_point"
    expect = [_typed(p) for p in _LOOKALIKES]
    assert run_sweep(f, _LOOKALIKES, workers=1, store=store) == expect
    assert len(calls) == len(_LOOKALIKES)  # none served another point's result
    calls.clear()
    assert run_sweep(f, _LOOKALIKES, workers=1, store=store) == expect
    assert calls == []  # every one from the store, each its own


def _scaled(x: float, *, scale: float, offset: float = 0.0) -> float:
    return scale * x + offset


@pytest.mark.parametrize("changed", [{"scale": 3.0}, {"offset": 0.5}, {"scale": 2.0, "offset": -0.0}])
def test_a_changed_parameter_of_the_function_never_returns_a_stored_result(tmp_path, changed):
    """The same points of a function with another keyword argument (a study's parameter bound with
    functools.partial) are other points: computed anew, never served the first study's results."""
    import functools

    store = tmp_path / "s.jsonl"
    first = functools.partial(_scaled, scale=2.0)
    assert run_sweep(first, [1.0, 2.0], workers=1, store=store) == [2.0, 4.0]
    second = functools.partial(_scaled, **{"scale": 2.0, **changed})
    assert point_key(first, 1.0) != point_key(second, 1.0)
    want = [_scaled(x, **{"scale": 2.0, **changed}) for x in (1.0, 2.0)]
    got = run_sweep(second, [1.0, 2.0], workers=1, store=store)
    assert got == want and [math.copysign(1, v) for v in got] == [math.copysign(1, v) for v in want]
    assert run_sweep(first, [1.0, 2.0], workers=1, store=store) == [2.0, 4.0]  # the first study still its own


_DTYPES = ["?", "i1", "<i2", "<i4", "<i8", "u1", "<u2", "<u4", "<u8", "<f2", "<f4", "<f8", ">f8", ">i4", "<c8",
           "<c16", "<U3"]
_SHAPES = [(), (0,), (4,), (2, 3), (2, 0, 3), (1, 1, 2), (3, 1)]


def _sample(dtype: np.dtype, shape: tuple[int, ...]) -> np.ndarray:
    """An array of `dtype` and `shape` holding the dtype's extremes (min, max, tiny, nan, inf, -0.0, words)."""
    n = math.prod(shape)
    if dtype.kind == "b":
        pool = [True, False]
    elif dtype.kind in "iu":
        info = np.iinfo(dtype)
        pool = [info.min, info.max, 0, 1, info.max // 3]
    elif dtype.kind in "fc":
        info = np.finfo(dtype)
        pool = [info.max, -info.max, info.tiny, -0.0, np.inf, -np.inf, np.nan, 1 / 3]
        if dtype.kind == "c":
            pool = [complex(a, b) for a, b in zip(pool, pool[::-1], strict=True)]
    else:
        pool = ["", "a", "xyz", "é€"]
    return np.array([pool[i % len(pool)] for i in range(n)], dtype=dtype).reshape(shape)


@pytest.mark.parametrize("shape", _SHAPES, ids=str)
@pytest.mark.parametrize("dtype", _DTYPES)
def test_every_dtype_and_shape_round_trips_bit_for_bit(dtype, shape):
    """Arrays of every storable dtype (byte order included) and shape (0-d, empty, column, ...) and their scalars come
    back from plain JSON with the same dtype, shape and bytes."""
    a = _sample(np.dtype(dtype), shape)
    back = decode_value(json.loads(json.dumps(encode_value(a), allow_nan=False)))
    assert type(back) is np.ndarray and back.dtype == a.dtype and back.shape == a.shape
    if a.dtype.kind not in "fc":
        assert back.tobytes() == a.tobytes()
    else:  # NaN payloads are not kept (encode_value's docstring): every NaN made the plain NaN, part by part
        for part in ((np.real, np.imag) if a.dtype.kind == "c" else (np.real,)):
            x, y = part(a), part(back)
            assert np.array_equal(np.isnan(x), np.isnan(y))
            assert np.where(np.isnan(y), 0, y).tobytes() == np.where(np.isnan(x), 0, x).tobytes()
    for s in a.ravel()[:3]:
        sb = decode_value(json.loads(json.dumps(encode_value(s), allow_nan=False)))
        assert type(sb) is type(s) and sb.dtype == s.dtype
        assert _same(sb, s)
