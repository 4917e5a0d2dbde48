"""The Pinocchio path of the IFToMM gates: the same MJCF read by Pinocchio (`buildModelFromMJCF`).

The closures are the stated ones (`geometry.DESIGN`) on Pinocchio's own frames; the constrained dynamics are the index-1
DAE replaced by the penalty formulation `(M + p J^T J) a = -h - p J^T (Jdot v + 2 w J v + w^2 r)` (p = 1e7, w = 10/s:
positive definite whatever the rank of J, so the Bricard's redundant rows need no special treatment), integrated by
scipy (DOP853 by default). The four-bar's reference is integrated on its parallelogram branch q = (s, -s, s)
(Pinocchio's M(q) and h(q, v) projected on the branch tangent): the Lagrange-multiplier and penalty formulations both
leave the branch at the singular positions (measured: rcond/damping variants end up on the anti-parallelogram branch or
stall; see the package README), which is exactly what the A02 gate is about.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

from ...engines import pinocchio_engine as pe
from ...errors import ModelFileError, SceneError, SolverError
from ...paths import mjcf_path
from ...results import SimResult
from ...scenes import Scene
from .geometry import DESIGN, MECHANISMS, Closure, Trajectory
from .modelfiles import check_pinocchio_model
from .mujoco import initial_velocity, mujoco_model
from .outputs import result


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


def run(scene: Scene) -> SimResult:
    """The Pinocchio path's run: the scene's mechanism from q = 0 at the input's rate (the initial rates on the free
    motion from MuJoCo's compiled closures), integrated by scipy with the scene's method and tolerances."""
    p = scene.build_params()
    mech = scene.effects["mechanism"]
    rate = float(scene.input.get("rate", 0.0))
    sv = scene.solver
    pm = PinocchioMechanism(mech, p.gravity, p.penalty, p.penalty_omega)  # checks the file first (Pinocchio)
    m = mujoco_model(mech, 1e-3, "rk4", p.solref_timeconst, p.gravity)
    v0 = initial_velocity(m, rate)
    tr = pm.simulate(v0, sv.duration, sv.sample_dt or 1e-2, method=sv.method, rtol=sv.rtol, atol=sv.atol,
                     max_step=sv.max_step)
    return result(scene, tr, m, v0, p.gravity)
