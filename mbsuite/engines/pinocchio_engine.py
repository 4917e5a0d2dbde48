"""Pinocchio plumbing: loading URDF/MJCF with clear errors, loop-closure constraints, rank/SVD/screw utilities."""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import ModelFileError
from .mujoco_engine import FileCheck, load_model, one_line, read_model_text


@contextlib.contextmanager
def _native_stderr() -> Iterator[list[str]]:
    """Capture what C++ code writes to file descriptor 2 during the block (urdfdom reports parse errors there and
    carries on); the captured lines are appended to the yielded list."""
    lines: list[str] = []
    fd = 2  # the process's standard error, whatever Python's sys.stderr is wrapped in
    try:
        sys.stderr.flush()
        saved = os.dup(fd)
    except (AttributeError, OSError, ValueError):
        yield lines
        return
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), fd)
        try:
            yield lines
        finally:
            os.dup2(saved, fd)
            os.close(saved)
            tmp.seek(0)
            lines += [x for x in tmp.read().decode("utf-8", "replace").splitlines() if x.strip()]


def _load(builder, kind: str, path: str | Path, check: FileCheck | None) -> pin.Model:
    p = Path(path)
    if not p.is_file():
        raise ModelFileError(f"{kind} file not found: {p}")

    read_model_text(p)
    if kind == "MJCF":  # MuJoCo's parser is strict (types, ranges); Pinocchio's ignores what it does not read
        load_model(p, check=check)
    try:
        with _native_stderr() as said:
            model = builder(str(p))
    except Exception as exc:
        raise ModelFileError(f"Pinocchio cannot load {kind} {p}: {one_line(exc)}") from exc
    errors = [x for x in said if "error" in x.lower()]
    if errors:
        raise ModelFileError(f"Pinocchio reports errors reading {kind} {p}: {one_line('; '.join(errors))}")
    if check is not None:
        check(p, "urdf" if kind == "URDF" else "pinocchio", model)
    return model


def load_urdf(path: str | Path, *, check: FileCheck | None = None) -> pin.Model:
    """Build a Pinocchio model from a URDF file; parse errors (also those urdfdom only prints) become
    ModelFileError naming the file. `check(path, "urdf", model)`: the checks a model hands in for its own file."""
    return _load(pin.buildModelFromUrdf, "URDF", path, check)


def load_mjcf(path: str | Path, *, check: FileCheck | None = None) -> pin.Model:
    """Build a Pinocchio model from an MJCF file (only the first top-level body of <worldbody> is kept by Pinocchio);
    the file is compiled by MuJoCo first, whose parser refuses what Pinocchio's would skip.
    `check(path, "pinocchio", model)`: the checks a model hands in for its own file."""
    return _load(pin.buildModelFromMJCF, "MJCF", path, check)


def frame_id(model: pin.Model, name: str) -> int:
    """The id of frame `name`; a ModelFileError listing the frames if it is missing."""
    if not model.existFrame(name):
        raise ModelFileError(f"model '{model.name}' has no frame '{name}'; frames: {[f.name for f in model.frames]}")
    return model.getFrameId(name)


def numerical_rank(J: np.ndarray, rtol: float = 1e-9) -> tuple[int, np.ndarray]:
    """Rank by SVD: singular values above `rtol * s_max` count (documented relative tolerance). Returns (rank, s)."""
    s = np.linalg.svd(np.asarray(J, dtype=float), compute_uv=False)
    if s.size == 0 or s[0] == 0.0:
        return 0, s
    return int(np.sum(s > rtol * s[0])), s
