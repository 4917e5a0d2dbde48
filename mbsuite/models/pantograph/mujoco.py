"""MuJoCo path of the pantograph: the MJCF of exactly the scene's effects, stepped by mbsuite's native core.
`run_mujoco(scene)` is the path's run, `view_model(scene)` the model `mbsuite view` shows, `mujoco_modes` MuJoCo's own
linearisation; `MujocoPantograph` holds the compiled model, its statics and its time stepping.

The model is `modelfiles.mjcf_text(p, cfg=...)` (the shipped `mjcf/pantograph.xml` is that text for Table 3-I and the
lab effects). What each effect puts into it (nothing else is built):
- gravity off: `opt.gravity = 0`;  viscous off: joint damping 0;  coulomb off: joint frictionloss 0; frictionloss
  constraints get solreffriction = (2 timestep, 1) whatever the timestep;
- contact unilateral: the `catenary` actuator's force limited to <= 0 (the wire only pushes);
- cylinder constant: a plain actuator with the affine bias Pg Ap (no state, no plugin);
- cylinder linear / nonlinear: the engine plugin `mbsuite.pantograph.cylinder` (Eqs 3.24-3.26 / 3.15-3.22
  corrected; one activation) on the base joint;
- elbow compliant: the passive engine plugin `mbsuite.pantograph.elbow` (Eq 3.13 with App. B's theta_e(theta_1));
- elbow rigid: a joint equality q2 = poly(q1), a quartic fit of pi - q1 - theta_e(q1) over the working range (soft
  equality, solref timeconst = 2 timestep; its fit error is reported by `rigid_elbow_fit`).
The plugins are C (`native/pantograph.c`); their Python twins in `python_effects.py` are the readable reference and a
test holds the two equal to 1e-12.

The ram is ctrl[catenary] = y_w(t_k + c h) during step k, with c = 1/2 for RK4 (the hold value that represents y_w over
the step to O(h^2); with c = 0 RK4 degrades to first order: F1 phase error 0.38 deg vs 6e-7 deg at 4.25 Hz, h = 5e-4 s)
and c = 0 for the Euler family, whose semi-implicit update is leapfrog-like in position with forces belonging at t_k
(lab scene, h = 5e-4 s: max phase error 0.51 deg with c = 0 vs 0.92 deg with c = 1/2 over 2-10 Hz).
"""

from __future__ import annotations

import copy
import functools
import math
from collections.abc import Callable

import mujoco
import numpy as np
from scipy.optimize import fsolve

from ...engines import core, native
from ...engines import mujoco_engine as mje
from ...errors import GeometryError, SceneError
from ...results import SimResult, assemble
from ...scenes import Scene
from ...trust.health import judge
from .equations import PantographConfig, PantographODE
from .health import excursion, step_figures
from .inputs import Start, config_of, input_of, start_of
from .linearise import modes_from_eigs
from .modelfiles import E_THETA_Q, mjcf_text, rigid_elbow_fit, theta_to_q
from .outputs import contact_losses, signals
from .params import PantographParams

#: plausibility bound on every joint angle (rad): the URDF's joint limits. A state beyond it is garbage, not physics.
JOINT_BOUND = 2.0 * math.pi
MODES_TIMESTEP = 1e-4  # MuJoCo's discrete-time linearisation is mapped to continuous time by log(mu)/h


@functools.lru_cache(maxsize=64)
def _compiled(p: PantographParams, cfg: PantographConfig, integrator: str, timestep: float,
              plugins: bool) -> mujoco.MjModel:
    if plugins:
        native.load()
    m = mje.load_model(mjcf_text(p, timestep=timestep, cfg=cfg, plugins=plugins), from_string=True)
    mje.set_integrator(m, integrator, timestep)
    return m


def compiled_model(p: PantographParams, cfg: PantographConfig, integrator: str, timestep: float,
                   plugins: bool = True) -> mujoco.MjModel:
    """A private copy of the compiled model of these parameters and effects (compiled once per process)."""
    return copy.copy(_compiled(p, cfg, integrator, float(timestep), plugins))


