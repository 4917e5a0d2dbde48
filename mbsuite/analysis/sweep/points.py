"""The generic parameter-study point of `mbsuite sweep`, and a coarse companion of an error estimate (module-level,
so they pickle to any executor)."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ...errors import MbsuiteError
from ...results import to_jsonable

#: the key of a companion's values that says it failed (its message)
FAILED = "__failed__"


def companion_values(evaluate: Callable[[dict], Mapping[str, float]], scene_d: dict) -> dict[str, Any]:
    """`evaluate` on a coarse companion of an error estimate (`mbsuite.analysis.errorestimate`): its warnings
    silenced (it runs with `solver.allow_inaccurate`: a health figure past its bound is expected of it, not of the
    run), a failure returned as `{FAILED: message}` instead of raised (the estimate then falls back to the refined
    companions)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return dict(evaluate(scene_d))
    except MbsuiteError as exc:
        return {FAILED: f"{type(exc).__name__}: {exc}"}


def scene_headlines(scene_d: dict) -> dict[str, float]:
    """The headline values of one time run of the scene `scene_d` (a `Scene.to_dict()`), its health judged."""
    from ...pathrun import run_judged
    from ...scenes import scene_from_dict

    scene = scene_from_dict(scene_d)
    return dict(scene.spec.accuracy.values(scene, run_judged(scene)))


def scene_point(job: tuple[dict, dict] | tuple[dict, dict, int]) -> dict[str, Any]:
    """A generic parameter-study point: `job = (scene_dict, sections[, level])`; runs `scene.replace(**sections)` and
    returns per-signal statistics (min, max, mean, final) and the solver stats. With a `level`, the scene is first
    refined that many times (`mbsuite.trust.estimate`: its path's refinement) and the result also holds its headline
    values
    (`headlines`), for the point's error estimate; a negative level is a coarse companion (`refine(scene, level)`,
    `companion_values`: only its headlines). Module-level, so it pickles to any executor."""
    from ...pathrun import run_judged as run
    from ...scenes import scene_from_dict

    scene_d, sections, *rest = job
    scene = scene_from_dict(scene_d)
    if sections:
        scene = scene.replace(**sections)
    acc = scene.spec.accuracy
    if rest and int(rest[0]) < 0:  # a coarse companion: its headline values only, or why it failed
        try:
            comp = acc.refinement(scene).refine(scene, int(rest[0])).replace(solver={"allow_inaccurate": True})
        except MbsuiteError as exc:
            return {"signals": {}, "stats": {}, "headlines": {FAILED: str(exc)}}
        return {"signals": {}, "stats": {}, "headlines": companion_values(scene_headlines, comp.to_dict())}
    if rest:
        scene = acc.refinement(scene).refine(scene, int(rest[0]))
    res = run(scene)
    sig = getattr(res, "signals", {}) or {}
    out = {"signals": {k: {"min": float(np.min(v)), "max": float(np.max(v)), "mean": float(np.mean(v)),
                           "final": float(v[-1])} for k, v in sig.items()},
           "stats": to_jsonable(getattr(res, "stats", {}) or {})}
    if rest:
        out["headlines"] = {k: float(v) for k, v in acc.values(scene, res).items()}
    return out
