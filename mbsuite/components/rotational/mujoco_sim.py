"""The MuJoCo path of a rotor system (`interfaces.RotorSystem`): hinge bodies, friction elements as a stick/slip state
machine with real locks.

Conventions of the MJCF files a model hands in (one file per rotor topology):
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

The step loop is mbsuite's native core (`mbsuite.engines.core.Stepper`) with the rotor state machine as its native
stepper (`native/rotors.c`, packed by `native_stepper.py`): per step, at the core's forward of the current state,
sliding elements whose slip changed sign are tried for a lock (velocities of the new rigid group set to their
momentum-weighted mean, the equality activated, `mj_forward` gives the constraint torque; if it exceeds the breakaway
torque the element slides on in the other direction), stuck elements break loose when the equality force at the
current state exceeds the breakaway torque, the sliding torques are applied through the actuators, the energy terms
are accumulated and the row recorded - all in C. Python runs only the discrete controller, at its sample instants (the
core's `between`), and writes the command states into an array the C side reads. `stepper.RotorStepper` is the same
state machine in Python (the readable twin, statement for statement; `MujocoRotorSim.run(..., stepper="python")`).

Schedules and source shapes are evaluated in C: a `mbsuite.engines.inputs` signal directly, any other Python callable
tabulated on the run's half-step grid (`signal_for`: exact at every instant the state machine evaluates it).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from ...engines import mujoco_engine
from ...errors import ModelFileError, ParameterError
from .commands import Controller
from .interfaces import RefResult, RotorSystem
from .native_stepper import NativeRotorRun
from .rotor_run import RotorRun
from .stepper import RotorStepper


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
            return NativeRotorRun(run).run()
        return RotorStepper(run).run(t_end).result()
