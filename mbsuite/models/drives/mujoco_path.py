"""MuJoCo path: the same rotor systems as hinge bodies, friction elements as a stick/slip state machine with real locks.

Conventions of the MJCF files (`mjcf/coupled_clutches.xml`, `mjcf/drive_step_up.xml`, `mjcf/drive_step_up_down.xml`):
* one hinge joint per rotor, named like the rotor; inertias, bearing damping and spring rates are set at run time
  from the `RotorSystem` (the files hold the topology);
* friction element X: actuator `fric_X` (on the joint for a ground element, on the fixed tendon `rel_X` = q_b - q_a
  for a clutch) carries the sliding torque while the element slips; the joint equality `lock_X` (inactive in the file)
  is switched on with `d.eq_active` while it is stuck - a real lock, not `frictionloss` (which creeps);
* spring between two rotors: fixed tendon `spring_X` with stiffness (and damping D); spring to ground: joint
  stiffness (and D added to the joint damping);
* torque source L: actuator `src_L` with gain c0 (ctrl = shape(t)) and affine velocity bias c1; a quadratic source
  (c2 != 0) has gain 1 and ctrl = c0 shape + c2 w^2 at the speed predicted at mid-step, held over the step;
* a general element (a row g over the rotors, `Friction.g`: behind an ideal planetary or gear): fixed tendon `rel_X`
  with the coefficients g (set at run time), actuator `fric_X` on it, and a *tendon* equality `lock_X` on it (its
  force acts as -g tau_e).

The step loop is mbsuite's native core (`mbsuite.engines.core.Stepper`) with the drives' state machine as its native
stepper (`native/drives.c`, packed by `native_stepper.py`): per step, at the core's forward of the current state,
sliding elements whose slip changed sign are tried for a lock (velocities of the new rigid group set to their
momentum-weighted mean, the equality activated, `mj_forward` gives the constraint torque; if it exceeds the breakaway
torque the element slides on in the other direction), stuck elements break loose when the equality force at the
current state exceeds the breakaway torque, the sliding torques are applied through the actuators, the energy terms
are accumulated and the row recorded - all in C. Python runs only the discrete controller, at its sample instants (the
core's `between`), and writes the command states into an array the C side reads. `stepper.RotorStepper` is the same
state machine in Python (the readable twin, statement for statement; `MujocoRotorSim.run(..., stepper="python")`).

Schedules and source shapes are evaluated in C: a `mbsuite.engines.signals` signal directly, any other Python callable
tabulated on the run's half-step grid (`signal_for`: exact at every instant the state machine evaluates it).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from ...engines import mujoco_engine
from ...engines.signals import Signal, Table
from ...errors import ModelFileError, ParameterError, SceneError
from .friction import MODE_NAME, CommandQueue, Controller, RefResult, RotorSystem

HINT = "reduce solver.timestep"
#: steps between two drains of the native event buffer when no controller sets the pace
CHUNK = 4096


def signal_for(fn: Callable[[float], float] | Signal, grid: np.ndarray, what: str) -> Signal:
    """A signal the native state machine can evaluate: `fn` itself if it is a `mbsuite.engines.signals` signal, else
    `fn` tabulated on `grid` (the run's instants t_k and t_k + dt/2, at which the state machine evaluates schedules
    and shapes: exact there, linear between). A non-finite value is refused, naming `what` and the time."""
    if isinstance(fn, Signal):
        return fn
    if not callable(fn):
        raise ParameterError(f"{what} must be a signal (mbsuite.engines.signals) or a callable of time, got {fn!r}")
    vals = np.array([float(fn(float(x))) for x in grid])
    bad = np.nonzero(~np.isfinite(vals))[0]
    if bad.size:
        raise ParameterError(f"{what} is not finite at t = {grid[bad[0]]:.6g} s (value {float(vals[bad[0]])!r})")
    return Table(tuple(grid.tolist()), tuple(vals.tolist()))


class MujocoRotorSim:
    """A `RotorSystem` on its MJCF topology: the compiled model with the system's numbers (see the module docstring).
    One simulation object per thread: its model and data are its own, `run` resets them."""

    def __init__(self, sys: RotorSystem, mjcf: str | Path, *, timestep: float = 1e-4, integrator: str = "rk4",
                 lock_timeconst: float | None = None):
        self.sys = sys
        self.mjcf = Path(mjcf)
        self.m = mujoco_engine.load_model(mjcf)
        mujoco_engine.set_integrator(self.m, integrator, timestep)
        m = self.m

        def idx(kind, name):
            i = mujoco.mj_name2id(m, kind, name)
            if i < 0:
                raise ModelFileError(f"{mjcf}: no {kind.name[6:].lower()} named '{name}'")
            return i

        self.jnt = [idx(mujoco.mjtObj.mjOBJ_JOINT, nm) for nm in sys.names]
        self.dof = [int(m.jnt_dofadr[j]) for j in self.jnt]
        self.qadr = [int(m.jnt_qposadr[j]) for j in self.jnt]
        if m.nv != sys.n:
            raise ModelFileError(f"{mjcf}: {m.nv} degrees of freedom, the rotor system has {sys.n}")
        for i, j in enumerate(self.jnt):
            if m.jnt_type[j] != mujoco.mjtJoint.mjJNT_HINGE:
                raise ModelFileError(f"{mjcf}: joint '{sys.names[i]}' must be a hinge")
            m.body_inertia[m.jnt_bodyid[j]] = sys.J[i]
            m.dof_damping[self.dof[i]] = sys.B[i]
            m.jnt_stiffness[j] = 0.0
        for s in sys.springs:
            if s.b < 0:
                m.jnt_stiffness[self.jnt[s.a]] = s.K
                m.dof_damping[self.dof[s.a]] += s.D
            else:
                k = idx(mujoco.mjtObj.mjOBJ_TENDON, f"spring_{s.name}")
                m.tendon_stiffness[k] = s.K
                m.tendon_damping[k] = s.D
        self.eq = [idx(mujoco.mjtObj.mjOBJ_EQUALITY, f"lock_{f.name}") for f in sys.frictions]
        self.act = [idx(mujoco.mjtObj.mjOBJ_ACTUATOR, f"fric_{f.name}") for f in sys.frictions]
        # general elements: the tendon rel_X takes the row g as its coefficients; their locks are tendon equalities
        self.general = any(f.g is not None for f in sys.frictions)
        for e, f in enumerate(sys.frictions):
            if f.g is None:
                continue
            k = idx(mujoco.mjtObj.mjOBJ_TENDON, f"rel_{f.name}")
            if m.eq_type[self.eq[e]] != mujoco.mjtEq.mjEQ_TENDON or m.eq_obj1id[self.eq[e]] != k:
                raise ModelFileError(f"{mjcf}: lock_{f.name} must be a tendon equality on rel_{f.name}")
            coef = np.zeros(sys.n)
            for w in range(m.tendon_adr[k], m.tendon_adr[k] + m.tendon_num[k]):
                i = self.jnt.index(int(m.wrap_objid[w]))
                m.wrap_prm[w] = sys.rows[e, i]
                coef[i] = sys.rows[e, i]
            if not np.array_equal(coef, sys.rows[e]):
                raise ModelFileError(f"{mjcf}: tendon rel_{f.name} does not span the rotors of its row {sys.rows[e]}")
        # lock force -> element torque: a joint equality acts +lambda on rotor a; a tendon equality g lambda
        self.eq_sign = [-1.0 if m.eq_type[k] == mujoco.mjtEq.mjEQ_TENDON else 1.0 for k in self.eq]
        # actuator sign: joint actuator acts +ctrl on rotor a; tendon (q_b - q_a) acts -ctrl on a
        self.act_sign = [1.0 if m.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT else -1.0 for a in self.act]
        self.src = [idx(mujoco.mjtObj.mjOBJ_ACTUATOR, f"src_{s.label}") for s in sys.sources]
        for s, a in zip(sys.sources, self.src, strict=True):
            m.actuator_gainprm[a, 0] = s.c0 if s.c2 == 0.0 else 1.0
            m.actuator_biasprm[a, :3] = (0.0, 0.0, s.c1)
        # a few coaxial rotors are one constraint island: island discovery only costs (5 % per step measured; the
        # results agree to round-off, 1e-11 rad/s)
        m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_ISLAND
        tc = lock_timeconst if lock_timeconst is not None else 2.0 * timestep
        for e in self.eq:
            m.eq_solref[e] = (tc, 1.0)
            m.eq_solimp[e] = (0.9999, 0.9999, 0.001, 0.5, 2.0)
        labels = sys.part_labels()
        if len(set(labels)) != len(labels):
            raise ParameterError(f"friction part labels must be unique, got {labels}")
        self.d = mujoco.MjData(m)
        # mujoco 4: run-time inertia changes reach M only after mj_setConst (it refreshes the cached constants)
        mujoco.mj_setConst(m, self.d)
        mujoco.mj_forward(m, self.d)
        Mdiag = np.diag(mujoco_engine.full_inertia(m, self.d))[self.dof]
        if not np.allclose(Mdiag, sys.J, rtol=1e-9, atol=0):
            raise ModelFileError(f"{mjcf}: joint-space inertia {Mdiag} does not match the rotor inertias {sys.J}")

    def run(self, q0, w0, t_end: float, *, controller: Controller | None = None, u0: dict[str, int] | None = None,
            sample_dt: float = 1e-3, stepper: str = "native") -> RefResult:
        """Simulate from (q0, w0) for t_end seconds, recording every `sample_dt`; the controller is sampled at its
        period (not at t_end, as the hand path). `stepper`: "native" (the C state machine in the native core) or
        "python" (its Python twin, `stepper.RotorStepper`: the same results, at Python's cost)."""
        if stepper not in ("native", "python"):
            raise ValueError(f"unknown stepper {stepper!r}; valid: ['native', 'python']")
        run = RotorRun(self, q0, w0, t_end, controller=controller, u0=u0, sample_dt=sample_dt)
        if stepper == "native":
            from .native_stepper import NativeRotorRun

            return NativeRotorRun(run).run()
        from .stepper import RotorStepper

        return RotorStepper(run).advance(t_end).result()


class RotorRun:
    """One run's set-up, used by the native stepper and its Python twin: step counts, the command states and the
    controller with its actuation queue, the schedules and shapes as signals, the initial state, and the assembly of
    the recorded rows into a `RefResult`.

    Recorded row: q (n), w (n), modes (n_elements), command states, energy terms [source, viscous per rotor, per part]
    (cumulative, before the step's work), lock-impact energy (cumulative)."""

    def __init__(self, sim: MujocoRotorSim, q0: Sequence[float], w0: Sequence[float], t_end: float, *,
                 controller: Controller | None = None, u0: dict[str, int] | None = None, sample_dt: float = 1e-3):
        self.sim = sim
        self.sys = sys = sim.sys
        self.m, self.d = m, d = sim.m, sim.d
        n = sys.n
        self.dt = dt = float(m.opt.timestep)
        q0, w0 = self._state("initial positions q0", q0, n), self._state("initial speeds w0", w0, n)
        if not (math.isfinite(t_end) and t_end >= 0):
            raise SceneError(f"duration must be a finite number >= 0 s, got {t_end!r}")
        if not (math.isfinite(sample_dt) and sample_dt > 0):
            raise SceneError(f"sample_dt must be positive, got {sample_dt!r}")
        self.nstep = int(round(t_end / dt))
        self.every = max(1, int(round(sample_dt / dt)))
        self.u = {c: 0 for c in sys.commands()}
        self.u.update(u0 or {})
        self.commands = list(self.u)
        self.u_arr = np.array([float(v) for v in self.u.values()])
        self.controller = controller
        self.period = CHUNK
        self.queue = None
        if controller is not None:
            ratio = controller.dt / dt
            if abs(ratio - round(ratio)) > 1e-9:
                raise SceneError(f"controller period {controller.dt} s is not a multiple of the MuJoCo timestep {dt} s")
            self.period = int(round(ratio))
            self.queue = CommandQueue(sys.delays, controller.dt, self.u)
        self.part_owner = [e for e, f in enumerate(sys.frictions) for _ in f.parts]
        self.labels = sys.part_labels()
        self.timevar = any(pt.schedule is not None for f in sys.frictions for pt in f.parts)
        k = np.arange(self.nstep + 1) * dt
        grid = np.empty(2 * k.size)
        grid[0::2], grid[1::2] = k, k + 0.5 * dt  # the instants t_k and t_k + dt/2 the state machine evaluates
        self.schedules = [None if pt.schedule is None else
                          signal_for(pt.schedule, grid, f"schedule of friction part '{pt.label}'")
                          for f in sys.frictions for pt in f.parts]
        self.shapes = [None if s.shape is None else signal_for(s.shape, grid, f"shape of torque source '{s.label}'")
                       for s in sys.sources]
        self.dampers = sys.dampers()
        self.e_names = (["source"] + [f"viscous_{nm}" for nm in sys.names] + self.labels
                        + [f"damper_{s.name}" for s in self.dampers])
        self.nrec = 2 * n + len(sys.frictions) + len(self.commands) + len(self.e_names) + 1
        mujoco.mj_resetData(m, d)
        for i in range(n):
            d.qpos[sim.qadr[i]] = q0[i]
            d.qvel[sim.dof[i]] = w0[i]
        self._qadr = np.array(sim.qadr, int)
        self._dof = np.array(sim.dof, int)

    @staticmethod
    def _state(what: str, x: Sequence[float], n: int) -> np.ndarray:
        a = np.asarray(x, dtype=float)
        if a.shape != (n,) or not np.all(np.isfinite(a)):
            raise ParameterError(f"{what} must be {n} finite numbers (one per rotor), got {x!r}")
        return a

    def sample(self, k: int) -> None:
        """The controller at step k (a multiple of its period): it sees the state at t_k; the commands due by then
        (quantised actuation delays) take effect for this step."""
        t = k * self.dt
        kc = k // self.period
        d = self.d
        self.queue.issue(kc, self.controller(kc, t, d.qpos[self._qadr], d.qvel[self._dof]))
        pending = self.queue.pending
        while pending and pending[0][0] <= t + 0.5 * self.dt:
            _, c, v = pending.pop(0)
            if c not in self.u:
                raise SceneError(f"the controller commands {c!r}, which no friction part of the system obeys "
                                 f"(commands: {self.commands})")
            self.u[c] = v
            self.u_arr[self.commands.index(c)] = v

    def event(self, t: float, t_step: float, e: int, old: int, new: int) -> dict[str, Any]:
        """An event record: interpolated time t, the step boundary t_step where it was applied, modes."""
        return {"t": float(t), "element": self.sys.frictions[e].name, "from": MODE_NAME[int(old)],
                "to": MODE_NAME[int(new)], "t_step": float(t_step)}

    def result(self, rows: np.ndarray, events: list[dict[str, Any]], stats: dict[str, Any]) -> RefResult:
        """The recorded rows (one per `every` steps from step 0) as a RefResult; times are step x dt."""
        n, ne = self.sys.n, len(self.sys.frictions)
        t = np.arange(rows.shape[0]) * self.every * self.dt
        c0 = 2 * n + ne
        e0 = c0 + len(self.commands)
        energy = {k: rows[:, e0 + i].copy() for i, k in enumerate(self.e_names)}
        energy["lock_impact"] = rows[:, -1].copy()
        return RefResult(t=t, q=rows[:, :n].T.copy(), w=rows[:, n:2 * n].T.copy(),
                         modes=rows[:, 2 * n:c0].T.astype(int), energy=energy, events=events,
                         u={c: rows[:, c0 + i].copy() for i, c in enumerate(self.commands)}, stats=stats)
