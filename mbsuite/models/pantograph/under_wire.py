"""This pantograph under a catenary: two adapters that implement the catenary's pantograph protocol, one per engine
path (`PATHS`, keyed like the model's path table `SPEC.paths`), made by `make(params, effects, engine, timestep)` (the
model's `ModelSpec.under_wire`).

The protocol (defined by the catenary, met here by structure only; this module imports no catenary code). The
catenary advances its wire with the trapezoidal rule, so over one step of length dt the contact force f (>= 0 pushes
the head down and the wire up) varies linearly from f0 to f1:
- `static(y_wire, k_wire) -> f`: static equilibrium pressing on a wire at height y_wire (m, from the undisturbed
  contact wire level) through a spring k_wire (N/m); returns the static contact force (N);
- `trial(t, dt, f0, f1) -> y`: contact-point height (m, same datum) at t + dt under that force history, state
  unchanged; `commit()` accepts the last trial;
- `head() -> y`, `signals() -> {name: value}`; `affine = False` (the catenary couples by a secant iteration on f1);
  `engine` names the path; `engine_warnings()` (MuJoCo path) the MuJoCo warnings raised;
- `aerodynamic(head, frame)`: constant vertical forces (N, upward; the catenary's aerodynamic uplift, F = c v^2) on the
  head body at its mass centre and on the frame's upper arm at its mass centre, before `static` (whose equilibrium
  then includes them). Both paths apply them at the same points: the hand-derived ODE by their generalised forces
  (`PantographODE.aero_forces_theta`), MuJoCo as xfrc_applied on the bodies `head` and `upper_arm` (applied at a
  body's mass centre), carried by the saved integration state into every step.

Heights: the contact-point height y_d is measured from the base pivot; the undisturbed wire is at the operating height
y_op, so the catenary sees y_d - y_op. The static uplift is not a parameter: it follows from the supply pressure Pg (the
cylinder's static force Pg Ap through the linkage); `static_force` / `pressure_for_static_force` relate the two.

Effects are this model's (`SPEC.effects`, defaults for the ones not given). Under the wire the head-wire contact is the
catenary's penalty spring and its own `contact` law (unilateral or bilateral); the pantograph's ram spring ks and its
`contact` effect play no part (both adapters use the spring as a pure force input).

- `EppingerReference` ("reference"): the hand-derived ODE `PantographODE.rhs_with_force`, advanced over each catenary
  step by classical RK4 with the force varying linearly f0 -> f1 (the catenary's force history). Coulomb friction uses
  the model's smooth law c tanh(w / omega_s) (`coulomb = true` is read as "smooth"): the event-exact stick/slip of the
  reference path locates each stick/slip event with an adaptive integrator, which a fixed-step coupled scheme whose
  step is set by the catenary cannot do (an event inside a step would be missed or would need the whole wire rolled
  back); the smooth law is the model's own regularisation and RK4 at the catenary's dt resolves its time scale.
- `EppingerMujoco` ("mujoco"): the MuJoCo model of exactly these effects (`MujocoPantograph`: the cylinder and the
  elbow spring are engine plugins, nothing in Python), its `catenary` actuator turned into a pure force input (gain 1,
  bias 0, unlimited). A trial restores the committed state (`mj_setState`), writes the step's mean contact force
  (f0 + f1)/2 into the actuator's ctrl and advances one step of length dt through mbsuite's native core
  (`core.Stepper.run(1)`, with every check of the core at that step: MuJoCo's warnings of a broken state, plugin
  faults, finite state); the committed state is saved with `mj_getState` (the integration state: time, qpos, qvel,
  act, ctrl, warm start).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np

from ...engines import core
from ...engines.mujoco_engine import warnings_raised
from ...errors import ParameterError, SceneError, SolverError
from .equations import PantographConfig, PantographODE
from .modelfiles import q_to_theta
from .mujoco import MujocoPantograph
from .params import PantographParams


def config(effects: dict[str, Any] | None, coulomb_law: Callable[[bool | str], bool | str]) -> PantographConfig:
    """The pantograph's effects under the wire for an engine path (module docstring): the model's defaults for the
    effects not given, the ram contact bilateral (the catenary owns the contact law), Coulomb friction as the path can
    integrate it at a fixed step (`coulomb_law` of the path's adapter)."""
    eff = {**dataclasses.asdict(PantographConfig()), **(effects or {})}
    eff["contact"] = "bilateral"
    eff["coulomb"] = coulomb_law(eff["coulomb"])
    return PantographConfig(**eff)


def _no_free_equilibrium(k_wire: float, params: PantographParams) -> None:
    if k_wire <= 0.0:
        raise ParameterError(
            f"the Eppinger pantograph does not press on the wire at supply pressure Pg = {params.Pg:g} Pa (its static "
            "contact force is <= 0 with these parameters) and has no equilibrium off the wire: raise Pg "
            "(see pressure_for_static_force)")


class EppingerReference:
    """Eppinger pantograph under the wire, hand-derived ODE path (module docstring)."""

    affine = False
    engine = "reference"

    def __init__(self, params: dict[str, Any] | None = None, effects: dict[str, Any] | None = None,
                 name: str = "eppinger"):
        self.name = name
        self.params = PantographParams(**(params or {}))
        self.cfg = config(effects, self.coulomb_law)
        self.aero = (0.0, 0.0)
        self.ode = PantographODE(self.params, self.cfg)
        self.y_op = self.params.y_op
        self.x = np.zeros(self.ode.n)
        self._pending = None

    def aerodynamic(self, head: float, frame: float) -> None:
        """The constant aerodynamic uplift (N, upward) at the head's and the upper arm's mass centres (module
        docstring); before `static`."""
        self.aero = (float(head), float(frame))
        self.ode = PantographODE(self.params, self.cfg, aero=self.aero)

    @classmethod
    def build(cls, params: dict[str, Any], effects: dict[str, Any], timestep: float) -> EppingerReference:
        """`make`'s constructor: RK4 takes each step the catenary asks for, whatever its length."""
        return cls(params, effects)

    @staticmethod
    def coulomb_law(coulomb: bool | str) -> bool | str:
        """Coulomb friction at the catenary's fixed step: `true` is read as the smooth law (module docstring)."""
        return "smooth" if coulomb is True else coulomb

    def static(self, y_wire: float, k_wire: float) -> float:
        """Static equilibrium under the wire at height y_w; returns the contact force."""
        _no_free_equilibrium(k_wire, self.params)
        ode = PantographODE(dataclasses.replace(self.params, ks=float(k_wire)), self.cfg, aero=self.aero)
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
        """Contact-point height (m, from the undisturbed wire) after one RK4 step of dt under the force f0 -> f1,
        pending until `commit`."""
        xn = self._rk4(t, dt, f0, f1)
        self._pending = xn
        return self.ode.contact_height(xn) - self.y_op

    def commit(self) -> None:
        """Take the last trial step."""
        self.x = self._pending

    def head(self) -> float:
        """Current contact-point height y_d."""
        return self.ode.contact_height(self.x) - self.y_op

    def signals(self) -> dict[str, float]:
        """The pantograph's own signals at the current state."""
        t = self.ode.theta(self.x[: self.ode.nq])
        return {"head_displacement": self.head(), "theta_1": float(t[0]), "theta_2": float(t[1]),
                "theta_h": float(t[2])}

    def native(self, dt: float) -> ReferenceNativePort:
        """This pantograph as a one-port of the catenary's compiled loop: its ODE and RK4 step in C
        (`native/ode_port.c`)."""
        return ReferenceNativePort(self)


class ReferenceNativePort:
    """An `EppingerReference` as its C one-port (`ode_port.OdePort`): the same RK4 step of the same ODE, outputs the
    head height and the three absolute angles."""

    def __init__(self, pan: EppingerReference):
        from .ode_port import OdePort

        self.pan = pan
        self._op = OdePort(pan)
        self.port = self._op.port

    def load(self) -> None:
        """The pantograph's committed state into the port."""
        self._op.push(self.pan)

    def pull(self) -> None:
        """The port's committed state back into the pantograph."""
        self._op.pull(self.pan)

    def signals(self, rows: np.ndarray) -> dict[str, np.ndarray]:
        """Recorded output rows as the pantograph's signals."""
        return self._op.signals(rows)

    def failure(self, code: int) -> str:
        """The words of the failed trial."""
        return self._op.failure(code)


class EppingerMujoco:
    """Eppinger pantograph under the wire, MuJoCo path (module docstring). `timestep` must be the catenary's."""

    affine = False
    engine = "mujoco"

    def __init__(self, params: dict[str, Any] | None = None, effects: dict[str, Any] | None = None,
                 timestep: float = 1e-4, integrator: str = "implicitfast", name: str = "eppinger"):
        self.name = name
        self.params = PantographParams(**(params or {}))
        self.cfg = config(effects, self.coulomb_law)
        self.sim = MujocoPantograph(self.params, self.cfg, integrator=integrator, timestep=timestep)
        m, d = self.m, self.d = self.sim.model, self.sim.data
        self.y_op = self.params.y_op
        self.timestep = float(m.opt.timestep)
        i = self.i_cat = self.sim.i_cat
        # the shipped ram spring, restored by every static() (which rescales it) before the force input replaces it
        self._spring = (m.actuator_gainprm[i].copy(), m.actuator_biasprm[i].copy(), int(m.actuator_forcelimited[i]),
                        int(m.actuator_ctrllimited[i]))
        self.site_c = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "contact_point")
        self.site_o = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "origin")
        # one step per call, every check of the core at that step (check_every=1)
        self.stepper = core.Stepper(m, d, (), check_every=1, what="Eppinger pantograph under the catenary (MuJoCo)",
                                    hint="reduce solver.timestep")
        self._spec = mujoco.mjtState.mjSTATE_INTEGRATION
        n = mujoco.mj_stateSize(m, self._spec)
        self._state = np.empty(n)
        self._pending = np.empty(n)
        self._holds = None  # which state the data holds with its kinematics: "committed", "trial" or None

    @classmethod
    def build(cls, params: dict[str, Any], effects: dict[str, Any], timestep: float) -> EppingerMujoco:
        """`make`'s constructor: the model is built with the catenary's time step."""
        return cls(params, effects, timestep=timestep)

    @staticmethod
    def coulomb_law(coulomb: bool | str) -> bool | str:
        """MuJoCo's frictionloss is its own regularised Coulomb law: `smooth` is read as `true`."""
        return True if coulomb == "smooth" else coulomb

    def _height(self) -> float:
        mujoco.mj_kinematics(self.m, self.d)
        xpos = self.d.site_xpos
        return float(xpos[self.site_c, 2] - xpos[self.site_o, 2]) - self.y_op

    def _as_force_input(self) -> None:
        m, i = self.m, self.i_cat
        m.actuator_gainprm[i, :] = 0.0
        m.actuator_gainprm[i, 0] = 1.0
        m.actuator_biasprm[i, :] = 0.0
        m.actuator_forcelimited[i] = 0
        m.actuator_ctrllimited[i] = 0

    def aerodynamic(self, head: float, frame: float) -> None:
        """The constant aerodynamic uplift (N, upward) as xfrc_applied at the head's and the upper arm's mass centres
        (module docstring; `MujocoPantograph.set_uplift`); before `static`, whose saved state carries it."""
        self.sim.set_uplift(head, frame)

    def static(self, y_wire: float, k_wire: float) -> float:
        """Static equilibrium under the wire at height y_w; returns the contact force."""
        _no_free_equilibrium(k_wire, self.params)
        m, d, i = self.m, self.d, self.i_cat
        gain, bias, flim, clim = self._spring
        m.actuator_gainprm[i], m.actuator_biasprm[i] = gain, bias
        m.actuator_forcelimited[i], m.actuator_ctrllimited[i] = flim, clim
        # static equilibrium on the ram spring rescaled to the stiffness k_wire, at the wire height
        scale = k_wire / float(self.params.ks)
        m.actuator_gainprm[i, 0] *= scale
        m.actuator_biasprm[i, 1] *= scale
        y_w = self.y_op + y_wire
        self.sim.set_static(self.sim.equilibrium(y_w), y_w)
        f_up = float(d.actuator_force[i])
        self._as_force_input()
        d.ctrl[i] = -f_up
        d.qacc_warmstart[:] = 0.0
        mujoco.mj_getState(m, d, self._state, self._spec)
        self._holds = None
        return -f_up

    def trial(self, t: float, dt: float, f0: float, f1: float) -> float:
        """Contact-point height (m, from the undisturbed wire) after one MuJoCo step of dt under the mean force
        (f0 + f1)/2, pending until `commit`."""
        if dt != self.timestep:
            raise SolverError(f"Eppinger pantograph (MuJoCo) built for time step {self.timestep:g} s, asked to step "
                              f"{dt:g} s: build it with the catenary's time step")
        mujoco.mj_setState(self.m, self.d, self._state, self._spec)
        # the step's mean contact force (trapezoidal force history), held in the data's ctrl during the one step
        self.d.ctrl[self.i_cat] = -0.5 * (f0 + f1)
        self.stepper.run(1, record=False)
        y = self._height()
        mujoco.mj_getState(self.m, self.d, self._pending, self._spec)
        self._holds = "trial"
        return y

    def commit(self) -> None:
        """Take the last trial step."""
        self._state, self._pending = self._pending, self._state
        # the data still holds the last trial (now committed) unless head()/signals() restored the old state since
        self._holds = "committed" if self._holds == "trial" else None

    def _sync(self) -> None:
        if self._holds != "committed":
            mujoco.mj_setState(self.m, self.d, self._state, self._spec)
            mujoco.mj_kinematics(self.m, self.d)
            self._holds = "committed"

    def head(self) -> float:
        """Current contact-point height y_d."""
        self._sync()
        xpos = self.d.site_xpos
        return float(xpos[self.site_c, 2] - xpos[self.site_o, 2]) - self.y_op

    def signals(self) -> dict[str, float]:
        """The pantograph's own signals at the current state."""
        self._sync()
        th = q_to_theta(np.array(self.d.qpos[:3]))
        return {"head_displacement": self.head(), "theta_1": float(th[0]), "theta_2": float(th[1]),
                "theta_h": float(th[2])}

    def engine_warnings(self) -> dict[str, int]:
        """MuJoCo warning counters raised during the run (empty if none)."""
        return warnings_raised(self.d)

    def native(self, dt: float) -> MujocoNativePort:
        """This pantograph as the MuJoCo one-port of the catenary's compiled loop (`engines/native/oneport.c`)."""
        if dt != self.timestep:
            raise SolverError(f"Eppinger pantograph (MuJoCo) built for time step {self.timestep:g} s, asked to step "
                              f"{dt:g} s: build it with the catenary's time step")
        return MujocoNativePort(self)


