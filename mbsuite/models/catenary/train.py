"""Several pantographs on one train under the FE catenary: each with its own record and statistics.

The scene (the model README, "Two pantographs"): the leading pantograph's contact point is at x_0(t) = x_start + V t,
pantograph k's at x_k(t) = x_0(t) - s_k with s_k the sum of the spacings ahead of it. Before its entry time
s_k / V a trailing pantograph exerts no force and is not integrated; at its entry step it is put at its static
equilibrium against the wire where it stands (at x_start = 0 the wire is pinned: exactly the single pantograph's start
state), and from then on it runs in the wave of the ones ahead. The passage lasts until the last pantograph reaches
x_end; each pantograph's record runs from its own x_start to x_end and its statistics are those of a single passage
(`stats.en50318_statistics` on that record) except the uplift: the largest steady-arm displacement in the window while
the pantograph is within `uplift_reach` (30 m) of the steady arm, so that each pantograph is charged with its own.

Stepping: the catenary in the compiled core (`native_core`), all contact points in one local problem per step (the
contact forces and the slack droppers solved together, exactly). 2-mass pantographs only: the whole passage runs in
C between entries; any nonlinear pantograph (Eppinger): the core's stages with a secant iteration on every nonlinear
pantograph's force (the single-pantograph scheme, Jacobi-style over the pantographs).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import ParameterError, SolverError
from .fe import CatenaryFE, assemble
from .native_core import NativeCore
from .pantographs import Pantograph, TwoMassPantograph
from .pantographs import build as build_pantograph
from .params import CatenaryParams
from .sim import CHECK_EVERY, CoupledResult, CoupledSimulation, _native_error, steps_to_cover
from .stats import en50318_statistics, supports_in_window

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

#: length of a pantograph head along the track (m): two contact points closer than this would share one head
HEAD_WIDTH = 0.5
#: most pantographs on one train (the compiled core's fixed per-step buffer)
MAX_PANTOGRAPHS = 64
#: a steady arm's uplift is charged to a pantograph while it is within this distance of it (m)
UPLIFT_REACH = 30.0


@dataclass
class TrainRun:
    """A passage of several pantographs: per pantograph its record (CoupledResult on its own x), statistics and
    filtered force; the catenary's support displacements over the whole passage."""

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


def check_train(p: CatenaryParams, spacings: Sequence[float], head_width: float = HEAD_WIDTH) -> list[float]:
    """Offsets s_k (m) of the pantographs behind the leading one from the spacings; errors name the bad value: a
    spacing below a head width, or a train whose leading pantograph would leave the line before the last one ends
    its run."""
    if len(spacings) + 1 > MAX_PANTOGRAPHS:
        raise ParameterError(f"{len(spacings) + 1} pantographs; the core takes at most {MAX_PANTOGRAPHS}")
    offsets = [0.0]
    for i, s in enumerate(spacings):
        if isinstance(s, bool) or not isinstance(s, int | float) or not math.isfinite(s):
            raise ParameterError(f"spacing[{i}] = {s!r} must be a finite number of metres")
        if s < head_width:
            raise ParameterError(f"spacing[{i}] = {s!r} m puts two pantographs closer than a head width "
                                 f"({head_width} m); valid: >= {head_width} m")
        offsets.append(offsets[-1] + float(s))
    lead_end = p.x_end + offsets[-1]
    if lead_end > p.length + 1e-9:
        raise ParameterError(
            f"spacings {list(spacings)} m: the leading pantograph would be at x = {lead_end:g} m, outside the "
            f"catenary [0, {p.length:g}] m, when the last one reaches x_end = {p.x_end:g} m; valid: total spacing "
            f"<= {p.length - p.x_end:g} m (or lengthen the line: n_spans)")
    return offsets


def _entry_step(offset: float, V: float, dt: float) -> int:
    return steps_to_cover(offset, V, dt)


