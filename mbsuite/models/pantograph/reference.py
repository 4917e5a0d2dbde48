"""The reference path of the pantograph: the hand-derived equations (`equations.py`) integrated by scipy's
`solve_ivp` with event-exact Coulomb friction and contact loss, and the path's `run_reference(scene)`.

Coulomb friction is event-exact: a joint slides with a constant friction torque -c d (d = direction) until its rate
crosses zero; then it sticks if the constraint torque that keeps it stuck is within c, else it reverses. A stuck joint
breaks loose when that torque reaches c. Between events the right-hand side is smooth, so adaptive integrators never see
the sign() discontinuity that stalls them (the thesis' FORTRAN used SIGN(c, w), erratum 17). A unilateral contact
opens and closes at events too (contact losses with start time and duration).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from ...errors import SolverError
from ...results import SimResult, assemble
from ...scenes import Scene
from ...stepping import Stepping
from .equations import G_JOINTS, JOINT_NAMES, FrictionModes, PantographODE
from .health import excursion
from .inputs import config_of, input_of, start_of
from .outputs import signals


@dataclass
class RefSolution:
    """A reference-path solution: times, states, events, RHS calls and smooth segments."""
    t: np.ndarray
    x: np.ndarray  # (n, len(t))
    events: list[dict]
    nfev: int
    nsteps: int
    nsegments: int


class EventExactIntegrator(Stepping):
    """The reference path's step object (`mbsuite.stepping.StepObject`): `solve_ivp` from one friction/contact event
    to the next. `step()` integrates one smooth segment (to the next event or to `t_end`) and re-decides the friction
    modes after an event (stick if the constraint torque is within c, otherwise slide in the direction the free motion
    takes); `solution()` gathers the samples. Events are located by solve_ivp's root finder (to ~1e-12 s here)."""

    def __init__(self, ode: PantographODE, y_w: Callable[[float], float], t_end: float, x0: np.ndarray, *,
                 method: str = "LSODA", rtol: float = 1e-8, atol: float = 1e-10, max_step: float = 0.0,
                 t_eval: np.ndarray | None = None, max_events: int = 200_000, max_nfev: int = 50_000_000,
                 breaks: tuple[float, ...] = ()):
        self.ode, self.y_w, self.t_end, self.t_eval = ode, y_w, t_end, t_eval
        self.breaks = tuple(sorted(float(b) for b in breaks if 0.0 < b < t_end))
        self.method, self.max_events, self.max_nfev = method, max_events, max_nfev
        self.x = np.asarray(x0, dtype=float).copy()
        self.t = 0.0
        self.modes = FrictionModes()
        self.exact = ode.cfg.coulomb is True and np.any(ode.c > 0)
        self.unilateral = ode.cfg.contact == "unilateral"
        if self.exact:
            self.modes = _decide_modes(ode, self.x, y_w(0.0),
                                       FrictionModes(stuck=np.ones(3, dtype=bool) & (ode.c > 0)))
            self.x = _project_stuck(ode, self.x, self.modes)
        self.in_contact = not self.unilateral or ode.contact_height(self.x) >= y_w(0.0)
        self._t_out: list[np.ndarray] = []
        self._x_out: list[np.ndarray] = []
        self.events: list[dict] = []
        self.nfev = self.nsteps = self.nsegments = 0
        self._kw = {"method": method, "rtol": rtol, "atol": atol}
        if max_step > 0:
            self._kw["max_step"] = max_step
        self._loss_start = None if self.in_contact else 0.0
        self.status = "running" if self.t < t_end else "finished"

    def _one_step(self) -> None:
        """Integrate one smooth segment: to the next friction/contact event, the input's next jump or `t_end`. Its
        parts run once per segment, not per RHS evaluation (solve_ivp's loop is the lambda in `_integrate`): the
        segment's events (`_segment_events`) and samples (`_segment_samples`), the integration, the samples kept
        (`_keep`), and what the event that ended it changes (`_contact_switched`, `_friction_switched`)."""
        t0, t_end = self.t, self.t_end
        self.nsegments += 1
        if self.nsegments > self.max_events:
            raise SolverError(f"more than {self.max_events} friction/contact events before t = {t0:.6g} s (mode "
                              "chattering)")
        # a discontinuity of the input (a step) ends the segment: integrate to it on the input's left limit
        brk = next((b for b in self.breaks if b > t0), None)
        t_stop = t_end if brk is None else brk
        u = self.y_w if brk is None else _left_limit(self.y_w, brk)
        evs, kinds = self._segment_events(u)
        te = self._segment_samples(t0, t_stop, brk)
        sol = self._integrate(u, t0, t_stop, te, evs)
        at_break = brk is not None and sol.status == 0
        x_brk = self._keep(sol, te, at_break)
        if at_break:
            self._cross_break(brk, x_brk)
            return
        if sol.status == 0:
            self.t, self.status = t_end, "finished"
            return
        # a terminal event fired: find which
        k = next(i for i, te_ in enumerate(sol.t_events) if te_.size)
        t0 = float(sol.t_events[k][0])
        x = sol.y_events[k][0].copy()
        kind, j = kinds[k]
        if kind == "contact":
            self._contact_switched(t0)
        else:
            x = self._friction_switched(kind, j, t0, x)
        self.t, self.x = t0, x
        if self.t >= t_end:
            self.status = "finished"

    def _segment_events(self, u: Callable[[float], float]) -> tuple[list, list[tuple[str, int]]]:
        """The segment's terminal events and their kinds: per joint with friction, its release (stuck) or its rate's
        zero (sliding); the contact's closing or opening (unilateral contact)."""
        ode, modes = self.ode, self.modes
        evs, kinds = [], []
        if self.exact:
            for j in range(3):
                if ode.c[j] == 0:
                    continue
                if modes.stuck[j]:
                    evs.append(_stuck_event(ode, u, modes, j))
                    kinds.append(("release", j))
                else:
                    evs.append(_slide_event(ode, modes, j))
                    kinds.append(("zero_rate", j))
        if self.unilateral:
            evs.append(_contact_event(ode, u, self.in_contact))
            kinds.append(("contact", -1))
        return evs, kinds

    def _segment_samples(self, t0: float, t_stop: float, brk: float | None) -> np.ndarray | None:
        """The sample times of `t_eval` in the segment (None: every solver step)."""
        t_eval = self.t_eval
        te = None if t_eval is None else t_eval[(t_eval >= t0) & (t_eval <= t_stop)]
        if brk is not None and te is not None:  # the break's own sample belongs to the next segment
            te = np.append(te[te < brk], brk)
        return te

    def _integrate(self, u: Callable[[float], float], t0: float, t_stop: float, te: np.ndarray | None, evs: list):
        """solve_ivp over the segment in the current friction modes, its cost counted and its failures a
        SolverError."""
        ode = self.ode
        seg_modes = self.modes if self.exact else None
        try:
            sol = solve_ivp(lambda t, x, m=seg_modes: ode.rhs(t, x, u(t), m), (t0, t_stop), self.x,
                            t_eval=te, events=evs or None, **self._kw)
        except ValueError as exc:  # solve_ivp's event root finder on a bracket its interpolant does not keep
            raise SolverError(f"reference integrator {self.method} failed to locate a friction/contact event after "
                              f"t = {t0:.6g} s ({exc}); tighten solver.rtol or choose another solver.method") from None
        self.nfev += sol.nfev
        self.nsteps += max(len(sol.t) - 1, 0) if self.t_eval is None else 0
        if sol.status == -1:
            raise SolverError(f"reference integrator {self.method} failed at t = {sol.t[-1]:.6g} s: {sol.message}")
        if self.nfev > self.max_nfev:
            raise SolverError(f"reference integrator exceeded {self.max_nfev} RHS evaluations (step-size collapse)")
        return sol

    def _keep(self, sol, te: np.ndarray | None, at_break: bool) -> np.ndarray | None:
        """Keep the segment's samples; at an input jump, return the state there (its sample, if sampled, is left to
        the next segment)."""
        st = np.asarray(sol.t, dtype=float)
        sy = np.asarray(sol.y, dtype=float).reshape(self.ode.n, st.size)
        x_brk = None
        if at_break and te is not None:  # keep the state at the break, leave its sample to the next segment
            x_brk, st, sy = sy[:, -1].copy(), st[:-1], sy[:, :-1]
        elif at_break:
            x_brk = sy[:, -1].copy()
        if st.size:
            self._t_out.append(st)
            self._x_out.append(sy)
        return x_brk

    def _contact_switched(self, t0: float) -> None:
        """The contact closed (a loss ends and is recorded) or opened (a loss starts) at t0."""
        self.in_contact = not self.in_contact
        if self.in_contact:
            self.events.append({"kind": "contact_loss", "t_start": self._loss_start,
                                "duration": t0 - self._loss_start})
            self._loss_start = None
        else:
            self._loss_start = t0

    def _friction_switched(self, kind: str, j: int, t0: float, x: np.ndarray) -> np.ndarray:
        """Joint j's rate reached zero (`zero_rate`: it sticks) or its holding torque reached c (`release`: it breaks
        loose in the direction the torque drives it); the modes re-decided, the state projected onto them and the
        stick/slip/reversal events recorded. Returns the projected state."""
        ode, y_w, modes = self.ode, self.y_w, self.modes
        old = modes.stuck.copy()
        if kind == "zero_rate":
            modes.stuck[j] = True
        else:  # the holding torque of joint j reached c: it breaks loose in the direction the torque drives it
            f_s = ode.contact_force(y_w(t0), ode.contact_height(x))
            _, mu, _, _ = ode._dynamics(x, f_s, modes)
            pos = int(np.flatnonzero(modes.stuck & (ode.c > 0)).tolist().index(j))
            modes.stuck[j] = False
            modes.direction[j] = -math.copysign(1.0, mu[pos])
        modes = self.modes = _decide_modes(ode, x, y_w(t0), modes)
        x = _project_stuck(ode, x, modes)
        changed = np.flatnonzero(old != modes.stuck)
        for jj in changed:
            self.events.append({"kind": "stick" if modes.stuck[jj] else "slip", "joint": JOINT_NAMES[jj],
                                "t": t0})
        if kind == "zero_rate" and not modes.stuck[j]:
            self.events.append({"kind": "reversal", "joint": JOINT_NAMES[j], "t": t0})
        return x

    def _cross_break(self, t0: float, x: np.ndarray) -> None:
        """At a jump of the input: re-decide the friction modes (a stuck joint whose holding torque jumped past c
        breaks loose now) and the contact (the wire may jump away from the head or onto it)."""
        ode, y_w = self.ode, self.y_w
        if self.exact:
            old = self.modes.stuck.copy()
            self.modes = _decide_modes(ode, x, y_w(t0), self.modes)
            x = _project_stuck(ode, x, self.modes)
            for jj in np.flatnonzero(old != self.modes.stuck):
                self.events.append({"kind": "stick" if self.modes.stuck[jj] else "slip", "joint": JOINT_NAMES[jj],
                                    "t": t0})
        if self.unilateral:
            touching = ode.contact_height(x) >= y_w(t0)
            if touching and not self.in_contact:
                self.events.append({"kind": "contact_loss", "t_start": self._loss_start,
                                    "duration": t0 - self._loss_start})
                self._loss_start = None
            elif self.in_contact and not touching:
                self._loss_start = t0
            self.in_contact = touching
        self.t, self.x = t0, x

    def solution(self) -> RefSolution:
        """The samples so far (t_eval's, or every solver step without t_eval), the events (a contact loss still
        open at the end has duration None) and the cost. Raises SolverError on a non-finite state."""
        events = list(self.events)
        if self._loss_start is not None:
            events.append({"kind": "contact_loss", "t_start": self._loss_start, "duration": None})
        t = np.concatenate(self._t_out) if self._t_out else np.zeros(0)
        X = np.concatenate(self._x_out, axis=1) if self._x_out else np.zeros((self.ode.n, 0))
        if self.t_eval is None and t.size:
            keep = np.concatenate([[True], np.diff(t) > 0])
            t, X = t[keep], X[:, keep]
        if not np.all(np.isfinite(X)):
            raise SolverError("reference integration produced non-finite states")
        return RefSolution(t, X, events, self.nfev, self.nsteps, self.nsegments)


