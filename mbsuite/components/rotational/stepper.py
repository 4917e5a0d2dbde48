"""The rotor library's stick/slip state machine in Python: the readable twin of `native/rotors.c`, as a step object.

`RotorStepper(run)` holds the state of a MuJoCo run of a rotor system (modes, armed flags, event functions, energy
terms, lock-impact energy, events) and `step()` makes one step exactly as the native core does with the C stepper:
controller at its sample instants; `mj_forward` at the current state and control; `decide` (the mode decisions at
t_k, the lock trials, the events, the sliding torques held over the step and the forward the integrator needs - the C
hook's POST_FORWARD stage); the row recorded every `every` steps; the model's
integrator; `work` (the energy terms of the step - the POST_STEP stage); MuJoCo's warnings and a finite state
checked. `run(t)` steps up to t and `result()` makes the final decision at t_end and returns the `RefResult`.

Every method mirrors the C function of the same name statement for statement (plain loops, the same floating-point
operations in the same order), so that a test can hold the two paths equal. It exists to be read and to check the
native stepper; runs use the native one (`MujocoRotorSim.run(..., stepper="python")` selects this one). About 530
lines: it mirrors `native/rotors.c` function for function and is kept in one file to be read beside it.
"""

from __future__ import annotations

import math
from functools import partial

import mujoco
import numpy as np

from ...errors import SolverError
from .interfaces import BWD, FREE, FWD, STUCK, RefResult
from .rotor_run import CHATTER_N, CHATTER_WINDOW, HINT, RotorRun

ZERO_SLIP = 1e-12  # rad/s: a free element engaging at a smaller slip is tried for a lock
_INTEGRATE = {
    mujoco.mjtIntegrator.mjINT_EULER: mujoco.mj_Euler,
    mujoco.mjtIntegrator.mjINT_RK4: lambda m, d: mujoco.mj_RungeKutta(m, d, 4),
    mujoco.mjtIntegrator.mjINT_IMPLICIT: mujoco.mj_implicit,
    mujoco.mjtIntegrator.mjINT_IMPLICITFAST: mujoco.mj_implicit,
}
_BROKEN = (mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL, mujoco.mjtWarning.mjWARN_BADQACC,
           mujoco.mjtWarning.mjWARN_BADCTRL, mujoco.mjtWarning.mjWARN_CNSTRFULL)