def simulate_train(p: CatenaryParams, speed_kmh: float, dt: float, pantographs: Sequence[str | Pantograph],
                   spacings: Sequence[float], dropper_law: str = "slack", contact: str = "unilateral",
                   engine: str = "reference", pantograph_section: dict[str, Any] | None = None,
                   progress: Callable[[int, int], None] | None = None, fe: CatenaryFE | None = None,
                   record_energy: int = 0, stepwise: bool = False, head_width: float = HEAD_WIDTH,
                   record_droppers: bool = False, max_steps: float | None = None,
                   allow_inaccurate: bool = False) -> TrainRun:
    """Run a train of pantographs (leading first) at `speed_kmh` with `spacings` (m, between consecutive contact
    points). Names are built on `engine` (reference2mass always on its only path). `record_energy` > 0 records the
    energy terms every that many steps, `record_droppers` the droppers' elastic tensions T0 + k delta and slack status
    at every step (`TrainRun.dropper_elastic`, `dropper_slack`; both on the stage path). `stepwise` forces the
    Python-driven stage loop even for 2-mass pantographs (the path the nonlinear pantographs take; a test holds both
    equal)."""
    from .analysis import check_size, check_timestep, check_wave_resolution, speed_regime

    if len(pantographs) != len(spacings) + 1:
        raise ParameterError(f"{len(pantographs)} pantographs need {len(pantographs) - 1} spacings, got "
                             f"{len(spacings)}")
    if not (isinstance(speed_kmh, int | float) and math.isfinite(speed_kmh) and speed_kmh > 0):
        raise ParameterError(f"speed must be a positive number of km/h, got {speed_kmh!r}")
    check_timestep(p, dt)
    offsets = check_train(p, spacings, head_width)
    V = speed_kmh / 3.6
    regime = speed_regime(p, V)
    import dataclasses

    check_size(dataclasses.replace(p, x_end=p.x_end + offsets[-1]), V, dt, max_steps)  # the whole train's steps
    step_warn = check_wave_resolution(p, dt, allow_inaccurate)
    t0, c0 = time.perf_counter(), time.process_time()
    fe = fe if fe is not None else assemble(p)
    pans, names, engines = [], [], []
    for k in pantographs:
        if isinstance(k, str):
            eng = "reference" if k == "reference2mass" else engine
            pans.append(build_pantograph(k, p, engine=eng, dt=dt, section=pantograph_section, contact=contact))
            names.append(k)
            engines.append(eng)
        else:
            pans.append(k)
            names.append(getattr(k, "name", "custom"))
            engines.append(str(getattr(k, "engine", "reference")))
    nc = len(pans)
    sim = CoupledSimulation(fe, pans[0], V, dt, dropper_law=dropper_law, contact=contact)
    lead = sim.start(p.x_start, p.x_end)
    nsingle = lead.nsteps
    entries = [_entry_step(s, V, dt) for s in offsets]
    ntotal = entries[-1] + nsingle
    xs = np.array([p.x_start - s for s in offsets])
    xend = np.array([p.x_end + (offsets[-1] - s) for s in offsets])
    core = NativeCore(sim, nc, xs, xend)
    core.u[:], core.q[:], core.p[:] = lead.u, lead.q, lead.p
    all_affine = (all(isinstance(pn, TwoMassPantograph) for pn in pans) and not stepwise and not record_energy
                  and not record_droppers)
    nd = fe.T0.size
    DE = np.zeros((ntotal + 1, nd)) if record_droppers else None
    DS = np.zeros((ntotal + 1, nd), bool) if record_droppers else None
    nrec = ntotal + 1
    T = np.zeros(nrec)
    X, F, H, W, FR = (np.zeros((nrec, nc)) for _ in range(5))
    U = np.zeros((nrec, fe.supports.size))
    NS = np.zeros(nrec, dtype=np.int32)
    psig: list[dict[str, np.ndarray]] = [{} for _ in range(nc)]
    static_forces = [0.0] * nc

    def enter(k: int, n: int) -> None:
        x = float(xs[k] + V * n * dt)
        core.place(k, x)
        if k == 0:
            f, head = lead.force, lead.head
        else:
            f = pans[k].static(core.wire(k), p.k_contact)
            if sim.unilateral and f < 0:
                f = pans[k].static(core.wire(k), 0.0)
            head = pans[k].head()
        core.present[k], core.active[k] = 1, int(f > 0 or not sim.unilateral)
        core.set_force(k, f)
        core.head[k] = head
        static_forces[k] = float(f)
        if all_affine:
            pans[k].pack(core.pm[16 * k:16 * k + 16], dt)

    en_rows: list[dict[str, float]] = []
    en_t: list[float] = []
    for k in range(nc):
        if entries[k] == 0:
            enter(k, 0)
    w_start = time.perf_counter()
    if all_affine:
        core.set_records(t=T, x=X, f=F, head=H, wire=W, frame=FR, up=U, ns=NS)
        core.record(0, 0.0)
        stops = sorted({e for e in entries if e > 0} | {ntotal})
        n = 0
        for stop in stops:
            while n < stop:
                n1 = min(n + CHECK_EVERY * 25, stop)
                code = core.run(n, n1, CHECK_EVERY)
                if code:
                    raise SolverError(_native_error(core, code, static_forces[0]))
                n = n1
                if progress is not None:
                    progress(n, ntotal)
            for k in range(nc):
                if entries[k] == stop and stop < ntotal:
                    enter(k, stop)
                    core.record(stop, stop * dt)
        for k in range(nc):
            pans[k].unpack(core.pm[16 * k:16 * k + 16])
            psig[k] = {"head_displacement": H[:, k].copy(), "frame_displacement": FR[:, k].copy()}
    else:
        _record_row(core, 0, 0.0, T, X, F, H, W, U, NS, pans, psig, nrec)
        if record_energy:
            en_rows.append(_energy(core, sim, pans))
            en_t.append(0.0)
        secant = _Secant(pans, core, dt)
        for n in range(1, ntotal + 1):
            t_new = n * dt
            core.predict(t_new)
            secant.couple(t_new - dt)
            core.advance()
            if n % CHECK_EVERY == 0 or n == ntotal:
                code = core.check()
                if code:
                    raise SolverError(_native_error(core, code, static_forces[0]))
            for k in range(nc):
                if entries[k] == n and n < ntotal:
                    enter(k, n)
            _record_row(core, n, t_new, T, X, F, H, W, U, NS, pans, psig, nrec)
            if DE is not None:
                DE[n] = fe.T0 + sim.kd * (core.u[sim.mw] - core.u[sim.cw])
                DS[n, core.slk[:core.nslack]] = True
            if record_energy and n % record_energy == 0:
                en_rows.append(_energy(core, sim, pans))
                en_t.append(t_new)
            if progress is not None and (n % CHECK_EVERY == 0 or n == ntotal):
                progress(n, ntotal)
    wall = time.perf_counter() - w_start
    results, stats, filtered = [], [], []
    sx = fe.x[fe.supports]
    for k in range(nc):
        rows = slice(entries[k], entries[k] + nsingle + 1)
        x = X[rows, k]
        res = CoupledResult(t=T[rows] - T[entries[k]], x=x, force=F[rows, k], head=H[rows, k], wire=W[rows, k],
                            uplift=U[rows], n_slack=NS[rows], panto={kk: v[rows] for kk, v in psig[k].items()},
                            support_x=sx, stats={"steps": nsingle})
        near = np.abs(x[:, None] - sx[None, :]) <= UPLIFT_REACH
        up = np.where(near, res.uplift, -np.inf)
        s, ff = en50318_statistics(res.t, x, res.force, np.where(np.isfinite(up), up, 0.0), sx, dt, p)
        # the uplift charged to this pantograph: only while it is within UPLIFT_REACH of the steady arm
        win = supports_in_window(sx, p)
        per = {f"{xsup:g}": float(1000 * np.max(up[:, j])) for j, xsup in enumerate(sx) if win[j]}
        s["uplift_at_supports_mm"] = per
        s["uplift_mm"] = max(per.values()) if per else 0.0
        results.append(res)
        stats.append(s)
        filtered.append(ff)
    t3, c3 = time.perf_counter(), time.process_time()
    energy = None
    if record_energy:
        energy = {key: np.array([r[key] for r in en_rows]) for key in en_rows[0]}
    timing = {"total_s": t3 - t0, "cpu_s": c3 - c0, "loop_wall_s": wall, "steps": ntotal, "dofs": fe.n,
              "native_loop": bool(all_affine), "local_solves": core.n_local}
    return TrainRun(params=p, speed_kmh=float(speed_kmh), dt=float(dt), dropper_law=dropper_law, names=names,
                    offsets=offsets, engines=engines, results=results, stats=stats, filtered=filtered,
                    static_forces=static_forces, timing=timing, energy=energy,
                    energy_t=None if energy is None else np.array(en_t), warnings=list(regime["warnings"]) + step_warn,
                    dropper_elastic=DE, dropper_slack=DS, t=T, x=X)


