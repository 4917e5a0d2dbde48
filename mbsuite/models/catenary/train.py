"""The one passage loop: a pantograph, or a train of several, under the FE catenary (`run_passage`, configured by a
`config.PassageConfig`), each pantograph with its own record and statistics; a single pantograph is a train of one.

A train (the model README, "Two pantographs"): the leading pantograph's contact point is at x_0(t) = x_start + V t,
pantograph k's at x_k(t) = x_0(t) - s_k with s_k the sum of the spacings ahead of it. Before its entry time
s_k / V a trailing pantograph exerts no force and is not integrated; at its entry step it is put at its static
equilibrium against the wire where it stands (at x_start = 0 the wire is pinned: exactly the single pantograph's start
state), and from then on it runs in the wave of the ones ahead. The passage lasts until the last pantograph reaches
x_end; each pantograph's record runs from its own x_start to x_end and its statistics are those of a single passage
(`stats.en50318_statistics` on that record) except, on a train of several, the uplift: the largest steady-arm
displacement in the window while the pantograph is within `UPLIFT_REACH` (30 m) of the steady arm, so that each
pantograph is charged with its own.

Stepping (`TrainPassage`, a step object): the catenary in the compiled core (`native_core`), all contact points in one
local problem per step (the contact forces and the slack droppers solved together, exactly). Every pantograph that
offers a one-port (`native`: the 2-mass, lumped and transfer-function pantographs, the Eppinger pantograph on both
paths) runs with the catenary in the compiled loop between entries, a nonlinear one coupled by a secant iteration on
its force in C. With dropper/energy diagnostics, `stepwise`, or a pantograph object without a one-port, the passage
takes the core's stages with the same coupling from Python (`_Secant`, the compiled loop's test oracle); a single
pantograph with `native = False` takes the readable Python `passage.Passage`, the twin the core is tested against.
Both Python loops are test oracles and diagnostics, not the way a shipped scene steps.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import SceneError, SolverError
from ...stepping import Stepping
from .aerodynamics import Uplift
from .config import HEAD_WIDTH, PassageConfig
from .fe import CatenaryFE, assemble
from .native_core import NativeCore
from .pantographs import Pantograph
from .pantographs import build_train as build_pantographs
from .params import CatenaryParams
from .passage import CHECK_EVERY, CoupledResult, Passage, dropper_energy, irregularity_at, steps_to_cover
from .sim import CoupledSimulation
from .stats import en50318_statistics, insulator_statistics, supports_in_window, window_statistics

#: a steady arm's uplift is charged to a pantograph of a train while it is within this distance of it (m)
UPLIFT_REACH = 30.0
#: steps the compiled loop runs between two returns to Python (progress calls)
CHUNK = CHECK_EVERY * 25


@dataclass
class TrainRun:
    """A passage of one or several pantographs: per pantograph its record (CoupledResult on its own x), statistics
    and filtered force; the catenary's support displacements over the whole passage."""

    params: CatenaryParams
    speed_kmh: float
    dt: float
    dropper_law: str
    names: list[str]
    offsets: list[float]
    engines: list[str]
    results: list[CoupledResult]
    stats: list[dict]
    filtered: list[np.ndarray]
    static_forces: list[float]
    timing: dict
    energy: dict[str, np.ndarray] | None = None
    energy_t: np.ndarray | None = None
    warnings: list[str] = field(default_factory=list)
    dropper_elastic: np.ndarray | None = None  # (steps + 1, droppers) T0 + k delta, global time (record_droppers)
    dropper_slack: np.ndarray | None = None  # (steps + 1, droppers) slack status (record_droppers)
    t: np.ndarray | None = None  # global time of the passage (s)
    x: np.ndarray | None = None  # (steps + 1, pantographs) positions on the global time
    regime: dict = field(default_factory=dict)  # `config.speed_regime` of the speed
    engine_warnings: list[dict[str, int]] = field(default_factory=list)  # per pantograph: its engine's warnings
    aerodynamics: list[Uplift] | None = None  # per pantograph: its aerodynamic uplift (None: no [aerodynamics])


