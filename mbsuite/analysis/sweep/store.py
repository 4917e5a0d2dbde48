"""The sweep store (`SweepStore`): one JSON-lines file of checksummed records shared by any number of writers, with
sidecar locks, claims and writer liveness (the format and its guarantees: the package docstring)."""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import re
import socket
import uuid
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from .encoding import StoreError, StoreWarning, decode_value, digest, encode_value, record_key

FORMAT = "mbsuite-sweep-store"
SCHEMA_VERSION = 1
_OWNER = re.compile(r"[0-9a-f]{32}")


def _no_duplicate_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out = dict(pairs)
    if len(out) != len(pairs):
        raise ValueError("duplicate key in a JSON object")
    return out


def _record_line(body: dict[str, Any]) -> bytes:
    return (json.dumps({"body": body, "sha256": digest(body)}, separators=(",", ":"), ensure_ascii=True,
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
        if digest(body) != rec["sha256"]:
            self._report(n, offset, "checksum mismatch (the record was altered or damaged)")
            return
        kind = body.get("type")
        if kind == "result":
            key, fn, point = body.get("key"), body.get("fn"), body.get("point")
            if not (isinstance(key, str) and isinstance(fn, str) and "point" in body and "result" in body):
                self._report(n, offset, "a result record without key, fn, point and result")
            elif record_key(fn, point) != key:
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
        if digest(body) != rec["sha256"]:
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