def _record_row(core: NativeCore, n: int, t: float, T, X, F, H, W, U, NS, pans, psig, nrec: int) -> None:
    T[n] = t
    for k in range(len(pans)):
        X[n, k] = core.xc[k]
        if core.present[k]:
            F[n, k] = core.f[k]
            H[n, k] = core.head[k]
            W[n, k] = core.wire(k)
            for key, v in pans[k].signals().items():
                arr = psig[k].get(key)
                if arr is None:
                    arr = psig[k][key] = np.zeros(nrec)
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
        core, dt, pans = self.core, self.dt, self.pans
        nc = len(pans)
        fprev = core.f.copy()
        nonlin = []
        ya, fa = {}, {}
        for k in range(nc):
            if not core.present[k]:
                continue
            pan = pans[k]
            if pan.affine and hasattr(pan, "affine_map"):
                core.P[k], core.gp[k] = pan.affine_map(dt, float(fprev[k]))
            else:
                y0 = pan.trial(t, dt, float(fprev[k]), float(fprev[k]))
                if self.gp[k] is None:
                    self.gp[k] = y0 - pan.trial(t, dt, float(fprev[k]), float(fprev[k]) + 1.0)
                core.gp[k] = self.gp[k]
                core.P[k] = y0 + self.gp[k] * fprev[k]
                ya[k], fa[k] = y0, float(fprev[k])
                nonlin.append(k)
        yh = {}
        for _it in range(30):
            core.local()
            done = True
            for k in nonlin:
                f = float(core.f[k])
                pan = pans[k]
                if f == fa[k]:
                    yh[k] = pan.trial(t, dt, float(fprev[k]), f)
                    continue
                y = yh[k] = pan.trial(t, dt, float(fprev[k]), f)
                err = y - (core.P[k] - core.gp[k] * f)
                if abs(err) < 1e-13 + 1e-11 * abs(y):
                    continue
                done = False
                if abs(f - fa[k]) > 1e-9:
                    g_new = (ya[k] - y) / (f - fa[k])
                    if g_new > 0:
                        self.gp[k] = g_new
                        core.gp[k] = g_new
                core.P[k] = y + core.gp[k] * f
                fa[k], ya[k] = f, y
            if done:
                break
        else:
            raise SolverError(f"pantograph-catenary coupling did not converge at t = {t + dt:.6f} s")
        for k in range(nc):
            if not core.present[k]:
                continue
            pan = pans[k]
            if k not in nonlin:
                yh[k] = pan.trial(t, dt, float(fprev[k]), float(core.f[k]))
            pan.commit()
            core.head[k] = yh[k]
        core.job.n_local += 1