class TrainPassage(Stepping):
    """A passage of the pantographs `pans` (leading first, `offsets` m behind the leading one) stepped in the compiled
    core (module docstring), a `mbsuite.stepping.StepObject`: `step()` runs one chunk of C steps up to the next entry
    (`compiled`: every pantograph through its one-port) or one coupled step through the core's stages; the records
    (`T`, `X`, `F`, `H`, `W`, `OUT` the one-ports' outputs, `U`, `NS`, one row per step from the start) fill as it
    goes. The leading
    pantograph starts from `lead`, the static state of the single passage."""

    def __init__(self, sim: CoupledSimulation, pans: list[Pantograph], lead: Passage, offsets: list[float],
                 compiled: bool, record_energy: int = 0, record_droppers: bool = False):
        p, dt, V = sim.fe.params, sim.dt, sim.V
        self.sim, self.pans, self.lead, self.compiled = sim, pans, lead, compiled
        self.dt, self.V = dt, V
        nc = len(pans)
        self.nsingle = lead.nsteps
        self.entries = [steps_to_cover(s, V, dt) for s in offsets]
        self.nsteps = self.entries[-1] + self.nsingle
        self.xs = np.array([p.x_start - s for s in offsets])
        xend = np.array([p.x_end + (offsets[-1] - s) for s in offsets])
        core = self.core = NativeCore(sim, nc, self.xs, xend)
        line = sim.fe.line
        if core.ncw > 1 and line.contacts_at(p.x_start) != [0]:
            raise SceneError(f"line {line.name!r}: the pantographs start at x_start = {p.x_start:g} m, where the "
                             f"contact wires {[line.contacts[c].name for c in line.contacts_at(p.x_start)]} are: on a "
                             "route they start on the first contact wire alone (its static equilibrium)")
        core.u[:], core.q[:], core.p[:] = lead.u, lead.q, lead.p
        nrec = self.nsteps + 1
        nd = sim.fe.T0.size
        ncon = nc * core.ncw
        self.DE = np.zeros((nrec, nd)) if record_droppers else None
        self.DS = np.zeros((nrec, nd), bool) if record_droppers else None
        self.T = np.zeros(nrec)
        self.X, self.F, self.H, self.W = (np.zeros((nrec, ncon)) for _ in range(4))
        self.U = np.zeros((nrec, sim.fe.arm_cw.size))
        self.NS = np.zeros(nrec, dtype=np.int32)
        self.psig: list[dict[str, np.ndarray]] = [{} for _ in range(nc)]
        self.static_forces = [0.0] * nc
        self.ports = [pan.native(dt) for pan in pans] if compiled else []
        self.OUT = np.zeros((nrec, core.attach(self.ports))) if compiled else None
        self.record_energy = record_energy
        self.energy_rows: list[dict[str, float]] = []
        self.energy_t: list[float] = []
        self.n, self.t = 0, 0.0
        for k in range(nc):
            if self.entries[k] == 0:
                self._enter(k, 0)
        if compiled:
            core.set_records(t=self.T, x=self.X, f=self.F, head=self.H, wire=self.W, out=self.OUT, up=self.U,
                             ns=self.NS)
            core.record(0, 0.0)
            self._stops = sorted({e for e in self.entries if e > 0} | {self.nsteps})
        else:
            self._record(0, 0.0)
            self._secant = _Secant(pans, core, dt)
        self.status = "running" if self.nsteps > 0 else "finished"
        if self.status == "finished":
            self._finish()

    def _enter(self, k: int, n: int) -> None:
        """Pantograph k enters at step n: placed where it stands, at its static equilibrium against the wire (through
        the contact spring in series with the contact wire's point-load defect there)."""
        sim, core, pan = self.sim, self.core, self.pans[k]
        ks = core.contacts_of(k)
        for c in ks:  # every contact of the head (one per contact wire; on its wire's x-range only)
            core.present[c] = 1
            core.place(c, float(self.xs[k] + self.V * n * self.dt))
        o = ks[0]  # the owner: the first contact wire, where a pantograph enters (checked above)
        if k == 0:
            f, head = self.lead.force, self.lead.head
        else:
            f = pan.static(core.wire(o), float(core.kce[o]))
            if sim.unilateral and f < 0:
                f = pan.static(core.wire(o), 0.0)
            head = pan.head()
        core.active[o] = int(f > 0 or not sim.unilateral)
        core.set_force(o, f)
        for c in ks:
            core.head[c] = head
        self.static_forces[k] = float(f)
        if self.compiled:
            self.ports[k].load()

    def _one_step(self) -> None:
        """One chunk of C steps up to the next entry (compiled) or one coupled step (stages); SolverError on a
        failure."""
        self._chunk() if self.compiled else self._stage_step()
        self.t = self.n * self.dt
        if self.n >= self.nsteps:
            self.status = "finished"
            self._finish()

    def _chunk(self) -> None:
        stop = next(s for s in self._stops if s > self.n)
        n1 = min(self.n + CHUNK, stop)
        self.core.run_chunks(self.n, n1, CHECK_EVERY, CHUNK, self.static_forces[0])
        self.n = n1
        if n1 == stop and stop < self.nsteps:
            for k in range(len(self.pans)):
                if self.entries[k] == stop:
                    self._enter(k, stop)
                    self.core.record(stop, stop * self.dt)

    def _stage_step(self) -> None:
        core, sim, n = self.core, self.sim, self.n + 1
        t_new = n * self.dt
        core.predict(t_new)
        self._secant.couple(t_new - self.dt)
        core.advance()
        if n % CHECK_EVERY == 0 or n == self.nsteps:
            code = core.check()
            if code:
                raise SolverError(core.failure(code, self.static_forces[0]))
        for k in range(len(self.pans)):
            if self.entries[k] == n and n < self.nsteps:
                self._enter(k, n)
        self._record(n, t_new)
        if self.DE is not None:
            self.DE[n] = sim.fe.T0 + sim.kd * (core.u[sim.up] - core.u[sim.lo])
            self.DS[n, core.slk[:core.nslack]] = True
        if self.record_energy and n % self.record_energy == 0:
            self.energy_rows.append(_energy(core, sim, self.pans))
            self.energy_t.append(t_new)
        self.n = n

    def _record(self, n: int, t: float) -> None:
        _record_row(self.core, n, t, self.T, self.X, self.F, self.H, self.W, self.U, self.NS, self.pans, self.psig,
                    self.nsteps + 1)
        if n == 0 and self.record_energy:
            self.energy_rows.append(_energy(self.core, self.sim, self.pans))
            self.energy_t.append(0.0)

    def _finish(self) -> None:
        if self.compiled:
            for k, port in enumerate(self.ports):
                port.pull()
                off = int(self.core.ooff[k * self.core.ncw])
                self.psig[k] = port.signals(self.OUT[:, off:off + int(port.port.nout)])

    def results(self) -> list[CoupledResult]:
        """Each pantograph's record from its entry, on the time since its entry and its own position."""
        fe, core = self.sim.fe, self.core
        sx = fe.arm_x
        left = core.left_at()
        if np.any(np.isfinite(left)):  # a section no longer stepped: its steady arms' records end there
            self.U[self.T[:, None] >= left[None, :]] = np.nan
        out = []
        for k in range(len(self.pans)):
            e = self.entries[k]
            rows = slice(e, e + self.nsingle + 1)
            ks = list(core.contacts_of(k))
            o = ks[0]
            force, wire, wires = self.F[rows, o], self.W[rows, o], None
            if len(ks) > 1:  # a route: the head's force is its contacts' sum; the wire it meets the lowest one on
                x = self.X[rows, o]
                wires = {}
                for c, kc in enumerate(ks):
                    w = fe.line.contacts[c]
                    wires[w.name] = {"force": self.F[rows, kc].copy(), "wire": self.W[rows, kc].copy(),
                                     "on": (x >= w.x0) & (x <= w.x1)}
                force = self.F[rows, ks[0]].copy()
                for kc in ks[1:]:
                    force = force + self.F[rows, kc]
                height = np.where(np.stack([v["on"] for v in wires.values()]),
                                  np.stack([v["wire"] for v in wires.values()]), np.inf)
                wire = np.min(height, axis=0)
            out.append(CoupledResult(t=self.T[rows] - self.T[e], x=self.X[rows, o], force=force,
                                     head=self.H[rows, o], wire=wire, uplift=self.U[rows],
                                     n_slack=self.NS[rows], panto={kk: v[rows] for kk, v in self.psig[k].items()},
                                     support_x=sx, stats={"steps": self.nsingle}, wires=wires,
                                     support_names=fe.arm_names))
        return out


