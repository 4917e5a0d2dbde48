"""The `run` hook of the IFToMM gates: a time simulation on MuJoCo or the Pinocchio reference."""

from __future__ import annotations

import numpy as np

from ...errors import SceneError
from ...results import SimResult, assemble
from ...scenes import Scene
from .mechanisms import PinocchioMechanism, initial_velocity, mujoco_model, simulate_mujoco

OUTPUTS = {"input_angle": "rad", "input_rate": "rad/s", "branch_angle": "rad", "energy": "J", "energy_drift": "J",
           "closure_residual": "m"}


def branch_angle(mechanism: str, q: np.ndarray) -> np.ndarray:
    """Four-bar: the coupler's absolute angle (0 on the parallelogram branch). Bricard: q1 + q3 (0 on the motion
    through the cube-hexagon pose, whose joints 1, 3, 5 turn by +-the same angle)."""
    return q[:, 0] + q[:, 1] if mechanism == "fourbar" else q[:, 0] + q[:, 2]


def run(scene: Scene) -> SimResult:
    p = scene.build_params()
    mech = scene.effects["mechanism"]
    rate = float(scene.input.get("rate", 6.0 if mech == "fourbar" else 0.0))
    sv = scene.solver
    if sv.engine == "mujoco":
        if sv.timestep * 2 > p.solref_timeconst + 1e-15:
            raise SceneError(f"solver.timestep {sv.timestep:g} s is too large for the closures' solref time constant "
                             f"{p.solref_timeconst:g} s (MuJoCo needs timeconst >= 2 timestep)")
        m = mujoco_model(mech, sv.timestep, sv.integrator, p.solref_timeconst, p.gravity)
        tr = simulate_mujoco(m, initial_velocity(m, rate), sv.duration, sv.sample_dt or sv.timestep)
    else:
        m = mujoco_model(mech, 1e-3, "rk4", p.solref_timeconst, p.gravity)
        pm = PinocchioMechanism(mech, p.gravity, p.penalty, p.penalty_omega)
        tr = pm.simulate(initial_velocity(m, rate), sv.duration, sv.sample_dt or 1e-2, method=sv.method,
                         rtol=sv.rtol, atol=sv.atol, max_step=sv.max_step)
    sig = {"input_angle": tr.q[:, 0], "input_rate": tr.v[:, 0], "branch_angle": branch_angle(mech, tr.q),
           "energy": tr.energy, "energy_drift": tr.energy - tr.energy[0], "closure_residual": tr.closure}
    stats = dict(tr.stats)
    stats.update({"energy_drift_max": float(np.max(np.abs(sig["energy_drift"]))),
                  "closure_residual_max": float(np.max(tr.closure)),
                  "branch_angle_max": float(np.max(np.abs(sig["branch_angle"])))})
    return assemble(scene, tr.t, sig, engine=sv.engine, stats=stats)