def _energy(core: NativeCore, sim: CoupledSimulation, pans: list) -> dict[str, float]:
    """Energy terms of the coupled train (as `Passage.energy_terms`): catenary (kinetic + wires and supports +
    droppers with their exact law, relative to the static state), every pantograph, every contact spring, and the
    power the imposed horizontal motion feeds in through the sloping wire, summed over the contacts."""
    fe = sim.fe
    u = core.u
    v = sim._mass().solve(0.5 * (core.q + core.p))
    delta = u[sim.mw] - u[sim.cw]
    kd, T0 = sim.kd, fe.T0
    if sim.slack:
        Vd = np.where(delta >= -T0 / kd, T0 * delta + 0.5 * kd * delta**2, -0.5 * T0**2 / kd)
    else:
        Vd = T0 * delta + 0.5 * kd * delta**2
    E_c = 0.5 * v @ (fe.M @ v) + 0.5 * u @ (fe.K0 @ u) + float(np.sum(Vd - T0 * delta))
    E_p = E_k = P = 0.0
    for k, pan in enumerate(pans):
        if not core.present[k]:
            continue
        E_p += pan.energy()
        f = float(core.f[k])
        E_k += f * f / (2 * fe.params.k_contact)
        e = int(core.elem[k])
        he = fe.x[e + 1] - fe.x[e]
        xi = (core.xc[k] - fe.x[e]) / he
        dN = np.array([(-6 * xi + 6 * xi * xi) / he, 1 - 4 * xi + 3 * xi * xi, (6 * xi - 6 * xi * xi) / he,
                       3 * xi * xi - 2 * xi])
        dofs = core.dofs[4 * k:4 * k + 4]
        valid = core.cwdof.reshape(-1)[2 * e:2 * e + 4] >= 0
        slope = float(dN @ (np.where(valid, u[dofs], 0.0) + core.w0d[4 * k:4 * k + 4]))
        P += -f * sim.V * slope
    return {"catenary": E_c, "pantograph": E_p, "contact": E_k, "drive_power": P}