def simulate(ode: PantographODE, y_w: Callable[[float], float], t_end: float, x0: np.ndarray, **options) -> RefSolution:
    """Integrate from x0 at t = 0 to t_end with solve_ivp, splitting at friction and contact events (event-exact
    stick/slip and contact loss); `options` are those of `EventExactIntegrator`."""
    sim = EventExactIntegrator(ode, y_w, t_end, x0, **options)
    sim.run(t_end)
    return sim.solution()


def run_reference(scene: Scene) -> SimResult:
    """The reference path's run: the scene's ram input (sine/step/static) on the hand-derived equations with scipy's
    `solver.method`, `rtol`, `atol` (`max_step` default: 1/16 of a sine's period), sampled every `sample_dt`
    (default `timestep`). Health figure: `excursion`."""
    p = scene.build_params()
    ode = PantographODE(p, config_of(scene))
    u = input_of(scene, p)
    s = scene.solver
    start = start_of(scene, ode, u)
    dt_out = s.sample_dt or s.timestep
    t_eval = np.arange(0.0, s.duration + 0.5 * dt_out, dt_out)
    max_step = s.max_step or (1.0 / (16.0 * u.frequency) if u.kind == "sine" else 0.0)
    breaks = (u.t_step,) if u.kind == "step" else ()  # the ram's jump ends a smooth segment
    sol = simulate(ode, u, s.duration, start.x0, method=s.method, rtol=s.rtol, atol=s.atol, max_step=max_step,
                   t_eval=t_eval, breaks=breaks)
    th = np.array([ode.theta(sol.x[: ode.nq, k]) for k in range(sol.t.size)])
    P = sol.x[-1] if ode.has_P else None
    return assemble(scene, sol.t, signals(ode, th, u(sol.t), P), engine="reference", events=sol.events,
                    stats={"nfev": sol.nfev, "segments": sol.nsegments, "method": s.method, "rtol": s.rtol},
                    health=[excursion(th, start.theta0)])