def run_passage(cfg: PassageConfig, progress: Callable[[int, int], None] | None = None, fe: CatenaryFE | None = None,
                native: bool | None = None, record_energy: int = 0, record_droppers: bool = False,
                stepwise: bool = False) -> TrainRun:
    """Check, build, step and analyse one passage (`cfg`; the EN 50318 procedure for each pantograph). Everything is
    checked (`PassageConfig.check`) before anything is built. `native`: None = the compiled core wherever it applies,
    False = never (a single pantograph takes the Python path, a train the core's stages), True = the compiled C loop
    or an error. `record_energy` > 0 records the energy terms every that many steps, `record_droppers` the droppers'
    elastic tensions T0 + k delta and slack status at every step (both on the core's stages); `stepwise` takes the
    core's stages even for 2-mass pantographs (a test holds both equal). `progress(n, nsteps)` reports the steps."""
    adm = cfg.check()
    p, dt = cfg.params, cfg.dt
    t0, c0 = time.perf_counter(), time.process_time()
    fe = fe if fe is not None else assemble(p)
    pans = build_pantographs(list(cfg.pantographs), p, cfg.engine, dt, cfg.pantograph_section, cfg.contact)
    if adm.uplift is not None:
        apply_uplift(pans, adm.uplift)
    sim = CoupledSimulation(fe, pans[0], adm.V, dt, dropper_law=cfg.dropper_law, contact=cfg.contact)
    t1 = time.perf_counter()
    diagnostics = bool(record_energy or record_droppers)
    portable = all(hasattr(pn, "native") for pn in pans)
    if native and (not portable or diagnostics or stepwise):
        raise SolverError("the compiled loop steps pantographs that offer a one-port (`native`) and records every "
                          "step without dropper/energy diagnostics; use native=False for this run")
    compiled = portable and native is not False and not diagnostics and not stepwise
    tp = None
    if len(pans) == 1 and not compiled and not diagnostics and not stepwise and fe.n_contact_wires == 1:
        res = sim.run(p.x_start, p.x_end, progress=progress, native=False)
        results, static_forces, local_solves = [res], [float(res.force[0])], res.stats["local_solves"]
        T, X = res.t, res.x[:, None]
    else:
        tp = TrainPassage(sim, pans, sim.start(p.x_start, p.x_end), adm.offsets, compiled, record_energy,
                          record_droppers)
        while tp.status == "running":
            tp.step()
            if progress is not None and (compiled or tp.n % CHECK_EVERY == 0 or tp.n == tp.nsteps):
                progress(tp.n, tp.nsteps)
        results, static_forces, local_solves = tp.results(), tp.static_forces, tp.core.n_local
        T, X = tp.T, tp.X
    t2 = time.perf_counter()
    stats, filtered = [], []
    for res in results:
        s, ff = _statistics(res, dt, p, alone=len(results) == 1)
        stats.append(s)
        filtered.append(ff)
    t3, c3 = time.perf_counter(), time.process_time()
    steps = int(T.size - 1)
    timing = {"build_s": t1 - t0, "integrate_s": t2 - t1, "statistics_s": t3 - t2, "total_s": t3 - t0,
              "cpu_s": c3 - c0, "loop_wall_s": t2 - t1, "steps": steps, "dofs": fe.n,
              "us_per_step": 1e6 * (t2 - t1) / max(steps, 1), "native": compiled, "native_loop": compiled,
              "local_solves": local_solves}
    energy = None
    if tp is not None and record_energy:
        energy = {key: np.array([r[key] for r in tp.energy_rows]) for key in tp.energy_rows[0]}
    return TrainRun(params=p, speed_kmh=float(cfg.speed_kmh), dt=float(dt), dropper_law=cfg.dropper_law,
                    names=[n if isinstance(n, str) else getattr(n, "name", "custom") for n in cfg.pantographs],
                    offsets=adm.offsets, engines=[str(getattr(pn, "engine", "reference")) for pn in pans],
                    results=results, stats=stats, filtered=filtered, static_forces=static_forces, timing=timing,
                    energy=energy, energy_t=None if energy is None else np.array(tp.energy_t),
                    warnings=adm.warnings, dropper_elastic=None if tp is None else tp.DE,
                    dropper_slack=None if tp is None else tp.DS, t=T, x=X, regime=adm.regime,
                    engine_warnings=[pn.engine_warnings() if hasattr(pn, "engine_warnings") else {} for pn in pans],
                    aerodynamics=adm.uplift)


