"""Hand-derived pantograph equations of motion in plain numpy/scipy (Eppinger 1984, "An experimental and analytical
study of pantograph dynamics"), with the corrections stated in the model README applied.

Coordinates are the thesis' absolute angles theta = (theta_1, theta_2, theta_h) (Fig 3-3). With
K12 = m2 l1 d2 + mh l1 l2, K13 = mh l1 dh, K23 = mh l2 dh and the catenary force f_s = ks (y_w - y_d) on the head
(positive pulls up), Eqs 3.10-3.12 (= A.28, A.31, A.34 after errata 4, 5, 8) read M(theta) theta'' = R with

    M = [[I1+m1 d1^2+(m2+mh) l1^2, K12 cos(t1+t2),        K13 cos(t1-th)],
         [K12 cos(t1+t2),          I2+m2 d2^2+mh l2^2,    K23 cos(t2+th)],
         [K13 cos(t1-th),          K23 cos(t2+th),        Ih+mh dh^2    ]]
    R1 = K12 t2'^2 sin(t1+t2) + K13 th'^2 sin(th-t1) + cos t1 (l1 f_s - g(m1 d1+m2 l1+mh l1)) + Fc lb sin(alpha-t1)
         - Te dte/dt1
    R2 = K12 t1'^2 sin(t1+t2) + K23 th'^2 sin(t2+th) + cos t2 (l2 f_s - g(m2 d2+mh l2)) + Te
    R3 = K13 t1'^2 sin(t1-th) + K23 t2'^2 sin(t2+th) + cos th (lh f_s - g mh dh) - kh th
    Te = ke (theta_e - t2) + be (theta_e' - t2')                       (3.13-3.14, + sign per erratum 9)

plus joint friction on the relative rates w = G theta', G = [[1,0,0],[1,1,0],[0,1,1]] (base, knuckle, head; A.15):
generalised force -G^T (b w + c sgn w) (Eqs 3.6-3.8). Cylinders (7th state P): linear 3.24-3.26, nonlinear 3.15-3.22 as
corrected (errata 10-14). A rigid elbow replaces the elbow spring by theta_2 = theta_e(theta_1) (coordinates reduced to
q = (theta_1, theta_h)). Coulomb friction enters through `FrictionModes` (stuck / sliding direction per joint); the
reference path (`reference.py`) decides the modes event by event.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import fsolve

from ...errors import GeometryError, SceneError, SolverError
from .elbow import Elbow
from .params import PantographParams, critical_ratio

G_JOINTS = np.array([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 1.0]])  # joint rates w = G theta' (A.15)
JOINT_NAMES = ("base", "knuckle", "head")


@dataclass(frozen=True)
class PantographConfig:
    """The effects of a pantograph scene (see the model README)."""

    gravity: bool = True
    elbow: str = "compliant"  #: "compliant" (spring ke, 3 DOF) | "rigid" (theta_2 = theta_e(theta_1), 2 DOF)
    elbow_kinematics: str = "B6"  #: "B6" (thesis) | "exact" (chain wrap, erratum 22)
    cylinder: str = "linear"  #: "constant" (Pg Ap) | "linear" (3.24-3.26) | "nonlinear" (3.15-3.22 corrected)
    viscous: bool = True  #: joint viscous damping b1, b2, bh
    coulomb: bool | str = True  #: False | True (event-exact stick/slip) | "smooth" (c tanh(w/omega_s))
    contact: str = "bilateral"  #: "bilateral" (ram attached) | "unilateral" (push only)

    def __post_init__(self) -> None:
        checks = {"elbow": ("compliant", "rigid"), "elbow_kinematics": ("B6", "exact"),
                  "cylinder": ("constant", "linear", "nonlinear"), "contact": ("bilateral", "unilateral")}
        for k, allowed in checks.items():
            if getattr(self, k) not in allowed:
                raise SceneError(f"pantograph effect {k} = {getattr(self, k)!r}; valid: {list(allowed)}")
        if self.coulomb not in (False, True, "smooth"):
            raise SceneError(f"pantograph effect coulomb = {self.coulomb!r}; valid: [False, True, 'smooth']")


@dataclass
class FrictionModes:
    """Per-joint Coulomb state: `stuck[j]` or sliding in direction `direction[j]` (+1/-1)."""

    stuck: np.ndarray = field(default_factory=lambda: np.zeros(3, dtype=bool))
    direction: np.ndarray = field(default_factory=lambda: np.ones(3))


class PantographODE:
    """x' = f(t, x) for the pantograph: x = [q, q', P?] with q = theta (compliant elbow) or (theta_1, theta_h) (rigid).

    `y_w(t)` is the ram/wire height. Use `rhs_with_force` to drive the head with an external vertical force instead
    (catenary coupling). `aero` = (F_head, F_frame): constant vertical forces (N, upward; the catenary's aerodynamic
    uplift) at the head's and the upper arm's mass centres (`aero_forces_theta`); none by default."""

    def __init__(self, params: PantographParams | None = None, config: PantographConfig | None = None, *,
                 aero: tuple[float, float] = (0.0, 0.0), **effects):
        self.p = params or PantographParams()
        self.cfg = config or PantographConfig(**effects)
        self.aero = (float(aero[0]), float(aero[1]))
        self.elbow = Elbow(self.p, exact=self.cfg.elbow_kinematics == "exact")
        self.nq = 3 if self.cfg.elbow == "compliant" else 2
        self.has_P = self.cfg.cylinder in ("linear", "nonlinear")
        self.n = 2 * self.nq + int(self.has_P)
        p = self.p
        self.K12 = p.m2 * p.l1 * p.d2 + p.mh * p.l1 * p.l2
        self.K13 = p.mh * p.l1 * p.dh
        self.K23 = p.mh * p.l2 * p.dh
        self.g = p.g if self.cfg.gravity else 0.0
        self.b = np.array([p.b1, p.b2, p.bh]) if self.cfg.viscous else np.zeros(3)
        self.c = np.array([p.c1, p.c2, p.ch]) if self.cfg.coulomb else np.zeros(3)
        self.r_crit = critical_ratio(p.gamma)  # choking pressure ratio (Eq 3.17: 0.528 for gamma = 1.4)
        self.gas = p.cd * p.Ao * math.sqrt(2.0 * p.gamma / (p.R_gas * (p.gamma - 1.0))) / math.sqrt(p.T)

    # ---------------------------------------------------------------- kinematics
    def theta(self, q: np.ndarray) -> np.ndarray:
        """Absolute angles (theta_1, theta_2, theta_h) from the generalized coordinates (rigid elbow: theta_2 =
        theta_e(theta_1))."""
        if self.nq == 3:
            return np.asarray(q[:3], dtype=float)
        return np.array([q[0], self.elbow(q[0]).theta_e, q[1]])

    def theta_jacobian(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """J = d theta / d q and the vector Jdot q' / q'1^2 (nonzero only for the rigid elbow)."""
        if self.nq == 3:
            return np.eye(3), np.zeros(3)
        e = self.elbow(q[0])
        return np.array([[1.0, 0.0], [e.dtheta_e, 0.0], [0.0, 1.0]]), np.array(
            [0.0, self.elbow.second_derivative(q[0]), 0.0]
        )

    def contact_height(self, x: np.ndarray) -> float:
        """y_d = l1 sin t1 + l2 sin t2 + lh sin th (A.2-A.5 with the backward-pointing upper arm)."""
        t = self.theta(x[: self.nq])
        p = self.p
        return p.l1 * math.sin(t[0]) + p.l2 * math.sin(t[1]) + p.lh * math.sin(t[2])

    def contact_jacobian_theta(self, t: np.ndarray) -> np.ndarray:
        """d y_d / d theta = (l1 cos theta_1, l2 cos theta_2, lh cos theta_h)."""
        p = self.p
        return np.array([p.l1 * math.cos(t[0]), p.l2 * math.cos(t[1]), p.lh * math.cos(t[2])])

    # ---------------------------------------------------------------- hand-derived model pieces (absolute angles)
    def mass_matrix_theta(self, t: np.ndarray) -> np.ndarray:
        """Mass matrix M(theta) of Eqs 3.10-3.12 (A.28, A.31, A.34 after errata 4, 5, 8)."""
        p = self.p
        m11 = p.I1 + p.m1 * p.d1**2 + (p.m2 + p.mh) * p.l1**2
        m22 = p.I2 + p.m2 * p.d2**2 + p.mh * p.l2**2
        m33 = p.Ih + p.mh * p.dh**2
        m12 = self.K12 * math.cos(t[0] + t[1])
        m13 = self.K13 * math.cos(t[0] - t[2])
        m23 = self.K23 * math.cos(t[1] + t[2])
        return np.array([[m11, m12, m13], [m12, m22, m23], [m13, m23, m33]])

    def velocity_forces_theta(self, t: np.ndarray, td: np.ndarray) -> np.ndarray:
        """Centripetal terms of R (Eqs 3.10-3.12 right-hand sides)."""
        s12 = math.sin(t[0] + t[1])
        return np.array([
            self.K12 * td[1] ** 2 * s12 + self.K13 * td[2] ** 2 * math.sin(t[2] - t[0]),
            self.K12 * td[0] ** 2 * s12 + self.K23 * td[2] ** 2 * math.sin(t[1] + t[2]),
            self.K13 * td[0] ** 2 * math.sin(t[0] - t[2]) + self.K23 * td[1] ** 2 * math.sin(t[1] + t[2]),
        ])

    def gravity_forces_theta(self, t: np.ndarray) -> np.ndarray:
        """-dV_gravity/d theta (V from A.17)."""
        p, g = self.p, self.g
        return -g * np.array([
            (p.m1 * p.d1 + (p.m2 + p.mh) * p.l1) * math.cos(t[0]),
            (p.m2 * p.d2 + p.mh * p.l2) * math.cos(t[1]),
            p.mh * p.dh * math.cos(t[2]),
        ])

    def contact_force(self, y_w: float, y_d: float) -> float:
        """f_s on the head (positive up). Bilateral: ks (y_w - y_d). Unilateral: the wire only pushes down."""
        f = self.p.ks * (y_w - y_d)
        return min(f, 0.0) if self.cfg.contact == "unilateral" else f

    def cylinder_lever(self, t1: float) -> tuple[float, float]:
        """x_p = lb cos(alpha - t1) and d x_p / d t1 = lb sin(alpha - t1) (3.19, 3.20 with erratum 13)."""
        p = self.p
        return p.lb * math.cos(p.alpha - t1), p.lb * math.sin(p.alpha - t1)

    def cylinder_force(self, t1: float, P: float | None) -> float:
        """Cylinder force on the lever: linear 3.26, nonlinear 3.22 (P - Pa) Ap, constant Pg Ap."""
        p = self.p
        if self.cfg.cylinder == "constant":
            return p.Pg * p.Ap  # 3.23 / 3.27
        if self.cfg.cylinder == "linear":
            return p.Pg * p.Ap + p.kc * (P - self.cylinder_lever(t1)[0])  # 3.26
        return (P - p.Pa) * p.Ap  # 3.22

    def orifice_mass_flow(self, P: float) -> float:
        """Mass flow into the cylinder (kg/s), 3.17 corrected: sign(Ps - P) (erratum 12), Pu/sqrt(T) (erratum 10),
        exponent (gamma-1)/gamma (erratum 14), choked below the critical ratio (2/(gamma+1))^(gamma/(gamma-1))
        (the thesis' 0.528 for gamma = 1.4), linear in dp for Pd/Pu > r_laminar."""
        p = self.p
        Ps = p.Ps
        Pu, Pd = (Ps, P) if P <= Ps else (P, Ps)
        if Pu <= 0.0:
            raise SolverError(f"nonlinear cylinder: non-positive absolute pressure P = {P:.6g} Pa")
        r = Pd / Pu
        sgn = 1.0 if P <= Ps else -1.0
        if r > p.r_laminar:
            # laminar band: the flow at r_laminar scaled linearly with the pressure difference (keeps f Lipschitz)
            Pu_l = Ps
            dp_l = Pu_l * (1.0 - p.r_laminar)
            rl = p.r_laminar
            m_l = self.gas * Pu_l * rl ** (1.0 / p.gamma) * math.sqrt(1.0 - rl ** ((p.gamma - 1.0) / p.gamma))
            return m_l * (Ps - P) / dp_l
        r = max(r, self.r_crit)
        return sgn * self.gas * Pu * r ** (1.0 / p.gamma) * math.sqrt(1.0 - r ** ((p.gamma - 1.0) / p.gamma))

    def cylinder_rate(self, t1: float, t1d: float, P: float) -> float:
        """Rate of the cylinder state: linear 3.24-3.25, nonlinear corrected 3.18/3.21 (errata 10-14)."""
        p = self.p
        xp, dxp = self.cylinder_lever(t1)
        if self.cfg.cylinder == "linear":
            return p.kc / p.bc * (xp - P)  # 3.25
        V = p.V0 + p.Ap * xp
        if V <= 0.0:
            raise SolverError(f"nonlinear cylinder volume became non-positive (V = {V:.3g} m^3) at theta_1 = {t1:.4g}")
        dV = p.Ap * dxp * t1d
        return p.R_gas * p.T / V * self.orifice_mass_flow(P) - P / V * dV  # 3.16 with 3.17

    def elbow_torque(self, t: np.ndarray, td: np.ndarray) -> tuple[float, float]:
        """Te = ke (theta_e - t2) + be (theta_e' t1' - t2') and d theta_e / d t1 (3.13-3.14, erratum 9)."""
        e = self.elbow(t[0])
        Te = self.p.ke * (e.theta_e - t[1]) + self.p.be * (e.dtheta_e * td[0] - td[1])
        return Te, e.dtheta_e

    def aero_forces_theta(self, t: np.ndarray, R: np.ndarray) -> None:
        """Add to R the generalised forces of the aerodynamic uplift `aero` = (F_head, F_frame): vertical, F_head at
        the head's mass centre y = l1 sin t1 + l2 sin t2 + dh sin th, F_frame at the upper arm's (the frame's body
        that meets the airflow above the roof) y = l1 sin t1 + d2 sin t2, the points where the MuJoCo path applies
        them (xfrc_applied at the bodies' mass centres): F_head (l1 cos t1, l2 cos t2, dh cos th) + F_frame
        (l1 cos t1, d2 cos t2, 0)."""
        p = self.p
        fh, ff = self.aero
        R[0] += (fh + ff) * (p.l1 * math.cos(t[0]))
        R[1] += (fh * p.l2 + ff * p.d2) * math.cos(t[1])
        R[2] += fh * (p.dh * math.cos(t[2]))

    def applied_forces_theta(self, t: np.ndarray, td: np.ndarray, f_s: float, P: float | None) -> np.ndarray:
        """R without joint friction: centripetal + gravity + catenary + aerodynamic uplift + head spring + cylinder +
        elbow."""
        p = self.p
        R = self.velocity_forces_theta(t, td) + self.gravity_forces_theta(t)
        R += f_s * self.contact_jacobian_theta(t)
        if self.aero != (0.0, 0.0):
            self.aero_forces_theta(t, R)
        R[2] -= p.kh * t[2]
        R[0] += self.cylinder_force(t[0], P) * self.cylinder_lever(t[0])[1]
        if self.nq == 3:
            Te, dte = self.elbow_torque(t, td)
            R[0] -= Te * dte
            R[1] += Te
        return R

    # ---------------------------------------------------------------- reduced dynamics with friction modes
    def _dynamics(self, x: np.ndarray, f_s: float, modes: FrictionModes | None):
        """(q'', constraint torques of stuck joints, joint rates, Gq) for the given friction modes."""
        nq = self.nq
        q, qd = x[:nq], x[nq : 2 * nq]
        P = x[2 * nq] if self.has_P else None
        J, jd = self.theta_jacobian(q)
        t = self.theta(q)
        td = J @ qd
        Mt = self.mass_matrix_theta(t)
        R = self.applied_forces_theta(t, td, f_s, P) - Mt @ (jd * qd[0] ** 2)
        Gq = G_JOINTS @ J
        w = Gq @ qd
        tau = -self.b * w
        if self.cfg.coulomb == "smooth":
            tau -= self.c * np.tanh(w / self.p.omega_s)
        stuck = np.zeros(3, dtype=bool)
        if self.cfg.coulomb is True and modes is not None:
            stuck = modes.stuck & (self.c > 0)
            tau = np.where(stuck, 0.0, tau - self.c * modes.direction)
        M = J.T @ Mt @ J
        F = J.T @ R + Gq.T @ tau
        if not stuck.any():
            return np.linalg.solve(M, F), np.zeros(0), w, Gq
        Gs = Gq[stuck]
        k = Gs.shape[0]
        rhs_c = -(G_JOINTS @ (jd * qd[0] ** 2))[stuck]
        K = np.block([[M, -Gs.T], [Gs, np.zeros((k, k))]])
        sol = np.linalg.lstsq(K, np.concatenate([F, rhs_c]), rcond=None)[0]
        return sol[:nq], sol[nq:], w, Gq

    def rhs_with_force(self, t: float, x: np.ndarray, f_up: float, modes: FrictionModes | None = None) -> np.ndarray:
        """x' with a given vertical force f_up on the contact point (positive up), e.g. from a catenary model."""
        nq = self.nq
        qdd, _, _, _ = self._dynamics(x, f_up, modes)
        dx = np.empty(self.n)
        dx[:nq] = x[nq : 2 * nq]
        dx[nq : 2 * nq] = qdd
        if self.has_P:
            J, _ = self.theta_jacobian(x[:nq])
            t1d = (J @ x[nq : 2 * nq])[0]
            dx[2 * nq] = self.cylinder_rate(x[0], t1d, x[2 * nq])
        return dx

    def rhs(self, t: float, x: np.ndarray, y_w: float, modes: FrictionModes | None = None) -> np.ndarray:
        """State derivative of the smooth model at ram height y_w (Coulomb friction from the current stick/slip
        state)."""
        return self.rhs_with_force(t, x, self.contact_force(y_w, self.contact_height(x)), modes)

    def energy(self, x: np.ndarray, y_w: float) -> float:
        """Total mechanical energy T + V (A.16-A.17 with the elbow 3.13 and the cylinder as a potential):
        exact for the constant cylinder (V_c = -Pg Ap x_p) and the linear one's spring (+ kc (P - x_p)^2 / 2)."""
        p = self.p
        nq = self.nq
        q, qd = x[:nq], x[nq : 2 * nq]
        J, _ = self.theta_jacobian(q)
        t = self.theta(q)
        td = J @ qd
        T = 0.5 * td @ self.mass_matrix_theta(t) @ td
        Vg = -float(self.gravity_forces_theta(np.zeros(3)) @ np.sin(t))  # g (m d ...) sin(theta)
        y_d = self.contact_height(x)
        dy = y_w - y_d
        Vs = 0.5 * p.ks * (min(dy, 0.0) if self.cfg.contact == "unilateral" else dy) ** 2
        V = Vg + Vs + 0.5 * p.kh * t[2] ** 2
        fh, ff = self.aero  # the potential of the constant aerodynamic uplift at the two mass centres
        V -= fh * (p.l1 * math.sin(t[0]) + p.l2 * math.sin(t[1]) + p.dh * math.sin(t[2]))
        V -= ff * (p.l1 * math.sin(t[0]) + p.d2 * math.sin(t[1]))
        if nq == 3:
            V += 0.5 * p.ke * (self.elbow(t[0]).theta_e - t[1]) ** 2
        xp = self.cylinder_lever(t[0])[0]
        if self.cfg.cylinder == "nonlinear":
            raise ValueError("energy() is defined for the constant and linear cylinders (the gas is an open system)")
        V -= p.Pg * p.Ap * xp
        if self.cfg.cylinder == "linear":
            V += 0.5 * p.kc * (x[-1] - xp) ** 2
        return float(T + V)

    # ---------------------------------------------------------------- statics
    def static_residual(self, q: np.ndarray, y_w: float) -> np.ndarray:
        """Generalised static force (friction-free, cylinder at its static force Pg Ap) — zero at equilibrium."""
        t = self.theta(q)
        J, _ = self.theta_jacobian(q)
        f_s = self.contact_force(y_w, self.contact_height(np.concatenate([q, np.zeros(self.nq)])))
        p = self.p
        R = self.gravity_forces_theta(t) + f_s * self.contact_jacobian_theta(t)
        if self.aero != (0.0, 0.0):
            self.aero_forces_theta(t, R)
        R[2] -= p.kh * t[2]
        R[0] += p.Pg * p.Ap * self.cylinder_lever(t[0])[1]
        if self.nq == 3:
            Te, dte = self.elbow_torque(t, np.zeros(3))
            R[0] -= Te * dte
            R[1] += Te
        return J.T @ R

    def equilibrium(self, y_w: float | None = None) -> np.ndarray:
        """Static equilibrium state x0 (velocities zero, cylinder state at rest) at ram height y_w (default y_op)."""
        p = self.p
        y_w = p.y_op if y_w is None else float(y_w)
        reach = p.l1 + p.l2 + p.lh
        if not 0.0 < y_w < reach:
            raise GeometryError(
                f"operating height {y_w} m cannot be reached: the linkage spans 0 < y_d < l1 + l2 + lh = {reach} m"
            )
        s = (y_w - 0.0) / (p.l1 + p.l2)
        if s >= 1.0:
            raise GeometryError(
                f"operating height {y_w} m is beyond the frame's reach l1 + l2 = {p.l1 + p.l2} m (head excluded)"
            )
        th0 = math.asin(s)
        guess = np.array([th0, th0, 0.0]) if self.nq == 3 else np.array([th0, 0.0])
        if self.cfg.contact == "unilateral":
            # the guess puts y_d = y_w, on the kink of the clipped force, where fsolve stalls: start from the closed
            # contact's (smooth) equilibrium, which is this one whenever it pushes the wire (f_s <= 0)
            closed = PantographODE(p, PantographConfig(**{**self.cfg.__dict__, "contact": "bilateral"}),
                                   aero=self.aero)
            guess = closed.equilibrium(y_w)[: self.nq]
        q, info, ier, msg = fsolve(lambda q: self.static_residual(q, y_w), guess, xtol=1e-14, full_output=True)
        res = np.max(np.abs(self.static_residual(q, y_w)))
        if ier != 1 and res > 1e-8:
            raise GeometryError(f"no static equilibrium found at operating height {y_w} m ({msg.strip()})")
        q = self._newton_polish(q, y_w)
        t = self.theta(q)
        if not (0.0 < t[0] < math.pi / 2 and 0.0 < t[1] < math.pi / 2 and abs(t[2]) < math.pi / 2):
            raise GeometryError(
                f"equilibrium at operating height {y_w} m is outside the working range (theta = {t.round(4).tolist()})"
            )
        x = np.zeros(self.n)
        x[: self.nq] = q
        if self.cfg.cylinder == "linear":
            x[-1] = self.cylinder_lever(q[0])[0]
        elif self.cfg.cylinder == "nonlinear":
            x[-1] = p.Ps
        return x

    def _newton_polish(self, q: np.ndarray, y_w: float, iters: int = 8) -> np.ndarray:
        for _ in range(iters):
            r = self.static_residual(q, y_w)
            h = 1e-7
            Jr = np.column_stack([
                (self.static_residual(q + h * e, y_w) - self.static_residual(q - h * e, y_w)) / (2 * h)
                for e in np.eye(self.nq)
            ])
            dq = np.linalg.solve(Jr, -r)
            q = q + dq
            if np.max(np.abs(dq)) < 1e-15:
                break
        return q