# --- scene section ------------------------------------------------------------------------------------------------
TRAIN_KEYS = ("pantographs", "spacings")


def validate_section(value: Any) -> dict[str, Any]:
    """Validator of a scene's `[train]` section: `pantographs` (names of the `pantograph` effect's values, leading
    first) and `spacings` (m between consecutive contact points, one fewer). Spacing limits are checked against the
    line when the passage starts (`check_train`)."""
    from ...errors import SceneError
    from .pantographs import PANTOGRAPH_MODELS

    if not isinstance(value, dict):
        raise SceneError(f"[train] must be a table with keys {list(TRAIN_KEYS)}, got {value!r}")
    bad = sorted(set(value) - set(TRAIN_KEYS))
    if bad:
        raise SceneError(f"unknown key(s) {bad} in [train]; valid keys: {list(TRAIN_KEYS)}")
    names = value.get("pantographs")
    valid = ["reference2mass", *PANTOGRAPH_MODELS]
    if not isinstance(names, list) or not names or any(n not in valid for n in names):
        raise SceneError(f"[train] pantographs must be a non-empty list of {valid}, got {names!r}")
    sp = value.get("spacings", [])
    if not isinstance(sp, list) or len(sp) != len(names) - 1:
        raise SceneError(f"[train] spacings must be a list of {len(names) - 1} distances (m) for {len(names)} "
                         f"pantographs, got {sp!r}")
    for i, s in enumerate(sp):
        if isinstance(s, bool) or not isinstance(s, int | float) or not math.isfinite(s) or s < HEAD_WIDTH:
            raise SceneError(f"[train] spacings[{i}] = {s!r} m: valid spacings are >= a head width ({HEAD_WIDTH} m)")
    return {"pantographs": list(names), "spacings": [float(s) for s in sp]}


