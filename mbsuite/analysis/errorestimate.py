"""Run a scene's companions and estimate the error of its headline outputs (`mbsuite.trust.estimate`).

    est = error_estimate(scene)                        # the run and its companions in parallel on all local cores
    est = error_estimate(scene, base=values_of_run)    # the run's own values as level 0: only the companions run
    est["max"].error, est["max"].order                 # one headline's estimated error and observed order
    est.companions, est.settings, est.fallback         # which companions ran, at what settings, and why fine ones

The companions are the scene refined once and twice, or, where the model's refinement declares it
(`Refinement.companions = "coarse"`), the scene coarsened once and twice (a fraction of the run's cost), with the
refined ones as the fallback where the coarse ones cannot run (a coarser scene that does not exist, a companion that
fails) or are not in the asymptotic range (`mbsuite.trust.estimate.check_coarse`). A coarse companion is a
companion, not a result: it runs with `solver.allow_inaccurate` set and its warnings silenced (a coarser step may
well be past a health bound the run meets), and nothing of it reaches the run's result but its headline values.

`evaluate(scene_dict) -> {headline: value}` computes one level; it must be module-level (it runs in worker
processes). The default, `run_values`, runs the scene's time simulation (`mbsuite.run`) and reads the model's headline
values from the result; commands with their own kind of run (the catenary passage, a sweep point, a frequency
response) pass theirs.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from typing import Any

from ..engines.core import n_workers
from ..errors import MbsuiteError
from ..progress import active, planned
from ..scenes import Scene
from ..trust.estimate import ErrorEstimate, Refinement, declared, estimate
from .sweep import run_sweep
from .sweep.points import FAILED, companion_values, scene_headlines


def run_values(scene_d: dict) -> dict[str, float]:
    """The headline values of one time run of the scene `scene_d` (a `Scene.to_dict()`)."""
    return scene_headlines(scene_d)


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


def cost(ref: Refinement, level: int) -> float:
    """The work of the scene refined `level` times (coarsened for a negative level) relative to the run's: the
    factor to the power of the level times the number of settings it scales together (the catenary's mesh and
    step: 4 per level)."""
    return float(ref.factor) ** (level * len(ref.setting.split("+")))


def _work(weights: list[float]) -> str:
    """The runs' work in words, e.g. `about 1, 1/4 and 1/16 of the run's work`."""
    words = [f"{w:g}" if w >= 1 else f"1/{1 / w:g}" for w in weights]
    return f"about {', '.join(words[:-1])} and {words[-1]} x the run's work" if len(words) > 1 else ""


def coarse_companions(scene: Scene, ref: Refinement) -> list[Scene]:
    """The scene coarsened once and twice (`ref.refine(scene, -1)`, `-2`), each with `solver.allow_inaccurate` set;
    a `MbsuiteError` saying why where one does not exist."""
    return [ref.refine(scene, -k).replace(solver={"allow_inaccurate": True}) for k in (1, 2)]


def error_estimate(scene: Scene, *, base: Mapping[str, float] | None = None,
                   evaluate: Callable[[dict], Mapping[str, float]] = run_values, workers: int = 0,
                   companions: str | None = None, base_seconds: float | None = None) -> ErrorEstimate:
    """The estimated error of every headline of `scene` from its companions (module docstring,
    `mbsuite.trust.estimate`).

    `base`: the headline values of the scene's own run when the caller has it (only the companions run then);
    `workers`: local processes for the levels (0 = all cores); `companions`: "fine" or "coarse" to override the
    model's declaration (`Refinement.companions`; None: as declared); `base_seconds`: the wall time of the run whose
    values `base` are, when known: the companions' time is then estimated (their work relative to the run's, `cost`)
    and checked against the command's budget before any of them runs (`mbsuite.progress`)."""
    acc = scene.spec.accuracy
    heads = declared(scene)
    ref = acc.refinement(scene)
    kind = ref.companions if companions is None else companions
    if kind not in ("fine", "coarse"):
        raise ValueError(f"companions must be 'fine' or 'coarse', got {kind!r}")
    fallback, coarse = "", None
    if kind == "coarse":
        coarse, why, run = _coarse_estimate(scene, ref, heads, base, evaluate, workers, base_seconds)
        if coarse is not None and coarse.passed:
            return coarse
        base = base if base is not None else run  # the run's values, when they were computed, are not run again
        if coarse is not None:
            why = (f"the coarse companions ({'; '.join(coarse.settings[1:])}) are not in the asymptotic range for "
                   f"{coarse.failure_text()}")
        fallback = f"refined companions run instead of coarse ones: {why}"
        study = active()
        if study is not None:  # said before the (far longer) refined companions start
            study.say(f"error estimate: {fallback}")
    levels = [ref.refine(scene, k) for k in (0, 1, 2)]
    jobs = [sc.to_dict() for sc in levels[1:]] if base is not None else [sc.to_dict() for sc in levels]
    # the most refined copy is the longest: submit it first, so the others share the remaining cores
    w = [cost(ref, k) for k in (range(1, 3) if base is not None else range(3))][::-1]
    with planned("error estimate (refined companions)", len(jobs), min(n_workers(workers), len(jobs)),
                 detail=_work(w) + (", after the coarse ones" if coarse is not None else ""), weights=tuple(w),
                 unit=base_seconds if base is not None else None):
        results = run_sweep(evaluate, jobs[::-1], workers=workers, desc="error estimate", executor="local")[::-1]
    vals: list[Any] = ([dict(base)] if base is not None else []) + [dict(r) for r in results]
    est = estimate(vals, heads, ref, settings=level_settings(scene, levels))
    est.fallback, est.coarse = fallback, coarse
    return est


def _coarse_estimate(scene: Scene, ref: Refinement, heads, base: Mapping[str, float] | None,
                     evaluate: Callable[[dict], Mapping[str, float]], workers: int,
                     base_seconds: float | None = None) -> tuple[ErrorEstimate | None, str, dict[str, float] | None]:
    """(the estimate from the coarse companions or None, why they could not run, the run's values if computed
    here)."""
    try:
        comps = coarse_companions(scene, ref)
    except MbsuiteError as exc:
        return None, str(exc), None
    # the run first (when it is not given: the longest job), then the companion coarsened once
    jobs = ([] if base is not None else [(evaluate, scene.to_dict())]) + [
        (functools.partial(companion_values, evaluate), sc.to_dict()) for sc in comps]
    w = [cost(ref, k) for k in ((-1, -2) if base is not None else (0, -1, -2))]
    with planned("error estimate (coarse companions)", len(jobs), min(n_workers(workers), len(jobs)),
                 detail=_work(w), weights=tuple(w), unit=base_seconds if base is not None else None):
        results = run_sweep(_call, jobs, workers=workers, desc="error estimate", executor="local")
    run = dict(results[0]) if base is None else None
    failed = [(k, r[FAILED]) for k, r in enumerate(results[-2:], start=1) if FAILED in r]
    if failed:
        k, msg = failed[0]
        return None, f"the companion coarsened {'once' if k == 1 else 'twice'} failed: {msg}", run
    vals = [dict(base) if base is not None else run, *(dict(r) for r in results[-2:])]
    est = estimate(vals, heads, ref, settings=level_settings(scene, [scene, *comps]), companions="coarse")
    return est, "", run


def _call(job: tuple[Callable[[dict], Mapping[str, float]], dict]) -> dict[str, Any]:
    """One level of the coarse estimate: `(fn, scene_dict)` -> fn(scene_dict) (module-level: it runs in worker
    processes)."""
    fn, scene_d = job
    return dict(fn(scene_d))
