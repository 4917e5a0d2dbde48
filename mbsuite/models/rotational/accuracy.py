"""The rotational examples' headline outputs, the tolerances their shipped settings meet, and how a run is refined.

Headlines (`headlines(scene)`; names are `[accuracy]` keys):
- `n_events`, the number of clutch/brake mode changes of the run. An event is discrete: a refinement must not add or
  drop one. Its tolerance is 0.5 (the counts of all three levels equal); a count that differs is an estimate >= 1 and
  fails first (it is the first headline), so event times of lists of different lengths are never passed as an
  accuracy;
- every lock-up of the mode sequence the Modelica Association's reference results (CoupledClutches, Friction,
  OneWayClutch) or the MSL equations' closed forms (OneWayClutchDisengaged, SimpleGearShift) give (`LOCKUPS`; k-th
  lock-up of an element: `t_lock_<element>_<k>`), and the speed of every inertia at the end of the run
  (`w_end_<inertia>`).

Refinement: the hand path (event-exact, DOP853 between events) by dividing rtol and atol by 10 per level
(`rtol_refinement`: nominal order 1 in the tolerance); MuJoCo by halving the step (`REFINE_ORDER`, see there).
"""

from __future__ import annotations

import math
from typing import Any

from ...trust.estimate import Headline, Refinement, rtol_refinement, timestep_refinement

#: lock-ups per element of each example: CoupledClutches, Friction and OneWayClutch from the Modelica Association's
#: reference results (`data/msl/`), OneWayClutchDisengaged and SimpleGearShift from the MSL equations' closed forms
#: (tests/rotational/test_msl.py); a test reads them back from those sources
LOCKUPS = {"coupled_clutches": {"clutch1": 2, "clutch2": 1, "clutch3": 1},
           "msl_friction": {"clutch": 3, "brake": 1},
           "msl_one_way_clutch": {"oneWayClutch": 5},
           "msl_one_way_clutch_disengaged": {"oneWayClutch": 4},
           "msl_simple_gear_shift": {"clutch": 1}}

#: inertias whose end speed is a headline (signal `<name>.w`)
INERTIAS = {"coupled_clutches": ("J1", "J2", "J3", "J4"),
            "msl_friction": ("inertia1", "inertia2", "inertia3"),
            "msl_one_way_clutch": ("inertiaIn", "inertiaOut"),
            "msl_one_way_clutch_disengaged": ("inertiaIn", "inertiaOut"),
            "msl_simple_gear_shift": ("engine", "load")}

#: nominal order of the MuJoCo path in the step: whatever the integrator, lock-ups are applied at the step after the
#: slip changes sign and sliding torques are held over a step, so lock-up times and everything they move converge at
#: first order (the scenes' comments: "lock timing first-order in dt")
REFINE_ORDER = 1.0

#: count tolerance: the number of events must be the same at every level
COUNT_TOL = 0.5

#: declared tolerances at the shipped settings, per path, measured on the five shipped scenes at their defaults
#: (`nice .venv/bin/python scripts/drives_accuracy.py`: the estimate of `--error-estimate` and the true error against
#: the hand path at rtol 1e-12 / MuJoCo at 1/16 of the step; README, Declared accuracy). Hand path (rtol 1e-9):
#: lock-ups 2.5e-9 s (the OneWayClutch's grazing lock), end speeds 1.6e-8 rad/s (CoupledClutches): bounds 4x, 6x.
#: MuJoCo (RK4 at the scenes' steps): lock-ups 3.1e-4 s (the grazing lock, 3 steps; others <= 2.8e-5), end speeds
#: 4.0e-5 rad/s (CoupledClutches): bounds 3.2x, 5x.
TOL: dict[str, dict[str, float]] = {
    "reference": {"t_lock": 1e-8, "w_end": 1e-7},
    "mujoco": {"t_lock": 1e-3, "w_end": 2e-4},
}


def _path(scene: Any) -> str:
    return "mujoco" if scene.solver.engine == "mujoco" else "reference"


def headlines(scene: Any) -> tuple[Headline, ...]:
    """The scene's headlines (module docstring), tolerances of its path."""
    name = scene.effects["example"]
    tol = TOL[_path(scene)]
    out = [Headline("n_events", "1", COUNT_TOL, "number of mode changes of the run (must not change under refinement)")]
    for el, n in LOCKUPS[name].items():
        out += [Headline(f"t_lock_{el}_{k}", "s", tol["t_lock"], f"lock-up {k} of {el}") for k in range(1, n + 1)]
    out += [Headline(f"w_end_{b}", "rad/s", tol["w_end"], f"speed of {b} at the end of the run")
            for b in INERTIAS[name]]
    return tuple(out)


def _locks(events: list[dict], element: str) -> list[float]:
    return [float(e["t"]) for e in events if e["element"] == element and e["to"] == "stuck"]


def values(scene: Any, res: Any) -> dict[str, float]:
    """The headline values of a run's result (NaN for a lock-up that did not happen)."""
    name = scene.effects["example"]
    out = {"n_events": float(len(res.events))}
    for el, n in LOCKUPS[name].items():
        t = _locks(res.events, el)
        for k in range(1, n + 1):
            out[f"t_lock_{el}_{k}"] = t[k - 1] if len(t) >= k else math.nan
    for b in INERTIAS[name]:
        out[f"w_end_{b}"] = float(res.stats["final"][f"{b}.w"])
    return out


def refinement(scene: Any) -> Refinement:
    """Hand path: rtol and atol / 10 per level; MuJoCo: halve the step (nominal order `REFINE_ORDER`)."""
    if scene.solver.engine == "mujoco":
        return timestep_refinement(REFINE_ORDER)
    return rtol_refinement()