def run_train_scene(scene, speed_kmh: float | None = None, progress=None, spacings: Sequence[float] | None = None,
                    **overrides: Any) -> TrainRun:
    """A train passage of a scene with a `[train]` section (its parameters with `overrides`, speed, time step,
    effects; `spacings` overrides the section's)."""
    import dataclasses

    from .analysis import scene_speed

    p = scene.build_params()
    if overrides:
        p = dataclasses.replace(p, **overrides)
    tr = scene.sections["train"]
    return simulate_train(p, scene_speed(scene, speed_kmh), scene.solver.timestep, tr["pantographs"],
                          list(tr["spacings"] if spacings is None else spacings),
                          dropper_law=scene.effects["droppers"], contact=scene.effects["contact"],
                          engine=scene.solver.engine, pantograph_section=scene.sections.get("pantograph"),
                          progress=progress, max_steps=scene.solver.max_steps,
                          allow_inaccurate=scene.solver.allow_inaccurate)


# --- outputs ------------------------------------------------------------------------------------------------------
STAT_KEYS = ("Fm", "sigma", "stat_max", "stat_min", "max", "min", "uplift_mm", "loss_pct")


def _label(run: TrainRun, k: int) -> str:
    role = "leading" if k == 0 else ("trailing" if len(run.names) == 2 else f"#{k + 1}")
    path = "" if run.engines[k] == "reference" or run.names[k] == "reference2mass" else f", {run.engines[k]}"
    return f"{role} {run.names[k]}{path} (s = {run.offsets[k]:g} m)"


def _assessments(run: TrainRun, criteria) -> list[dict]:
    from .quality import assess

    return [assess(s, run.speed_kmh, criteria, float(s["n_samples_window"]) * run.dt) for s in run.stats]


def train_report(run: TrainRun, quality=None):
    """Table (one column per pantograph), JSON data and writer (per-pantograph CSV, force/uplift plot, quality plot)
    of a train passage; `quality` (QualityCriteria) adds the quality report of every pantograph."""
    from pathlib import Path

    from ...plotting import save
    from ...results import Report, format_table, write_csv
    from .quality import plot as quality_plot
    from .quality import table_rows
    from .stats import STAT_NAMES

    labels = [_label(run, k) for k in range(len(run.names))]
    rows = [[STAT_NAMES[key]] + [f"{s[key]:.2f}" for s in run.stats] for key in STAT_KEYS]
    lines = [f"train of {len(run.names)} pantographs, {run.speed_kmh:g} km/h (element {run.params.element_length:g} m, "
             f"dt {run.dt:g} s, {run.timing['steps']} steps, {run.timing['cpu_s']:.2f} s CPU); window "
             f"[{run.params.window_start:g}, {run.params.window_end:g}] m on each pantograph's own position",
             format_table(["statistic", *labels], rows)]
    for k, s in enumerate(run.stats):
        c = s["loss_counts"]
        lines.append(f"{labels[k]}: static contact force {run.static_forces[k]:.2f} N; contact losses in window "
                     f"{len(s['loss_events'])} (<5 ms: {c['short_lt_5ms']}, 5-20 ms: {c['damaging_5_20ms']}, "
                     f">20 ms: {c['power_loss_gt_20ms']})")
    for w in run.warnings:
        lines.append(f"WARNING: {w}")
    data = {"speed_kmh": run.speed_kmh, "element_length": run.params.element_length, "timestep": run.dt,
            "timing": run.timing,
            "pantographs": [{"name": run.names[k], "engine": run.engines[k], "offset_m": run.offsets[k],
                             "static_contact_force": run.static_forces[k],
                             "statistics": {key: run.stats[k][key] for key in STAT_KEYS},
                             "uplift_at_supports_mm": run.stats[k]["uplift_at_supports_mm"],
                             "loss_events": run.stats[k]["loss_events"]} for k in range(len(run.names))],
            "warnings": run.warnings}
    qs = []
    if quality is not None:
        qs = _assessments(run, quality)
        for k, q in enumerate(qs):
            data["pantographs"][k]["quality"] = q
            lines.append(f"current-collection quality, {labels[k]}, {quality.system} criteria: "
                         f"{'PASS' if q['pass'] else 'FAIL'}")
            lines.append(format_table(["criterion", "value", "limit", "verdict"], table_rows(q)))
        data["quality_pass"] = all(q["pass"] for q in qs)

    def write(out: Path) -> list[Path]:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        files = []
        for k, res in enumerate(run.results):
            tag = f"p{k + 1}_{run.names[k]}_{run.speed_kmh:g}kmh"
            files.append(write_csv(out / f"contact_force_{tag}.csv", [
                ("t", "s", res.t), ("x", "m", res.x), ("force", "N", res.force),
                ("force_filtered_20Hz", "N", run.filtered[k]), ("head_height", "m", res.head),
                ("wire_height", "m", res.wire)]))
        files.append(save(train_figure(run, labels), out / f"train_force_{run.speed_kmh:g}kmh.png"))
        if qs:
            files.append(quality_plot(list(zip(labels, qs, strict=True)),
                                      out / f"quality_train_{run.speed_kmh:g}kmh.png"))
        return files

    return Report(data=data, table="\n".join(lines), write=write)


