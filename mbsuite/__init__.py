"""mbsuite: cross-checked multibody models of railway mechanisms on Pinocchio and MuJoCo.

    >>> import mbsuite
    >>> scene = mbsuite.load_scene("pantograph")          # the model's default scene
    >>> res = mbsuite.run(scene)                            # engine from scene.solver.engine
"""

from __future__ import annotations

from . import native  # noqa: E402  (mbsuite.native.load(): register the engine plugins with MuJoCo)
from .errors import (  # noqa: E402
    GeometryError,
    MbsuiteError,
    ModelFileError,
    ParameterError,
    SceneError,
    SolverError,
)
from .health import AccuracyError, judge  # noqa: E402
from .modelfiles import load_model_file  # noqa: E402
from .paths import model_file, model_files  # noqa: E402
from .registry import get_model  # noqa: E402
from .registry import models as model_specs
from .scenes import Scene, load_scene, scene_from_dict  # noqa: E402
from .timerun import run_judged, run_name  # noqa: E402
from .version import __version__


def run(scene: Scene | str, engine: str | None = None, *, error_estimate: bool = False, workers: int = 0):
    """Run a scene's time simulation on its path (`solver.engine`, or `engine`: a key or label of the model's path
    table, `mbsuite list`), returning a `SimResult` whose health figures are judged here, once.

    `error_estimate=True` also runs the scene refined once and twice (`mbsuite.accuracy`; `workers` local processes,
    0 = all cores) and attaches `res.error_estimate`: per headline output the estimated error and the observed order;
    an estimate above its declared tolerance is a health figure like any other."""
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
