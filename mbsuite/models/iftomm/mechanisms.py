"""Two gates of the IFToMM multibody benchmark through mbsuite's MuJoCo and Pinocchio machinery.

- `fourbar` (A02-type): the parallelogram four-bar of `mjcf/iftomm_fourbar.xml`; every half turn of the crank all bars
  are collinear, the closure Jacobian loses rank and the mechanism may switch to the anti-parallelogram branch.
  Branch indicator: the coupler's absolute angle (0 on the parallelogram branch).
- `bricard` (A04-type): the orthogonal Bricard linkage of `mjcf/iftomm_bricard.xml`; 6 closure rows on 5 joint
  coordinates with 1 DOF: the closure Jacobian has rank 4 (two redundant rows: the Bricard's own and the axial
  distance of the two `connect`s that make the sixth hinge).

Engines:
- `mujoco`: the MJCF as shipped (soft `connect` equalities, solref timeconst from the parameters), stepped by the
  native core (`mbsuite.engines.core`); energy from MuJoCo's own `mj_energyPos/Vel`, closure error from the
  `connect` constraint rows.
- `reference`: the same file read by Pinocchio (`buildModelFromMJCF`); the closures are taken from MuJoCo's compiled
  `connect` anchors (body -> Pinocchio joint of the same name), and the constrained dynamics are the index-1 DAE
  replaced by the penalty formulation `(M + p J^T J) a = -h - p J^T (Jdot v + 2 w J v + w^2 r)` (p = 1e7, w = 10/s:
  positive definite whatever the rank of J, so the Bricard's redundant rows need no special treatment), integrated by
  scipy (DOP853 by default). The four-bar's reference is integrated on its parallelogram branch q = (s, -s, s)
  (Pinocchio's M(q) and h(q, v) projected on the branch tangent): the Lagrange-multiplier and penalty formulations
  both leave the branch at the singular positions (measured: rcond/damping variants end up on the anti-parallelogram
  branch or stall; see the package README), which is exactly what the A02 gate is about.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

from ...engines import core
from ...engines import mujoco_engine as mje
from ...engines import pinocchio_engine as pe
from ...errors import ModelFileError, SceneError, SolverError
from ...paths import mjcf_path

MECHANISMS = ("fourbar", "bricard")


@dataclass
class Closure:
    """A point closure: point `a` fixed in Pinocchio joint `ja` equals point `b` fixed in joint `jb` (0 = world)."""

    ja: int
    a: np.ndarray
    jb: int
    b: np.ndarray


@dataclass
class Trajectory:
    """A simulated trajectory: samples t, q, v, energy [J] and closure error [m], plus solver statistics."""
    t: np.ndarray
    q: np.ndarray  # (N, nq)
    v: np.ndarray  # (N, nv)
    energy: np.ndarray
    closure: np.ndarray  # max |closure error| (m) per sample
    stats: dict = field(default_factory=dict)


#: bar length of every benchmark bar [m] (the files' stated geometry)
BAR = 1.0
#: the stated geometry of each file: bodies and joints it must hold and its loop closures, each
#: (connect name, body1, point on body1, body2 or "world", point on body2), points in the bodies' frames [m]
DESIGN: dict[str, dict] = {
    "fourbar": {"bodies": ("crank", "coupler", "rocker"), "joints": ("crank", "coupler", "rocker"),
                # the coupler's far end C meets the rocker's tip: both bars BAR long, ground pivots BAR apart
                "closures": (("C", "coupler", (BAR, 0.0, 0.0), "rocker", (0.0, BAR, 0.0)),)},
    "bricard": {"bodies": ("bar1", "bar2", "bar3", "bar4", "bar5"), "joints": ("j1", "j2", "j3", "j4", "j5"),
                # the sixth hinge (axis x through the cube corner (0, 0, 1)): two points of bar5's end on that axis
                "closures": (("j6a", "bar5", (0.0, -BAR, 0.0), "world", (0.0, 0.0, BAR)),
                             ("j6b", "bar5", (0.5 * BAR, -BAR, 0.0), "world", (0.5 * BAR, 0.0, BAR)))},
}
#: largest closure gap at the initial pose q = 0, relative to the bar length, accepted at load (files rounded to 6
#: digits pass; a moved pivot or a changed bar length fails by orders of magnitude)
CLOSURE_RTOL = 1e-6


def _closure_error(path, name: str, body: str, gap: float, engine: str) -> ModelFileError:
    return ModelFileError(f"{path}: loop closure {name!r} (body {body!r}) does not assemble at the initial pose q = 0 "
                          f"({engine}): residual {gap:.4g} m > {CLOSURE_RTOL:g} x bar length {BAR:g} m; the file's "
                          "pivots and bar lengths must match the stated geometry")


def check_mujoco_model(m: mujoco.MjModel, path, mechanism: str) -> None:
    """Checks at load of an IFToMM MJCF compiled from `path` (DESIGN): the bodies, joints and <connect>s are present
    and join the stated bodies; each connect's anchor is the stated point and meets the stated point of its second
    body at q = 0 (MuJoCo places the second side of a connect at compile time, so any geometry would "close"); every
    moving body has mass > 0 and a positive definite inertia (triangle inequality). Else ModelFileError naming the
    file, the body and the residual."""
    des = DESIGN[mechanism]
    ob = mujoco.mjtObj
    missing = [f"body {n!r}" for n in des["bodies"] if mujoco.mj_name2id(m, ob.mjOBJ_BODY, n) < 0]
    missing += [f"joint {n!r}" for n in des["joints"] if mujoco.mj_name2id(m, ob.mjOBJ_JOINT, n) < 0]
    missing += [f"connect {c[0]!r}" for c in des["closures"] if mujoco.mj_name2id(m, ob.mjOBJ_EQUALITY, c[0]) < 0]
    if missing:
        raise ModelFileError(f"{path}: the IFToMM {mechanism} needs {', '.join(missing)}, which the file lacks")
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)

    def world(body: str, pt) -> np.ndarray:
        if body == "world":
            return np.asarray(pt, float)
        b = mujoco.mj_name2id(m, ob.mjOBJ_BODY, body)
        return d.xpos[b] + d.xmat[b].reshape(3, 3) @ np.asarray(pt, float)

    for name, b1, a, b2, b in des["closures"]:
        e = mujoco.mj_name2id(m, ob.mjOBJ_EQUALITY, name)
        id2 = 0 if b2 == "world" else mujoco.mj_name2id(m, ob.mjOBJ_BODY, b2)
        if (m.eq_type[e] != mujoco.mjtEq.mjEQ_CONNECT or int(m.eq_obj1id[e]) != mujoco.mj_name2id(m, ob.mjOBJ_BODY, b1)
                or int(m.eq_obj2id[e]) != id2):
            raise ModelFileError(f"{path}: equality {name!r} must be a <connect> from body {b1!r} to {b2!r}")
        gap = max(float(np.linalg.norm(m.eq_data[e, 0:3] - np.asarray(a))),
                  float(np.linalg.norm(world(b1, a) - world(b2, b))))
        if not gap <= CLOSURE_RTOL * BAR:
            raise _closure_error(path, name, b2 if b2 != "world" else b1, gap, "MuJoCo")
    for i in range(1, m.nbody):
        if m.body_jntnum[i] == 0:
            continue
        inertia = np.sort(m.body_inertia[i])
        if not (m.body_mass[i] > 0 and inertia[0] > 0 and inertia[0] + inertia[1] >= inertia[2] * (1 - 1e-12)):
            raise ModelFileError(f"{path}: body {mujoco.mj_id2name(m, ob.mjOBJ_BODY, i)!r} has mass "
                                 f"{m.body_mass[i]:g} kg and principal inertia {m.body_inertia[i].tolist()} kg m^2: a "
                                 "moving body needs mass > 0 and a positive definite inertia (triangle inequality)")


def _pin_point(model: pin.Model, data: pin.Data, path, body: str, point) -> np.ndarray:
    """World position (after forward kinematics) of a point fixed in MJCF body `body` ("world": the point itself)."""
    if body == "world":
        return np.asarray(point, float)
    if not model.existFrame(body, pin.FrameType.BODY):
        raise ModelFileError(f"{path}: Pinocchio finds no body {body!r} in the file")
    f = model.frames[model.getFrameId(body, pin.FrameType.BODY)]
    return data.oMi[f.parentJoint].act(f.placement.act(np.asarray(point, float)))


def check_pinocchio_model(model: pin.Model, path, mechanism: str) -> None:
    """Checks at load of an IFToMM file read by Pinocchio (DESIGN): every stated closure assembles at the neutral
    pose q = 0 on Pinocchio's own frames, and the body of every joint has mass > 0 and a positive definite inertia.
    Else ModelFileError naming the file, the body and the residual."""
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    for name, b1, a, b2, b in DESIGN[mechanism]["closures"]:
        gap = float(np.linalg.norm(_pin_point(model, data, path, b1, a) - _pin_point(model, data, path, b2, b)))
        if not gap <= CLOSURE_RTOL * BAR:
            raise _closure_error(path, name, b2 if b2 != "world" else b1, gap, "Pinocchio")
    for j in range(1, model.njoints):
        inertia = model.inertias[j]
        eig = np.linalg.eigvalsh(inertia.inertia)
        if not (inertia.mass > 0 and eig[0] > 0):
            raise ModelFileError(f"{path}: the body on joint {model.names[j]!r} has mass {inertia.mass:g} kg and "
                                 f"inertia eigenvalues {eig.tolist()} kg m^2: a moving body needs mass > 0 and a "
                                 "positive definite inertia")


#: file stem -> mechanism of the IFToMM model files (`check_model_file`)
FILE_STEMS = {f"iftomm_{m}": m for m in MECHANISMS}


def check_model_file(path, engine: str, model) -> None:
    """The checks of an IFToMM model file (`iftomm_fourbar`, `iftomm_bricard`) as a loader compiled it, for the
    engines' loaders (`ModelSpec.file_checks`): engine "mujoco" with an `mujoco.MjModel` (`check_mujoco_model`),
    "pinocchio" or "urdf" with a `pin.Model` (`check_pinocchio_model`). Raises ModelFileError naming the file, the
    body/closure and the residual."""
    from pathlib import Path

    path = Path(path)
    mechanism = FILE_STEMS.get(path.stem)
    if mechanism is None:
        raise ModelFileError(f"{path}: not an IFToMM model file; valid names: {sorted(FILE_STEMS)}")
    if engine == "mujoco":
        check_mujoco_model(model, path, mechanism)
    elif engine in ("pinocchio", "urdf"):
        check_pinocchio_model(model, path, mechanism)
    else:
        raise ModelFileError(f"{path}: unknown engine {engine!r} for the IFToMM file checks; valid: "
                             "['mujoco', 'pinocchio', 'urdf']")


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


class PinocchioMechanism:
    """The MJCF read by Pinocchio with the closures of MuJoCo's compiled `connect`s (see module docstring)."""

    def __init__(self, mechanism: str, gravity: float, penalty: float = 1e7, omega: float = 10.0):
        if mechanism not in MECHANISMS:
            raise SceneError(f"unknown IFToMM mechanism {mechanism!r}; valid: {list(MECHANISMS)}")
        self.path = mjcf_path(f"iftomm_{mechanism}")
        self.model = pe.load_mjcf(self.path)
        self.model.gravity.linear = np.array([0.0, -gravity, 0.0])
        self.data = self.model.createData()
        # the stated closures (DESIGN) on Pinocchio's own frames, checked at the initial pose before anything else
        check_pinocchio_model(self.model, self.path, mechanism)
        self.closures = [Closure(*self._on_joint(b1, a), *self._on_joint(b2, b))
                         for _, b1, a, b2, b in DESIGN[mechanism]["closures"]]
        self.mj = mujoco_model(mechanism, 1e-3, "rk4", 0.004, gravity)
        self.penalty, self.omega = float(penalty), float(omega)
        # the four-bar is integrated on its parallelogram branch q = (s, -s, s): a linear map, exact on that branch;
        # penalty and multiplier formulations leave the branch at the singular positions (README)
        self.branch = np.array([[1.0], [-1.0], [1.0]]) if mechanism == "fourbar" else None

    def _on_joint(self, body: str, point) -> tuple[int, np.ndarray]:
        """(Pinocchio joint, the point in that joint's frame) of a point fixed in MJCF body `body` ("world": 0)."""
        if body == "world":
            return 0, np.asarray(point, float)
        if not self.model.existFrame(body, pin.FrameType.BODY):
            raise ModelFileError(f"{self.path}: Pinocchio finds no body {body!r} in the file")
        f = self.model.frames[self.model.getFrameId(body, pin.FrameType.BODY)]
        return int(f.parentJoint), f.placement.act(np.asarray(point, float))

    def _points(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pin.forwardKinematics(self.model, self.data, q)
        pin.computeJointJacobians(self.model, self.data, q)
        r, J = [], []
        for c in self.closures:
            pts, jacs = [], []
            for j, loc in ((c.ja, c.a), (c.jb, c.b)):
                if j == 0:
                    pts.append(loc)
                    jacs.append(np.zeros((3, self.model.nv)))
                    continue
                M = self.data.oMi[j]
                p = M.act(loc)
                J6 = pin.getJointJacobian(self.model, self.data, j, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
                jacs.append(J6[:3] - pin.skew(p - M.translation) @ J6[3:])
                pts.append(p)
            r.append(pts[0] - pts[1])
            J.append(jacs[0] - jacs[1])
        return np.concatenate(r), np.vstack(J)

    def closure(self, q: np.ndarray) -> np.ndarray:
        """Closure errors (stacked point gaps [m]) at q."""
        return self._points(q)[0]

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """Penalty formulation (Bayo et al.): (M + p J^T J) a = -h - p J^T (Jdot v + 2 w J v + w^2 r).

        M + p J^T J stays positive definite when J loses rank (singular positions, redundant closures), unlike the
        Lagrange-multiplier KKT system; the closure error obeys r'' + 2 w r' + w^2 r = O(1/p)."""
        nq = self.model.nq
        q, v = x[:nq], x[nq:]
        if self.branch is not None:  # reduced to the branch's tangent: q = T s, v = T s'
            T = self.branch
            s, sd = q[:T.shape[1]], v[:T.shape[1]]
            qq, vv = T @ s, T @ sd
            M = pin.crba(self.model, self.data, qq)
            M = np.triu(M) + np.triu(M, 1).T
            h = pin.nonLinearEffects(self.model, self.data, qq, vv)
            sdd = np.linalg.solve(T.T @ M @ T, -T.T @ h)
            return np.concatenate([sd, np.zeros(nq - sd.size), sdd, np.zeros(nq - sd.size)])
        r, J = self._points(q)
        eps = 1e-7
        _, J2 = self._points(q + eps * v)
        Jdv = (J2 - J) @ v / eps
        M = pin.crba(self.model, self.data, q)
        M = np.triu(M) + np.triu(M, 1).T
        h = pin.nonLinearEffects(self.model, self.data, q, v)
        w, p = self.omega, self.penalty
        a = np.linalg.solve(M + p * J.T @ J, -h - p * J.T @ (Jdv + 2 * w * (J @ v) + w * w * r))
        return np.concatenate([v, a])

    def energy(self, q: np.ndarray, v: np.ndarray) -> float:
        """Kinetic plus potential energy [J] at (q, v) (Pinocchio)."""
        return float(pin.computeKineticEnergy(self.model, self.data, q, v)
                     + pin.computePotentialEnergy(self.model, self.data, q))

    def simulate(self, v0: np.ndarray, duration: float, sample_dt: float, method: str = "DOP853",
                 rtol: float = 1e-10, atol: float = 1e-12, max_step: float = 0.0) -> Trajectory:
        """Integrate from the initial pose with velocity v0 for `duration` s (scipy `method`), sampled every
        `sample_dt`; on the four-bar the reduced branch dynamics, else the penalty formulation (`rhs`)."""
        nq = self.model.nq
        if self.branch is not None:
            s0 = np.linalg.lstsq(self.branch, v0, rcond=None)[0]
            if np.max(np.abs(self.branch @ s0 - v0)) > 1e-9 * max(1.0, np.max(np.abs(v0))):
                raise SceneError("initial velocity is not on the four-bar's parallelogram branch")
            v0 = np.concatenate([s0, np.zeros(nq - s0.size)])
        x0 = np.concatenate([np.zeros(nq), v0])
        t_eval = np.arange(0.0, duration + 0.5 * sample_dt, sample_dt)
        t_eval = t_eval[t_eval <= duration]
        sol = solve_ivp(self.rhs, (0.0, duration), x0, method=method, rtol=rtol, atol=atol, t_eval=t_eval,
                        max_step=max_step or math.inf)
        if not sol.success or not np.all(np.isfinite(sol.y)):
            raise SolverError(f"Pinocchio constrained dynamics ({method}, rtol {rtol:g}) failed: {sol.message}")
        q, v = sol.y[:nq].T, sol.y[nq:].T
        if self.branch is not None:
            k = self.branch.shape[1]
            q, v = q[:, :k] @ self.branch.T, v[:, :k] @ self.branch.T
        e = np.array([self.energy(a, b) for a, b in zip(q, v, strict=True)])
        res = np.array([float(np.max(np.abs(self.closure(a)))) for a in q])
        return Trajectory(sol.t, q, v, e, res, {"nfev": int(sol.nfev), "method": method, "rtol": rtol})
