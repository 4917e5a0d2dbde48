"""The MuJoCo path of the IFToMM gates: the MJCF as shipped (soft `connect` equalities, solref time constant from the
parameters), stepped by the native core (`mbsuite.engines.core`); energy from MuJoCo's own `mj_energyPos/Vel`, the
closure error from the `connect` constraint rows."""

from __future__ import annotations

import mujoco
import numpy as np

from ...engines import core
from ...engines import mujoco_engine as mje
from ...engines import pinocchio_engine as pe
from ...errors import SceneError
from ...paths import mjcf_path
from ...results import SimResult
from ...scenes import Scene
from .geometry import MECHANISMS, Trajectory
from .modelfiles import check_mujoco_model
from .outputs import result


def mujoco_model(mechanism: str, timestep: float, integrator: str, solref_timeconst: float,
                 gravity: float) -> mujoco.MjModel:
    """The mechanism's MJCF compiled and checked at load (`check_mujoco_model`), with the run's settings."""
    if mechanism not in MECHANISMS:
        raise SceneError(f"unknown IFToMM mechanism {mechanism!r}; valid: {list(MECHANISMS)}")
    path = mjcf_path(f"iftomm_{mechanism}")
    m = mje.load_model(path)
    check_mujoco_model(m, path, mechanism)
    mje.set_integrator(m, integrator, timestep)
    m.eq_solref[:, 0] = solref_timeconst
    m.opt.gravity[:] = [0.0, -gravity, 0.0]
    return m


def closure_jacobian_rank(m: mujoco.MjModel, q: np.ndarray, rtol: float = 1e-9) -> tuple[int, np.ndarray]:
    """Rank (SVD, relative tolerance rtol) and singular values of MuJoCo's equality-constraint Jacobian at q."""
    d = mujoco.MjData(m)
    d.qpos[:] = q
    mujoco.mj_forward(m, d)
    rows = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    J = d.efc_J.reshape(d.nefc, m.nv)[rows] if d.nefc else np.zeros((0, m.nv))
    return pe.numerical_rank(J, rtol)


def initial_velocity(m: mujoco.MjModel, rate: float) -> np.ndarray:
    """Joint velocity at qpos0 on the mechanism's free motion (null space of the closure Jacobian), scaled so that
    the first (input) joint turns at `rate` rad/s."""
    if rate == 0.0:
        return np.zeros(m.nv)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    rows = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    J = d.efc_J.reshape(d.nefc, m.nv)[rows]
    _, s, Vt = np.linalg.svd(J)
    n = Vt[-1]
    if abs(n[0]) < 1e-9:
        raise SceneError("the input joint does not move on this mechanism's free motion")
    return rate * n / n[0]


def channels(m: mujoco.MjModel) -> list[core.Channel]:
    """What a MuJoCo run of a gate records: joint positions and rates, MuJoCo's potential and kinetic energy, and the
    three constraint rows of every `connect` (its closure error)."""
    out = [core.Channel("q", "qpos", 0, m.nq), core.Channel("v", "qvel", 0, m.nv),
           core.Channel("energy", "energy", 0, 2)]
    out += [core.Channel(f"closure_{e}", "eq_pos", e, 3) for e in range(m.neq)]
    return out


def closure_of(tr: core.Trajectory, m: mujoco.MjModel) -> np.ndarray:
    """Max |closure error| (m) over every connect's rows, per recorded sample."""
    if not m.neq:
        return np.zeros(tr.t.size)
    return np.max(np.abs(np.hstack([tr[f"closure_{e}"] for e in range(m.neq)])), axis=1)


def simulate_mujoco(m: mujoco.MjModel, v0: np.ndarray, duration: float, sample_dt: float) -> Trajectory:
    """MuJoCo from q = 0 (the assembled pose of the files) with joint rates v0, on the native core."""
    d = mujoco.MjData(m)
    d.qvel[:] = v0
    n = int(round(duration / m.opt.timestep))
    every = max(1, int(round(sample_dt / m.opt.timestep))) if sample_dt > 0 else 1
    what = f"IFToMM {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, 1)} (MuJoCo)"
    tr = core.Stepper(m, d, channels(m), every=every, what=what).run(n)
    q = tr["q"].reshape(tr.t.size, m.nq)
    v = tr["v"].reshape(tr.t.size, m.nv)
    return Trajectory(tr.t, q, v, tr["energy"].sum(axis=1), closure_of(tr, m),
                      {"steps": tr.steps, "warnings": tr.warnings})


def view_model(scene: Scene) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The scene's mechanism as MuJoCo runs it (`mbsuite view`): compiled with the scene's settings, at q = 0 with
    the scene's initial rates."""
    p = scene.build_params()
    sv = scene.solver
    m = mujoco_model(scene.effects["mechanism"], sv.timestep, sv.integrator, p.solref_timeconst, p.gravity)
    d = mujoco.MjData(m)
    d.qvel[:] = initial_velocity(m, float(scene.input.get("rate", 0.0)))
    mujoco.mj_forward(m, d)
    return m, d


def run(scene: Scene) -> SimResult:
    """The MuJoCo path's run: the scene's mechanism from q = 0 at the input's rate, as a SimResult."""
    p = scene.build_params()
    rate = float(scene.input.get("rate", 0.0))  # the scene loader fills in the declared default (0: at rest)
    sv = scene.solver
    if sv.timestep * 2 > p.solref_timeconst + 1e-15:
        raise SceneError(f"solver.timestep {sv.timestep:g} s is too large for the closures' solref time constant "
                         f"{p.solref_timeconst:g} s (MuJoCo needs timeconst >= 2 timestep)")
    m = mujoco_model(scene.effects["mechanism"], sv.timestep, sv.integrator, p.solref_timeconst, p.gravity)
    v0 = initial_velocity(m, rate)
    tr = simulate_mujoco(m, v0, sv.duration, sv.sample_dt or sv.timestep)
    return result(scene, tr, m, v0, p.gravity)