def thetas(qpos: np.ndarray) -> np.ndarray:
    """(N, 3) absolute angles theta = E q + (0, pi, 0) from (N, 3) joint positions."""
    return np.atleast_2d(qpos) @ E_THETA_Q.T + np.array([0.0, math.pi, 0.0])


def hold_offset(integrator: str) -> float:
    """Where in the step the ram input is sampled (module docstring): mid-step for RK4, the step start otherwise."""
    return 0.5 if integrator == "rk4" else 0.0


class MujocoPantograph:
    """The pantograph in MuJoCo for a parameter set and effects. `model`/`data` are this object's own."""

    def __init__(self, params: PantographParams | None = None, config: PantographConfig | None = None,
                 integrator: str = "implicitfast", timestep: float = 5e-4, *, plugins: bool = True):
        self.p = params or PantographParams()
        self.cfg = config or PantographConfig()
        self.integrator = integrator
        self.timestep = float(timestep)
        self.plugins = plugins  # False: the model of the Python twins, which runs with their MuJoCo callbacks
        self.model = compiled_model(self.p, self.cfg, integrator, self.timestep, plugins)
        self.data = mujoco.MjData(self.model)
        self.hold_offset = hold_offset(integrator)
        self.i_cat = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, "catenary")
        self.i_cyl = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, "cylinder")
        self._ode = PantographODE(self.p, self.cfg)
        self.xfrc: np.ndarray | None = None  # constant body forces (nbody x 6) every static state carries

    def set_uplift(self, head: float, frame: float) -> None:
        """Constant vertical forces (N, upward) at the mass centres of the bodies `head` and `upper_arm` (the
        catenary's aerodynamic uplift on the head and the frame; `PantographODE.aero_forces_theta` applies them at
        the same points), as xfrc_applied: `set_static` puts them in the data, so the integration state saved from
        it carries them into every step; the statics (`static_residual`) include them."""
        m = self.model
        x = np.zeros((m.nbody, 6))
        x[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "head"), 2] = float(head)
        x[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "upper_arm"), 2] = float(frame)
        self.xfrc = x if np.any(x) else None
        self._ode = PantographODE(self.p, self.cfg, aero=(float(head), float(frame)))

    # ------------------------------------------------------------------ statics
    def cylinder_rest(self, q1: float) -> float | None:
        """The cylinder state at rest at theta_1 = q1 (linear: P = x_p; nonlinear: supply pressure), or None."""
        if self.cfg.cylinder == "linear":
            return self._ode.cylinder_lever(q1)[0]
        if self.cfg.cylinder == "nonlinear":
            return self.p.Ps
        return None

    def set_static(self, q: np.ndarray, y_w: float, data: mujoco.MjData | None = None) -> None:
        """Put the data (default: this object's) at rest at joint positions q, ram height y_w, cylinder at rest, the
        constant body forces of `set_uplift` applied; then mj_forward."""
        d, m = (self.data if data is None else data), self.model
        mujoco.mj_resetData(m, d)
        d.qpos[:] = q
        if self.xfrc is not None:
            d.xfrc_applied[:] = self.xfrc
        d.ctrl[self.i_cat] = y_w
        if m.na:
            d.act[m.actuator_actadr[self.i_cyl]] = self.cylinder_rest(float(q[0]))
        mujoco.mj_forward(m, d)
        core.check_plugin_faults(m, d, "pantograph statics (MuJoCo)")

    def static_residual(self, q: np.ndarray, y_w: float) -> np.ndarray:
        """qfrc_passive + qfrc_actuator - qfrc_bias at rest (friction-free), from MuJoCo's own force evaluation, plus
        the generalised force of the constant body forces (`set_uplift`; mj_applyFT at each body's mass centre, as
        MuJoCo applies xfrc_applied)."""
        self.set_static(q, y_w)
        d, m = self.data, self.model
        r = d.qfrc_passive + d.qfrc_actuator - d.qfrc_bias
        if self.xfrc is not None:
            for b in np.flatnonzero(np.any(self.xfrc != 0.0, axis=1)):
                mujoco.mj_applyFT(m, d, self.xfrc[b, :3], self.xfrc[b, 3:], d.xipos[b], int(b), r)
        if self.cfg.elbow == "rigid":  # reduce onto the constraint manifold: tangent direction (1, dq2/dq1, 0)
            coef, _ = rigid_elbow_fit(self.p, self.cfg.elbow_kinematics == "exact")
            dq2 = np.polynomial.polynomial.polyval(q[0], np.polynomial.polynomial.polyder(coef))
            c = np.polynomial.polynomial.polyval(q[0], coef) - q[1]
            return np.array([r[0] + dq2 * r[1], c, r[2]])
        return r.copy()

    def equilibrium(self, y_w: float | None = None, guess: np.ndarray | None = None) -> np.ndarray:
        """Joint positions of the static equilibrium at ram height y_w (default y_op): Newton's method on MuJoCo's own
        residual (central-difference Jacobian), started from `guess` or the hand-derived equilibrium (fsolve if Newton
        does not converge from there)."""
        y_w = self.p.y_op if y_w is None else float(y_w)
        if guess is None:
            ode = self._ode
            guess = theta_to_q(ode.theta(ode.equilibrium(y_w)[:ode.nq]))
        q = np.asarray(guess, dtype=float).copy()
        for _ in range(8):
            r = self.static_residual(q, y_w)
            h = 1e-7
            Jr = np.column_stack([(self.static_residual(q + h * e, y_w) - self.static_residual(q - h * e, y_w))
                                  / (2 * h) for e in np.eye(3)])
            dq = np.linalg.solve(Jr, -r)
            q = q + dq
            if np.max(np.abs(dq)) < 1e-15:
                break
        if not np.max(np.abs(self.static_residual(q, y_w))) < 1e-8:
            q, *_ = fsolve(lambda x: self.static_residual(x, y_w), guess, xtol=1e-14, full_output=True)
        res = np.max(np.abs(self.static_residual(q, y_w)))
        if not res <= 1e-6:
            raise GeometryError(f"MuJoCo: no static equilibrium at y_w = {y_w} m (residual {res:.3g} N m)")
        return q

    # ------------------------------------------------------------------ time simulation
    def channels(self) -> list[core.Channel]:
        """What a run records: joint positions (with their plausibility bound), velocities and the cylinder state."""
        m = self.model
        ch = [core.Channel("qpos", "qpos", 0, 3, -JOINT_BOUND, JOINT_BOUND), core.Channel("qvel", "qvel", 0, 3)]
        if m.na:
            ch.append(core.Channel("act", "act", 0, m.na))
        return ch

    def ram_input(self, y_w: Callable[[np.ndarray], np.ndarray], nstep: int) -> np.ndarray:
        """ctrl[catenary] for each step: y_w at the hold instant of the integrator (module docstring)."""
        h = self.model.opt.timestep
        return np.asarray(y_w((np.arange(nstep) + self.hold_offset) * h), dtype=float).reshape(nstep, 1)

    def stepper(self, every: int = 1, what: str = "pantograph (MuJoCo)",
                data: mujoco.MjData | None = None) -> core.Stepper:
        """A native-core stepper of this model recording `channels()` every `every` steps."""
        return core.Stepper(self.model, self.data if data is None else data, self.channels(), every=every, what=what,
                            allow_callbacks=not self.plugins)

    def simulate(self, y_w: Callable[[np.ndarray], np.ndarray], t_end: float, q0: np.ndarray | None = None, *,
                 every: int = 1, what: str = "pantograph (MuJoCo)",
                 data: mujoco.MjData | None = None) -> core.Trajectory:
        """Step from the static equilibrium (or q0) at rest for t_end seconds under the ram y_w (vectorised callable
        of time), recording every `every` steps. Failures raise SolverError. With `data` (and q0) given, nothing of
        this object is touched: runs in several threads share the model."""
        nstep = int(round(t_end / self.model.opt.timestep))
        y0 = float(np.asarray(y_w(np.zeros(1))).ravel()[0])
        self.set_static(self.equilibrium(y0) if q0 is None else q0, y0, data)
        d = self.data if data is None else data
        d.time = 0.0
        return self.stepper(every, what, d).run(nstep, ctrl=self.ram_input(y_w, nstep), ctrl_idx=[self.i_cat])

    def start_q(self, start: Start, y0: float) -> np.ndarray:
        """Joint positions of a run's start (`inputs.start_of`) at ram height y0 = y_w(0): MuJoCo's own static
        equilibrium (Newton from the hand-derived one) or the thesis' FORTRAN start as it stands."""
        if start.at_rest:
            return self.equilibrium(y0, theta_to_q(start.theta0))
        return theta_to_q(start.x0[:3])


