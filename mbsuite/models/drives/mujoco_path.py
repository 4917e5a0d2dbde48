"""MuJoCo path: the same rotor systems as hinge bodies, friction elements as a stick/slip state machine with real locks.

Conventions of the MJCF files (`mjcf/coupled_clutches.xml`, `mjcf/drive_step_up.xml`, `mjcf/drive_step_up_down.xml`):
* one hinge joint per rotor, named like the rotor; inertias, bearing damping and spring rates are set at run time
  from the `RotorSystem` (the files hold the topology);
* friction element X: actuator `fric_X` (on the joint for a ground element, on the fixed tendon `rel_X` = q_b - q_a
  for a clutch) carries the sliding torque while the element slips; the joint equality `lock_X` (inactive in the file)
  is switched on with `d.eq_active` while it is stuck - a real lock, not `frictionloss` (which creeps);
* spring between two rotors: fixed tendon `spring_X` with stiffness; spring to ground: joint stiffness;
* torque source L: actuator `src_L` with gain c0 (ctrl = shape(t)) and affine velocity bias c1.

Per step: sliding elements whose slip changed sign are tried for a lock (velocities of the new rigid group are set to
their momentum-weighted mean, the equality is activated, `mj_forward` gives the constraint torque; if it exceeds the
breakaway torque the element slides on in the other direction), stuck elements break loose when the equality force at
the current state (an `mj_forward` at the start of the step) exceeds the breakaway torque, and the sliding torques are
applied through the actuators. The controller is sampled at its period, not at t_end (as the hand path).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from ...engines import mujoco_engine
from ...errors import ModelFileError, SceneError
from .friction import BWD, FREE, FWD, MODE_NAME, STUCK, CommandQueue, Controller, RefResult, RotorSystem


class MujocoRotorSim:
    def __init__(self, sys: RotorSystem, mjcf: str | Path, *, timestep: float = 1e-4, integrator: str = "rk4",
                 lock_timeconst: float | None = None):
        self.sys = sys
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
            m.body_inertia[m.jnt_bodyid[j]] = sys.J[i]
            m.dof_damping[self.dof[i]] = sys.B[i]
            m.jnt_stiffness[j] = 0.0
        for s in sys.springs:
            if s.b < 0:
                m.jnt_stiffness[self.jnt[s.a]] = s.K
            else:
                m.tendon_stiffness[idx(mujoco.mjtObj.mjOBJ_TENDON, f"spring_{s.name}")] = s.K
        self.eq = [idx(mujoco.mjtObj.mjOBJ_EQUALITY, f"lock_{f.name}") for f in sys.frictions]
        self.act = [idx(mujoco.mjtObj.mjOBJ_ACTUATOR, f"fric_{f.name}") for f in sys.frictions]
        # actuator sign: joint actuator acts +ctrl on rotor a; tendon (q_b - q_a) acts -ctrl on a
        self.act_sign = [1.0 if m.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT else -1.0 for a in self.act]
        self.src = [idx(mujoco.mjtObj.mjOBJ_ACTUATOR, f"src_{s.label}") for s in sys.sources]
        for s, a in zip(sys.sources, self.src, strict=True):
            m.actuator_gainprm[a, 0] = s.c0
            m.actuator_biasprm[a, :3] = (0.0, 0.0, s.c1)
        tc = lock_timeconst if lock_timeconst is not None else 2.0 * timestep
        for e in self.eq:
            m.eq_solref[e] = (tc, 1.0)
            m.eq_solimp[e] = (0.9999, 0.9999, 0.001, 0.5, 2.0)
        self.d = mujoco.MjData(m)
        self._dof_idx = np.array(self.dof, int)
        self._qadr_idx = np.array(self.qadr, int)
        self._eq_pos = {int(e): k for k, e in enumerate(self.eq)}
        self._G_all = sys.G(list(range(len(sys.frictions))))  # w_rel = G w for every element
        # mujoco 4: run-time inertia changes reach M only after mj_setConst (it refreshes the cached constants)
        mujoco.mj_setConst(m, self.d)
        mujoco.mj_forward(m, self.d)
        Mdiag = np.diag(mujoco_engine.full_inertia(m, self.d))[self.dof]
        if not np.allclose(Mdiag, sys.J, rtol=1e-9, atol=0):
            raise ModelFileError(f"{mjcf}: joint-space inertia {Mdiag} does not match the rotor inertias {sys.J}")

    # -- helpers -------------------------------------------------------------------------------------------------
    def _w(self) -> np.ndarray:
        return self.d.qvel[self._dof_idx]  # fancy indexing: a copy

    def _q(self) -> np.ndarray:
        return self.d.qpos[self._qadr_idx]

    def _eq_forces(self) -> np.ndarray:
        """Force of every friction element's lock equality from the last `mj_forward` (0 where inactive)."""
        d = self.d
        out = np.zeros(len(self.eq))
        nefc = d.nefc
        if nefc:
            rows = np.nonzero(d.efc_type[:nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)[0]
            seen = set()
            for r in rows:  # the first row of each equality (a joint equality has one)
                k = self._eq_pos.get(int(d.efc_id[r]))
                if k is not None and k not in seen:
                    out[k] = d.efc_force[r]
                    seen.add(k)
        return out

    def _activate(self, stuck: list[int]) -> float:
        """Lock the elements `stuck`: project velocities (plastic impact), set the equality offsets and activate.
        Returns the kinetic energy removed by the projection."""
        m, d, sys = self.m, self.d, self.sys
        J = np.array([m.body_inertia[m.jnt_bodyid[j], 2] for j in self.jnt])  # hinge about z through the COM
        w = self._w()
        if stuck:
            G = sys.G(stuck)
            Minv = np.diag(1.0 / J)
            S = G @ Minv @ G.T
            w_new = w - Minv @ G.T @ np.linalg.pinv(S, rcond=1e-12) @ G @ w
        else:
            w_new = w
        dke = 0.5 * float(np.sum(J * (w**2 - w_new**2)))
        for i, dof in enumerate(self.dof):
            d.qvel[dof] = w_new[i]
        q = self._q()
        for e, f in enumerate(sys.frictions):
            on = e in stuck
            if on and not d.eq_active[self.eq[e]]:
                m.eq_data[self.eq[e], 0] = q[f.a] - (q[f.b] if f.b >= 0 else 0.0)
                m.eq_data[self.eq[e], 1] = 1.0 if f.b >= 0 else 0.0
            d.eq_active[self.eq[e]] = on
        return dke

    def run(self, q0, w0, t_end: float, *, controller: Controller | None = None, u0: dict[str, int] | None = None,
            sample_dt: float = 1e-3) -> RefResult:
        m, d, sys = self.m, self.d, self.sys
        n, ne = sys.n, len(sys.frictions)
        dt = float(m.opt.timestep)
        mujoco.mj_resetData(m, d)
        for i in range(n):
            d.qpos[self.qadr[i]] = q0[i]
            d.qvel[self.dof[i]] = w0[i]
        part_owner = [e for e, f in enumerate(sys.frictions) for _ in f.parts]
        labels = sys.part_labels()
        peaks = np.array([f.peak for f in sys.frictions])
        u = {c: 0 for c in sys.commands()}
        u.update(u0 or {})
        if controller is not None:
            ratio = controller.dt / dt
            if abs(ratio - round(ratio)) > 1e-9:
                raise SceneError(f"controller period {controller.dt} s is not a multiple of the MuJoCo timestep {dt} s")
            every = int(round(ratio))
            queue = CommandQueue(sys.delays, controller.dt, u)
        modes = np.full(ne, FREE)
        armed = np.zeros(ne, bool)
        events: list[dict[str, Any]] = []
        n_steps = int(round(t_end / dt))
        out_every = max(1, int(round(sample_dt / dt)))
        n_out = n_steps // out_every + 1
        T = np.empty(n_out)
        Q = np.empty((n, n_out))
        W = np.empty((n, n_out))
        MO = np.empty((ne, n_out), int)
        UU = {c: np.empty(n_out) for c in u}
        e_names = ["source"] + [f"viscous_{nm}" for nm in sys.names] + labels
        E = {k: np.empty(n_out) for k in e_names + ["lock_impact"]}
        acc = np.zeros(len(e_names))
        stats = {"reset_energy": 0.0, "lock_trials": 0, "steps": n_steps}
        k_out = 0

        # levels depend on time only through schedules: without any, cache them per command state
        timevar = any(pt.schedule is not None for f in sys.frictions for pt in f.parts)
        lv_cache: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}

        def levels(t):
            key = None if timevar else tuple(u[c] for c in u)
            if key is not None and key in lv_cache:
                return lv_cache[key]
            lv = sys.levels(t, u)
            el = np.zeros(ne)
            np.add.at(el, part_owner, lv)
            if key is not None:
                lv_cache[key] = (lv, el)
            return lv, el

        G_all = self._G_all
        free_tol = np.array([1e-12 * max(1.0, sum(p.level for p in f.parts)) for f in sys.frictions])
        part_idx = np.arange(len(part_owner))
        part_el = np.array(part_owner, int)
        rk4 = m.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4
        g_prev = np.full(ne, np.nan)  # event function of each element at the previous step (slip or overload)
        g_now = np.full(ne, np.nan)

        def note(t, e, old, new):
            """Record a mode change; the time is the linear interpolation of the event function within the step."""
            if old != new:
                te = t
                if np.isfinite(g_prev[e]) and np.isfinite(g_now[e]) and g_prev[e] != g_now[e]:
                    frac = g_now[e] / (g_now[e] - g_prev[e])
                    if 0.0 <= frac <= 1.0:
                        te = t - frac * dt
                events.append({"t": float(te), "element": sys.frictions[e].name, "from": MODE_NAME[int(old)],
                               "to": MODE_NAME[int(new)], "t_step": float(t)})

        def step_work(tm, lv, w0, q0, w1, q1):
            """Energy terms of one step: constant (held) torques do work torque x displacement (exact for the
            integrated motion, also when a slip reverses inside the step); velocity-proportional terms trapezoidal."""
            out = np.zeros(len(e_names))
            dq = q1 - q0
            for s in sys.sources:
                i = s.body
                out[0] += s.c0 * (s.shape(tm) if s.shape else 1.0) * dq[i] + s.c1 * 0.5 * (w0[i] ** 2 + w1[i] ** 2) * dt
            out[1:1 + n] = sys.B * 0.5 * (w0**2 + w1**2) * dt
            sliding = (modes == FWD) | (modes == BWD)
            if sliding.any():
                dqr = G_all @ dq  # relative displacement of every element
                on = sliding[part_el]
                out[1 + n + part_idx[on]] = modes[part_el[on]] * lv[on] * dqr[part_el[on]]
            return out

        first = True
        lam_all = np.zeros(ne)  # lock-equality forces of the last mj_forward
        for step in range(n_steps + 1):
            t = step * dt
            if controller is not None and step % every == 0 and step < n_steps:  # as the hand path: none at t_end
                k = step // every
                queue.issue(k, controller(k, t, self._q(), self._w()))
                while queue.pending and queue.pending[0][0] <= t + 0.5 * dt:
                    _, c, v = queue.pending.pop(0)
                    u[c] = v
            lv, el = levels(t)
            wr = G_all @ self._w()
            old = modes.copy()
            fresh = False  # d holds an mj_forward of the current state and ctrl
            any_stuck = not first and bool(np.any(modes == STUCK))
            if any_stuck:
                mujoco.mj_forward(m, d)  # constraint torques at the current state for the break-loose test
                lam_all = self._eq_forces()
                fresh = True
            trial: list[int] = []
            g_now[:] = np.nan
            sl = (modes == FWD) | (modes == BWD)
            g_now[sl] = modes[sl] * wr[sl]
            if any_stuck:
                st = modes == STUCK
                g_now[st] = peaks[st] * el[st] - np.abs(lam_all[st])
            for e in range(ne):
                if el[e] <= free_tol[e]:
                    modes[e] = FREE
                elif modes[e] == FREE:
                    if abs(wr[e]) < 1e-12:
                        trial.append(e)
                    else:
                        modes[e] = int(np.sign(wr[e]))
                        armed[e] = True
                elif modes[e] in (FWD, BWD):
                    if modes[e] * wr[e] > 0:
                        armed[e] = True
                    elif armed[e]:
                        trial.append(e)
                elif modes[e] == STUCK and not first:
                    lam = lam_all[e]
                    if abs(lam) > peaks[e] * el[e]:
                        modes[e] = FWD if lam > 0 else BWD
                        armed[e] = False
            if trial or np.any(modes != old):
                for e in trial:
                    modes[e] = STUCK
                # lock trial: activate, evaluate constraint torques, release the most overloaded until consistent
                for _ in range(2 * ne + 2):
                    stuck = [e for e in range(ne) if modes[e] == STUCK]
                    dke = self._activate(stuck)
                    stats["reset_energy"] += dke
                    self._set_ctrl(t, el, modes)
                    mujoco.mj_forward(m, d)
                    lam_all = self._eq_forces()
                    fresh = True
                    stats["lock_trials"] += 1
                    if not stuck:
                        break
                    lam = lam_all[stuck]
                    ratio = np.abs(lam) / (peaks[stuck] * el[stuck])
                    r = int(np.argmax(ratio))
                    if ratio[r] <= 1.0:
                        break
                    e = stuck[r]
                    modes[e] = FWD if lam[r] > 0 else BWD
                    armed[e] = False
                # the KE removed by the plastic lock is slip loss of the locking element(s)
            if not first:
                for e in np.nonzero(modes != old)[0]:
                    note(t, int(e), old[e], modes[e])
            first = False
            # event functions of the new modes, for interpolating the next event
            wr = G_all @ self._w()
            g_prev[:] = np.nan
            sl = (modes == FWD) | (modes == BWD)
            g_prev[sl] = modes[sl] * wr[sl]
            st = modes == STUCK
            g_prev[st] = peaks[st] * el[st] - np.abs(lam_all[st])
            # held over the step: time-varying levels and source shapes at mid-step (second order)
            lv_mid, el_mid = levels(t + 0.5 * dt) if timevar else (lv, el)
            ctrl_before = d.ctrl.copy()
            self._set_ctrl(t + 0.5 * dt, el_mid, modes)
            fresh = fresh and np.array_equal(ctrl_before, d.ctrl)
            if step % out_every == 0 and k_out < n_out:
                T[k_out] = t
                Q[:, k_out] = self._q()
                W[:, k_out] = self._w()
                MO[:, k_out] = modes
                for c in u:
                    UU[c][k_out] = u[c]
                for i, k in enumerate(e_names):
                    E[k][k_out] = acc[i]
                E["lock_impact"][k_out] = stats["reset_energy"]
                k_out += 1
            if step == n_steps:
                break
            w_a, q_a = self._w(), self._q()
            if fresh and rk4:
                # the forward of this state and ctrl is already in d: mj_step without repeating it
                mujoco.mj_checkPos(m, d)
                mujoco.mj_checkVel(m, d)
                mujoco.mj_checkAcc(m, d)
                mujoco.mj_RungeKutta(m, d, 4)
            else:
                mujoco.mj_step(m, d)
            mujoco_engine.check_finite(m, d, "drives MuJoCo path")
            acc += step_work(t + 0.5 * dt, lv_mid, w_a, q_a, self._w(), self._q())
        stats["warnings"] = mujoco_engine.warnings_raised(d)
        return RefResult(t=T[:k_out], q=Q[:, :k_out], w=W[:, :k_out], modes=MO[:, :k_out],
                         energy={k: v[:k_out] for k, v in E.items()}, events=events,
                         u={c: v[:k_out] for c, v in UU.items()}, stats=stats)

    def _set_ctrl(self, t: float, el: np.ndarray, modes: np.ndarray) -> None:
        d = self.d
        for e in range(len(self.sys.frictions)):
            tau = modes[e] * el[e] if modes[e] in (FWD, BWD) else 0.0
            d.ctrl[self.act[e]] = self.act_sign[e] * tau
        for s, a in zip(self.sys.sources, self.src, strict=True):
            d.ctrl[a] = s.shape(t) if s.shape is not None else 1.0
