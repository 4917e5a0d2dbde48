"""mbsuite: cross-checked multibody models of railway mechanisms on Pinocchio and MuJoCo.

    >>> import mbsuite
    >>> scene = mbsuite.load_scene("pantograph")          # the model's default scene
    >>> res = mbsuite.run(scene)                            # engine from scene.solver.engine
"""

from __future__ import annotations

__version__ = "0.1.0"

from .errors import (  # noqa: E402
    GeometryError,
    MbsuiteError,
    ModelFileError,
    ParameterError,
    SceneError,
    SolverError,
)
from .registry import get_model, models  # noqa: E402
from .scenes import Scene, load_scene, scene_from_dict  # noqa: E402


def run(scene: Scene | str, engine: str | None = None):
    """Run a scene's time simulation with its engine (or `engine`), returning a `SimResult`."""
    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    spec = scene.spec
    if spec.run is None:
        raise SceneError(f"model '{spec.name}' has no time simulation")
    if engine is not None:
        scene = scene.replace(solver={"engine": engine})
    return spec.run(scene)


__all__ = [
    "GeometryError",
    "MbsuiteError",
    "ModelFileError",
    "ParameterError",
    "Scene",
    "SceneError",
    "SolverError",
    "get_model",
    "load_scene",
    "models",
    "run",
    "scene_from_dict",
]