def _left_limit(y_w: Callable[[float], float], b: float) -> Callable[[float], float]:
    """The input up to the jump at `b`, held at its left limit from `b` on (a segment ending at `b` sees no jump)."""
    left = y_w(float(np.nextafter(b, -np.inf)))
    return lambda t: y_w(t) if t < b else left


def _slide_event(ode: PantographODE, modes: FrictionModes, j: int):
    def ev(t, x):
        J, _ = ode.theta_jacobian(x[: ode.nq])
        return float((G_JOINTS @ J)[j] @ x[ode.nq : 2 * ode.nq])

    ev.terminal = True
    ev.direction = -float(modes.direction[j])
    return ev


def _stuck_event(ode: PantographODE, y_w, modes: FrictionModes, j: int):
    idx = int(np.flatnonzero(modes.stuck & (ode.c > 0)).tolist().index(j))

    def ev(t, x):
        f_s = ode.contact_force(y_w(t), ode.contact_height(x))
        _, mu, _, _ = ode._dynamics(x, f_s, modes)
        return float(ode.c[j] - abs(mu[idx]))

    ev.terminal = True
    ev.direction = -1.0
    return ev


def _contact_event(ode: PantographODE, y_w, in_contact: bool):
    def ev(t, x):
        return ode.contact_height(x) - y_w(t)

    ev.terminal = True
    ev.direction = -1.0 if in_contact else 1.0
    return ev


