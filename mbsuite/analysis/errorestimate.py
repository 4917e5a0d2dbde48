"""Run a scene's refined copies and estimate the error of its headline outputs (`mbsuite.trust.estimate`).

    est = error_estimate(scene)                        # levels 0, 1, 2 in parallel on all local cores
    est = error_estimate(scene, base=values_of_run)    # the run's own values as level 0: only the refined copies run
    est["max"].error, est["max"].order                 # one headline's estimated error and observed order

`evaluate(scene_dict) -> {headline: value}` computes one level; it must be module-level (it runs in worker
processes). The default, `run_values`, runs the scene's time simulation (`mbsuite.run`) and reads the model's headline
values from the result; commands with their own kind of run (the catenary passage, a sweep point, a frequency
response) pass theirs.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from ..scenes import Scene, scene_from_dict
from ..trust.estimate import ErrorEstimate, declared, estimate
from .sweep import run_sweep


def run_values(scene_d: dict) -> dict[str, float]:
    """The headline values of one time run of the scene `scene_d` (a `Scene.to_dict()`)."""
    from ..pathrun import run_judged as run

    scene = scene_from_dict(scene_d)
    return dict(scene.spec.accuracy.values(scene, run(scene)))


def level_settings(scene: Scene, levels: list[Scene]) -> list[str]:
    """What each level ran, in words: the refined setting's value at each level (e.g. `solver.timestep = 0.0005`)."""
    ref = scene.spec.accuracy.refinement(scene)
    out = []
    for sc in levels:
        parts = []
        for name in ref.setting.split("+"):
            section, _, key = name.strip().partition(".")
            if section == "solver":
                v = getattr(sc.solver, key)
            else:
                v = getattr(sc.build_params(), key) if section == "params" else sc.to_dict()[section].get(key)
            parts.append(f"{name.strip()} = {v:g}" if isinstance(v, float) else f"{name.strip()} = {v}")
        out.append(", ".join(parts))
    return out


def error_estimate(scene: Scene, *, base: Mapping[str, float] | None = None,
                   evaluate: Callable[[dict], Mapping[str, float]] = run_values, workers: int = 0) -> ErrorEstimate:
    """The estimated error of every headline of `scene` from the scene refined once and twice
    (`mbsuite.trust.estimate`).

    `base`: the headline values of the scene's own run when the caller has it (only the refined copies run then);
    `workers`: local processes for the levels (0 = all cores)."""
    acc = scene.spec.accuracy
    heads = declared(scene)
    ref = acc.refinement(scene)
    levels = [ref.refine(scene, k) for k in (0, 1, 2)]
    jobs = [sc.to_dict() for sc in levels[1:]] if base is not None else [sc.to_dict() for sc in levels]
    # the most refined copy is the longest: submit it first, so the others share the remaining cores
    results = run_sweep(evaluate, jobs[::-1], workers=workers, desc="error estimate", executor="local")[::-1]
    vals: list[Any] = ([dict(base)] if base is not None else []) + [dict(r) for r in results]
    return estimate(vals, heads, ref, settings=level_settings(scene, levels))
