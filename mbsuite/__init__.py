"""mbsuite: cross-checked multibody models of railway mechanisms on Pinocchio and MuJoCo.

    >>> import mbsuite
    >>> scene = mbsuite.load_scene("pantograph")          # the model's default scene
    >>> res = mbsuite.run(scene)                            # engine from scene.solver.engine

The names below are imported on first use (PEP 562), so `import mbsuite` and `mbsuite --version` load neither the
engines nor the models.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .errors import (
    GeometryError,
    MbsuiteError,
    ModelFileError,
    ParameterError,
    SceneError,
    SolverError,
)
from .version import __version__

if TYPE_CHECKING:
    from . import native
    from .modelfiles import load_model_file
    from .paths import model_file, model_files
    from .registry import get_model
    from .registry import models as model_specs
    from .scenes import Scene, load_scene, scene_from_dict
    from .simulate import run
    from .trust.health import AccuracyError

# public name -> (module, attribute; None: the module itself)
_LAZY = {
    "native": ("mbsuite.native", None),
    "AccuracyError": ("mbsuite.trust.health", "AccuracyError"),
    "judge": ("mbsuite.trust.health", "judge"),
    "load_model_file": ("mbsuite.modelfiles", "load_model_file"),
    "model_file": ("mbsuite.paths", "model_file"),
    "model_files": ("mbsuite.paths", "model_files"),
    "get_model": ("mbsuite.registry", "get_model"),
    "model_specs": ("mbsuite.registry", "models"),
    "Scene": ("mbsuite.scenes", "Scene"),
    "load_scene": ("mbsuite.scenes", "load_scene"),
    "scene_from_dict": ("mbsuite.scenes", "scene_from_dict"),
    "run": ("mbsuite.simulate", "run"),
    "run_judged": ("mbsuite.pathrun", "run_judged"),
    "run_name": ("mbsuite.pathrun", "run_name"),
}


def __getattr__(name: str) -> Any:
    """Import a public name on first use (and keep it in the module, so the next use is a plain lookup)."""
    try:
        module, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'mbsuite' has no attribute {name!r}") from None
    value = importlib.import_module(module)
    value = value if attr is None else getattr(value, attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})


__all__ = [
    "__version__",
    "AccuracyError",
    "GeometryError",
    "MbsuiteError",
    "ModelFileError",
    "ParameterError",
    "Scene",
    "SceneError",
    "SolverError",
    "get_model",
    "load_model_file",
    "load_scene",
    "model_file",
    "model_files",
    "model_specs",
    "native",
    "run",
    "scene_from_dict",
]
