"""The IFToMM gates' headline outputs, the tolerances their shipped settings meet, and how a run is refined.

Headlines: the input joint's angle at the end of the run (rad), the largest loop-closure residual (m) and the largest
energy drift (J). The tolerance bounds the discretisation error of the model as posed (on MuJoCo the soft closures
are part of the model: their own floor against the rigid closed form, 0.175 rad of crank angle in 10 s, is stated in
docs/accuracy.md and is not a discretisation error). MuJoCo runs are refined by halving the step and the sample grid
the maxima are read off (RK4: nominal order 4; euler/implicitfast: 1), the Pinocchio path by tightening rtol (its
maxima stay on the 10 ms sample grid: the README states what that grid misses).
"""

from __future__ import annotations

from typing import Any

from ...trust.estimate import Headline, Refinement, rtol_refinement, timestep_refinement

#: nominal order of each MuJoCo integrator in the step
ORDER = {"euler": 1.0, "implicit": 1.0, "implicitfast": 1.0, "rk4": 4.0, "discrete": 1.0}

#: declared tolerances at the shipped settings, above the largest estimate measured on both scenes and both paths
#: (`mbsuite run iftomm/<scene> [--engine reference] --error-estimate`) and the largest true error against a much
#: refined run (MuJoCo: h/16 sampled at sample_dt/16; Pinocchio: LSODA rtol 1e-10; tests/iftomm/test_accuracy.py):
#: final angle: estimate 6.6e-5 rad, true 5.0e-5 (Bricard, Pinocchio), bound 15x; closure residual: estimate 2.9e-8 m
#: (Bricard, MuJoCo), true 2.4e-7 m (four-bar, MuJoCo: the peak between the 10 ms samples, which the timestep
#: refinement does not see), bound 4.2x the true error; energy drift: estimate 1.5e-4 J, true 1.2e-4 J (Bricard,
#: Pinocchio), bound 6.6x
TOL = {"final_angle": 1e-3, "closure_residual_max": 1e-6, "energy_drift_max": 1e-3}


def headlines(scene: Any) -> tuple[Headline, ...]:
    """Final input-joint angle, largest closure residual, largest energy drift."""
    return (Headline("final_angle", "rad", TOL["final_angle"], "input joint angle at the end of the run"),
            Headline("closure_residual_max", "m", TOL["closure_residual_max"], "largest loop-closure residual"),
            Headline("energy_drift_max", "J", TOL["energy_drift_max"], "largest |E(t) - E(0)|"))


def values(scene: Any, res: Any) -> dict[str, float]:
    """The headline values of a run's result."""
    return {"final_angle": float(res["input_angle"][-1]),
            "closure_residual_max": float(res.statistics["closure_residual_max"]),
            "energy_drift_max": float(res.statistics["energy_drift_max"])}


def refinement(scene: Any) -> Refinement:
    """MuJoCo: halve the step at the integrator's order; Pinocchio: rtol / 10."""
    if scene.solver.engine == "mujoco":
        return timestep_refinement(ORDER[scene.solver.integrator], samples=True)
    return rtol_refinement()
