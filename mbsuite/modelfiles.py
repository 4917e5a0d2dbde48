"""Loading a shipped model file with the checks its model declares for it (`ModelSpec.file_checks`).

The engine loaders (`mbsuite.engines.mujoco_engine.load_model`, `pinocchio_engine.load_urdf/load_mjcf`) name no model:
they run the check they are handed. This layer finds the model that declares a file of that name and hands its check.

    >>> import mbsuite
    >>> m = mbsuite.load_model_file(mbsuite.model_file("coupler_double"))              # MuJoCo, closures checked
    >>> pm = mbsuite.load_model_file(mbsuite.model_file("coupler_double", "urdf"), "pinocchio")
"""

from __future__ import annotations

from pathlib import Path

from .engines import mujoco_engine, pinocchio_engine
from .engines.mujoco_engine import FileCheck
from .errors import SceneError
from .registry import models

ENGINES = ("mujoco", "pinocchio")


def file_check(path: str | Path) -> FileCheck | None:
    """The check a model declares for a file of this name (its stem), or None."""
    stem = Path(path).stem
    return next((s.file_checks[stem] for s in models().values() if stem in s.file_checks), None)


def load_model_file(path: str | Path, engine: str = "mujoco"):
    """Load an MJCF (MuJoCo or Pinocchio) or URDF (Pinocchio) file and run its model's declared checks: an MjModel for
    engine "mujoco", a pin.Model for "pinocchio". A ModelFileError names the file and what is wrong."""
    p = Path(path)
    if engine not in ENGINES:
        raise SceneError(f"engine {engine!r} cannot load model files; valid engines: {list(ENGINES)}")
    check = file_check(p)
    if engine == "mujoco":
        return mujoco_engine.load_model(p, check=check)
    if p.suffix.lower() == ".urdf":
        return pinocchio_engine.load_urdf(p, check=check)
    return pinocchio_engine.load_mjcf(p, check=check)