def apply_uplift(pans: Sequence[Pantograph], uplift: Sequence[Uplift]) -> None:
    """Hand each pantograph its constant aerodynamic forces (`aerodynamic(head, frame)`, N upward) before its static
    state is set; a pantograph object without the method is refused naming it (its forces would be lost)."""
    for k, (pan, up) in enumerate(zip(pans, uplift, strict=True)):
        if not hasattr(pan, "aerodynamic"):
            raise SceneError(f"pantograph {k + 1} ({getattr(pan, 'name', type(pan).__name__)}) takes no aerodynamic "
                             "forces (it has no `aerodynamic(head, frame)`): remove the [aerodynamics] section or "
                             "give the pantograph the method")
        pan.aerodynamic(up.head, up.frame)


def _statistics(res: CoupledResult, dt: float, p: CatenaryParams, alone: bool) -> tuple[dict, np.ndarray]:
    """The EN 50318 statistics of one pantograph's record; on a train of several, the uplift charged to it is only
    that while it is within UPLIFT_REACH of the steady arm."""
    names = res.support_names
    if alone:
        s, ff = en50318_statistics(res.t, res.x, res.force, res.uplift, res.support_x, dt, p, names)
        if p.windows:
            s["windows"] = window_statistics(res.t, res.x, res.force, ff, res.uplift, res.support_x, dt, p, names,
                                             res.wires)
        _insulators(s, res, ff, dt, p)
        return s, ff
    sx, x = res.support_x, res.x
    names = names or [f"{xsup:g}" for xsup in sx]
    near = np.abs(x[:, None] - sx[None, :]) <= UPLIFT_REACH
    up = np.where(near, res.uplift, -np.inf)
    s, ff = en50318_statistics(res.t, x, res.force, np.where(np.isfinite(up), up, 0.0), sx, dt, p)
    win = supports_in_window(sx, p)
    per = {names[j]: float(1000 * np.nanmax(up[:, j])) for j in range(sx.size) if win[j]}
    s["uplift_at_supports_mm"] = per
    s["uplift_mm"] = max(per.values()) if per else 0.0
    if p.windows:
        s["windows"] = window_statistics(res.t, x, res.force, ff, np.where(np.isfinite(up), up, 0.0), sx, dt, p,
                                         names, res.wires)
    _insulators(s, res, ff, dt, p)
    return s, ff


