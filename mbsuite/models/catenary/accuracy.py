"""The catenary's headline outputs, the tolerances its shipped settings meet, and how a passage is refined.

Headlines: the eight EN 50318 statistics of every pantograph (`stats.STAT_NAMES`: Fm, sigma, Fm + 3 sigma,
Fm - 3 sigma, the actual max and min of the 20 Hz filtered force in N, the largest steady-arm uplift in mm, the
percentage of contact loss). A single pantograph's are named as its SimResult's statistics (`Fm`, ..., `uplift_mm`,
`loss_pct`); those of a train's pantograph k = 1, 2, ... (leading first) as the train's (`p1_Fm`, `p2_max`, ...).
The further statistics windows of `params.windows` (a route's sections and overlaps) add the same eight per window
and pantograph, the window named by its ends in m (`w300-480_sigma`, `p2_w300-480_sigma`; the headline window's are
the headlines).

Tolerances (absolute, at the scene's default settings): 1 N on every force statistic and 0.5 mm on the uplift (the
accuracy an EN 50318 / EN 50367 assessment reads its statistics to: the accepted ranges are 5-35 N wide, the uplift
range 7-10 mm); the contact loss `LOSS_TOL` + `LOSS_RTOL` times its value (below). The measured errors behind them
are in the comments below.

Refinement: the element length and the time step halved together (`refine`), which keeps the wave Courant number
c dt / h of the run. The trapezoidal rule is second order in dt (README, against a DOP853 solution: 4.0x per
halving); the cubic Hermite elements converge faster than that in the wire's deflection, so the pair converges at
order 2 where the statistics are smooth in the discretisation (`ORDER`). The actual max and min are read off the
record's samples (spacing dt): halving dt refines them with the rest.

Companions: coarse first (`Refinement.companions = "coarse"`: the error estimate runs the scene with both doubled
and quadrupled, 1/4 + 1/16 of the run's work, and falls back to the refined ones where those are not in the
asymptotic range, `mbsuite.trust.estimate`). A coarse companion exists only where its mesh nests in the run's: every
interval between key points (supports, droppers, clamps, masses, wire ends: always nodes, `mesh.build_nodes`) is a
whole number of its elements, each exactly 2 (4) of the run's (`mesh.coarsening_misfit`); on the EN 50318 line
(dropper intervals 5, 5.5 and 6.5 m) that holds for runs at 0.125 m and below, not at the shipped 0.5 m. Its time
step must stay below the contact-force filter's Nyquist bound (`config.check_timestep`); its size guards are the
run's (it is cheaper than the run), and its health bounds do not refuse it (a companion runs with
`solver.allow_inaccurate`).
"""

from __future__ import annotations

from typing import Any

from ...scenes import Scene, scene_from_dict
from ...trust.estimate import Headline, Refinement
from .stats import STAT_NAMES

#: the statistics of one pantograph, in the order of the EN 50318 tables
STATS = tuple(STAT_NAMES)
#: unit of each statistic
UNITS = {**{k: "N" for k in STATS}, "uplift_mm": "mm", "loss_pct": "%"}
#: nominal order of the refinement (element length and time step halved together: the trapezoidal rule's 2)
ORDER = 2.0
#: contact loss (percentage of the window's samples): 0.05 % + 10 % of the value. The lost time is a sum of loss
#: events whose durations each carry the discretisation's error, so the error scales with the loss: on the two
#: pantographs at 300 km/h (trailing loss 1.51 %) the default 0.5 m / 2e-4 s is 0.078 % off a run 8x finer, the
#: error estimate says 0.127 % (bound 0.20 %); with linear droppers at 300 km/h (3.18 %) 0.041 % off a run 4x finer
#: (bound 0.37 %); every other shipped scene loses no contact at any resolution. Where a verdict is read (the AC
#: arcing limit NQ <= 0.2 %, the DC limit 0.1 %) the bound is 0.06-0.07 %, a third of the AC limit. Counting the lost
#: time between samples (the gap's zero crossings interpolated) moves the trailing pantograph's 1.430 % to 1.440 %
#: only: the error is the dynamics', not the sampling's.
LOSS_TOL = 0.05
LOSS_RTOL = 0.1
#: declared tolerances at the shipped settings
TOL = {**{k: 1.0 for k in STATS}, "uplift_mm": 0.5, "loss_pct": LOSS_TOL}


def pantograph_count(scene: Scene) -> int:
    """How many pantographs the scene's passage runs (its `[train]` section's, else one)."""
    train = scene.sections.get("train")
    return len(train["pantographs"]) if train else 1


def window_keys(scene: Scene) -> tuple[str, ...]:
    """The keys of the scene's further statistics windows ("<start>-<end>", m; `stats.window_statistics`) but the
    headline window's (its statistics are the headlines already)."""
    p = scene.build_params()
    return tuple(f"{a:g}-{b:g}" for a, b in p.windows if (a, b) != (p.window_start, p.window_end))


def names(n_pantographs: int, windows: tuple[str, ...] = ()) -> tuple[str, ...]:
    """The headline names of a passage of `n_pantographs` with the further windows `windows` (module docstring)."""
    stats = STATS + tuple(f"w{w}_{s}" for w in windows for s in STATS)
    if n_pantographs == 1:
        return stats
    return tuple(f"p{k}_{s}" for k in range(1, n_pantographs + 1) for s in stats)