def _decide_modes(ode: PantographODE, x: np.ndarray, y_w: float, modes: FrictionModes) -> FrictionModes:
    """Release stuck joints whose holding torque exceeds c, worst first, until all stuck joints hold."""
    modes = FrictionModes(modes.stuck.copy(), modes.direction.copy())
    f_s = ode.contact_force(y_w, ode.contact_height(x))
    for _ in range(4):
        if not modes.stuck.any():
            break
        _, mu, _, _ = ode._dynamics(x, f_s, modes)
        idx = np.flatnonzero(modes.stuck)
        excess = np.abs(mu) - ode.c[idx]
        worst = int(np.argmax(excess))
        if excess[worst] <= 1e-12 * max(1.0, ode.c[idx][worst]):
            break
        j = idx[worst]
        modes.stuck[j] = False
        modes.direction[j] = -math.copysign(1.0, mu[worst])
    return modes


def _project_stuck(ode: PantographODE, x: np.ndarray, modes: FrictionModes) -> np.ndarray:
    """Set stuck joints' rates exactly to zero by the mass-weighted projection of q' (an impulse of ~rtol size)."""
    if not modes.stuck.any():
        return x
    nq = ode.nq
    q, qd = x[:nq], x[nq : 2 * nq]
    J, _ = ode.theta_jacobian(q)
    M = J.T @ ode.mass_matrix_theta(ode.theta(q)) @ J
    Gs = (G_JOINTS @ J)[modes.stuck]
    Minv_Gt = np.linalg.solve(M, Gs.T)
    lam = np.linalg.lstsq(Gs @ Minv_Gt, Gs @ qd, rcond=None)[0]
    x = x.copy()
    x[nq : 2 * nq] = qd - Minv_Gt @ lam
    return x
