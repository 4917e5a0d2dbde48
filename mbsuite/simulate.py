"""`run` (public as `mbsuite.run`): a scene's time simulation on its path, its health figures judged once, with an
optional error estimate of its headline outputs (`mbsuite.analysis.errorestimate`)."""

from __future__ import annotations

import time

from .errors import SceneError
from .pathrun import run_judged, run_name
from .scenes import Scene, load_scene
from .trust.health import InaccurateResult, judge_estimate


def run(scene: Scene | str, engine: str | None = None, *, error_estimate: bool = False, workers: int = 0):
    """Run a scene's time simulation on its path (`solver.engine`, or `engine`: a key or label of the model's path
    table, `mbsuite list`), returning a `SimResult` whose health figures are judged here, once.

    `error_estimate=True` also runs the scene's companions (refined once and twice, or coarsened once and twice
    where the model declares it: `mbsuite.trust.estimate`; `workers` local processes, 0 = all cores) and attaches
    `res.error_estimate`: per headline output the estimated error and the observed order. An estimate above its
    declared tolerance keeps the result: with the scene's `solver.allow_inaccurate` a warning in `res.warnings`,
    else also an `InaccurateResult` (an `AccuracyError`) whose `result` is `res`, flagged the same way."""
    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    spec = scene.spec
    if engine is not None and spec.paths:
        scene = scene.replace(solver={"engine": engine})
    if error_estimate and spec.paths and spec.accuracy is None:
        raise SceneError(f"model '{spec.name}' declares no headline outputs: no error estimate")
    t0 = time.perf_counter()
    res = run_judged(scene)
    if error_estimate:
        from .analysis.errorestimate import error_estimate as estimate_error
        from .progress import OverBudget

        try:
            res.error_estimate = estimate_error(scene, base=spec.accuracy.values(scene, res), workers=workers,
                                                base_seconds=time.perf_counter() - t0)
        except OverBudget as exc:  # the run is kept (`OverBudget.result`): the command line shows it, then stops
            exc.result = res
            raise
        figures = res.error_estimate.figures()
        res.health.extend(figures)
        inaccurate = judge_estimate(figures, allow_inaccurate=scene.solver.allow_inaccurate, what=run_name(scene))
        res.warnings.extend(inaccurate)
        if inaccurate and not scene.solver.allow_inaccurate:
            raise InaccurateResult(inaccurate, res)
    return res