def _parts(name: str) -> tuple[int, str | None, str]:
    """(pantograph index from 0, window key or None, statistic) of a headline name (`p2_w300-480_max`)."""
    k, window = 0, None
    head, _, tail = name.partition("_")
    if head[:1] == "p" and head[1:].isdigit():
        k, name = int(head[1:]) - 1, tail
    head, _, tail = name.partition("_")
    if head[:1] == "w" and "-" in head:
        window, name = head[1:], tail
    return k, window, name


def _stat_of(name: str) -> str:
    """The statistic a headline name reads (`p2_w300-480_max` -> `max`)."""
    return _parts(name)[2]


def headlines(scene: Scene) -> tuple[Headline, ...]:
    """The eight statistics of every pantograph of the scene's passage with their tolerances."""
    n = pantograph_count(scene)
    out = []
    for name in names(n, window_keys(scene)):
        k, window, stat = _parts(name)
        who = "" if n == 1 else f"pantograph {k + 1}: "
        where = "" if window is None else f"window {window} m: "
        out.append(Headline(name, UNITS[stat], TOL[stat], who + where + STAT_NAMES[stat],
                            rtol=LOSS_RTOL if stat == "loss_pct" else 0.0))
    return tuple(out)


def values(scene: Scene, res: Any) -> dict[str, float]:
    """The headline values of a passage's SimResult (its `statistics`; a further window's from its `stats["windows"]`,
    a train's pantograph's under "p<k>")."""
    n = pantograph_count(scene)
    out = {}
    for name in names(n, window_keys(scene)):
        k, window, stat = _parts(name)
        if window is None:
            out[name] = float(res.statistics[name])
        else:
            w = res.stats["windows"] if n == 1 else res.stats["windows"][f"p{k + 1}"]
            out[name] = float(w[window]["statistics"][stat])
    return out


def stats_values(stats: list[dict]) -> dict[str, float]:
    """The headline values from the per-pantograph statistics of a passage (`TrainRun.stats`, leading first; the
    further windows' from each one's "windows")."""
    keys = tuple(stats[0].get("windows", {}))
    out = {}
    for name in names(len(stats), keys):
        k, window, stat = _parts(name)
        s = stats[k] if window is None else stats[k]["windows"][window]
        out[name] = float(s[stat])
    return out


def refine(scene: Scene, level: int) -> Scene:
    """The scene with `params.element_length` and `solver.timestep` halved `level` times; the size guards
    (`solver.max_steps`: steps, `params.max_element_steps`: elements x steps) grow with them (the user asked for the
    finer run). A negative level: both doubled -level times (`coarsen`)."""
    if level == 0:
        return scene
    if level < 0:
        return coarsen(scene, -level)
    p, s = scene.build_params(), scene.solver
    return scene.replace(params={"element_length": p.element_length / 2**level,
                                 "max_element_steps": p.max_element_steps * 4**level},
                         solver={"timestep": s.timestep / 2**level, "max_steps": s.max_steps * 2**level})


def coarsen(scene: Scene, times: int) -> Scene:
    """The scene with `params.element_length` and `solver.timestep` doubled `times` times (a coarse companion of the
    error estimate; module docstring): a `SceneError` naming the key points where the coarser mesh does not nest in
    the scene's, or the bound a doubled parameter breaks. The size guards stay the scene's (the companion does a
    fraction of the scene's work)."""
    from ...errors import MbsuiteError, SceneError
    from .config import check_timestep
    from .mesh import coarsening_misfit, line_of

    f = 2**times
    p, s = scene.build_params(), scene.solver
    h, dt = p.element_length * f, s.timestep * f
    what = (f"the {f}x coarser companion (params.element_length = {h:g} m, solver.timestep = {dt:g} s)")
    bad = coarsening_misfit(line_of(p), p.element_length, f)
    if bad is not None:
        a, b, n = bad
        raise SceneError(
            f"{what} does not fit the line: the key points x = {a:g} and {b:g} m (supports, droppers, clamps, masses "
            f"and wire ends are nodes) are {b - a:g} m apart, {n} element(s) of the run, not a whole number of {h:g} m "
            f"elements of {f} each (a coarse companion's element length must divide every interval between key "
            "points)")
    try:
        out = scene.replace(params={"element_length": h}, solver={"timestep": dt})
        check_timestep(out.build_params(), dt)
    except MbsuiteError as exc:
        raise SceneError(f"{what} is not a valid scene: {exc}") from None
    return out


def refinement(scene: Scene) -> Refinement:
    """Element length and time step halved together, nominal order `ORDER`; coarse companions first."""
    return Refinement("params.element_length + solver.timestep", 2.0, ORDER, refine,
                      "element length and time step halved together (the wave Courant number held)",
                      companions="coarse")


def passage_values(scene_d: dict) -> dict[str, float]:
    """The headline values of one passage of the scene `scene_d` (a `Scene.to_dict()`) on its path, a train's if it
    has a `[train]` section (the `evaluate` of the `mbsuite catenary` command's error estimate; module-level, it runs
    in worker processes)."""
    from .analysis import scene_config
    from .train import run_passage

    scene = scene_from_dict(scene_d)
    return stats_values(run_passage(scene_config(scene, scene.solver.engine)).stats)
