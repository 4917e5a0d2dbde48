"""The drives' headline outputs, the tolerances their shipped settings meet, and how a run is refined.

Headlines (`headlines(scene)`; names are `[accuracy]` keys):
- every scene: `n_events`, the number of clutch/brake/bearing mode changes of the run. An event is discrete: a
  refinement must not add or drop one. Its tolerance is 0.5 (the counts of all three levels equal); a count that
  differs is an estimate >= 1 and fails first (it is the first headline), so event times of lists of different
  lengths are never passed as an accuracy;
- the mean load and motor speeds over [t_settle, T] (the angle
  travelled over the time, `drive.mean_speeds`: no quadrature error of the output grid), the efficiency E_out/E_in
  over the same window (Eq 3.22 corrected; where the scene has a load torque), and the first lock-up at or after
  t_settle of each switched element (brake and clutch of the step-up drive, clutches a and b of the step-up/step-down
  drive): the event the work-precision study's physics metric compares (`cases.DrivesStudy`).

Refinement: the hand path (event-exact, DOP853 between events) by dividing rtol and atol by 10 per level
(`rtol_refinement`: nominal order 1 in the tolerance); MuJoCo by halving the step (`REFINE_ORDER`, see there).

The tolerances bound the discretisation error of each path as posed. Between the paths there are model differences no
refinement removes (docs/accuracy.md): the controllers truncate waits computed from the state to controller samples,
so a state difference far below the tolerances can put a command, and the lock-up after it, one sample (1-2 ms) from
the hand path's; that is not a discretisation error of either path. The same truncation makes MuJoCo's drive
headlines piecewise smooth in the step: within a piece they converge (observed orders 0.8-2.6), across a piece's end a
lock-up moves by whole samples, which the estimate sees only when it happens between its levels (TOL).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...trust.estimate import Headline, Refinement, rtol_refinement, timestep_refinement
from .drive import T0_TOL

#: the switched elements of each drive whose first lock-up in the window is a headline: headline suffix -> element
SWITCHED = {"step_up": {"brake": "spring_ground", "clutch": "clutch"},
            "step_up_down": {"clutch_a": "clutch_a", "clutch_b": "clutch_b"}}

#: nominal order of the MuJoCo path in the step: whatever the integrator, lock-ups are applied at the step after the
#: slip changes sign and sliding torques are held over a step, so lock-up times and everything they move converge at
#: first order (the scenes' comments: "lock timing first-order in dt")
REFINE_ORDER = 1.0

#: count tolerance: the number of events must be the same at every level
COUNT_TOL = 0.5

#: declared tolerances at the shipped settings, per path, measured on all 13 shipped scenes at their defaults
#: (`nice .venv/bin/python scripts/drives_accuracy.py`: the estimate of `--error-estimate` and the true error against
#: the hand path at rtol 1e-12 / MuJoCo at 1/16 of the step; README, Declared accuracy). Hand path (rtol 1e-9):
#: speeds 3.3e-5 rad/s (susd_100w_efficiency), efficiency 8.3e-8 (same), lock-ups <= 1.0e-9 s: bounds 9x, 12x,
#: 10x.
#: MuJoCo (RK4 at the scenes' 1e-4 / 2e-5 / 1e-5 s), open-loop drives:
#: speeds 1.09 rad/s (susd_500w_open; true 0.52), efficiency 1.9e-3 (same), lock-ups 3.0e-3 s estimated
#: (susd_100w_reverse: a computed wait truncating to the next controller sample between the levels) and 4.1e-3 s true
#: (step_up_motor_resonant: two 2 ms samples, at 1/16 of the step only, which no estimate from the step and its halves
#: can see): bounds 3.7x, 5.3x, 3.7x (of the true 4.1e-3). The closed-loop scenes on MuJoCo change their number of
#: events under refinement (n_events fails: README).
TOL: dict[str, dict[str, float]] = {
    "reference": {"speed": 3e-4, "efficiency": 1e-6, "t_lock": 1e-8},
    "mujoco": {"speed": 4.0, "efficiency": 1e-2, "t_lock": 1.5e-2},
}


def _path(scene: Any) -> str:
    return "mujoco" if scene.solver.engine == "mujoco" else "reference"


def _has_load_torque(scene: Any) -> bool:
    """A drive with a Coulomb load torque tau_l > 0 (its output work defines the efficiency)."""
    p = scene.build_params().resolved()
    return bool(p["tau_l"])


def headlines(scene: Any) -> tuple[Headline, ...]:
    """The scene's headlines (module docstring), tolerances of its path."""
    mech = scene.effects["mechanism"]
    tol = TOL[_path(scene)]
    out = [Headline("n_events", "1", COUNT_TOL, "number of mode changes of the run (must not change under refinement)"),
           Headline("mean_load_speed", "rad/s", tol["speed"], "mean load speed over [t_settle, T]"),
           Headline("mean_motor_speed", "rad/s", tol["speed"], "mean motor speed over [t_settle, T]")]
    if _has_load_torque(scene):
        out.append(Headline("efficiency", "1", tol["efficiency"], "E_out / E_in over [t_settle, T]"))
    out += [Headline(f"t_lock_{k}", "s", tol["t_lock"], f"first lock-up of the {k.replace('_', ' ')} at "
                     "t >= t_settle (none in the window: NaN, an infinite estimate)") for k in SWITCHED[mech]]
    return tuple(out)


def _locks(events: list[dict], element: str, t0: float) -> list[float]:
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
    cyc = res.statistics
    out["mean_load_speed"] = float(cyc.get("mean_load_speed", math.nan))
    out["mean_motor_speed"] = float(cyc.get("mean_motor_speed", math.nan))
    if _has_load_torque(scene):
        out["efficiency"] = float(cyc.get("efficiency", math.nan))
    for k, el in SWITCHED[mech].items():
        t = _locks(res.events, el, scene.solver.t_settle - T0_TOL)
        out[f"t_lock_{k}"] = t[0] if t else math.nan
    return out


def refinement(scene: Any) -> Refinement:
    """Hand path: rtol and atol / 10 per level; MuJoCo: halve the step (nominal order `REFINE_ORDER`)."""
    if scene.solver.engine == "mujoco":
        return timestep_refinement(REFINE_ORDER)
    return rtol_refinement()
