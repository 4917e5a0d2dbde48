"""The coupler's headline outputs, the tolerances its shipped settings meet, and how a run is refined.

Headlines of a double-coupler run (statistics over the settled window t >= max(t_settle, t_ramp),
`SimResult.statistics`, declared in `scenario.STATISTICS`):
- MuJoCo path: the largest |phi_c - phi_c,kin| (the soft closures' torsional wind-up against the rigid FPP), the mean
  input torque, the largest closure residual, the input torque's peak-to-peak ripple and the largest |link force|;
- kinematic reference: the mean input torque, its ripple, the largest closure residual of the solved FPP and the
  criterion the run computes, c5 as a peak-to-peak, `phi_c_kin_fluctuation_pp` = ptp(phi_a - phi_c) (Maniowski &
  Czauderna, Eq 20). Its phi_c - phi_c,kin is zero by construction and is no headline.

Refinement. MuJoCo: the step halved at the integrator's order (implicitfast, the shipped one: 1) with the samples'
spacing `sample_dt` halved with it, so that maxima, ripples and means read off the record are refined too; the dry
friction's time constant, which by default follows the timestep (2 timesteps), is held at the run's value, so every
level solves the same model. MuJoCo's closures are soft constraints and part of the model (solref 2 ms: the wind-up
of 3.5e-5 rad is theirs, not a discretisation error); the estimate measures the discretisation of that model, not the
closures' softness, as on the IFToMM gates. Reference: everything is solved on the sample grid (the FPP at every
sample, the rates of the power balance by central differences in time, the ripple and c5 read off it), so
`sample_dt` is halved, nominal order 2; the Gauss-Newton tolerance (|r| <= 1e-13 R^2) and the continuation that only
seeds it (`reference.revolution_guess`) leave rounding-level errors (the closure residual's 1e-14 m) and are not
refined.
"""

from __future__ import annotations

from typing import Any

from ...trust.estimate import Headline, Refinement, refine_timestep

#: nominal order of each MuJoCo integrator in the step
ORDER = {"euler": 1.0, "implicit": 1.0, "implicitfast": 1.0, "rk4": 4.0}
#: nominal order of the kinematic reference in its sample spacing (central differences, extrema off the grid)
ORDER_REFERENCE = 2.0

#: headline name -> (unit, description)
HEADLINES = {
    "phi_c_err_max": ("rad", "largest |phi_c - phi_c,kin| in the window"),
    "torque_in_mean": ("N m", "mean input torque in the window"),
    "closure_residual_max": ("m", "largest SS-link closure gap in the window"),
    "torque_in_ripple_pp": ("N m", "peak-to-peak input torque in the window"),
    "link_force_max_abs": ("N", "largest |link force| in the window"),
    "phi_c_kin_fluctuation_pp": ("rad", "c5 as peak-to-peak: ptp(phi_a - phi_c) of the FPP in the window (Eq 20)"),
}
MUJOCO = ("phi_c_err_max", "torque_in_mean", "closure_residual_max", "torque_in_ripple_pp", "link_force_max_abs")
REFERENCE = ("torque_in_mean", "torque_in_ripple_pp", "closure_residual_max", "phi_c_kin_fluctuation_pp")

#: declared tolerances at the shipped settings (`python scripts/coupler_accuracy.py`: every shipped scene on both
#: paths, the estimate and the true error against a run 16x finer of another method; the machine was shared).
#: Largest estimate over the five scenes, MuJoCo (implicitfast 0.5 ms; double_massless 0.125 ms), all on
#: double_phibc90 but the link force: phi_c_err_max 7.3e-7 rad, bound 5e-6 (6.9x); torque_in_mean 2.5e-3 N m, bound
#: 0.01 (4.1x); closure_residual_max 1.95e-6 m, bound 1e-5 (5.1x); torque_in_ripple_pp 0.073 N m, bound 0.3 (4.1x);
#: link_force_max_abs 1.39 N (double_massless), bound 5 (3.6x; 1.5 % of its 327 N; 28x the other scenes' 0.18 N)
TOL = {"phi_c_err_max": 5e-6, "torque_in_mean": 0.01, "closure_residual_max": 1e-5, "torque_in_ripple_pp": 0.3,
       "link_force_max_abs": 5.0}