def _find(parent: list[int], i: int) -> int:
    """Root of node i in the union-find forest `parent` (path halving, as the C)."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


class RotorStepper:
    """A run of a rotor system on MuJoCo, one step at a time (module docstring)."""

    def __init__(self, run: RotorRun):
        self.rotor_run = run
        self.m, self.d = run.m, run.d
        sim, sys = run.sim, run.sys
        self.n, self.ne = sys.n, len(sys.frictions)
        self.fr = sys.frictions
        self.parts = [pt for f in sys.frictions for pt in f.parts]
        self.owner = run.part_owner
        self.cmd = [run.commands.index(pt.command) if pt.command is not None else -1 for pt in self.parts]
        self.peak = [f.peak for f in sys.frictions]
        self.free_tol = [1e-12 * max(1.0, sum(p.level for p in f.parts)) for f in sys.frictions]
        self.J = [float(x) for x in sys.J]
        self.B = [float(x) for x in sys.B]
        self.dof, self.qadr = sim.dof, sim.qadr
        self.eq, self.act, self.act_sign, self.src = sim.eq, sim.act, sim.act_sign, sim.src
        self.modes = [FREE] * self.ne
        self.armed = [False] * self.ne
        self.lam = [0.0] * self.ne
        self.gprev = [math.nan] * self.ne
        self.gnow = [math.nan] * self.ne
        self.wr = [0.0] * self.ne
        self.lvm: list[float] = []
        self.wa = [0.0] * self.n
        self.qa = [0.0] * self.n
        self.general = sim.general
        self.grow = [[float(x) for x in r] for r in sys.rows]
        self.eq_sign = list(sim.eq_sign)
        self.oneway = [f.one_way_hold is not None for f in sys.frictions]
        self.hold = [f.one_way_hold or 0.0 for f in sys.frictions]
        self.dampers = run.dampers
        self.sheld = [0.0] * len(sys.sources)
        self.acc = [0.0] * (1 + self.n + len(self.parts) + len(self.dampers))
        self.first = True
        self.reset_energy = 0.0
        self.lock_trials = 0
        self.chatter: list[list[int]] = [[] for _ in range(self.ne)]
        self.events: list[dict] = []
        self.rows: list[list[float]] = []
        self.row: list[float] = []
        self.k = 0
        self.done = False
        self._integrate = _INTEGRATE.get(run.m.opt.integrator, None)
        self._warn0 = [int(self.d.warning[w].number) for w in _BROKEN]

    # ---- the state ------------------------------------------------------------------------------------------------
    def w(self, i: int) -> float:
        """Speed of rotor i [rad/s]."""
        return float(self.d.qvel[self.dof[i]])

    def q(self, i: int) -> float:
        """Angle of rotor i [rad]."""
        return float(self.d.qpos[self.qadr[i]])

    def levels(self, t: float) -> tuple[list[float], list[float]]:
        """Sliding torque of every part and element at t under the current commands (C: levels)."""
        run = self.rotor_run
        el = [0.0] * self.ne
        lv = []
        for p, pt in enumerate(self.parts):
            v = pt.level
            if self.cmd[p] >= 0:
                v *= float(run.u_arr[self.cmd[p]])
            sig = run.schedules[p]
            if sig is not None:
                s = sig(t)
                if not math.isfinite(s):
                    raise SolverError(f"rotor MuJoCo path: the schedule of friction part '{pt.label}' is not finite "
                                      f"({s!r}) at t = {t:.6g} s")
                v *= s if s > 0.0 else 0.0
            lv.append(v)
            el[self.owner[p]] += v
        return lv, el

    def shape(self, s: int, t: float) -> float:
        """Value of source shape s at time t (1 without a shape)."""
        sig = self.rotor_run.shapes[s]
        return 1.0 if sig is None else sig(t)

    def slips(self) -> None:
        """Update the slip speed of every friction element from the current state."""
        for e, f in enumerate(self.fr):
            if self.general:
                v = 0.0
                for i in range(self.n):
                    v += self.grow[e][i] * self.w(i)
                self.wr[e] = v
            else:
                self.wr[e] = (self.w(f.b) if f.b >= 0 else 0.0) - self.w(f.a)

    def capacity(self, e: int, el: list[float]) -> float:
        """Breakaway torque of element e at levels el (a disengaged one-way clutch: its hold torque)."""
        if self.oneway[e] and el[e] <= self.free_tol[e]:
            return self.hold[e]
        return self.peak[e] * el[e]

    def overload(self, e: int, el: list[float]) -> float:
        """Lock force over breakaway (> 1: it breaks); a one-way clutch holds any negative force."""
        lam = (self.lam[e] if self.lam[e] > 0.0 else 0.0) if self.oneway[e] else abs(self.lam[e])
        return lam / self.capacity(e, el)

    def lock_forces(self) -> None:
        """Force of each element's lock from the last forward: first row of its equality, 0 if inactive."""
        d = self.d
        self.lam = [0.0] * self.ne
        seen = [False] * self.ne
        eq2el = {k: e for e, k in enumerate(self.eq)}
        for r in range(d.nefc):
            if d.efc_type[r] != mujoco.mjtConstraint.mjCNSTR_EQUALITY:
                continue
            e = eq2el.get(int(d.efc_id[r]), -1)
            if e >= 0 and not seen[e]:
                self.lam[e] = self.eq_sign[e] * float(d.efc_force[r])
                seen[e] = True

    def engage(self) -> float:
        """Switch the locks to the stuck set: plastic impact (each rigid group of rotors joined by stuck elements
        takes its momentum-weighted mean speed, 0 if held to the ground), offsets of newly engaged locks, equality
        activation. Returns the kinetic energy removed (C: engage)."""
        m, d, n = self.m, self.d, self.n
        if self.general:
            dke = self.project()
            for e, f in enumerate(self.fr):
                on = self.modes[e] == STUCK
                k = self.eq[e]
                if on and not d.eq_active[k]:
                    if m.eq_type[k] == mujoco.mjtEq.mjEQ_TENDON:
                        off = 0.0
                        for i in range(n):
                            off += self.grow[e][i] * self.q(i)
                        m.eq_data[k, 1] = 0.0
                    else:
                        off = self.q(f.a) - (self.q(f.b) if f.b >= 0 else 0.0)
                        m.eq_data[k, 1] = 1.0 if f.b >= 0 else 0.0
                    m.eq_data[k, 0] = off
                d.eq_active[k] = on
            return 0.5 * dke
        parent = list(range(n + 1))  # node n = ground
        find = partial(_find, parent)
        for e, f in enumerate(self.fr):
            if self.modes[e] != STUCK:
                continue
            a, b = find(f.a), find(f.b if f.b >= 0 else n)
            if a == b:
                continue
            if a == n:
                parent[b] = a
            else:
                parent[a] = b
        ground = find(n)
        size = [0] * (n + 1)
        sJ = [0.0] * (n + 1)
        sJw = [0.0] * (n + 1)
        for i in range(n):
            r = find(i)
            size[r] += 1
            sJ[r] += self.J[i]
            sJw[r] += self.J[i] * self.w(i)
        dke = 0.0
        for i in range(n):
            r = find(i)
            w = wn = self.w(i)
            if r == ground:
                wn = 0.0
            elif size[r] > 1:
                wn = sJw[r] / sJ[r]
            dke += self.J[i] * (w * w - wn * wn)
            d.qvel[self.dof[i]] = wn
        for e, f in enumerate(self.fr):
            on = self.modes[e] == STUCK
            k = self.eq[e]
            if on and not d.eq_active[k]:
                m.eq_data[k, 0] = self.q(f.a) - (self.q(f.b) if f.b >= 0 else 0.0)
                m.eq_data[k, 1] = 1.0 if f.b >= 0 else 0.0
            d.eq_active[k] = on
        return 0.5 * dke

    def project(self) -> float:
        """General systems: the plastic impact as the M-orthogonal projection onto the stuck constraints,
        w -= M^-1 G^T (G M^-1 G^T)^-1 G w, Gaussian elimination with partial pivoting (C: project)."""
        n, ne, d = self.n, self.ne, self.d
        rows = [e for e in range(ne) if self.modes[e] == STUCK]
        k = len(rows)
        if not k:
            return 0.0
        Sm = [[0.0] * (k + 1) for _ in range(k)]
        dmax = 0.0
        for r in range(k):
            gr = self.grow[rows[r]]
            for c in range(k):
                gc = self.grow[rows[c]]
                v = 0.0
                for i in range(n):
                    v += gr[i] * gc[i] / self.J[i]
                Sm[r][c] = v
            b = 0.0
            for i in range(n):
                b += gr[i] * self.w(i)
            Sm[r][k] = b
            if Sm[r][r] > dmax:
                dmax = Sm[r][r]
        piv = [-1] * k
        used = 0
        for c in range(k):
            best, bv = -1, 1e-12 * dmax
            for r in range(used, k):
                if abs(Sm[r][c]) > bv:
                    bv, best = abs(Sm[r][c]), r
            if best < 0:
                continue
            if best != used:
                Sm[used], Sm[best] = Sm[best], Sm[used]
            for r in range(k):
                if r == used:
                    continue
                f = Sm[r][c] / Sm[used][c]
                if f == 0.0:
                    continue
                for j in range(c, k + 1):
                    Sm[r][j] -= f * Sm[used][j]
            piv[c] = used
            used += 1
        lam = [Sm[piv[c]][k] / Sm[piv[c]][c] if piv[c] >= 0 else 0.0 for c in range(k)]
        dke = 0.0
        for i in range(n):
            w = self.w(i)
            dw = 0.0
            for c in range(k):
                dw += self.grow[rows[c]][i] * lam[c]
            wn = w - dw / self.J[i]
            dke += self.J[i] * (w * w - wn * wn)
            d.qvel[self.dof[i]] = wn
        return dke

    def set_ctrl(self, t: float, el: list[float], mid: bool = False) -> None:
        """Sliding torques of the elements at levels el, sources at time t; a quadratic source's torque at the
        speed now, or predicted at mid-step (`mid`, held over the step)."""
        d = self.d
        for e in range(self.ne):
            md = self.modes[e]
            tau = md * el[e] if md in (FWD, BWD) else 0.0
            d.ctrl[self.act[e]] = self.act_sign[e] * tau
        for s, a in enumerate(self.src):
            v = self.shape(s, t)
            so = self.rotor_run.sys.sources[s]
            if so.c2 != 0.0:
                dof = self.dof[so.body]
                w = float(d.qvel[dof]) + (0.5 * self.rotor_run.dt * float(d.qacc[dof]) if mid else 0.0)
                v = so.c0 * v + so.c2 * w * w  # the actuator's gain is 1
                self.sheld[s] = v
            d.ctrl[a] = v

    def event_function(self, el: list[float], stuck_too: bool) -> list[float]:
        """Slip in the sliding direction, breakaway - |lock force| when stuck (if `stuck_too`), else NaN."""
        g = []
        for e in range(self.ne):
            md = self.modes[e]
            if md in (FWD, BWD):
                g.append(md * self.wr[e])
            elif md == STUCK and stuck_too:
                g.append(self.capacity(e, el) - (self.lam[e] if self.oneway[e] else abs(self.lam[e])))
            else:
                g.append(math.nan)
        return g

    def note(self, k: int, t: float, e: int, old: int, new: int) -> None:
        """A mode change of element e at step k: its time interpolated in the event function; chatter check."""
        te = t
        gp, gn = self.gprev[e], self.gnow[e]
        if math.isfinite(gp) and math.isfinite(gn) and gp != gn:
            frac = gn / (gn - gp)
            if 0.0 <= frac <= 1.0:
                te = t - frac * self.rotor_run.dt
        self.events.append(self.rotor_run.event(te, t, e, old, new))
        ring = self.chatter[e]
        if len(ring) == CHATTER_N and k - ring[0] < CHATTER_WINDOW:
            raise SolverError(f"rotor MuJoCo path: the stick/slip state machine does not settle: friction element "
                              f"'{self.fr[e].name}' changed mode {CHATTER_N + 1} times within {k - ring[0]} steps "
                              f"(mode chattering: the torque on it reverses within a few steps; {HINT}) at t = "
                              f"{t:.6g} s")
        ring.append(k)
        if len(ring) > CHATTER_N:
            ring.pop(0)

    # ---- one step -------------------------------------------------------------------------------------------------
    def decide(self, k: int) -> None:
        """The mode decisions at t_k, the lock trials, the events and the torques held over the step; d leaves with
        the forward of the final state, locks and control (C: decide)."""
        d, ne, dt = self.d, self.ne, self.rotor_run.dt
        t = k * dt
        for i in range(self.n):
            if not (math.isfinite(self.w(i)) and math.isfinite(self.q(i))):
                raise SolverError(f"rotor MuJoCo path: the speed or position of rotor "
                                  f"'{self.rotor_run.sys.names[i]}' is not finite at t = {t:.6g} s; {HINT}")
        lv, el = self.levels(t)
        self.slips()
        old = list(self.modes)
        any_stuck = not self.first and STUCK in self.modes
        if any_stuck:
            self.lock_forces()
        self.gnow = self.event_function(el, any_stuck)
        trial = []
        for e in range(ne):
            md, wr = self.modes[e], self.wr[e]
            if self.oneway[e]:  # Modelica OneWayClutch: stuck = locked or w_rel <= 0; slides forward only
                if md == FREE:
                    if wr > ZERO_SLIP:
                        self.modes[e] = FWD
                        self.armed[e] = True
                    else:
                        trial.append(e)
                elif md == FWD:
                    if wr > 0.0:
                        self.armed[e] = True
                    elif self.armed[e]:
                        trial.append(e)
                elif md == STUCK and not self.first and self.lam[e] > self.capacity(e, el):
                    self.modes[e] = FWD
                    self.armed[e] = False
            elif el[e] <= self.free_tol[e]:
                self.modes[e] = FREE
            elif md == FREE:
                if abs(wr) < ZERO_SLIP:
                    trial.append(e)
                else:
                    self.modes[e] = FWD if wr > 0.0 else BWD
                    self.armed[e] = True
            elif md in (FWD, BWD):
                if md * wr > 0.0:
                    self.armed[e] = True
                elif self.armed[e]:
                    trial.append(e)
            elif md == STUCK and not self.first:
                lam = self.lam[e]
                if abs(lam) > self.peak[e] * el[e]:
                    self.modes[e] = FWD if lam > 0.0 else BWD
                    self.armed[e] = False
        if trial or self.modes != old:
            for e in trial:
                self.modes[e] = STUCK
            self.lock_trial(t, el)
        if not self.first:
            for e in range(ne):
                if self.modes[e] != old[e]:
                    self.note(k, t, e, old[e], self.modes[e])
        self.first = False
        self.slips()
        self.gprev = self.event_function(el, True)
        lvm, elm = self.levels(t + 0.5 * dt) if self.rotor_run.timevar else (lv, el)
        self.lvm = lvm
        ctrl0 = d.ctrl.copy()
        self.set_ctrl(t + 0.5 * dt, elm, True)
        if not np.array_equal(ctrl0, d.ctrl):  # the forward of this state and locks, redone from the control on
            mujoco.mj_forwardSkip(self.m, d, mujoco.mjtStage.mjSTAGE_VEL, 0)
            mujoco.mj_checkAcc(self.m, d)
        self.wa = [self.w(i) for i in range(self.n)]
        self.qa = [self.q(i) for i in range(self.n)]
        self.row = (self.qa + self.wa + [float(x) for x in self.modes] + [float(x) for x in self.rotor_run.u_arr]
                    + list(self.acc) + [self.reset_energy])

    def lock_trial(self, t: float, el: list[float]) -> None:
        """Engage the stuck set, evaluate the lock forces, release the most overloaded until every lock holds."""
        for _ in range(2 * self.ne + 2):
            self.reset_energy += self.engage()
            self.set_ctrl(t, el)
            mujoco.mj_forward(self.m, self.d)
            self.lock_forces()
            self.lock_trials += 1
            worst, wratio = -1, 0.0
            for e in range(self.ne):
                if self.modes[e] != STUCK:
                    continue
                ratio = self.overload(e, el)
                if worst < 0 or ratio > wratio:
                    worst, wratio = e, ratio
            if worst < 0 or wratio <= 1.0:
                return
            self.modes[worst] = FWD if self.lam[worst] > 0.0 else BWD
            self.armed[worst] = False
        raise SolverError(f"rotor MuJoCo path: the lock trials did not settle at t = {t:.6g} s")

    def work(self, k: int) -> None:
        """Energy terms of step k: held torques x integrated displacement, velocity terms trapezoidal (C: work)."""
        n, dt = self.n, self.rotor_run.dt
        tm = k * dt + 0.5 * dt
        src = 0.0
        for s, so in enumerate(self.rotor_run.sys.sources):
            i = so.body
            w0, w1 = self.wa[i], self.w(i)
            held = self.sheld[s] if so.c2 != 0.0 else so.c0 * self.shape(s, tm)
            src += held * (self.q(i) - self.qa[i]) + so.c1 * 0.5 * (w0 * w0 + w1 * w1) * dt
        self.acc[0] += src
        for i in range(n):
            w0, w1 = self.wa[i], self.w(i)
            self.acc[1 + i] += self.B[i] * 0.5 * (w0 * w0 + w1 * w1) * dt
        for p in range(len(self.parts)):
            e = self.owner[p]
            md = self.modes[e]
            if md not in (FWD, BWD):
                continue
            f = self.fr[e]
            if self.general:
                dqr = 0.0
                for i in range(n):
                    dqr += self.grow[e][i] * (self.q(i) - self.qa[i])
            else:
                dqa = self.q(f.a) - self.qa[f.a]
                dqr = ((self.q(f.b) - self.qa[f.b]) if f.b >= 0 else 0.0) - dqa
            self.acc[1 + n + p] += md * self.lvm[p] * dqr
        for j, sp in enumerate(self.dampers):
            a, b = sp.a, sp.b
            r0 = (self.wa[b] if b >= 0 else 0.0) - self.wa[a]
            r1 = (self.w(b) if b >= 0 else 0.0) - self.w(a)
            self.acc[1 + n + len(self.parts) + j] += sp.D * 0.5 * (r0 * r0 + r1 * r1) * dt

    def _forward(self) -> None:
        m, d = self.m, self.d
        mujoco.mj_checkPos(m, d)
        mujoco.mj_checkVel(m, d)
        mujoco.mj_forward(m, d)
        mujoco.mj_checkAcc(m, d)
        self._check()

    def _check(self) -> None:
        d = self.d
        for w, n0 in zip(_BROKEN, self._warn0, strict=True):
            if d.warning[w].number > n0:
                raise SolverError(f"rotor MuJoCo path: MuJoCo diverged (warning {w.name[7:].lower()}) at t = "
                                  f"{d.time:.6g} s; {HINT}")
        if not (np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))):
            raise SolverError(f"rotor MuJoCo path: MuJoCo diverged (non-finite state) at t = {d.time:.6g} s; {HINT}")

    def step(self) -> None:
        """Step k -> k + 1 (module docstring)."""
        run, k = self.rotor_run, self.k
        if run.controller is not None and k % run.period == 0:
            run.sample(k)
        self._forward()
        self.decide(k)
        if k % run.every == 0:
            self.rows.append(self.row)
        if self._integrate is not None:
            self._integrate(self.m, self.d)
        else:
            mujoco.mj_step(self.m, self.d)
        self.work(k)
        self._check()
        self.k += 1

    def run(self, t_end: float) -> RotorStepper:
        """Step up to time t_end (at most the run's end; `mbsuite.stepping.StepObject`); returns self."""
        k_end = min(self.rotor_run.nstep, int(round(t_end / self.rotor_run.dt)))
        while self.k < k_end:
            self.step()
        return self

    @property
    def t(self) -> float:
        """Current time [s]: step count x timestep."""
        return self.k * self.rotor_run.dt

    @property
    def status(self) -> str:
        """"running" until every step of the run is made, then "finished" (`mbsuite.stepping.StepObject`; a failing
        step raises SolverError)."""
        return "finished" if self.k >= self.rotor_run.nstep else "running"

    def result(self) -> RefResult:
        """The final decision at the end of the run (recorded if on the output grid) and the RefResult."""
        run = self.rotor_run
        if self.k < run.nstep:
            self.run(run.nstep * run.dt)
        if not self.done:
            self._forward()
            self.decide(self.k)
            if run.nstep % run.every == 0:
                self.rows.append(self.row)
            self.done = True
        stats = {"reset_energy": self.reset_energy, "lock_trials": self.lock_trials, "steps": run.nstep,
                 "warnings": {mujoco.mjtWarning(i).name: int(w.number) for i, w in enumerate(self.d.warning)
                              if w.number > 0}}
        return run.result(np.array(self.rows, float).reshape(-1, run.nrec), self.events, stats)
