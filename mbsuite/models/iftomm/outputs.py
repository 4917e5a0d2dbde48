"""What a run of an IFToMM gate returns, whichever path ran it: the signals (with units), the statistics and the two
health figures (closure residual and energy drift, with the bounds of each path)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...results import SimResult, assemble
from ...scenes import Scene
from ...statistics import Statistic
from ...trust.health import Figure
from .geometry import BAR, Trajectory

if TYPE_CHECKING:
    import mujoco

OUTPUTS = {"input_angle": "rad", "input_rate": "rad/s", "branch_angle": "rad", "energy": "J", "energy_drift": "J",
           "closure_residual": "m"}

_RUN = "the whole run"
#: the statistics of a run (`SPEC.statistics`; `SimResult.statistics`)
STATISTICS = {
    "energy_drift_max": Statistic("J", "largest |E(t) - E(0)| of the mechanism's energy (kinetic + potential)", _RUN),
    "closure_residual_max": Statistic("m", "largest loop-closure gap", _RUN),
    "branch_angle_max": Statistic("rad", "largest |branch angle| (four-bar: the coupler's absolute angle; Bricard: "
                                         "q1 + q3), 0 on the benchmark's branch", _RUN),
    "energy_scale": Statistic("J", "the energy the motion can exchange: initial kinetic energy plus m g L of every "
                                   "moving bar", "the start of the run"),
}

#: health bounds, 5-6x the largest value measured on the shipped scenes (10 s, default solver settings):
#: closure residual [m per m of bar]: MuJoCo 9.3e-5 (four-bar), 1.67e-4 (Bricard); Pinocchio 4.4e-16, 3.2e-7;
#: energy drift [of `energy_scale`]: MuJoCo 6.0e-3 (0.359 J of 59.4 J; the soft closures' damping dissipates),
#: 8.2e-4 (0.040 J of 49.1 J); Pinocchio 1.2e-7, 2.1e-6 (DOP853 rtol 1e-8)
HEALTH_BOUNDS = {"mujoco": {"closure_residual": 1e-3, "energy_drift": 3e-2},
                 "reference": {"closure_residual": 2e-6, "energy_drift": 1e-5}}


def branch_angle(mechanism: str, q: np.ndarray) -> np.ndarray:
    """Four-bar: the coupler's absolute angle (0 on the parallelogram branch). Bricard: q1 + q3 (0 on the motion
    through the cube-hexagon pose, whose joints 1, 3, 5 turn by +-the same angle)."""
    return q[:, 0] + q[:, 1] if mechanism == "fourbar" else q[:, 0] + q[:, 2]


def energy_scale(m: mujoco.MjModel, v0: np.ndarray, gravity: float) -> float:
    """The energy the motion can exchange [J]: the initial kinetic energy (joint rates `v0`) plus m g L for every
    moving bar (the most potential energy a bar of length L can trade), independent of the potential's datum."""
    import mujoco  # here: listing the models imports no engine

    d = mujoco.MjData(m)
    d.qvel[:] = v0
    mujoco.mj_forward(m, d)
    bars = [b for b in range(1, m.nbody) if m.body_jntnum[b] > 0]
    return float(d.energy[1] + sum(m.body_mass[b] for b in bars) * gravity * BAR)


def health(stats: dict, engine: str) -> list[Figure]:
    """`closure_residual` (largest closure gap over the run, bound relative to the bar length) and `energy_drift`
    (largest |E(t) - E(0)| over the run relative to `energy_scale`: both benchmarks are conservative, no friction and
    no input after t = 0)."""
    b = HEALTH_BOUNDS[engine]
    fix = ("lower params.solref_timeconst (stiffer closures) or solver.timestep" if engine == "mujoco" else
           "lower solver.rtol / solver.atol")
    return [Figure("closure_residual", stats["closure_residual_max"], b["closure_residual"] * BAR, "m",
                   f"largest loop-closure gap over the run, bound {b['closure_residual']:g} x bar length", fix),
            Figure("energy_drift", stats["energy_drift_max"] / stats["energy_scale"], b["energy_drift"], "",
                   f"max |E(t) - E(0)| / energy scale {stats['energy_scale']:.4g} J (conservative benchmark)", fix)]


def result(scene: Scene, tr: Trajectory, m: mujoco.MjModel, v0: np.ndarray, gravity: float) -> SimResult:
    """The SimResult of a trajectory of the scene's mechanism (`m`: its MuJoCo model, `v0`: the initial rates)."""
    mech, engine = scene.effects["mechanism"], scene.solver.engine
    sig = {"input_angle": tr.q[:, 0], "input_rate": tr.v[:, 0], "branch_angle": branch_angle(mech, tr.q),
           "energy": tr.energy, "energy_drift": tr.energy - tr.energy[0], "closure_residual": tr.closure}
    statistics = {"energy_drift_max": float(np.max(np.abs(sig["energy_drift"]))),
                  "closure_residual_max": float(np.max(tr.closure)),
                  "branch_angle_max": float(np.max(np.abs(sig["branch_angle"]))),
                  "energy_scale": energy_scale(m, v0, gravity)}
    return assemble(scene, tr.t, sig, engine=engine, stats=dict(tr.stats), statistics=statistics,
                    health=health(statistics, engine))
