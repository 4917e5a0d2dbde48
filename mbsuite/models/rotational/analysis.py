"""Analyses of the rotational examples: a scene's run on its path before its `SimResult` (`simulate_scene`), and
CoupledClutches on both paths against the Modelica Association's Dymola result (`coupled_clutches_table`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...analysis.errorestimate import run_values
from ...components.rotational.interfaces import RefResult, RotorSystem
from ...scenes import Scene
from . import coupled_clutches as cc
from . import mujoco, reference
from .accuracy import values
from .scene_run import sim_result

#: each path's simulation of a scene, returning (result, rotor system): the runs behind `SPEC.paths`
SIMULATE = {"reference": reference.simulate, "mujoco": mujoco.simulate}


def simulate_scene(scene: Scene) -> tuple[RefResult, RotorSystem]:
    """Run a scene on its path (`SIMULATE`); returns (result, rotor system)."""
    return SIMULATE[scene.solver.engine](scene)


def estimate_points(scenes: list[Scene], bases: list[dict[str, float]], evaluate, workers: int = 0) -> list[Any]:
    """The error estimate (`mbsuite.trust.estimate`) of several runs at once: every run's two refined copies in one
    parallel batch (`workers` local processes, 0 = all cores); `bases` are the runs' own headline values and
    `evaluate(scene_dict)` computes one refined copy's (module-level)."""
    from ...analysis.errorestimate import level_settings
    from ...analysis.sweep import run_sweep
    from ...trust.estimate import declared, estimate

    refs = [sc.spec.accuracy.refinement(sc) for sc in scenes]
    levels = [[r.refine(sc, k) for k in (0, 1, 2)] for sc, r in zip(scenes, refs, strict=True)]
    jobs = [lv[k].to_dict() for lv in levels for k in (2, 1)]  # the most refined first: the longest runs start first
    out = run_sweep(evaluate, jobs, workers=workers, desc="error estimate", executor="local")
    return [estimate([dict(base), dict(out[2 * i + 1]), dict(out[2 * i])], declared(sc), ref,
                     settings=level_settings(sc, lv))
            for i, (sc, ref, lv, base) in enumerate(zip(scenes, refs, levels, bases, strict=True))]


def coupled_clutches_table(timestep: float = 1e-4, *, error_estimate: bool = False, workers: int = 0,
                           scene: Scene | None = None) -> dict[str, Any]:
    """Both paths against the Dymola reference: mode sequence with event times, and w1..w4 every 0.1 s. The runs are
    the scene `rotational/coupled_clutches` (or `scene`) on each path, MuJoCo at `timestep`: the settings of
    `mbsuite run rotational/coupled_clutches [--engine mujoco]`. `error_estimate`: each path's headlines (`accuracy.py`)
    also get their estimated error from the scene refined once and twice (`out[path]["error_estimate"]`, an
    `ErrorEstimate`)."""
    from ...scenes import load_scene

    base = scene if scene is not None else load_scene("rotational/coupled_clutches")
    ref = cc.load_reference()
    rev = cc.reference_events(ref)
    out: dict[str, Any] = {"reference_events": rev}
    grid = np.round(np.arange(0.0, cc.T_END + 1e-9, 0.1), 10)
    j_ref = [int(np.nonzero(np.isclose(ref["t"], tt))[0][-1]) for tt in grid]
    out["grid"] = grid.tolist()
    out["w_ref"] = ref["w"][:, j_ref].T.tolist()
    scenes = {"reference": base.replace(solver={"engine": "reference"}),
              "mujoco": base.replace(solver={"engine": "mujoco", "timestep": timestep})}
    bases = {}
    for eng, sc in scenes.items():
        run = simulate_scene(sc)
        res = run[0]
        bases[eng] = values(sc, sim_result(sc, *run))
        ev = cc.events_as_codes(res.events)
        rows = cc.match_events(ev, rev)
        idx = [int(np.argmin(np.abs(res.t - tt))) for tt in grid]
        w = res.w[:, idx].T
        dts = [r["t"] - r["t_ref"] for r in rows if r["t"] is not None and r["t_ref"] is not None]
        out[eng] = {"events": rows, "w": w.tolist(),
                    "same_sequence": all(r["t"] is not None and r["t_ref"] is not None for r in rows),
                    "max_event_dt": float(max(abs(x) for x in dts)) if dts else math.nan,
                    "max_w_err": float(np.max(np.abs(w - np.asarray(out["w_ref"]))))}
    if error_estimate:
        ests = estimate_points(list(scenes.values()), list(bases.values()), run_values, workers)
        for eng, est in zip(scenes, ests, strict=True):
            out[eng]["error_estimate"] = est
    return out
