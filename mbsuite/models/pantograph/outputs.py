"""The pantograph's output signals, the same for both engine paths (`UNITS`, `signals`), and the contact losses of a
sampled run (`contact_losses`).

Outputs follow the thesis (Ch. 5.1): F1 = l1 sin t1, F2 = l2 sin t2, HD = lh sin th, y_d = F1 + F2 + HD, against the
ram input y_w; the contact force ks (y_d - y_w) (clipped at 0 for the unilateral contact) and the cylinder's force
(3.26 linear, 3.22 nonlinear, Pg Ap constant) and state.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .elbow import theta_e_array

if TYPE_CHECKING:
    from .equations import PantographODE

UNITS = {
    "F1": "m", "F2": "m", "HD": "m", "y_d": "m", "y_w": "m", "theta1": "rad", "theta2": "rad", "thetah": "rad",
    "theta_e": "rad", "elbow_windup": "rad", "contact_force": "N", "cylinder_force": "N", "cylinder_state": "m or Pa",
}


def signals(ode: PantographODE, theta: np.ndarray, y_w: np.ndarray, P: np.ndarray | None) -> dict[str, np.ndarray]:
    """Output signals from absolute angles theta (N, 3), ram height and cylinder state (shared by both engines;
    vectorised)."""
    p = ode.p
    F1, F2, HD = p.l1 * np.sin(theta[:, 0]), p.l2 * np.sin(theta[:, 1]), p.lh * np.sin(theta[:, 2])
    y_d = F1 + F2 + HD
    fc = p.ks * (y_d - y_w)
    if ode.cfg.contact == "unilateral":
        fc = np.maximum(fc, 0.0)
    te, _ = theta_e_array(p, theta[:, 0], ode.cfg.elbow_kinematics == "exact")
    if ode.cfg.cylinder == "constant" or P is None:
        cyl = np.full_like(F1, p.Pg * p.Ap)
    elif ode.cfg.cylinder == "linear":
        cyl = p.Pg * p.Ap + p.kc * (P - p.lb * np.cos(p.alpha - theta[:, 0]))  # 3.26
    else:
        cyl = (P - p.Pa) * p.Ap  # 3.22
    out = {"F1": F1, "F2": F2, "HD": HD, "y_d": y_d, "y_w": y_w, "theta1": theta[:, 0], "theta2": theta[:, 1],
           "thetah": theta[:, 2], "theta_e": te, "elbow_windup": te - theta[:, 1], "contact_force": fc,
           "cylinder_force": cyl}
    if P is not None:
        out["cylinder_state"] = P
    return out


def contact_losses(t: np.ndarray, fc: np.ndarray) -> list[dict]:
    """Contact-loss intervals from a sampled contact force (MuJoCo path; the reference path locates them as events)."""
    lost = fc <= 0.0
    ev, start = [], None
    for k in range(len(t)):
        if lost[k] and start is None:
            start = t[k]
        elif not lost[k] and start is not None:
            ev.append({"kind": "contact_loss", "t_start": float(start), "duration": float(t[k] - start)})
            start = None
    if start is not None:
        ev.append({"kind": "contact_loss", "t_start": float(start), "duration": None})
    return ev
