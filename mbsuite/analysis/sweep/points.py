"""The generic parameter-study point of `mbsuite sweep` (module-level, so it pickles to any executor)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...results import to_jsonable


def scene_point(job: tuple[dict, dict]) -> dict[str, Any]:
    """A generic parameter-study point: `job = (scene_dict, sections)`; runs `scene.replace(**sections)` and returns
    per-signal statistics (min, max, mean, final) and the solver stats. Module-level, so it pickles to any executor."""
    from ... import run
    from ...scenes import scene_from_dict

    scene_d, sections = job
    scene = scene_from_dict(scene_d)
    if sections:
        scene = scene.replace(**sections)
    res = run(scene)
    sig = getattr(res, "signals", {}) or {}
    return {"signals": {k: {"min": float(np.min(v)), "max": float(np.max(v)), "mean": float(np.mean(v)),
                            "final": float(v[-1])} for k, v in sig.items()},
            "stats": to_jsonable(getattr(res, "stats", {}) or {})}
