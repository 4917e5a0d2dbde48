"""One run of a scene on its path (`SPEC.paths`, the scene's `solver.engine`), its health figures judged once: what
`mbsuite.run` does without an error estimate, and what each refined copy of an error estimate and each sweep point
runs (`mbsuite.analysis`)."""

from __future__ import annotations

from .errors import SceneError
from .scenes import Scene
from .trust.health import judge


def run_judged(scene: Scene):
    """Run `scene`'s time simulation on its path (`solver.engine`) and judge its health figures once
    (`mbsuite.trust.health.judge`: an `AccuracyError` for a figure above its bound unless `solver.allow_inaccurate`)."""
    spec = scene.spec
    if not spec.paths:
        raise SceneError(f"model '{spec.name}' has no time simulation")
    res = spec.paths[scene.solver.engine].run(scene)
    res.warnings.extend(judge(res.health, allow_inaccurate=scene.solver.allow_inaccurate, what=run_name(scene)))
    return res


def run_name(scene: Scene) -> str:
    """The run's name in a health message: model and scene."""
    return f"{scene.spec.name} scene {scene.name or scene.source or ''}".strip()
