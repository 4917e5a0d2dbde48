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
    from .health import AccuracyError
    from .modelfiles import load_model_file
    from .paths import model_file, model_files
    from .registry import get_model
    from .registry import models as model_specs
    from .scenes import Scene, load_scene, scene_from_dict

# public name -> (module, attribute; None: the module itself)
_LAZY = {
    "native": ("mbsuite.native", None),
    "AccuracyError": ("mbsuite.health", "AccuracyError"),
    "judge": ("mbsuite.health", "judge"),
    "load_model_file": ("mbsuite.modelfiles", "load_model_file"),
    "model_file": ("mbsuite.paths", "model_file"),
    "model_files": ("mbsuite.paths", "model_files"),
    "get_model": ("mbsuite.registry", "get_model"),
    "model_specs": ("mbsuite.registry", "models"),
    "Scene": ("mbsuite.scenes", "Scene"),
    "load_scene": ("mbsuite.scenes", "load_scene"),
    "scene_from_dict": ("mbsuite.scenes", "scene_from_dict"),
    "run_judged": ("mbsuite.timerun", "run_judged"),
    "run_name": ("mbsuite.timerun", "run_name"),
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


def run(scene: Scene | str, engine: str | None = None, *, error_estimate: bool = False, workers: int = 0):
    """Run a scene's time simulation on its path (`solver.engine`, or `engine`: a key or label of the model's path
    table, `mbsuite list`), returning a `SimResult` whose health figures are judged here, once.

    `error_estimate=True` also runs the scene refined once and twice (`mbsuite.accuracy`; `workers` local processes,
    0 = all cores) and attaches `res.error_estimate`: per headline output the estimated error and the observed order;
    an estimate above its declared tolerance is a health figure like any other."""
    from .health import judge
    from .scenes import Scene, load_scene
    from .timerun import run_judged, run_name

    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    spec = scene.spec
    if engine is not None and spec.paths:
        scene = scene.replace(solver={"engine": engine})
    if error_estimate and spec.paths and spec.accuracy is None:
        raise SceneError(f"model '{spec.name}' declares no headline outputs: no error estimate")
    res = run_judged(scene)
    if error_estimate:
        from .analysis.errorestimate import error_estimate as estimate_error

        res.error_estimate = estimate_error(scene, base=spec.accuracy.values(scene, res), workers=workers)
        figures = res.error_estimate.figures()
        res.health.extend(figures)
        res.warnings.extend(judge(figures, allow_inaccurate=scene.solver.allow_inaccurate, what=run_name(scene)))
    return res


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
