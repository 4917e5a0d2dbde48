"""The hand-derived path: an event-exact stick/slip simulation of a `RotorSystem` (Modelica's
`Rotational.Interfaces.PartialFriction` semantics). One class, `ReferenceSimulator`, kept whole (about 500 lines) so
that the state machine reads in one place.

* sliding: the element transmits tau_e = mode * level(t) (level = sliding torque), w_rel = w_b - w_a;
* a sliding element locks when w_rel reaches 0 **and** the torque needed to hold it is within the breakaway limit
  peak * level; otherwise it passes through to sliding the other way;
* a stuck element breaks loose when its constraint torque reaches +-peak * level and then slides at `level`;
* level <= 0 means free (no torque);
* several stuck elements form rigid groups (nested locks: clutch + brake, both clutches, all three bodies). The
  accelerations of a configuration are the M-orthogonal projection onto the constraint subspace; the constraint torques
  are the capacity-weighted minimum-norm solution (exact when the stuck elements contain no closed loop; for parallel
  elements it shares the torque in proportion to capacity, so they break together; `projection.StuckProjection`).

`simulate_reference` integrates the smooth pieces with scipy's DOP853 (dense output) and locates every lock/break
event by root finding on the dense output (brentq, |dt| ~ 1e-14 s); time breakpoints (controller actions, normal-force
steps) truncate the step exactly. A discrete controller is sampled at its period through the dense output. It drives
the step object `ReferenceSimulator` (`step()` = one DOP853 step of the current smooth piece, `run(t)`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import partial
from typing import Any

import numpy as np
from scipy.integrate import DOP853
from scipy.optimize import brentq

from ...errors import ParameterError, SolverError
from .commands import CommandQueue, Controller
from .interfaces import BWD, FREE, FWD, MODE_NAME, STUCK, Friction, RefResult, RotorSystem
from .projection import StuckProjection


def _const(y: np.ndarray):
    return lambda tt: y


def _root(fun, a: float, b: float) -> float:
    """Root of fun in [a, b] (brentq to ~1e-15 s); if round-off leaves no bracket the crossing is at an end point."""
    fa, fb = fun(a), fun(b)
    if fa == 0.0 or np.sign(fa) == np.sign(fb):
        return a if abs(fa) <= abs(fb) else b
    if fb == 0.0:
        return b
    return brentq(fun, a, b, xtol=1e-15, rtol=1e-15)


class ReferenceSimulator:
    """The event-exact hand path as a step object (in the spirit of scipy's `OdeSolver.step`): it holds the state -
    time, state vector with the energy terms, modes, commands, the DOP853 solver of the current smooth piece - and
    `step()` makes one step of that solver (locating lock/break events on its dense output and stopping at time
    breakpoints: schedule jumps, actuations, controller samples); `run(t)` steps until t, `result()` returns the
    sampled `RefResult`. `simulate_reference` drives it from 0 to t_end. See the module docstring for the semantics.

    State vector: q (n), w (n), then the energy terms [source, viscous per rotor (n), per part]."""

    def __init__(self, sys: RotorSystem, q0: Sequence[float], w0: Sequence[float], t_end: float, *,
                 controller: Controller | None = None, u0: dict[str, int] | None = None, sample_dt: float = 1e-3,
                 rtol: float = 1e-10, atol: float = 1e-12, max_step: float = np.inf, v_tol: float = 1e-9,
                 max_events_at_instant: int = 50):
        self.sys = sys
        self.n, self.ne = sys.n, len(sys.frictions)
        self.part_owner = [e for e, f in enumerate(sys.frictions) for _ in f.parts]
        self.peaks = np.array([f.peak for f in sys.frictions])
        self.labels = sys.part_labels()
        if len(set(self.labels)) != len(self.labels):
            raise ParameterError(f"friction part labels must be unique, got {self.labels}")
        self.t_end = t_end
        self.controller = controller
        self.rtol, self.atol, self.max_step, self.v_tol = rtol, atol, max_step, v_tol
        self.max_events_at_instant = max_events_at_instant
        self.u = {c: 0 for c in sys.commands()}
        self.u.update(u0 or {})
        self.queue = CommandQueue(sys.delays, controller.dt if controller else 1.0, self.u) if controller else None
        self.modes = np.full(self.ne, FREE)
        # a level below this is "free" (a schedule crossing zero leaves round-off like 20*cos(pi/2) = 1e-15)
        self.free_tol = np.array([1e-12 * max(1.0, sum(p.level for p in f.parts)) for f in sys.frictions])
        self.events: list[dict[str, Any]] = []
        self.dampers = sys.dampers()
        self.one_way = np.array([f.one_way_hold is not None for f in sys.frictions], bool)
        self.ne_tot = 1 + self.n + len(self.part_owner) + len(self.dampers)
        self._cfg_cache: dict[tuple, StuckProjection] = {}
        self.stats: dict[str, Any] = {"nfev": 0, "steps": 0, "restarts": 0, "reset_energy": 0.0, "events": 0}
        y = np.concatenate([np.asarray(q0, float), np.asarray(w0, float), np.zeros(self.ne_tot)])
        self.t = 0.0
        self.y = self._resolve(self.t, y, set(), set())
        self.t_samples = np.arange(0.0, t_end + 0.5 * sample_dt, sample_dt)
        self._out_y = np.empty((self.t_samples.size, y.size))
        self._out_m = np.empty((self.ne, self.t_samples.size), dtype=int)
        self._out_u = {c: np.empty(self.t_samples.size) for c in self.u}
        self._out_reset = np.empty(self.t_samples.size)  # cumulative plastic-lock loss, in step with the state
        self._i_out = 0
        self._ctrl_k = 0
        self._breaks = sorted(b for b in sys.breaks if 0.0 < b < t_end)
        self._bi = 0
        self._same_instant = 0
        self._last_event_t = -1.0
        self.solver: DOP853 | None = None  # the solver of the current smooth piece (None between pieces)
        self._f_known: list[tuple[float, np.ndarray]] = []  # (t, right-hand side) at the solver step's ends
        self._graze: dict[int, float] | None = None
        self._cfg: StuckProjection | None = None  # the piece's projection and sliding elements (modes fixed on a piece)
        self._slid: list[tuple[int, int]] = []
        self._evs: list = []
        self._g_old: list[float] = []
        self.done = False
        if controller is not None:  # controller at t = 0
            self.queue.issue(0, controller(0, 0.0, self.y[:self.n], self.y[self.n:2 * self.n]))
            self._ctrl_k = 1

    # ---- levels, configurations, forces --------------------------------------------------------------------------
    def levels(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Sliding torque of every part and of every element at t under the current commands."""
        lv = self.sys.levels(t, self.u)
        el = np.zeros(self.ne)
        np.add.at(el, self.part_owner, lv)
        return lv, el

    def config(self, t: float) -> StuckProjection:
        """The projection of the current set of stuck elements (cached; capacities only matter for closed loops of
        stuck elements, rebuilt if they changed)."""
        stuck = [e for e in range(self.ne) if self.modes[e] == STUCK]
        _, el = self.levels(t)
        caps = np.array([self.capacity(e, el) for e in stuck]) if stuck else np.zeros(0)
        key = tuple(stuck)
        c = self._cfg_cache.get(key)
        if c is None or (len(stuck) > 1 and not np.allclose(c.caps, caps)):
            c = StuckProjection(self.sys, stuck, caps)
            c.caps = caps  # type: ignore[attr-defined]
            self._cfg_cache[key] = c
        return c

    def forces(self, t: float, q: np.ndarray, w: np.ndarray, el: np.ndarray) -> np.ndarray:
        """Torques on the rotors: sources, springs, viscous bearings and the sliding elements."""
        f, _ = self.sys.free_torque(t, q, w)
        for e in range(self.ne):
            if self.modes[e] in (FWD, BWD):
                self.sys.apply(f, e, self.modes[e] * el[e])
        return f

    def _rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """Right-hand side of the current smooth piece (its modes and projection fixed): q' = w, w' = Pa f, and the
        energy rates [source power, B w^2 per rotor, level |slip| per sliding part]."""
        n, sys, cfg, slid = self.n, self.sys, self._cfg, self._slid
        q = y[:n]
        w = y[n:2 * n]
        f, p_src = sys.free_torque(t, q, w)
        lv, el = self.levels(t) if slid else (None, None)
        dy = np.empty(2 * n + self.ne_tot)
        dE = dy[2 * n:]
        dE[:] = 0.0
        for e, d in slid:
            fr = sys.frictions[e]
            sys.apply(f, e, d * el[e])
            wr = abs(((w[fr.b] if fr.b >= 0 else 0.0) - w[fr.a]) if fr.g is None else float(sys.rows[e] @ w))
            for i, pe in enumerate(self.part_owner):
                if pe == e:
                    dE[1 + n + i] = lv[i] * wr
        dy[:n] = w
        dy[n:2 * n] = cfg.Pa @ f
        dE[0] = p_src
        dE[1:1 + n] = sys.B * w * w
        k0 = 1 + n + len(self.part_owner)
        for i, s in enumerate(self.dampers):
            d_w = w[s.a] - (w[s.b] if s.b >= 0 else 0.0)
            dE[k0 + i] = s.D * d_w * d_w
        return dy

    def _slip(self, fr: Friction, t: float, y: np.ndarray) -> float:
        """Event function of a sliding element: its slip w_b - w_a (a lock when it reaches 0)."""
        n = self.n
        if fr.g is not None:
            return float(np.asarray(fr.g, float) @ y[n:2 * n])
        return (y[n + fr.b] if fr.b >= 0 else 0.0) - y[n + fr.a]

    def _margin(self, r: int, e: int, t: float, y: np.ndarray) -> float:
        """Event function of stuck element e (row r of the piece's projection): breakaway - |constraint torque|."""
        n = self.n
        el = self.levels(t)[1]
        lam = self._cfg.L[r] @ self.forces(t, y[:n], y[n:2 * n], el)
        if self.one_way[e]:  # a freewheel holds any torque toward w_rel < 0
            return self.capacity(e, el) - lam
        return self.capacity(e, el) - abs(lam)

    def capacity(self, e: int, el: np.ndarray) -> float:
        """Breakaway torque of element e at element levels el (a one-way clutch: peak x level while engaged, its
        hold torque while disengaged; Modelica `OneWayClutch.tau0_max`)."""
        if self.one_way[e] and el[e] <= self.free_tol[e]:
            return float(self.sys.frictions[e].one_way_hold)
        return float(self.peaks[e] * el[e])

    def _engaging(self, e: int, t: float, y: np.ndarray) -> float:
        """Event function of a free element: its level above the free tolerance (engagement by a rising schedule,
        e.g. a ramp from zero; Modelica's `free = fn <= 0` relation)."""
        return float(self.levels(t)[1][e] - 2.0 * self.free_tol[e])  # 2x: at the located root it is engaged

    def _event_functions(self) -> list:
        """Event functions g(t, y) of the current piece, the crossing direction that fires them and their tags: a
        sliding element's slip reaching zero (lock), a stuck element's constraint torque reaching its breakaway torque
        (break)."""
        funcs = [(partial(self._slip, self.sys.frictions[e]), -d, ("lock", e)) for e, d in self._slid]
        funcs += [(partial(self._margin, r, e), -1, ("break", e)) for r, e in enumerate(self._cfg.stuck)]
        funcs += [(partial(self._engaging, e), 1, ("engage", e)) for e in range(self.ne)
                  if self.modes[e] == FREE and any(p.schedule is not None for p in self.sys.frictions[e].parts)]
        return funcs

    # ---- mode changes ---------------------------------------------------------------------------------------------
    def _resolve(self, t: float, y: np.ndarray, lock_try: set[int], force_break: set[int]) -> np.ndarray:
        """Consistent modes at time t (Modelica's event iteration): try to lock every engaged element at zero slip,
        then release the most overloaded stuck element (torque above breakaway) until every stuck torque fits; the
        plastic lock equalises the velocities of rigid groups (momentum conserving projection)."""
        n, ne, modes = self.n, self.ne, self.modes
        w = y[n:2 * n]
        _, el = self.levels(t)
        wr = self.sys.w_rel(w)
        old = modes.copy()
        must_break: set[int] = set()
        for e in range(ne):
            if self.one_way[e]:  # Modelica OneWayClutch: stuck = locked or w_rel <= 0; slides forward only
                if modes[e] == FREE:
                    modes[e] = FWD if wr[e] > self.v_tol else STUCK
                elif modes[e] == FWD and (e in lock_try or wr[e] <= self.v_tol):
                    modes[e] = STUCK
                elif modes[e] == STUCK and e in force_break:
                    must_break.add(e)
            elif el[e] <= self.free_tol[e]:
                modes[e] = FREE
            elif modes[e] == FREE:
                modes[e] = STUCK if abs(wr[e]) <= self.v_tol else int(np.sign(wr[e]))
            elif modes[e] in (FWD, BWD) and (e in lock_try or abs(wr[e]) <= self.v_tol):
                modes[e] = STUCK
            elif modes[e] == STUCK and e in force_break:
                must_break.add(e)
        for _ in range(2 * ne + 2):
            cfg = self.config(t)
            if not cfg.stuck:
                break
            f = self.forces(t, y[:n], cfg.Pw @ w, el)
            lam = cfg.lam(f)
            ratio = np.array([(max(lam[r], 0.0) if self.one_way[e] else abs(lam[r])) / self.capacity(e, el)
                              for r, e in enumerate(cfg.stuck)])
            for r, e in enumerate(cfg.stuck):
                if e in must_break:
                    ratio[r] = max(ratio[r], 1.0 + 1e-6)
            r = int(np.argmax(ratio))
            if ratio[r] <= 1.0 + 1e-12:
                break
            e = cfg.stuck[r]
            modes[e] = FWD if lam[r] > 0 else BWD
            must_break.discard(e)
        cfg = self.config(t)
        y = y.copy()
        w_new = cfg.Pw @ w
        self.stats["reset_energy"] += 0.5 * float(np.sum(self.sys.J * (w**2 - w_new**2)))
        y[n:2 * n] = w_new
        for e in range(ne):
            if modes[e] != old[e] and t > 0.0:
                self.events.append({"t": float(t), "element": self.sys.frictions[e].name,
                                    "from": MODE_NAME[int(old[e])], "to": MODE_NAME[int(modes[e])]})
        return y

    def _record(self, tt: float, yy) -> None:
        """Sample the output grid up to tt from the dense output (or a constant state)."""
        ts = self.t_samples
        while self._i_out < ts.size and ts[self._i_out] <= tt + 1e-12:
            i = self._i_out
            self._out_y[i] = yy(ts[i]) if callable(yy) else yy
            self._out_m[:, i] = self.modes
            for c in self.u:
                self._out_u[c][i] = self.u[c]
            self._out_reset[i] = self.stats["reset_energy"]
            self._i_out += 1

    def _actuate(self) -> bool:
        """Apply the commands due now; True if a command state changed."""
        changed = False
        while self.queue.pending and self.queue.pending[0][0] <= self.t + 1e-12:
            _, c, v = self.queue.pending.pop(0)
            if self.u.get(c) != v:
                self.u[c] = v
                changed = True
        return changed

    # ---- stepping -------------------------------------------------------------------------------------------------
    def _start_piece(self) -> None:
        """A new smooth piece from the current state: modes fixed, fresh DOP853."""
        self._cfg = self.config(self.t)
        self._slid = [(e, int(self.modes[e])) for e in range(self.ne) if self.modes[e] in (FWD, BWD)]
        self._evs = self._event_functions()
        self.solver = DOP853(self._rhs, self.t, self.y, self.t_end, rtol=self.rtol, atol=self.atol,
                             max_step=self.max_step)
        self._f_known, self._graze = [], None
        self.stats["restarts"] += 1
        self._g_old = [g(self.t, self.y) for g, _, _ in self._evs]

    def _end_piece(self) -> None:
        self.stats["nfev"] += self.solver.nfev
        self.solver = None

    def _next_hard_time(self) -> tuple[float, str]:
        """The next time breakpoint: schedule break, pending actuation, controller sample, or the end."""
        t = self.t
        t_hard, kind = self.t_end, "end"
        while self._bi < len(self._breaks) and self._breaks[self._bi] <= t + 1e-15:
            self._bi += 1
        if self._bi < len(self._breaks) and self._breaks[self._bi] < t_hard:
            t_hard, kind = self._breaks[self._bi], "break"
        if self.queue is not None and self.queue.pending and self.queue.pending[0][0] < t_hard:
            t_hard, kind = self.queue.pending[0][0], "actuate"
        if self.controller is not None and self._ctrl_k * self.controller.dt < t_hard - 1e-15:
            t_hard, kind = self._ctrl_k * self.controller.dt, "sample"
        return t_hard, kind

    def step(self) -> None:
        """One step of the current piece's solver (a new piece is started first if needed); ends the piece at an
        event (after resolving the modes) or at a breakpoint that changes a command or schedule."""
        if self.done:
            return
        if self.solver is None:
            if self.t >= self.t_end - 1e-15:
                self._finish()
                return
            self._start_piece()
        solver = self.solver
        t_hard, kind = self._next_hard_time()
        # a new solver step only once the current one is used up: after a breakpoint that kept the piece (a controller
        # sample that changed nothing), the rest of the step, (self.t, solver.t], is scanned and recorded first with
        # this step's own dense output - stepping on would evaluate the next step's interpolant before its start
        # (extrapolated samples) and miss an event inside the rest
        if self.t >= solver.t and solver.t < t_hard and solver.status == "running":
            self._f_known = [(solver.t, solver.f)]  # the right-hand side at the step's start (`_grazing_step`)
            msg = solver.step()
            self._f_known.append((solver.t, solver.f))
            self._graze = None  # grazing locks of this solver step: found at its first scan
            if solver.status == "failed":
                raise SolverError(f"reference integrator failed at t = {solver.t:.6g} s: {msg}")
            self.stats["steps"] += 1
        t_new = min(solver.t, t_hard)
        sol = solver.dense_output() if solver.t_old is not None else None
        yfun = sol if sol is not None else _const(self.y)
        t_lo = solver.t_old if solver.t_old is not None else self.t
        t_lo = max(t_lo, self.t)
        y_new = yfun(t_new) if t_new < solver.t else solver.y
        g_new = [g(t_new, y_new) for g, _, _ in self._evs]
        fired = self._fired(g_new, yfun, t_lo, t_new)
        if fired:
            self._on_event(fired, yfun)
            self._end_piece()
        elif t_new >= t_hard - 1e-15 and t_hard < solver.t + 1e-15:
            self._record(t_hard, yfun)
            self.y = y_new if t_new < solver.t else solver.y
            self.t = t_hard
            if self._on_breakpoint(kind):
                self._end_piece()
            else:  # same smooth piece: keep the solver; the rest of its step is scanned in the next pass
                self._g_old = [g(self.t, self.y) for g, _, _ in self._evs]
        else:
            self._record(t_new, yfun)
            self._g_old = g_new
            self.t = t_new
            self.y = solver.y
            if solver.status == "finished":
                self._end_piece()

    def _fired(self, g_new: list[float], yfun, t_lo: float, t_new: float) -> list:
        """Events whose function crossed in its direction within (t_lo, t_new], with their located times."""
        fired = []
        for i, (g, d, tag) in enumerate(self._evs):
            a0, a1 = self._g_old[i], g_new[i]
            if (d < 0 and a0 > 0 and a1 <= 0) or (d > 0 and a0 < 0 and a1 >= 0):
                def gf(tt: float, g=g, yf=yfun) -> float:
                    return g(tt, yf(tt))

                te = _root(gf, t_lo, t_new)
                if tag[0] == "engage":  # a schedule jumping up: the first instant at which the element is engaged
                    for _ in range(8):
                        if te >= t_new or gf(te) >= 0.0:
                            break
                        te = min(t_new, float(np.nextafter(te, np.inf)))
                fired.append((te, tag))
            elif tag[0] != "engage" and t_new > t_lo and -d * a0 <= 0.0 and -d * a1 < 0.0:
                # a function that starts a piece at its zero - a slip after a pass-through (the lock was tried and
                # the element slides on the other way), a stuck torque at its breakaway limit - starts with a
                # round-off residue of either sign; on the wrong side its later crossing changes no sign at the
                # scan's ends, so it is located on the dense output instead (the same outcome for either residue)
                fired.append((self._first_return(lambda tt, g=g, yf=yfun, d=d: -d * g(tt, yf(tt)), t_lo, t_new), tag))
            elif tag[0] == "lock" and t_new > t_lo and -d * a0 > self.v_tol:
                if self._graze is None:
                    self._graze = self._grazing_step(yfun)
                te = self._graze.get(tag[1])
                if te is not None and t_lo < te <= t_new:
                    fired.append((te, tag))
        return fired

    @staticmethod
    def _first_return(s: Callable[[float], float], t_lo: float, t_new: float, n: int = 64) -> float:
        """First instant in (t_lo, t_new] at which an event function s (signed so that > 0 is its armed side: a slip
        in its sliding direction, a breakaway margin), having risen above zero, comes back to zero; s(t_lo) is a
        round-off residue <= 0 and s(t_new) < 0. The dense output is sampled at n points to bracket the first
        positive-to-non-positive change (a degree-7 interpolant has at most 7 roots), then located by `_root`. A
        function that never rose fires at t_lo (the state machine decides again there: a stuck torque past its limit
        breaks; a slip that cannot open is tried as a lock, a repeat is caught as mode chattering)."""
        ts = np.linspace(t_lo, t_new, n + 1)
        opened = False
        for k in range(1, n + 1):
            sk = s(float(ts[k]))
            if sk > 0.0:
                opened = True
            elif opened:
                return _root(s, float(ts[k - 1]), float(ts[k]))
        return t_lo

    def _grazing_step(self, yfun) -> dict[int, float]:
        """Grazing locks inside the current solver step: a slip that touches zero and turns back (e.g. a freewheel
        whose input torque reverses just as the speeds meet) changes no sign at the step's ends, but its rate turns
        from closing to opening inside it (the rates at the ends are the solver's own right-hand sides: free). Then
        the minimum is located; if the slip there is <= 0, the lock is the slip's first zero before it. Returns
        {element: lock time}."""
        out: dict[int, float] = {}
        if len(self._f_known) != 2 or self.solver is None or self.solver.t_old is None:
            return out
        (t0, f0), (t1, f1) = self._f_known
        n = self.n
        for e, d in self._slid:
            row, sgn = self.sys.rows[e], d
            if not (sgn * float(row @ f0[n:2 * n]) < 0.0 < sgn * float(row @ f1[n:2 * n])):
                continue

            def rate(tt: float, row=row, sgn=sgn) -> float:
                return sgn * float(row @ self._rhs(tt, yfun(tt))[n:2 * n])

            def slip(tt: float, row=row, sgn=sgn) -> float:
                return sgn * float(row @ yfun(tt)[n:2 * n])

            if slip(t0) <= self.v_tol:  # at the start of a slip
                continue
            tm = _root(rate, t0, t1)
            if slip(tm) <= 0.0:
                out[e] = _root(slip, t0, tm)
        return out

    def _on_event(self, fired: list, yfun) -> None:
        """Go to the earliest event, resolve the modes there (all events within 1e-13 s of it together)."""
        te = min(f[0] for f in fired)
        tags = [tag for tf, tag in fired if tf <= te + 1e-13]
        self._record(te, yfun)
        self.y = yfun(te)
        self.t = te
        self._same_instant = self._same_instant + 1 if abs(self.t - self._last_event_t) < 1e-12 else 0
        self._last_event_t = self.t
        if self._same_instant > self.max_events_at_instant:
            raise SolverError(f"friction state machine does not settle at t = {self.t:.9g} s (mode chattering)")
        self.stats["events"] += 1
        self.y = self._resolve(self.t, self.y, {e for k, e in tags if k == "lock"},
                               {e for k, e in tags if k == "break"})

    def _on_breakpoint(self, kind: str) -> bool:
        """At a time breakpoint: apply it; True if the piece ends (a command or schedule changed, or the end)."""
        changed = False
        if kind == "break":
            self._bi += 1
            changed = True
        elif kind == "actuate":
            changed = self._actuate()
        elif kind == "sample":
            n = self.n
            self.queue.issue(self._ctrl_k, self.controller(self._ctrl_k, self.t, self.y[:n], self.y[n:2 * n]))
            self._ctrl_k += 1
            if self.queue.pending and self.queue.pending[0][0] <= self.t + 1e-12:
                changed = self._actuate()
        if kind == "end":
            return True
        if changed:
            self.y = self._resolve(self.t, self.y, set(), set())
            return True
        return False

    def run(self, t_end: float) -> ReferenceSimulator:
        """Step until time t_end (at most the run's t_end; `mbsuite.stepping.StepObject`); returns self."""
        t = min(t_end, self.t_end)
        while not self.done and (self.t < t - 1e-15 or (t >= self.t_end - 1e-15 and self.solver is not None)):
            self.step()
        if t >= self.t_end - 1e-15:
            self._finish()
        return self

    @property
    def status(self) -> str:
        """"running" until the run reached t_end, then "finished" (`mbsuite.stepping.StepObject`; a failing step
        raises SolverError)."""
        return "finished" if self.done else "running"

    def _finish(self) -> None:
        if not self.done:
            y = self.y
            self._record(self.t_end + 1e-9, lambda tt: y)
            self.done = True

    def result(self) -> RefResult:
        """The sampled result of the steps made so far (the whole run after `run(t_end)`)."""
        n, m = self.n, self._i_out
        Y = self._out_y[:m]
        e_names = (["source"] + [f"viscous_{nm}" for nm in self.sys.names] + self.labels
                   + [f"damper_{s.name}" for s in self.dampers])
        energy = {nm: Y[:, 2 * n + i] for i, nm in enumerate(e_names)}
        energy["lock_impact"] = self._out_reset[:m]
        return RefResult(t=self.t_samples[:m], q=Y[:, :n].T, w=Y[:, n:2 * n].T, modes=self._out_m[:, :m],
                         energy=energy, events=self.events, u={c: v[:m] for c, v in self._out_u.items()},
                         stats=self.stats)


def simulate_reference(
    sys: RotorSystem,
    q0: Sequence[float],
    w0: Sequence[float],
    t_end: float,
    *,
    controller: Controller | None = None,
    u0: dict[str, int] | None = None,
    sample_dt: float = 1e-3,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    max_step: float = np.inf,
    v_tol: float = 1e-9,
    max_events_at_instant: int = 50,
) -> RefResult:
    """Event-exact simulation of `sys` from (q0, w0) to t_end (`ReferenceSimulator`); see the module docstring."""
    return ReferenceSimulator(sys, q0, w0, t_end, controller=controller, u0=u0, sample_dt=sample_dt, rtol=rtol,
                              atol=atol, max_step=max_step, v_tol=v_tol,
                              max_events_at_instant=max_events_at_instant).run(t_end).result()