def _insulators(s: dict, res: CoupledResult, ff: np.ndarray, dt: float, p: CatenaryParams) -> None:
    """The contact force at the line's section insulators (`stats.insulator_statistics`) in `s["insulators"]`, only
    when the line has some on its contact wires."""
    ins = insulator_statistics(res.t, res.x, res.force, ff, dt, p, res.wires)
    if ins:
        s["insulators"] = ins


def simulate_train(p: CatenaryParams, speed_kmh: float, dt: float, pantographs: Sequence[str | Pantograph],
                   spacings: Sequence[float], dropper_law: str = "slack", contact: str = "unilateral",
                   engine: str = "reference", pantograph_section: dict[str, Any] | None = None,
                   progress: Callable[[int, int], None] | None = None, fe: CatenaryFE | None = None,
                   record_energy: int = 0, stepwise: bool = False, head_width: float = HEAD_WIDTH,
                   record_droppers: bool = False, max_steps: float | None = None,
                   allow_inaccurate: bool = False, aerodynamics: dict[str, Any] | None = None) -> TrainRun:
    """A train of pantographs (leading first) at `speed_kmh` with `spacings` (m, between consecutive contact
    points): the `PassageConfig` of these arguments through `run_passage` (its options: `record_energy`,
    `record_droppers`, `stepwise`). Names are built on `engine` where they have it (`pantographs.build_train`).
    `aerodynamics`: an `[aerodynamics]` section (`aerodynamics.py`)."""
    cfg = PassageConfig(p, speed_kmh, dt, tuple(pantographs), tuple(spacings), dropper_law, contact, engine,
                        pantograph_section, max_steps, allow_inaccurate, head_width, aerodynamics)
    return run_passage(cfg, progress=progress, fe=fe, record_energy=record_energy, record_droppers=record_droppers,
                       stepwise=stepwise)


