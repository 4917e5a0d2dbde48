"""The pantograph's effects in Python: the readable reference of the engine plugins in `native/pantograph.c`.

`PythonEffects(p, cfg)` gives MuJoCo callbacks (`act_dyn` for the cylinder, `passive` for the elbow spring) for the
model `mjcf_text(..., plugins=False)`, in which the cylinder is a `user`-dynamics actuator on the lever site (force =
gain * act + bias) and the elbow spring is left out. The same equations as the plugins, written for reading: a test
runs every scene both ways and holds them equal to 1e-12. MuJoCo callbacks are process-global and hold the GIL;
install them only through `mbsuite.engines.mujoco_engine.callbacks`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import mujoco

from .elbow import Elbow
from .equations import PantographConfig, PantographODE
from .params import PantographParams


class PythonEffects:
    """The cylinder's state derivative and the elbow torque as MuJoCo callbacks (module docstring)."""

    def __init__(self, p: PantographParams, cfg: PantographConfig):
        self.p, self.cfg = p, cfg
        self.elbow = Elbow(p, exact=cfg.elbow_kinematics == "exact")
        self._gas = PantographODE(p, PantographConfig(cylinder="nonlinear"))  # orifice law (3.17 corrected)

    def callbacks(self) -> dict[str, Callable | None]:
        """The callbacks the effects need (None where the effect is off)."""
        return {"passive": self.elbow_passive if self.cfg.elbow == "compliant" else None,
                "act_dyn": self.cylinder_dyn if self.cfg.cylinder in ("linear", "nonlinear") else None}

    def elbow_passive(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        """Eq 3.13 mapped to the joints: Q = E^T (-Te dte/dt1, Te, 0), theta_2 = pi - q1 - q2."""
        qpos = d.qpos.tolist()
        e = self.elbow(qpos[0])
        te, dte = e.theta_e, e.dtheta_e
        Te = self.p.ke * (te - math.pi + qpos[0] + qpos[1])
        if self.p.be:
            qvel = d.qvel.tolist()
            Te += self.p.be * (dte * qvel[0] + qvel[0] + qvel[1])
        f = d.qfrc_passive
        f[0] -= Te * (dte + 1.0)
        f[1] -= Te

    def cylinder_dyn(self, m: mujoco.MjModel, d: mujoco.MjData, i: int) -> float:
        """P' of the linear (3.25) or nonlinear (3.16-3.17 corrected) cylinder; x_p is the lever site's x."""
        P = d.act[m.actuator_actadr[i]]
        xp = d.actuator_length[i]
        p = self.p
        if self.cfg.cylinder == "linear":
            return p.kc / p.bc * (xp - P)
        V = p.V0 + p.Ap * xp
        return p.R_gas * p.T / V * self._gas.orifice_mass_flow(P) - P / V * p.Ap * d.actuator_velocity[i]