class MujocoNativePort:
    """An `EppingerMujoco` as the MuJoCo one-port: its model and data, the core's job of its stepper (one checked
    step per trial), the contact point's height above the origin less y_op, ctrl = -(f0 + f1)/2 on the `catenary`
    actuator (the force input), outputs the height and q1 .. q3 (`signals` turns them into the absolute angles)."""

    names = ("head_displacement", "theta_1", "theta_2", "theta_h")

    def __init__(self, pan: EppingerMujoco):
        from ...engines.native.oneport import MujocoPort

        self.pan = pan
        self._mp = MujocoPort(pan.m, pan.d, pan.stepper._job, pan.i_cat, pan.site_c, pan.site_o, -1.0, pan.y_op,
                              pan._state, nq_out=3)
        self.port = self._mp.port

    def load(self) -> None:
        """The pantograph's committed state into the port."""
        self._mp.set_state(self.pan._state)

    def pull(self) -> None:
        """The port's committed state back into the pantograph (its data restored at the next read)."""
        self.pan._state[:] = self._mp.state()
        self.pan._holds = None

    def signals(self, rows: np.ndarray) -> dict[str, np.ndarray]:
        """Recorded output rows (height, q1, q2, q3) as the pantograph's signals."""
        th = q_to_theta(rows[:, 1:4].T)
        return {"head_displacement": rows[:, 0].copy(), "theta_1": th[0], "theta_2": th[1], "theta_h": th[2]}

    def failure(self, code: int) -> str:
        """The words of the failed MuJoCo step (the core's job holds its status)."""
        return str(self.pan.stepper._error(self.pan.stepper._job))


