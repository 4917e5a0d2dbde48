"""The generic parameter-study point of `mbsuite sweep` (module-level, so it pickles to any executor)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...results import to_jsonable


def scene_point(job: tuple[dict, dict] | tuple[dict, dict, int]) -> dict[str, Any]:
    """A generic parameter-study point: `job = (scene_dict, sections[, level])`; runs `scene.replace(**sections)` and
    returns per-signal statistics (min, max, mean, final) and the solver stats. With a `level`, the scene is first
    refined that many times (`mbsuite.trust.estimate`: its path's refinement) and the result also holds its headline
    values
    (`headlines`), for the point's error estimate. Module-level, so it pickles to any executor."""
    from ...pathrun import run_judged as run
    from ...scenes import scene_from_dict

    scene_d, sections, *rest = job
    scene = scene_from_dict(scene_d)
    if sections:
        scene = scene.replace(**sections)
    acc = scene.spec.accuracy
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
