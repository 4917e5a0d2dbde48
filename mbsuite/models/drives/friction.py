"""Coaxial rotor systems with Coulomb friction elements and an event-exact stick/slip state machine (hand-derived path).

A `RotorSystem` is a set of rigid rotors (inertia J_i, viscous bearing B_i to ground), linear torsion springs (between
two rotors or a rotor and ground), torque sources tau = c0*shape(t) + c1*w, and *friction elements* (clutches between
two rotors, brakes/bearings/Coulomb loads between a rotor and ground). The semantics follow Modelica's
`Rotational.Interfaces.PartialFriction` (modes -1 backward sliding, 0 stuck, 1 forward sliding, 2 free):

* sliding: the element transmits tau_e = mode * level(t) (level = sliding torque), w_rel = w_b - w_a;
* a sliding element locks when w_rel reaches 0 **and** the torque needed to hold it is within the breakaway limit
  peak * level; otherwise it passes through to sliding the other way;
* a stuck element breaks loose when its constraint torque reaches +-peak * level and then slides at `level`;
* level <= 0 means free (no torque);
* several stuck elements form rigid groups (nested locks: clutch + brake, both clutches, all three bodies). The
  accelerations of a configuration are the M-orthogonal projection onto the constraint subspace; the constraint torques
  are the capacity-weighted minimum-norm solution (exact when the stuck elements contain no closed loop; for parallel
  elements it shares the torque in proportion to capacity, so they break together).

Sign convention: an element between rotor a and rotor b (b = -1: ground) acts with +tau_e on a and -tau_e on b.

`simulate_reference` integrates the smooth pieces with scipy's DOP853 (dense output) and locates every lock/break
event by root finding on the dense output (brentq, |dt| ~ 1e-14 s); time breakpoints (controller actions, normal-force
steps) truncate the step exactly. A discrete controller is sampled at its period through the dense output.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
from scipy.integrate import DOP853
from scipy.optimize import brentq

from ...errors import ParameterError, SolverError

FWD, STUCK, BWD, FREE = 1, 0, -1, 2
MODE_NAME = {FWD: "forward", STUCK: "stuck", BWD: "backward", FREE: "free"}


@dataclass
class Part:
    """One contribution to a friction element's sliding torque: `level` N m, times the command `command` (0/1, None =
    always on) times `schedule(t)` (clipped at 0; None = 1). `output=True` marks a useful load (its work is output)."""

    label: str
    level: float
    command: str | None = None
    schedule: Callable[[float], float] | None = None
    output: bool = False


@dataclass
class Friction:
    """A Coulomb friction element between rotor `a` and rotor `b` (-1 = ground). Breakaway = `peak` x sliding torque."""

    name: str
    a: int
    b: int
    parts: list[Part]
    peak: float = 1.0


@dataclass
class Spring:
    """Linear torsion spring K (N m/rad) between rotor a and rotor b (-1 = ground): tau_a = -K (q_a - q_b)."""

    name: str
    a: int
    b: int
    K: float


@dataclass
class Source:
    """Torque source on rotor `body`: tau = c0 * shape(t) + c1 * w (a DC motor: c0 = Kt Vs / R, c1 = -Kt Ke / R)."""

    label: str
    body: int
    c0: float
    c1: float = 0.0
    shape: Callable[[float], float] | None = None


@dataclass
class RotorSystem:
    names: list[str]
    J: np.ndarray
    B: np.ndarray
    springs: list[Spring] = field(default_factory=list)
    frictions: list[Friction] = field(default_factory=list)
    sources: list[Source] = field(default_factory=list)
    breaks: list[float] = field(default_factory=list)  # times where a schedule jumps or crosses zero
    delays: dict[str, tuple[float, float]] = field(default_factory=dict)  # command -> (engage, release) delay (s)

    def __post_init__(self) -> None:
        self.J = np.asarray(self.J, float)
        self.B = np.asarray(self.B, float)
        for nm, j in zip(self.names, self.J, strict=True):
            if not (np.isfinite(j) and j > 0):
                raise ParameterError(f"inertia of rotor '{nm}' must be positive, got {j!r} kg m^2")
        for nm, b in zip(self.names, self.B, strict=True):
            if not (np.isfinite(b) and b >= 0):
                raise ParameterError(f"viscous bearing coefficient of rotor '{nm}' must be >= 0, got {b!r} N m s/rad")
        for s in self.springs:
            if not (np.isfinite(s.K) and s.K > 0):
                raise ParameterError(f"spring rate of '{s.name}' must be positive, got {s.K!r} N m/rad")
        for f in self.frictions:
            if f.peak < 1.0:
                raise ParameterError(f"breakaway factor of '{f.name}' must be >= 1, got {f.peak!r}")
            for p in f.parts:
                if not (np.isfinite(p.level) and p.level >= 0):
                    raise ParameterError(f"friction torque '{p.label}' of '{f.name}' must be >= 0, got {p.level!r} N m")

    @property
    def n(self) -> int:
        return len(self.names)

    def commands(self) -> list[str]:
        return sorted({p.command for f in self.frictions for p in f.parts if p.command})

    def part_labels(self) -> list[str]:
        return [p.label for f in self.frictions for p in f.parts]

    def levels(self, t: float, u: dict[str, float]) -> np.ndarray:
        """Sliding torque of every part at time t under engagement states u (flattened over elements)."""
        out = []
        for f in self.frictions:
            for p in f.parts:
                v = p.level
                if p.command is not None:
                    v *= u.get(p.command, 0.0)
                if p.schedule is not None:
                    v *= max(0.0, p.schedule(t))
                out.append(v)
        return np.asarray(out, float)

    def w_rel(self, w: np.ndarray) -> np.ndarray:
        return np.array([(w[f.b] if f.b >= 0 else 0.0) - w[f.a] for f in self.frictions])

    def G(self, idx: Sequence[int]) -> np.ndarray:
        """Constraint rows (d/dt w_rel) of the friction elements `idx`."""
        G = np.zeros((len(idx), self.n))
        for r, e in enumerate(idx):
            f = self.frictions[e]
            G[r, f.a] -= 1.0
            if f.b >= 0:
                G[r, f.b] += 1.0
        return G

    def stored_energy(self, q: np.ndarray, w: np.ndarray) -> tuple[float, float]:
        ke = 0.5 * float(np.sum(self.J * w**2))
        pe = 0.0
        for s in self.springs:
            d = q[s.a] - (q[s.b] if s.b >= 0 else 0.0)
            pe += 0.5 * s.K * d * d
        return ke, pe

    def free_torque(self, t: float, q: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, float]:
        """Torques of sources, springs and viscous bearings on each rotor, and the source power."""
        f = -self.B * w
        p_src = 0.0
        for s in self.sources:
            tau = s.c0 * (s.shape(t) if s.shape is not None else 1.0) + s.c1 * w[s.body]
            f[s.body] += tau
            p_src += tau * w[s.body]
        for s in self.springs:
            d = q[s.a] - (q[s.b] if s.b >= 0 else 0.0)
            f[s.a] -= s.K * d
            if s.b >= 0:
                f[s.b] += s.K * d
        return f, p_src


class Controller(Protocol):
    """A discrete controller sampled every `dt` seconds; returns the commanded states {command: 0/1} (or None)."""

    dt: float

    def __call__(self, k: int, t: float, q: np.ndarray, w: np.ndarray) -> dict[str, int] | None: ...


def delay_samples(delay: float, fs: float) -> int:
    """Actuation delay in controller samples, as the thesis' shift registers: `count = (int)(delay*sample_rate)`
    (App. C L2569-2575), i.e. truncation - but of the product rounded to 9 decimals, so that a delay that is a whole
    number of samples in decimal (0.3 ms at 10 kHz: 0.0003*10000 = 2.9999999999999996 in binary) gives that number
    (3), not one less. The one conversion used by the command queue, the controllers and `drive.build_controller`."""
    if not (math.isfinite(delay) and delay >= 0.0):
        raise ParameterError(f"actuation delay must be a finite number >= 0 s, got {delay!r}")
    if not (math.isfinite(fs) and fs > 0.0):
        raise ParameterError(f"controller sample rate must be positive, got {fs!r}")
    return int(math.floor(round(delay * fs, 9)))


class CommandQueue:
    """Commands with pure actuation delays quantised to controller samples (`delay_samples`, thesis App. C)."""

    def __init__(self, delays: dict[str, tuple[float, float]], dt: float, initial: dict[str, int]):
        fs = 1.0 / dt
        self.counts = {c: (delay_samples(d_on, fs), delay_samples(d_off, fs)) for c, (d_on, d_off) in delays.items()}
        self.dt = dt
        self.commanded = dict(initial)
        self.pending: list[tuple[float, str, int]] = []

    def issue(self, k: int, cmds: dict[str, int] | None) -> None:
        if not cmds:
            return
        for c, v in cmds.items():
            if self.commanded.get(c, 0) != v:
                self.commanded[c] = v
                n_on, n_off = self.counts.get(c, (0, 0))
                n = n_on if v else n_off
                self.pending.append(((k + n) * self.dt, c, int(v)))
        self.pending.sort()


@dataclass
class RefResult:
    t: np.ndarray
    q: np.ndarray
    w: np.ndarray
    modes: np.ndarray  # (n_elements, n_samples)
    energy: dict[str, np.ndarray]
    events: list[dict[str, Any]]
    u: dict[str, np.ndarray]
    stats: dict[str, Any]


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


class _Config:
    """Precomputed projection for one set of stuck elements."""

    def __init__(self, sys: RotorSystem, stuck: list[int], caps: np.ndarray):
        n = sys.n
        Minv = np.diag(1.0 / sys.J)
        self.stuck = stuck
        if stuck:
            G = sys.G(stuck)
            S = G @ Minv @ G.T
            Sp = np.linalg.pinv(S, rcond=1e-12)
            self.Pa = Minv - Minv @ G.T @ Sp @ G @ Minv
            self.Pw = np.eye(n) - Minv @ G.T @ Sp @ G  # plastic-impact velocity projection
            W = np.diag(np.maximum(caps, 1e-300) ** 2)
            R = np.eye(n) - np.diag(sys.J) @ self.Pa  # f -> constraint torque resultant r = f - M a
            self.L = W @ G @ np.linalg.pinv(G.T @ W @ G, rcond=1e-12) @ R
        else:
            self.Pa = Minv
            self.Pw = np.eye(n)
            self.L = np.zeros((0, n))

    def lam(self, f: np.ndarray) -> np.ndarray:
        return self.L @ f


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
    """Event-exact simulation of `sys` from (q0, w0) to t_end; see the module docstring for the semantics."""
    n, ne = sys.n, len(sys.frictions)
    part_owner = [e for e, f in enumerate(sys.frictions) for _ in f.parts]
    npart = len(part_owner)
    peaks = np.array([f.peak for f in sys.frictions])
    labels = sys.part_labels()
    if len(set(labels)) != len(labels):
        raise ParameterError(f"friction part labels must be unique, got {labels}")
    u = {c: 0 for c in sys.commands()}
    u.update(u0 or {})
    queue = CommandQueue(sys.delays, controller.dt if controller else 1.0, u) if controller else None

    def elem_levels(t: float) -> tuple[np.ndarray, np.ndarray]:
        lv = sys.levels(t, u)
        el = np.zeros(ne)
        np.add.at(el, part_owner, lv)
        return lv, el

    modes = np.full(ne, FREE)
    # a level below this is "free" (a schedule crossing zero leaves round-off like 20*cos(pi/2) = 1e-15)
    free_tol = np.array([1e-12 * max(1.0, sum(p.level for p in f.parts)) for f in sys.frictions])
    events: list[dict[str, Any]] = []
    # energy layout: [source, viscous per rotor (n), per part (npart)]
    ne_tot = 1 + n + npart

    cfg_cache: dict[tuple, _Config] = {}

    def config(t: float) -> _Config:
        stuck = [e for e in range(ne) if modes[e] == STUCK]
        _, el = elem_levels(t)
        caps = peaks[stuck] * el[stuck] if stuck else np.zeros(0)
        key = tuple(stuck)
        c = cfg_cache.get(key)
        # capacities only matter for closed loops of stuck elements; rebuild if they changed
        if c is None or (len(stuck) > 1 and not np.allclose(c.caps, caps)):
            c = _Config(sys, stuck, caps)
            c.caps = caps  # type: ignore[attr-defined]
            cfg_cache[key] = c
        return c

    def make_rhs(cfg: _Config):
        slid = [(e, int(modes[e])) for e in range(ne) if modes[e] in (FWD, BWD)]
        Bw = sys.B

        def rhs(t: float, y: np.ndarray) -> np.ndarray:
            q = y[:n]
            w = y[n:2 * n]
            f, p_src = sys.free_torque(t, q, w)
            lv, el = elem_levels(t) if slid else (None, None)
            dy = np.empty(2 * n + ne_tot)
            dE = dy[2 * n:]
            dE[:] = 0.0
            for e, d in slid:
                fr = sys.frictions[e]
                tau = d * el[e]
                f[fr.a] += tau
                if fr.b >= 0:
                    f[fr.b] -= tau
                wr = abs((w[fr.b] if fr.b >= 0 else 0.0) - w[fr.a])
                for i, pe in enumerate(part_owner):
                    if pe == e:
                        dE[1 + n + i] = lv[i] * wr
            dy[:n] = w
            dy[n:2 * n] = cfg.Pa @ f
            dE[0] = p_src
            dE[1:1 + n] = Bw * w * w
            return dy

        return rhs, slid

    def event_funcs(cfg: _Config, slid):
        """Event functions g(t, y) and the crossing direction that fires them."""
        funcs = []
        for e, d in slid:
            fr = sys.frictions[e]

            def g(t, y, fr=fr):
                return (y[n + fr.b] if fr.b >= 0 else 0.0) - y[n + fr.a]

            funcs.append((g, -d, ("lock", e)))
        for r, e in enumerate(cfg.stuck):

            def gb(t, y, r=r, e=e):
                el = elem_levels(t)[1]
                lam = cfg.L[r] @ forces(t, y[:n], y[n:2 * n], el)
                return peaks[e] * el[e] - abs(lam)

            funcs.append((gb, -1, ("break", e)))
        return funcs

    def resolve(t: float, y: np.ndarray, lock_try: set[int], force_break: set[int]) -> np.ndarray:
        """Consistent modes at time t (Modelica's event iteration): try to lock every engaged element at zero slip,
        then release the most overloaded stuck element (torque above breakaway) until every stuck torque fits."""
        w = y[n:2 * n]
        _, el = elem_levels(t)
        wr = sys.w_rel(w)
        old = modes.copy()
        must_break: set[int] = set()
        for e in range(ne):
            if el[e] <= free_tol[e]:
                modes[e] = FREE
            elif modes[e] == FREE:
                modes[e] = STUCK if abs(wr[e]) <= v_tol else int(np.sign(wr[e]))
            elif modes[e] in (FWD, BWD) and (e in lock_try or abs(wr[e]) <= v_tol):
                modes[e] = STUCK
            elif modes[e] == STUCK and e in force_break:
                must_break.add(e)
        for _ in range(2 * ne + 2):
            cfg = config(t)
            if not cfg.stuck:
                break
            f = forces(t, y[:n], cfg.Pw @ w, el)
            lam = cfg.lam(f)
            ratio = np.abs(lam) / (peaks[cfg.stuck] * el[cfg.stuck])
            for r, e in enumerate(cfg.stuck):
                if e in must_break:
                    ratio[r] = max(ratio[r], 1.0 + 1e-6)
            r = int(np.argmax(ratio))
            if ratio[r] <= 1.0 + 1e-12:
                break
            e = cfg.stuck[r]
            modes[e] = FWD if lam[r] > 0 else BWD
            must_break.discard(e)
        # plastic lock: equalise the velocities of rigid groups (momentum conserving projection)
        cfg = config(t)
        y = y.copy()
        w_new = cfg.Pw @ w
        stats["reset_energy"] += 0.5 * float(np.sum(sys.J * (w**2 - w_new**2)))
        y[n:2 * n] = w_new
        for e in range(ne):
            if modes[e] != old[e] and t > 0.0:
                events.append({"t": float(t), "element": sys.frictions[e].name, "from": MODE_NAME[int(old[e])],
                               "to": MODE_NAME[int(modes[e])]})
        return y

    def forces(t: float, q: np.ndarray, w: np.ndarray, el: np.ndarray) -> np.ndarray:
        f, _ = sys.free_torque(t, q, w)
        for e in range(ne):
            if modes[e] in (FWD, BWD):
                fr = sys.frictions[e]
                tau = modes[e] * el[e]
                f[fr.a] += tau
                if fr.b >= 0:
                    f[fr.b] -= tau
        return f

    stats: dict[str, Any] = {"nfev": 0, "steps": 0, "restarts": 0, "reset_energy": 0.0, "events": 0}
    y = np.concatenate([np.asarray(q0, float), np.asarray(w0, float), np.zeros(ne_tot)])
    t = 0.0
    y = resolve(t, y, set(), set())
    t_samples = np.arange(0.0, t_end + 0.5 * sample_dt, sample_dt)
    out_y = np.empty((t_samples.size, y.size))
    out_m = np.empty((ne, t_samples.size), dtype=int)
    out_u = {c: np.empty(t_samples.size) for c in u}
    out_reset = np.empty(t_samples.size)  # cumulative plastic-lock (impact) loss, in step with the recorded state
    i_out = 0
    ctrl_k = 0
    breaks = sorted(b for b in sys.breaks if 0.0 < b < t_end)
    bi = 0
    same_instant = 0
    last_event_t = -1.0

    def record(tt, yy):
        nonlocal i_out
        while i_out < t_samples.size and t_samples[i_out] <= tt + 1e-12:
            out_y[i_out] = yy(t_samples[i_out]) if callable(yy) else yy
            out_m[:, i_out] = modes
            for c in u:
                out_u[c][i_out] = u[c]
            out_reset[i_out] = stats["reset_energy"]
            i_out += 1

    # controller at t = 0
    if controller is not None:
        queue.issue(0, controller(0, 0.0, y[:n], y[n:2 * n]))
        ctrl_k = 1

    while t < t_end - 1e-15:
        cfg = config(t)
        rhs, slid = make_rhs(cfg)
        evs = event_funcs(cfg, slid)
        solver = DOP853(rhs, t, y, t_end, rtol=rtol, atol=atol, max_step=max_step)
        stats["restarts"] += 1
        g_old = [g(t, y) for g, _, _ in evs]
        stop = False
        while not stop:
            # next hard time: schedule break, pending actuation, controller sample
            t_hard = t_end
            kind = "end"
            while bi < len(breaks) and breaks[bi] <= t + 1e-15:
                bi += 1
            if bi < len(breaks) and breaks[bi] < t_hard:
                t_hard, kind = breaks[bi], "break"
            if queue is not None and queue.pending and queue.pending[0][0] < t_hard:
                t_hard, kind = queue.pending[0][0], "actuate"
            if controller is not None and ctrl_k * controller.dt < t_hard - 1e-15:
                t_hard, kind = ctrl_k * controller.dt, "sample"
            if solver.t < t_hard and solver.status == "running":
                msg = solver.step()
                if solver.status == "failed":
                    raise SolverError(f"reference integrator failed at t = {solver.t:.6g} s: {msg}")
                stats["steps"] += 1
            t_new = min(solver.t, t_hard)
            sol = solver.dense_output() if solver.t_old is not None else None
            yfun = sol if sol is not None else _const(y)
            # state events in (t_cur_old, t_new]
            t_lo = solver.t_old if solver.t_old is not None else t
            t_lo = max(t_lo, t)
            y_new = yfun(t_new) if t_new < solver.t else solver.y
            g_new = [g(t_new, y_new) for g, _, _ in evs]
            fired = []
            for i, (g, d, tag) in enumerate(evs):
                a0, a1 = g_old[i], g_new[i]
                if (d < 0 and a0 > 0 and a1 <= 0) or (d > 0 and a0 < 0 and a1 >= 0):
                    te = _root(lambda tt, g=g, yf=yfun: g(tt, yf(tt)), t_lo, t_new)
                    fired.append((te, tag))
            if fired:
                te = min(f[0] for f in fired)
                tags = [tag for tf, tag in fired if tf <= te + 1e-13]
                record(te, yfun)
                y = yfun(te)
                t = te
                same_instant = same_instant + 1 if abs(t - last_event_t) < 1e-12 else 0
                last_event_t = t
                if same_instant > max_events_at_instant:
                    raise SolverError(f"friction state machine does not settle at t = {t:.9g} s (mode chattering)")
                stats["events"] += 1
                y = resolve(t, y, {e for k, e in tags if k == "lock"}, {e for k, e in tags if k == "break"})
                stop = True
            elif t_new >= t_hard - 1e-15 and t_hard < solver.t + 1e-15:
                record(t_hard, yfun)
                y = y_new if t_new < solver.t else solver.y
                t = t_hard
                changed = False
                if kind == "break":
                    bi += 1
                    changed = True
                elif kind == "actuate":
                    while queue.pending and queue.pending[0][0] <= t + 1e-12:
                        _, c, v = queue.pending.pop(0)
                        if u.get(c) != v:
                            u[c] = v
                            changed = True
                elif kind == "sample":
                    queue.issue(ctrl_k, controller(ctrl_k, t, y[:n], y[n:2 * n]))
                    ctrl_k += 1
                    if queue.pending and queue.pending[0][0] <= t + 1e-12:
                        while queue.pending and queue.pending[0][0] <= t + 1e-12:
                            _, c, v = queue.pending.pop(0)
                            if u.get(c) != v:
                                u[c] = v
                                changed = True
                if kind == "end":
                    stop = True
                elif changed:
                    y = resolve(t, y, set(), set())
                    stop = True
                else:
                    # same smooth piece: keep the solver; the rest of its step is scanned in the next pass
                    g_old = [g(t, y) for g, _, _ in evs]
            else:
                record(t_new, yfun)
                g_old = g_new
                t = t_new
                y = solver.y
                if solver.status == "finished":
                    stop = True
        stats["nfev"] += solver.nfev
    record(t_end + 1e-9, lambda tt: y)
    m = i_out
    Y = out_y[:m]
    e_names = ["source"] + [f"viscous_{nm}" for nm in sys.names] + labels
    energy = {nm: Y[:, 2 * n + i] for i, nm in enumerate(e_names)}
    energy["lock_impact"] = out_reset[:m]
    return RefResult(t=t_samples[:m], q=Y[:, :n].T, w=Y[:, n:2 * n].T, modes=out_m[:, :m], energy=energy,
                     events=events, u={c: v[:m] for c, v in out_u.items()}, stats=stats)


def simulate_velocity_band(
    sys: RotorSystem,
    q0: Sequence[float],
    w0: Sequence[float],
    t_end: float,
    *,
    controller: Controller | None = None,
    u0: dict[str, int] | None = None,
    sample_dt: float = 1e-3,
    velocity_tol: float = 0.01,
    rtol: float = 1e-3,
    atol: float = 1e-6,
    max_step: float = 0.0019,
) -> RefResult:
    """The thesis' numerical treatment (L805-813, App. C/D): no events; inside |w_rel| < velocity_tol an element is
    held (zero relative acceleration) while the torque it must carry is within its capacity; RK23 with the App. J
    settings (tol 1e-3, max step 1.9 ms). The velocity stays wherever it was inside the band, so positions creep.
    Held torques use the same capacity-weighted constraint solution as the event-exact path (the App. D two-body test
    evaluated jointly rather than clutch by clutch)."""
    from scipy.integrate import solve_ivp

    n, ne = sys.n, len(sys.frictions)
    part_owner = [e for e, f in enumerate(sys.frictions) for _ in f.parts]
    peaks = np.array([f.peak for f in sys.frictions])
    labels = sys.part_labels()
    u = {c: 0 for c in sys.commands()}
    u.update(u0 or {})
    queue = CommandQueue(sys.delays, controller.dt if controller else 1.0, u) if controller else None
    cache: dict[tuple, _Config] = {}
    ne_tot = 1 + n + len(part_owner)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        q, w = y[:n], y[n:2 * n]
        lv = sys.levels(t, u)
        el = np.zeros(ne)
        np.add.at(el, part_owner, lv)
        wr = sys.w_rel(w)
        mode = np.where(el <= 0, FREE, np.where(np.abs(wr) < velocity_tol, STUCK, np.sign(wr))).astype(int)
        f0, p_src = sys.free_torque(t, q, w)
        for _ in range(2 * ne + 2):
            stuck = [e for e in range(ne) if mode[e] == STUCK]
            caps = peaks[stuck] * el[stuck]
            key = (tuple(stuck), tuple(np.round(caps, 12)) if len(stuck) > 1 else ())
            cfg = cache.get(key) or cache.setdefault(key, _Config(sys, stuck, caps))
            f = f0.copy()
            for e in range(ne):
                if mode[e] in (FWD, BWD):
                    fr = sys.frictions[e]
                    f[fr.a] += mode[e] * el[e]
                    if fr.b >= 0:
                        f[fr.b] -= mode[e] * el[e]
            if not stuck:
                break
            lam = cfg.lam(f)
            ratio = np.abs(lam) / caps
            r = int(np.argmax(ratio))
            if ratio[r] <= 1.0:
                break
            mode[stuck[r]] = FWD if lam[r] > 0 else BWD
        dy = np.zeros(2 * n + ne_tot)
        dy[:n] = w
        dy[n:2 * n] = cfg.Pa @ f
        dy[2 * n] = p_src
        dy[2 * n + 1:2 * n + 1 + n] = sys.B * w * w
        for i, e in enumerate(part_owner):
            if mode[e] in (FWD, BWD):
                dy[2 * n + 1 + n + i] = lv[i] * abs(wr[e])
        return dy

    y = np.concatenate([np.asarray(q0, float), np.asarray(w0, float), np.zeros(ne_tot)])
    t_samples = np.arange(0.0, t_end + 0.5 * sample_dt, sample_dt)
    Y = np.empty((t_samples.size, y.size))
    U = {c: np.empty(t_samples.size) for c in u}
    Y[0] = y
    for c in u:
        U[c][0] = u[c]
    k_out = 1
    t = 0.0
    dt_c = controller.dt if controller else t_end
    k = 0
    nfev = 0
    while t < t_end - 1e-12:
        if controller is not None:
            queue.issue(k, controller(k, t, y[:n], y[n:2 * n]))
            while queue.pending and queue.pending[0][0] <= t + 1e-12:
                _, c, v = queue.pending.pop(0)
                u[c] = v
        t_next = min((k + 1) * dt_c, t_end)
        for b in sys.breaks:
            if t < b < t_next:
                t_next = b
        ts = t_samples[(t_samples > t + 1e-12) & (t_samples <= t_next + 1e-12)]
        sol = solve_ivp(rhs, (t, t_next), y, method="RK23", rtol=rtol, atol=atol, max_step=max_step,
                        t_eval=ts if ts.size else None)
        if not sol.success:
            raise SolverError(f"velocity-band integration failed at t = {t:.6g} s: {sol.message}")
        nfev += sol.nfev
        for j in range(ts.size):
            Y[k_out] = sol.y[:, j]
            for c in u:
                U[c][k_out] = u[c]
            k_out += 1
        y = sol.y[:, -1] if not ts.size or abs(sol.t[-1] - t_next) < 1e-12 else \
            solve_ivp(rhs, (sol.t[-1], t_next), sol.y[:, -1], method="RK23", rtol=rtol, atol=atol).y[:, -1]
        if abs(t_next - (k + 1) * dt_c) < 1e-12:
            k += 1
        t = t_next
    Y = Y[:k_out]
    e_names = ["source"] + [f"viscous_{nm}" for nm in sys.names] + labels
    return RefResult(t=t_samples[:k_out], q=Y[:, :n].T, w=Y[:, n:2 * n].T, modes=np.zeros((ne, k_out), int),
                     energy={nm: Y[:, 2 * n + i] for i, nm in enumerate(e_names)}, events=[],
                     u={c: v[:k_out] for c, v in U.items()}, stats={"nfev": nfev, "reset_energy": 0.0})