#: the pantograph under the wire on each engine path, keyed like the model's path table `SPEC.paths`
PATHS: dict[str, type[EppingerReference] | type[EppingerMujoco]] = {"reference": EppingerReference,
                                                                      "mujoco": EppingerMujoco}


def make(params: dict[str, Any], effects: dict[str, Any], engine: str, timestep: float):
    """The Eppinger pantograph under the wire on an engine path: `params` overrides `PantographParams`, `effects` are
    this model's (defaults for the rest), `timestep` the catenary's step (s)."""
    if engine not in PATHS:
        raise SceneError(f"the pantograph has no engine path {engine!r} under the wire; valid: {list(PATHS)}")
    return PATHS[engine].build(params, effects, timestep)


def static_force(params: dict[str, Any] | None = None, k_contact: float = 5.0e4) -> float:
    """Static contact force (N) of the Eppinger pantograph at its operating height on an undisturbed rigid wire
    (contact spring k_contact, N/m)."""
    return EppingerReference(params).static(0.0, k_contact)


def pressure_for_static_force(target: float, params: dict[str, Any] | None = None, k_contact: float = 5.0e4,
                              tol: float = 1e-9) -> float:
    """Supply gauge pressure Pg (Pa) that gives the static contact force `target` (N), by the secant method (the
    static force is nearly affine in Pg: the cylinder's static force is Pg Ap)."""
    ov = dict(params or {})
    p0 = ov.get("Pg", PantographParams().Pg)
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