def train_figure(run: TrainRun, labels: list[str]) -> MplFigure:
    """Each pantograph's 20 Hz low-pass contact force and the contact-wire height at its contact point against its
    own position (the statistics window shaded); `labels` names the pantographs."""
    from ...plotting import figure

    p = run.params
    fig, axes = figure(2, 1, size=(11, 7), sharex=True)
    for k, res in enumerate(run.results):
        axes[0].plot(res.x, run.filtered[k], lw=1.0, label=f"{labels[k]}")
        axes[1].plot(res.x, 1000 * res.wire, lw=1.0, label=f"{labels[k]}")
    for ax in axes:
        ax.axvspan(p.window_start, p.window_end, color="0.9", zorder=-1)
        ax.set_xlim(p.x_start, p.x_end)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].set_ylabel("contact force F, 20 Hz low-pass [N]")
    axes[1].set_ylabel("contact-wire height at\nthe contact point [mm]")
    axes[1].set_xlabel("each pantograph's own position x [m]")
    axes[0].set_title(f"train of {len(run.names)} pantographs, {run.speed_kmh:g} km/h; wire height from its static "
                      "state (grey: statistics window)", fontsize=10)
    return fig


def train_to_simresult(run: TrainRun, scene):
    """A train passage as a SimResult: the leading pantograph's channels under the usual names (on its own record),
    `contact_force_p<k>` / `position_p<k>` for every pantograph k = 1, 2, ... (each on its own record; all records
    have the same length, one passage from x_start to x_end, on the time since the pantograph's entry), and per
    pantograph the eight statistics and quality verdicts in `stats` (`p<k>_Fm`, ..., `p<k>_quality_pass`)."""
    from ...results import assemble
    from .analysis import health_of_regime
    from .quality import criteria_from

    lead = run.results[0]
    signals = {"contact_force": lead.force, "contact_force_filtered": run.filtered[0], "position": lead.x,
               "head_height": lead.head, "wire_height": lead.wire, "slack_droppers": lead.n_slack.astype(float)}
    qs = _assessments(run, criteria_from(scene.sections.get("quality")))
    stats: dict[str, Any] = {"steps": run.timing["steps"], "cpu_s": run.timing["cpu_s"],
                             "total_s": run.timing["total_s"]}
    for k, s in enumerate(run.stats):
        stats.update({f"p{k + 1}_{key}": s[key] for key in STAT_KEYS})
        stats[f"p{k + 1}_static_contact_force"] = run.static_forces[k]
        stats[f"p{k + 1}_quality_pass"] = qs[k]["pass"]
    events = [{**e, "pantograph": k + 1} for k, s in enumerate(run.stats) for e in s["loss_events"]]
    res = assemble(scene, lead.t, signals, engine=run.engines[-1], events=events, stats=stats,
                   health=health_of_regime(run.speed_kmh / 3.6, run.params, run.dt))
    for k, r in enumerate(run.results):
        res.signals[f"contact_force_p{k + 1}"] = r.force
        res.units[f"contact_force_p{k + 1}"] = "N"
        res.signals[f"position_p{k + 1}"] = r.x
        res.units[f"position_p{k + 1}"] = "m"
    return res