def mujoco_modes(mp: MujocoPantograph, q0: np.ndarray, y_w: float) -> list[dict]:
    """Modes from MuJoCo's own finite-difference linearisation (mjd_transitionFD) at rest at joint positions q0 under
    ram height y_w, mapped to continuous time."""
    m, d = mp.model, mp.data  # the MujocoPantograph's own copy of the model: edited here, restored after
    if m.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4:  # mjd_transitionFD does not support RK4
        raise SceneError("MuJoCo modes: mjd_transitionFD does not support the rk4 integrator; use another integrator")
    nx = 2 * m.nv + m.na
    A = np.zeros((nx, nx))
    saved = m.dof_frictionloss.copy()
    m.dof_frictionloss[:] = 0.0  # Coulomb friction is not linearisable: excluded, as in the reference linearisation
    try:
        mp.set_static(q0, y_w)
        mujoco.mjd_transitionFD(m, d, 1e-7, True, A, None, None, None)
    finally:
        m.dof_frictionloss[:] = saved
    mu = np.linalg.eigvals(A)
    lam = np.log(mu.astype(complex)) / m.opt.timestep
    return modes_from_eigs(lam)


def run_mujoco(scene: Scene) -> SimResult:
    """The MuJoCo path's run: the MJCF of exactly the scene's effects (module docstring) with the scene's integrator
    and timestep, stepped by the native core under the ram input (sine/step/static), recorded every `sample_dt`.

    Health figures: `stability_margin`, `nyquist_ratio` (sine input) and `excursion`. The first two are known before
    stepping: a setting past its bound raises `AccuracyError` without running, unless `solver.allow_inaccurate`."""
    p = scene.build_params()
    cfg = config_of(scene)
    ode = PantographODE(p, cfg)
    u = input_of(scene, p)
    s = scene.solver
    start = start_of(scene, ode, u)
    what = f"pantograph scene {scene.name or '(unnamed)'} (MuJoCo)"
    pre = step_figures(scene, p, cfg, u)
    if not s.allow_inaccurate:
        judge(pre, what=what)  # raises AccuracyError before any step is taken
    mp = MujocoPantograph(p, cfg, s.integrator, s.timestep)
    q0 = mp.start_q(start, u(0.0))
    every = max(int(round((s.sample_dt or s.timestep) / s.timestep)), 1)
    tr = mp.simulate(u, s.duration, q0, every=every, what=what)
    P = tr["act"].reshape(tr.t.size, -1)[:, 0] if mp.model.na else None
    th = thetas(tr["qpos"])
    sig = signals(ode, th, u(tr.t), P)
    ev = contact_losses(tr.t, sig["contact_force"]) if cfg.contact == "unilateral" else []
    return assemble(scene, tr.t, sig, engine="mujoco", events=ev,
                    stats={"steps": tr.steps, "integrator": s.integrator, "timestep": s.timestep,
                           "warnings": tr.warnings}, health=[*pre, excursion(th, start.theta0)])


def view_model(scene: Scene) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The `mujoco_model` hook (`mbsuite view`): the compiled MuJoCo model of exactly the scene's effects with the
    scene's integrator and timestep, and its data in the state a MuJoCo run starts from: the static equilibrium at
    the ram height y_w(0) (or the scene's `initial = "fortran"` start), at rest, cylinder at rest,
    ctrl[catenary] = y_w(0), after mj_forward."""
    p = scene.build_params()
    cfg = config_of(scene)
    u = input_of(scene, p)
    s = scene.solver
    mp = MujocoPantograph(p, cfg, s.integrator, s.timestep)
    y0 = u(0.0)
    mp.set_static(mp.start_q(start_of(scene, PantographODE(p, cfg), u), y0), y0)
    mp.data.time = 0.0
    return mp.model, mp.data
