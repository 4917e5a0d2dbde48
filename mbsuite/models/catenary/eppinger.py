"""Thin adapters that run the Eppinger (Brecknell-Willis) pantograph of `mbsuite.models.pantograph` under the FE
catenary through the protocol of `pantographs.py`.

- `EppingerReference`: the hand-derived ODE (`PantographODE.rhs_with_force`), advanced over each catenary step by
  classical RK4 with the contact force varying linearly from f_n to f_{n+1} (the trapezoidal rule's force history).
  Coulomb friction uses the pantograph's documented smooth law (c tanh(w / omega_s)): the event-exact stick/slip of the
  reference path needs an adaptive integrator and cannot run inside a fixed-step coupled scheme.
- `EppingerMujoco`: the MuJoCo model of the same pantograph (`MujocoPantograph`), its `catenary` actuator turned into
  a pure force input (gain 1, bias 0, unlimited): each trial step restores the state, applies the step's mean contact
  force and calls `mj_step` with the catenary's time step.

Heights: the pantograph's contact-point height y_d is measured from its base pivot; the undisturbed CW level is the
operating height y_op, so the catenary sees y_d - y_op. The static uplift follows from the supply pressure Pg (the
cylinder's static force Pg Ap through the linkage), it is not set directly; `static()` returns it.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ...errors import SceneError
from .params import CatenaryParams

#: effects of the pantograph model used under the catenary (the thesis' model with its linear cylinder)
DEFAULT_EFFECTS = {"gravity": True, "elbow": "compliant", "cylinder": "linear", "viscous": True, "coulomb": "smooth",
                   "contact": "bilateral"}


def _pantograph_modules():
    try:
        from ..pantograph import params as pparams
        from ..pantograph import reference
    except ImportError as exc:  # pragma: no cover - depends on the pantograph package being present
        raise SceneError(f"the Eppinger pantograph needs mbsuite.models.pantograph ({exc})") from exc
    return pparams, reference


def _no_free_equilibrium(k_wire: float, params) -> None:
    if k_wire <= 0.0:
        from ...errors import ParameterError

        raise ParameterError(
            f"the Eppinger pantograph does not press on the wire at supply pressure Pg = {params.Pg:g} Pa (its static "
            "contact force is <= 0 with these parameters) and has no equilibrium off the wire: raise Pg "
            "(see pressure_for_static_force)")


class EppingerReference:
    """Eppinger pantograph, hand-derived ODE path (see module docstring)."""

    affine = False

    def __init__(self, overrides: dict[str, Any] | None = None, effects: dict[str, Any] | None = None,
                 name: str = "eppinger"):
        pparams, reference = _pantograph_modules()
        self.name = name
        self.params = pparams.PantographParams(**(overrides or {}))
        self.cfg = reference.PantographConfig(**{**DEFAULT_EFFECTS, **(effects or {})})
        self.ode = reference.PantographODE(self.params, self.cfg)
        self.y_op = self.params.y_op
        self.x = np.zeros(self.ode.n)
        self._pending = None

    def static(self, y_wire: float, k_wire: float) -> float:
        _no_free_equilibrium(k_wire, self.params)
        _, reference = _pantograph_modules()
        p = dataclasses.replace(self.params, ks=float(k_wire))
        ode = reference.PantographODE(p, self.cfg)
        y_w = self.y_op + y_wire
        self.x = ode.equilibrium(y_w)
        return float(k_wire * (ode.contact_height(self.x) - y_w))

    def _rk4(self, t: float, dt: float, f0: float, f1: float) -> np.ndarray:
        rhs = self.ode.rhs_with_force
        x = self.x
        fm = 0.5 * (f0 + f1)
        k1 = rhs(t, x, -f0)
        k2 = rhs(t + dt / 2, x + dt / 2 * k1, -fm)
        k3 = rhs(t + dt / 2, x + dt / 2 * k2, -fm)
        k4 = rhs(t + dt, x + dt * k3, -f1)
        return x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)

    def trial(self, t: float, dt: float, f0: float, f1: float) -> float:
        xn = self._rk4(t, dt, f0, f1)
        self._pending = xn
        return self.ode.contact_height(xn) - self.y_op

    def commit(self) -> None:
        self.x = self._pending

    def head(self) -> float:
        return self.ode.contact_height(self.x) - self.y_op

    def signals(self) -> dict[str, float]:
        t = self.ode.theta(self.x[: self.ode.nq])
        return {"head_displacement": self.head(), "theta_1": float(t[0]), "theta_2": float(t[1]),
                "theta_h": float(t[2])}


class EppingerMujoco:
    """Eppinger pantograph, MuJoCo path (see module docstring)."""

    affine = False

    def __init__(self, overrides: dict[str, Any] | None = None, effects: dict[str, Any] | None = None,
                 timestep: float = 1e-4, integrator: str = "implicitfast", name: str = "eppinger_mujoco"):
        import mujoco

        from ..pantograph import mujoco as pmj
        from ..pantograph.modelfiles import q_to_theta

        pparams, reference = _pantograph_modules()
        self.name = name
        self.mujoco = mujoco
        self.params = pparams.PantographParams(**(overrides or {}))
        eff = {**DEFAULT_EFFECTS, **(effects or {})}
        if eff["coulomb"] == "smooth":
            eff["coulomb"] = True  # MuJoCo's frictionloss is its own regularised Coulomb law
        self.cfg = reference.PantographConfig(**eff)
        self.sim = pmj.MujocoPantograph(self.params, self.cfg, integrator=integrator, timestep=timestep)
        self.m, self.d = self.sim.model, self.sim.data
        self.q_to_theta = q_to_theta
        self.y_op = self.params.y_op
        self._cbs = self.sim.callback_set()
        self.i_cat = self.sim.i_cat
        self.site_c = mujoco.mj_name2id(self.m, mujoco.mjtObj.mjOBJ_SITE, "contact_point")
        self.site_o = mujoco.mj_name2id(self.m, mujoco.mjtObj.mjOBJ_SITE, "origin")
        self._spec = mujoco.mjtState.mjSTATE_INTEGRATION
        self._state = None
        self._pending = None
        self._kind = "force"

    def _as_force_input(self) -> None:
        m, i = self.m, self.i_cat
        m.actuator_gainprm[i, :] = 0.0
        m.actuator_gainprm[i, 0] = 1.0
        m.actuator_biasprm[i, :] = 0.0
        m.actuator_forcelimited[i] = 0
        m.actuator_ctrllimited[i] = 0

    def _height(self) -> float:
        self.mujoco.mj_kinematics(self.m, self.d)
        return float(self.d.site_xpos[self.site_c, 2] - self.d.site_xpos[self.site_o, 2]) - self.y_op

    def _save(self) -> np.ndarray:
        n = self.mujoco.mj_stateSize(self.m, self._spec)
        s = np.empty(n)
        self.mujoco.mj_getState(self.m, self.d, s, self._spec)
        return s

    def static(self, y_wire: float, k_wire: float) -> float:
        from ...engines import mujoco_engine as mje

        _no_free_equilibrium(k_wire, self.params)
        # static equilibrium with the catenary actuator as the shipped spring of stiffness k_wire at the wire height
        m, i = self.m, self.i_cat
        ks = float(self.params.ks)
        m.actuator_gainprm[i, 0] *= k_wire / ks
        m.actuator_biasprm[i, 1] *= k_wire / ks
        y_w = self.y_op + y_wire
        q = self.sim.equilibrium(y_w)
        with mje.callbacks(**self._cbs):
            self.sim._set_static(q, y_w)
        f_up = float(self.d.actuator_force[i])
        self._as_force_input()
        self.d.ctrl[i] = -f_up
        self.d.qacc_warmstart[:] = 0.0
        self._state = self._save()
        return -f_up

    def trial(self, t: float, dt: float, f0: float, f1: float) -> float:
        from ...engines import mujoco_engine as mje

        mj, m, d = self.mujoco, self.m, self.d
        mj.mj_setState(m, d, self._state, self._spec)
        d.ctrl[self.i_cat] = -0.5 * (f0 + f1)  # the step's mean contact force (trapezoidal force history)
        with mje.callbacks(**self._cbs):
            mj.mj_step(m, d)
        y = self._height()
        self._pending = self._save()
        return y

    def commit(self) -> None:
        self._state = self._pending
        if not np.all(np.isfinite(self._state)):
            from ...errors import SolverError

            raise SolverError("Eppinger pantograph (MuJoCo): non-finite state; reduce solver.timestep")

    def head(self) -> float:
        self.mujoco.mj_setState(self.m, self.d, self._state, self._spec)
        return self._height()

    def engine_warnings(self) -> dict[str, int]:
        """MuJoCo warning counters raised during the run (empty if none)."""
        from ...engines import mujoco_engine as mje

        return mje.warnings_raised(self.d)

    def signals(self) -> dict[str, float]:
        self.mujoco.mj_setState(self.m, self.d, self._state, self._spec)
        th = self.q_to_theta(np.array(self.d.qpos[:3]))
        return {"head_displacement": self._height(), "theta_1": float(th[0]), "theta_2": float(th[1]),
                "theta_h": float(th[2])}


def make_eppinger(kind: str, p: CatenaryParams, overrides: dict[str, Any], dt: float = 1e-4):
    """The adapter named by the scene (`eppinger` = hand-derived ODE, `eppinger_mujoco` = MuJoCo)."""
    if kind == "eppinger":
        return EppingerReference(overrides)
    if kind == "eppinger_mujoco":
        return EppingerMujoco(overrides, timestep=dt)
    raise SceneError(f"unknown Eppinger pantograph path {kind!r}")


def static_force(overrides: dict[str, Any] | None = None, k_contact: float = 5.0e4) -> float:
    """Static contact force (N) of the Eppinger pantograph at its operating height on an undisturbed rigid wire."""
    return EppingerReference(overrides).static(0.0, k_contact)


def pressure_for_static_force(target: float, overrides: dict[str, Any] | None = None, k_contact: float = 5.0e4,
                              tol: float = 1e-9) -> float:
    """Supply gauge pressure Pg (Pa) that gives the static contact force `target` (N), by the secant method (the
    static force is nearly affine in Pg: the cylinder's static force is Pg Ap)."""
    from ...errors import ParameterError

    ov = dict(overrides or {})
    p0 = ov.get("Pg", 710185.0)
    p1 = 1.1 * p0
    f0 = static_force({**ov, "Pg": p0}, k_contact) - target
    f1 = static_force({**ov, "Pg": p1}, k_contact) - target
    for _ in range(30):
        if abs(f1) < tol * max(1.0, abs(target)):
            return p1
        if f1 == f0:
            break
        p0, p1, f0 = p1, p1 - f1 * (p1 - p0) / (f1 - f0), f1
        if p1 <= 0:
            break
        f1 = static_force({**ov, "Pg": p1}, k_contact) - target
    raise ParameterError(f"no supply pressure gives a static contact force of {target} N for {ov}")
