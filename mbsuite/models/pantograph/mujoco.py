"""MuJoCo path of the pantograph: the shipped MJCF edited by MjSpec for the effects a scene asks for.

What each effect installs (nothing else is built):
- gravity off: `opt.gravity = 0`;  viscous off: joint damping 0;  coulomb off: joint frictionloss 0;
  frictionloss constraints get solreffriction = (2 timestep, 1) whatever the timestep.
- contact unilateral: `catenary` actuator force limited to <= 0 (the wire only pushes).
- cylinder constant: the file as shipped (affine bias Pg Ap, no state, no callback).
- cylinder linear (3.24-3.26): `cylinder` gets dyntype user (act = P, m), gain kc, bias (Pg Ap, -kc, 0), so that
  force = Pg Ap + kc (P - x_p); the act_dyn callback returns P' = (kc/bc)(x_p - P).
- cylinder nonlinear (3.15-3.22 corrected): act = absolute pressure, gain Ap, bias (-Pa Ap, 0, 0); act_dyn returns
  P' = (R T / V) m'(P) - (P / V) Ap x_p' with V = V0 + Ap x_p.
- elbow compliant: a passive callback adds Eq 3.13's torque mapped to q: Q = E^T (-Te dte/dt1, Te, 0).
- elbow rigid: a joint equality q2 = poly(q1), a quartic fit of pi - t1 - theta_e(t1) over the working range (soft
  equality, solref timeconst = 2 timestep; its fit error is reported by `rigid_elbow_fit`).
The ram is ctrl[catenary] = y_w(t_k + c h) during step k, with c = 1/2 for RK4 (the hold value that represents y_w over
the step to O(h^2); with c = 0 RK4 degrades to first order: F1 phase error 0.38 deg vs 6e-7 deg at 4.25 Hz, h = 5e-4 s)
and c = 0 for the Euler family, whose semi-implicit update is leapfrog-like in position with forces belonging at t_k
(lab scene, h = 5e-4 s: max phase error 0.51 deg with c = 0 vs 0.92 deg with c = 1/2 over 2-10 Hz).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
from scipy.optimize import fsolve

from ...engines import mujoco_engine as mje
from ...errors import GeometryError, SolverError
from ...paths import mjcf_path
from .elbow import Elbow
from .modelfiles import mjcf_text, q_to_theta, theta_to_q
from .params import PantographParams
from .reference import PantographConfig, PantographODE

RIGID_FIT_RANGE = (0.15, 0.75)  # theta_1 range (rad) of the rigid-elbow polynomial fit


def rigid_elbow_fit(p: PantographParams, exact: bool = False) -> tuple[np.ndarray, float]:
    """Quartic coefficients (ascending) of q2(q1) = pi - q1 - theta_e(q1) and the max fit error (rad) on the range."""
    el = Elbow(p, exact)
    q1 = np.linspace(*RIGID_FIT_RANGE, 201)
    q2 = np.array([math.pi - a - el(a).theta_e for a in q1])
    c = np.polynomial.polynomial.polyfit(q1, q2, 4)
    err = float(np.max(np.abs(np.polynomial.polynomial.polyval(q1, c) - q2)))
    return c, err


@dataclass
class MujocoRun:
    t: np.ndarray
    qpos: np.ndarray  # (N, 3)
    qvel: np.ndarray
    act: np.ndarray  # (N, na)
    y_w: np.ndarray
    actuator_force: np.ndarray  # (N, nu)
    warnings: dict


class MujocoPantograph:
    """The pantograph in MuJoCo for a given parameter set and effects."""

    def __init__(self, params: PantographParams | None = None, config: PantographConfig | None = None,
                 integrator: str = "implicitfast", timestep: float = 5e-4):
        self.p = params or PantographParams()
        self.cfg = config or PantographConfig()
        self.timestep = timestep
        if self.p == PantographParams():
            spec = mujoco.MjSpec.from_file(str(mjcf_path("pantograph")))
        else:
            spec = mujoco.MjSpec.from_string(mjcf_text(self.p))
        self._edit(spec)
        self.model = mje.load_model(spec)
        mje.set_integrator(self.model, integrator, timestep)
        self.data = mujoco.MjData(self.model)
        self.hold_offset = 0.5 if integrator == "rk4" else 0.0
        self.elbow = Elbow(self.p, exact=self.cfg.elbow_kinematics == "exact")
        self.i_cat = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, "catenary")
        self.i_cyl = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, "cylinder")
        self._gas = PantographODE(self.p, PantographConfig(cylinder="nonlinear"))  # orifice law (3.17 corrected)

    # ------------------------------------------------------------------ building
    def _edit(self, spec: mujoco.MjSpec) -> None:
        cfg, p = self.cfg, self.p
        if not cfg.gravity:
            spec.option.gravity = [0.0, 0.0, 0.0]
        for j in spec.joints:
            j.solref_friction = [2.0 * self.timestep, 1.0]  # stiffest admissible friction constraint (see modelfiles)
            if not cfg.viscous:
                j.damping = [0.0, 0.0, 0.0]  # mujoco 4: damping is a 3-vector (polynomial coefficients)
            if not cfg.coulomb:
                j.frictionloss = 0.0
        cat = spec.actuator("catenary")
        if cfg.contact == "unilateral":
            cat.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            cat.forcerange = [-1e15, 0.0]
        cyl = spec.actuator("cylinder")
        if cfg.cylinder == "linear":
            cyl.dyntype = mujoco.mjtDyn.mjDYN_USER
            cyl.actdim = 1
            cyl.gainprm[0] = p.kc
            cyl.biasprm[:3] = [p.Pg * p.Ap, -p.kc, 0.0]
        elif cfg.cylinder == "nonlinear":
            cyl.dyntype = mujoco.mjtDyn.mjDYN_USER
            cyl.actdim = 1
            cyl.gainprm[0] = p.Ap
            cyl.biasprm[:3] = [-p.Pa * p.Ap, 0.0, 0.0]
        if cfg.elbow == "rigid":
            coef, _ = rigid_elbow_fit(p, cfg.elbow_kinematics == "exact")
            eq = spec.add_equality()
            eq.name = "rigid_elbow"
            eq.type = mujoco.mjtEq.mjEQ_JOINT
            eq.name1, eq.name2 = "knuckle_joint", "base_joint"
            eq.data[:5] = coef
            eq.solref = [2.0 * self.timestep, 1.0]

    # ------------------------------------------------------------------ callbacks (only those the effects need)
    def callback_set(self) -> dict[str, Callable | None]:
        return {
            "passive": self._elbow_passive if self.cfg.elbow == "compliant" else None,
            "act_dyn": self._cylinder_dyn if self.cfg.cylinder in ("linear", "nonlinear") else None,
        }

    def _elbow_passive(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        qpos = d.qpos.tolist()  # one conversion instead of numpy scalar reads (the callback runs every stage)
        te, dte = self.elbow.fast(qpos[0])
        Te = self.p.ke * (te - math.pi + qpos[0] + qpos[1])  # ke (theta_e - theta_2), theta_2 = pi - q1 - q2
        if self.p.be:
            qvel = d.qvel.tolist()
            Te += self.p.be * (dte * qvel[0] + qvel[0] + qvel[1])
        f = d.qfrc_passive
        f[0] -= Te * (dte + 1.0)
        f[1] -= Te

    def _cylinder_dyn(self, m: mujoco.MjModel, d: mujoco.MjData, i: int) -> float:
        P = d.act[m.actuator_actadr[i]]
        xp = d.actuator_length[i]
        p = self.p
        if self.cfg.cylinder == "linear":
            return p.kc / p.bc * (xp - P)
        V = p.V0 + p.Ap * xp
        return p.R_gas * p.T / V * self._gas.orifice_mass_flow(P) - P / V * p.Ap * d.actuator_velocity[i]

    # ------------------------------------------------------------------ statics
    def _set_static(self, q: np.ndarray, y_w: float) -> None:
        d, m = self.data, self.model
        d.qpos[:] = q
        d.qvel[:] = 0.0
        d.ctrl[self.i_cat] = y_w
        if m.na:
            mujoco.mj_kinematics(m, d)
            mujoco.mj_transmission(m, d)
            xp = d.actuator_length[self.i_cyl]
            d.act[m.actuator_actadr[self.i_cyl]] = xp if self.cfg.cylinder == "linear" else self.p.Ps
        mujoco.mj_forward(m, d)

    def static_residual(self, q: np.ndarray, y_w: float) -> np.ndarray:
        """qfrc_passive + qfrc_actuator - qfrc_bias at rest (friction-free), from MuJoCo's own force evaluation."""
        self._set_static(q, y_w)
        d = self.data
        r = d.qfrc_passive + d.qfrc_actuator - d.qfrc_bias
        if self.cfg.elbow == "rigid":  # reduce onto the constraint manifold: tangent direction (1, dq2/dq1, 0)
            coef, _ = rigid_elbow_fit(self.p, self.cfg.elbow_kinematics == "exact")
            dq2 = np.polynomial.polynomial.polyval(q[0], np.polynomial.polynomial.polyder(coef))
            c = np.polynomial.polynomial.polyval(q[0], coef) - q[1]
            return np.array([r[0] + dq2 * r[1], c, r[2]])
        return r.copy()

    def equilibrium(self, y_w: float | None = None) -> np.ndarray:
        y_w = self.p.y_op if y_w is None else y_w
        guess = theta_to_q(PantographODE(self.p, self.cfg).equilibrium(y_w)[[0, 1, 2]]
                           if self.cfg.elbow == "compliant" else _rigid_theta(self.p, self.cfg, y_w))
        with mje.callbacks(**self.callback_set()):
            q, _, ier, msg = fsolve(lambda q: self.static_residual(q, y_w), guess, xtol=1e-14, full_output=True)
            for _ in range(6):  # Newton polish on MuJoCo's residual
                r = self.static_residual(q, y_w)
                h = 1e-7
                Jr = np.column_stack([(self.static_residual(q + h * e, y_w) - self.static_residual(q - h * e, y_w))
                                      / (2 * h) for e in np.eye(3)])
                q = q - np.linalg.solve(Jr, r)
            res = np.max(np.abs(self.static_residual(q, y_w)))
        if res > 1e-6:
            raise GeometryError(f"MuJoCo: no static equilibrium at y_w = {y_w} m (residual {res:.3g} N m)")
        return q

    # ------------------------------------------------------------------ time simulation
    def simulate(self, y_w: Callable[[float], float], t_end: float, q0: np.ndarray | None = None) -> MujocoRun:
        """Step from the static equilibrium (or q0) for t_end seconds; returns every step. Divergence -> SolverError."""
        m, d = self.model, self.data
        h = m.opt.timestep
        nstep = int(round(t_end / h))
        if q0 is None:
            q0 = self.equilibrium(y_w(0.0))
        mujoco.mj_resetData(m, d)
        cbs = self.callback_set()
        yw = np.array([y_w(t) for t in (np.arange(nstep) + self.hold_offset) * h])
        ctrl = np.zeros((nstep, m.nu))
        ctrl[:, self.i_cat] = yw
        with mje.callbacks(**cbs):
            self._set_static(q0, y_w(0.0))
            d.time = 0.0
            qpos = np.empty((nstep + 1, m.nq))
            qvel = np.empty((nstep + 1, m.nv))
            act = np.empty((nstep + 1, m.na))
            frc = np.empty((nstep + 1, m.nu))
            qpos[0], qvel[0], act[0], frc[0] = d.qpos, d.qvel, d.act, d.actuator_force
            for k in range(nstep):
                d.ctrl[:] = ctrl[k]
                mujoco.mj_step(m, d)
                qpos[k + 1], qvel[k + 1], act[k + 1], frc[k + 1] = d.qpos, d.qvel, d.act, d.actuator_force
                if k % 256 == 255:
                    mje.check_finite(m, d, "pantograph (MuJoCo)")
            mje.check_finite(m, d, "pantograph (MuJoCo)")
        t = np.arange(nstep + 1) * h
        if not (np.all(np.isfinite(qpos)) and np.all(np.isfinite(qvel))):
            raise SolverError("pantograph (MuJoCo): non-finite state; reduce solver.timestep")
        yw_out = np.array([y_w(tt) for tt in t])
        return MujocoRun(t, qpos, qvel, act, yw_out, frc, mje.warnings_raised(d))

    def thetas(self, qpos: np.ndarray) -> np.ndarray:
        """(N, 3) absolute angles from (N, 3) joint positions."""
        return np.array([q_to_theta(q) for q in qpos])


def _rigid_theta(p: PantographParams, cfg: PantographConfig, y_w: float) -> np.ndarray:
    x = PantographODE(p, cfg).equilibrium(y_w)
    ode = PantographODE(p, cfg)
    return ode.theta(x[:2])
