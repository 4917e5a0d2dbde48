"""Pinocchio path of the pantograph: kinematics and rigid-body terms from the URDF (or the MJCF) alone.

Pinocchio supplies M(q) (CRBA), the generalised gravity g(q), frame placements and frame Jacobians of
`contact_point` and `cylinder_lever`. The springs that URDF cannot hold are added as generalised forces through those
Jacobians: catenary f_s J_z(contact)^T, cylinder Fc J_x(lever)^T, head spring -kh theta_h (1, 1, 1), elbow E^T(...).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from scipy.optimize import fsolve

from ...engines.pinocchio_engine import frame_id, load_mjcf, load_urdf
from ...errors import GeometryError
from ...paths import mjcf_path, urdf_path
from .elbow import Elbow
from .equations import PantographConfig, PantographODE
from .modelfiles import E_THETA_Q, q_to_theta, theta_to_q, urdf_text
from .params import PantographParams

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class PinocchioPantograph:
    """Rigid-body quantities of the pantograph from Pinocchio, in joint coordinates q (see modelfiles)."""

    def __init__(self, params: PantographParams | None = None, config: PantographConfig | None = None,
                 source: str = "urdf"):
        self.p = params or PantographParams()
        self.cfg = config or PantographConfig()
        if source not in ("urdf", "mjcf"):
            raise ValueError(f"source must be 'urdf' or 'mjcf', got {source!r}")
        if self.p != PantographParams():  # the shipped files hold Table 3-I: the URDF of these parameters instead
            if source != "urdf":
                raise NotImplementedError("the Pinocchio path reads other parameters from their URDF (source='urdf')")
            self.model = pin.buildModelFromXML(urdf_text(self.p))
        elif source == "urdf":
            self.model = load_urdf(urdf_path("pantograph"))
        else:
            self.model = load_mjcf(mjcf_path("pantograph"))
        self.model.gravity.linear[:] = [0.0, 0.0, -(self.p.g if self.cfg.gravity else 0.0)]
        self.data = self.model.createData()
        self.f_contact = frame_id(self.model, "contact_point")
        self.f_lever = frame_id(self.model, "cylinder_lever")
        self.elbow = Elbow(self.p, exact=self.cfg.elbow_kinematics == "exact")

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """Joint-space mass matrix M(q) (CRBA)."""
        M = pin.crba(self.model, self.data, np.asarray(q, float))
        return np.triu(M) + np.triu(M, 1).T

    def gravity(self, q: np.ndarray) -> np.ndarray:
        """g(q) with M q'' + C q' + g = tau (so the generalised gravity force is -g)."""
        return pin.computeGeneralizedGravity(self.model, self.data, np.asarray(q, float)).copy()

    def frame_position(self, q: np.ndarray, fid: int) -> np.ndarray:
        """World position of a named frame at joint positions q."""
        pin.framesForwardKinematics(self.model, self.data, np.asarray(q, float))
        return self.data.oMf[fid].translation.copy()

    def frame_jacobian(self, q: np.ndarray, fid: int) -> np.ndarray:
        """6 x nv frame Jacobian in the LOCAL_WORLD_ALIGNED frame (linear rows first)."""
        return pin.computeFrameJacobian(self.model, self.data, np.asarray(q, float), fid, LWA).copy()

    def contact_height(self, q: np.ndarray) -> float:
        """Height y_d of the contact point at joint positions q."""
        return float(self.frame_position(q, self.f_contact)[2])

    def static_generalized_force(self, q: np.ndarray, y_w: float, closed: bool = False) -> np.ndarray:
        """Sum of static generalised forces in q (zero at equilibrium), friction-free, cylinder at Pg Ap (`closed`:
        the contact held closed, bilateral)."""
        p = self.p
        y_d = self.contact_height(q)
        f_s = p.ks * (y_w - y_d)
        if self.cfg.contact == "unilateral" and not closed:
            f_s = min(f_s, 0.0)
        Q = -self.gravity(q)
        Q += f_s * self.frame_jacobian(q, self.f_contact)[2]
        Q += p.Pg * p.Ap * self.frame_jacobian(q, self.f_lever)[0]
        th = q_to_theta(q)
        Q -= p.kh * th[2] * np.ones(3)
        e = self.elbow(th[0])
        Te = p.ke * (e.theta_e - th[1])
        Q += np.array([-Te * (e.dtheta_e + 1.0), -Te, 0.0])
        return Q

    def equilibrium(self, y_w: float | None = None) -> np.ndarray:
        """Equilibrium joint positions q (compliant elbow)."""
        if self.cfg.elbow != "compliant":
            raise NotImplementedError("the Pinocchio equilibrium is implemented for the compliant elbow")
        y_w = self.p.y_op if y_w is None else y_w
        s = y_w / (self.p.l1 + self.p.l2)
        if not 0 < s < 1:
            raise GeometryError(f"operating height {y_w} m is out of the frame's reach")
        t0 = math.asin(s)
        guess = theta_to_q(np.array([t0, t0, 0.0]))
        if self.cfg.contact == "unilateral":  # the guess lies on the kink of the clipped force: start closed
            guess = fsolve(lambda q: self.static_generalized_force(q, y_w, closed=True), guess, xtol=1e-14,
                           full_output=True)[0]
        q, _, ier, msg = fsolve(lambda q: self.static_generalized_force(q, y_w), guess, xtol=1e-14, full_output=True)
        for _ in range(6):
            r = self.static_generalized_force(q, y_w)
            h = 1e-7
            Jr = np.column_stack([(self.static_generalized_force(q + h * e, y_w)
                                   - self.static_generalized_force(q - h * e, y_w)) / (2 * h) for e in np.eye(3)])
            q = q - np.linalg.solve(Jr, r)
        if np.max(np.abs(self.static_generalized_force(q, y_w))) > 1e-6:
            raise GeometryError(f"Pinocchio: no static equilibrium at y_w = {y_w} m ({msg.strip()})")
        return q


def reference_in_q(ode: PantographODE, q: np.ndarray) -> dict[str, np.ndarray]:
    """The hand-derived M, gravity force and contact Jacobian mapped to joint coordinates q (for cross-checks)."""
    E = E_THETA_Q
    th = q_to_theta(q)
    return {
        "M": E.T @ ode.mass_matrix_theta(th) @ E,
        "gravity_force": E.T @ ode.gravity_forces_theta(th),
        "contact_jacobian": ode.contact_jacobian_theta(th) @ E,
        "contact_height": ode.contact_height(np.concatenate([th, np.zeros(3)])),
    }
