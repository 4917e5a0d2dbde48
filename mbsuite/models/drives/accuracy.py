"""The drives' headline outputs, the tolerances their shipped settings meet, and how a run is refined.

Headlines (`headlines(scene)`; names are `[accuracy]` keys):
- every scene: `n_events`, the number of clutch/brake/bearing mode changes of the run. An event is discrete: a
  refinement must not add or drop one. Its tolerance is 0.5 (the counts of all three levels equal); a count that
  differs is an estimate >= 1 and fails first (it is the first headline), so event times of lists of different
  lengths are never passed as an accuracy;
- the thesis drives (step-up, step-up/step-down): the cycle-mean load and motor speeds over [t_settle, T]
  (`drive.cycle_stats`), the efficiency E_out/E_in over the same window (Eq 3.22 corrected; where the scene has a
  load torque), and the first lock-up at or after t_settle of each switched element (brake and clutch of the step-up
  drive, clutches a and b of the step-up/step-down drive): the event the work-precision study's physics metric
  compares (`cases.DrivesStudy`);
- the Modelica examples (CoupledClutches and the four `msl_*`): every lock-up of the mode sequence the Modelica
  Association's reference results (CoupledClutches, Friction, OneWayClutch) or the MSL equations' closed forms
  (OneWayClutchDisengaged, SimpleGearShift) give (`LOCKUPS`; k-th lock-up of an element: `t_lock_<element>_<k>`), and
  the speed of every inertia at the end of the run (`w_end_<inertia>`).

Refinement: the hand path (event-exact, DOP853 between events) by dividing rtol and atol by 10 per level
(`rtol_refinement`: nominal order 1 in the tolerance); MuJoCo by halving the step (`REFINE_ORDER`, see there).

The tolerances bound the discretisation error of each path as posed. Between the paths there are model differences no
refinement removes (docs/accuracy.md): on MuJoCo the controller commands at samples of a state that is a step
behind, so a lock-up can fall one controller sample (1 ms) from the hand path's; that is not an error of either path.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...accuracy import Headline, Refinement, rtol_refinement, timestep_refinement
from .drive import T0_TOL

#: the switched elements of each drive whose first lock-up in the window is a headline: headline suffix -> element
SWITCHED = {"step_up": {"brake": "spring_ground", "clutch": "clutch"},
            "step_up_down": {"clutch_a": "clutch_a", "clutch_b": "clutch_b"}}

#: lock-ups per element of each Modelica example: CoupledClutches, Friction and OneWayClutch from the Modelica
#: Association's reference results (`tests/data/msl/`), OneWayClutchDisengaged and SimpleGearShift from the MSL
#: equations' closed forms (tests/drives/test_msl.py); a test reads them back from those sources
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

#: declared tolerances at the shipped settings per path (placeholders until measured)
TOL: dict[str, dict[str, float]] = {
    "reference": {"speed": 1e-3, "efficiency": 1e-5, "t_lock": 1e-6, "w_end": 1e-6},
    "mujoco": {"speed": 1e-1, "efficiency": 1e-3, "t_lock": 1e-4, "w_end": 1e-4},
}


def _path(scene: Any) -> str:
    return "mujoco" if scene.solver.engine == "mujoco" else "reference"


def _has_load_torque(scene: Any) -> bool:
    """A drive with a Coulomb load torque tau_l > 0 (its output work defines the efficiency)."""
    p = scene.build_params().resolved(scene.effects["param_set"])
    return bool(p["tau_l"])


def headlines(scene: Any) -> tuple[Headline, ...]:
    """The scene's headlines (module docstring), tolerances of its path."""
    mech = scene.effects["mechanism"]
    tol = TOL[_path(scene)]
    out = [Headline("n_events", "1", COUNT_TOL, "number of mode changes of the run (must not change under refinement)")]
    if mech in SWITCHED:
        out += [Headline("mean_load_speed", "rad/s", tol["speed"], "cycle-mean load speed over [t_settle, T]"),
                Headline("mean_motor_speed", "rad/s", tol["speed"], "cycle-mean motor speed over [t_settle, T]")]
        if _has_load_torque(scene):
            out.append(Headline("efficiency", "1", tol["efficiency"], "E_out / E_in over [t_settle, T]"))
        out += [Headline(f"t_lock_{k}", "s", tol["t_lock"], f"first lock-up of the {k.replace('_', ' ')} at "
                         "t >= t_settle") for k in SWITCHED[mech]]
        return tuple(out)
    for el, n in LOCKUPS[mech].items():
        out += [Headline(f"t_lock_{el}_{k}", "s", tol["t_lock"], f"lock-up {k} of {el}") for k in range(1, n + 1)]
    out += [Headline(f"w_end_{b}", "rad/s", tol["w_end"], f"speed of {b} at the end of the run")
            for b in INERTIAS[mech]]
    return tuple(out)


def _locks(events: list[dict], element: str, t0: float = -math.inf) -> list[float]:
    return [float(e["t"]) for e in events if e["element"] == element and e["to"] == "stuck" and e["t"] >= t0]


def window_efficiency(t: np.ndarray, e_in: np.ndarray, e_out: np.ndarray, t0: float) -> float:
    """E_out / E_in over [t0, T] from the cumulative energies (NaN when no energy came in)."""
    i0 = int(np.searchsorted(t, t0 - T0_TOL))
    de_in = float(e_in[-1] - e_in[i0])
    return float(e_out[-1] - e_out[i0]) / de_in if de_in > 0 else math.nan


def values(scene: Any, res: Any) -> dict[str, float]:
    """The headline values of a run's result (NaN for a lock-up that did not happen)."""
    mech = scene.effects["mechanism"]
    out = {"n_events": float(len(res.events))}
    if mech in SWITCHED:
        cyc = res.stats.get("cycles", {})
        out["mean_load_speed"] = float(cyc.get("mean_load_speed", math.nan))
        out["mean_motor_speed"] = float(cyc.get("mean_motor_speed", math.nan))
        if _has_load_torque(scene):
            out["efficiency"] = float(cyc.get("efficiency", math.nan))
        for k, el in SWITCHED[mech].items():
            t = _locks(res.events, el, scene.solver.t_settle - T0_TOL)
            out[f"t_lock_{k}"] = t[0] if t else math.nan
        return out
    for el, n in LOCKUPS[mech].items():
        t = _locks(res.events, el)
        for k in range(1, n + 1):
            out[f"t_lock_{el}_{k}"] = t[k - 1] if len(t) >= k else math.nan
    for b in INERTIAS[mech]:
        out[f"w_end_{b}"] = float(res.stats["final"][f"{b}.w"])
    return out


def refinement(scene: Any) -> Refinement:
    """Hand path: rtol and atol / 10 per level; MuJoCo: halve the step (nominal order `REFINE_ORDER`)."""
    if scene.solver.engine == "mujoco":
        return timestep_refinement(REFINE_ORDER)
    return rtol_refinement()