def _record_row(core: NativeCore, n: int, t: float, T, X, F, H, W, U, NS, pans, psig, nrec: int) -> None:
    T[n] = t
    for h in range(len(pans)):
        ks = core.contacts_of(h)
        for k in ks:
            X[n, k] = core.xc[k]
            if core.present[k]:
                F[n, k] = core.f[k] if core.onw[k] else 0.0
                H[n, k] = core.head[k]
                # the height the contact spring meets
                W[n, k] = core.wire(k) + core.cbc[k] * core.f[k] if core.onw[k] else 0.0
        if core.present[ks[0]]:
            for key, v in pans[h].signals().items():
                arr = psig[h].get(key)
                if arr is None:
                    arr = psig[h][key] = np.zeros(nrec)
                arr[n] = v
    sup = core.supidx
    U[n] = np.where(sup >= 0, core.u[np.maximum(sup, 0)], 0.0)
    NS[n] = core.nslack


class _Secant:
    """The coupling of every present pantograph in one step through the core's local problem: an affine pantograph
    gives its exact head map, a nonlinear one is iterated by the secant rule on its force (slope kept between steps),
    all together until every nonlinear head map is consistent (1e-11 relative, as the single-pantograph scheme)."""

    def __init__(self, pans: list, core: NativeCore, dt: float):
        self.pans, self.core, self.dt = pans, core, dt
        self.gp: list[float | None] = [None] * len(pans)

    def couple(self, t: float) -> None:
        """One step's coupling (class docstring); on a route a head's force is its contacts' sum (`head_force`)
        and its head map is shared by its contacts."""
        core, dt, pans = self.core, self.dt, self.pans
        nc = len(pans)
        fprev = [core.head_force(k) for k in range(nc)]
        nonlin = []
        ya, fa = {}, {}

        def share(k: int) -> None:
            for c in core.contacts_of(k)[1:]:
                core.P[c], core.gp[c] = core.P[k * core.ncw], core.gp[k * core.ncw]

        for k in range(nc):
            o = k * core.ncw
            if not core.present[o]:
                continue
            pan = pans[k]
            if pan.affine and hasattr(pan, "affine_map"):
                core.P[o], core.gp[o] = pan.affine_map(dt, float(fprev[k]))
            else:
                y0 = pan.trial(t, dt, float(fprev[k]), float(fprev[k]))
                if self.gp[k] is None:
                    self.gp[k] = y0 - pan.trial(t, dt, float(fprev[k]), float(fprev[k]) + 1.0)
                core.gp[o] = self.gp[k]
                core.P[o] = y0 + self.gp[k] * fprev[k]
                ya[k], fa[k] = y0, float(fprev[k])
                nonlin.append(k)
            share(k)
        yh = {}
        for _it in range(30):
            core.local()
            done = True
            for k in nonlin:
                o = k * core.ncw
                f = core.head_force(k)
                pan = pans[k]
                if f == fa[k]:
                    yh[k] = pan.trial(t, dt, float(fprev[k]), f)
                    continue
                y = yh[k] = pan.trial(t, dt, float(fprev[k]), f)
                err = y - (core.P[o] - core.gp[o] * f)
                if abs(err) < 1e-13 + 1e-11 * abs(y):
                    continue
                done = False
                if abs(f - fa[k]) > 1e-9:
                    g_new = (ya[k] - y) / (f - fa[k])
                    if g_new > 0:
                        self.gp[k] = g_new
                        core.gp[o] = g_new
                core.P[o] = y + core.gp[o] * f
                share(k)
                fa[k], ya[k] = f, y
            if done:
                break
        else:
            raise SolverError(f"pantograph-catenary coupling did not converge at t = {t + dt:.6f} s")
        for k in range(nc):
            ks = core.contacts_of(k)
            if not core.present[ks[0]]:
                continue
            pan = pans[k]
            if k not in nonlin:
                yh[k] = pan.trial(t, dt, float(fprev[k]), core.head_force(k))
            pan.commit()
            for c in ks:
                core.head[c] = yh[k]
        core.job.n_local += 1