#: the kinematic reference (sample_dt 2 ms), largest estimate: torque_in_mean 7.2e-7 N m (double_phibc90; the power
#: balance gives the load, 1000 N m, exactly over whole revolutions), bound 1e-5 (14x); torque_in_ripple_pp 0.027 N m
#: (double_phibc90), bound 0.3 (11x); phi_c_kin_fluctuation_pp 4.7e-7 rad (double_phibc90), bound 5e-6 (11x);
#: closure_residual_max 1.15e-13 m (rounding: every sample's gap is below the Gauss-Newton tolerance, 1e-13 R^2 / (2 l)
#: = 5.3e-14 m, so no estimate exceeds 3 x that = 1.6e-13), bound 1e-12 (8.7x)
TOL_REFERENCE = {"torque_in_mean": 1e-5, "torque_in_ripple_pp": 0.3, "closure_residual_max": 1e-12,
                 "phi_c_kin_fluctuation_pp": 5e-6}


def names(scene: Any) -> tuple[str, ...]:
    """The headline names of the scene's path."""
    return MUJOCO if scene.solver.engine == "mujoco" else REFERENCE


def headlines(scene: Any) -> tuple[Headline, ...]:
    """The headlines of the scene's path with their tolerances (module docstring)."""
    tol = TOL if scene.solver.engine == "mujoco" else TOL_REFERENCE
    return tuple(Headline(n, HEADLINES[n][0], tol[n], HEADLINES[n][1]) for n in names(scene))


def values(scene: Any, res: Any) -> dict[str, float]:
    """The headline values of a run's result (its statistics)."""
    return {n: float(res.statistics[n]) for n in names(scene)}


def refine_mujoco(scene: Any, level: int) -> Any:
    """The scene with `solver.timestep` and `solver.sample_dt` halved `level` times (the size guard grows with them)
    and the dry friction's time constant held at the scene's (by default 2 timesteps of the unrefined run)."""
    if level == 0:
        return scene
    out = refine_timestep(scene, level).replace(solver={"sample_dt": scene.solver.sample_dt / 2**level})
    if scene.effects.get("friction") and scene.build_params().solref_friction_timeconst is None:
        out = out.replace(params={"solref_friction_timeconst": 2.0 * scene.solver.timestep})
    return out


def refine_samples(scene: Any, level: int) -> Any:
    """The scene with the kinematic reference's grid spacing (`solver.sample_dt`, or 10 timesteps where it is 0,
    `reference.run_reference`) halved `level` times."""
    if level == 0:
        return scene
    s = scene.solver
    return scene.replace(solver={"sample_dt": (s.sample_dt or 10 * s.timestep) / 2**level})


def refinement(scene: Any) -> Refinement:
    """MuJoCo: step and samples halved at the integrator's order; reference: samples halved, order 2."""
    if scene.solver.engine == "mujoco":
        return Refinement("solver.timestep + solver.sample_dt", 2.0, ORDER[scene.solver.integrator], refine_mujoco,
                          "step and sample spacing halved together, the friction time constant held")
    return Refinement("solver.sample_dt", 2.0, ORDER_REFERENCE, refine_samples,
                      "sample spacing halved (the FPP, the power balance's rates and the extrema on it)")


def much_refined(scene: Any) -> Any:
    """A much finer run of another method, the yardstick of the declared tolerances (`tests/coupler/
    test_accuracy.py`, `scripts/coupler_accuracy.py`). MuJoCo: RK4 (order 4) at h/8 sampled every sample_dt/16, the
    friction time constant held; reference: sample_dt/16."""
    if scene.solver.engine == "mujoco":
        return refine_mujoco(scene, 4).replace(solver={"integrator": "rk4", "timestep": scene.solver.timestep / 8})
    return refine_samples(scene, 4)
