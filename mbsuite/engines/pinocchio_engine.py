"""Pinocchio plumbing: loading URDF/MJCF with clear errors, loop-closure constraints, rank/SVD/screw utilities."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import ModelFileError


def _load(builder, kind: str, path: str | Path) -> pin.Model:
    p = Path(path)
    if not p.is_file():
        raise ModelFileError(f"{kind} file not found: {p}")
    try:
        return builder(str(p))
    except Exception as exc:
        raise ModelFileError(f"Pinocchio cannot load {kind} {p}: {exc}") from exc


def load_urdf(path: str | Path) -> pin.Model:
    """Build a Pinocchio model from a URDF file; parse errors become ModelFileError naming the file."""
    return _load(pin.buildModelFromUrdf, "URDF", path)


def load_mjcf(path: str | Path) -> pin.Model:
    """Build a Pinocchio model from an MJCF file (only the first top-level body of <worldbody> is kept by Pinocchio)."""
    return _load(pin.buildModelFromMJCF, "MJCF", path)


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