def _energy(core: NativeCore, sim: CoupledSimulation, pans: list) -> dict[str, float]:
    """Energy terms of the coupled train (as `Passage.energy_terms`): catenary (kinetic + wires and supports +
    droppers with their exact law, relative to the static state), every pantograph, every contact spring (with the
    wire's point-load defect under it), and the power the imposed horizontal motion feeds in through the sloping
    wire (its height irregularity included), summed over the contacts."""
    fe = sim.fe
    u = core.u
    v = sim.mass().solve(0.5 * (core.q + core.p))
    E_c = 0.5 * v @ (fe.M @ v) + 0.5 * u @ (fe.K0 @ u) + dropper_energy(sim, u)
    E_p = E_k = P = 0.0
    for h, pan in enumerate(pans):
        if core.present[h * core.ncw]:
            E_p += pan.energy()
    for k in range(len(pans) * core.ncw):
        if not core.onw[k]:
            continue
        f = float(core.f[k])
        E_k += 0.5 * f * f * (1.0 / fe.params.k_contact + float(core.cbc[k]))
        e = int(core.elem[k])
        he = fe.x[e + 1] - fe.x[e]
        xi = (core.xc[k] - fe.x[e]) / he
        dN = np.array([(-6 * xi + 6 * xi * xi) / he, 1 - 4 * xi + 3 * xi * xi, (6 * xi - 6 * xi * xi) / he,
                       3 * xi * xi - 2 * xi])
        dofs = core.dofs[4 * k:4 * k + 4]
        valid = fe.cw_dof_of(int(core.cwk[k])).reshape(-1)[2 * e:2 * e + 4] >= 0
        slope = (float(dN @ (np.where(valid, u[dofs], 0.0) + core.w0d[4 * k:4 * k + 4]))
                 + irregularity_at(fe.irregularity, float(core.xc[k]))[1])
        P += -f * sim.V * slope
    return {"catenary": E_c, "pantograph": E_p, "contact": E_k, "drive_power": P}
