"""Run a catenary scene: build the FE catenary and the pantograph, integrate, compute the EN 50318 statistics, and
package the result for the CLI (table, JSON data, CSV and PNG writers) and as a SimResult (`results.assemble`)."""

from __future__ import annotations

import dataclasses
import math
import textwrap
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import ParameterError, SceneError
from ...health import Figure, judge
from ...results import Report, SimResult, format_table, write_csv
from ...results import assemble as assemble_result
from .fe import CatenaryFE, assemble
from .pantographs import Pantograph
from .pantographs import build as build_pantograph
from .params import MAX_ELEMENT_STEPS, CatenaryParams
from .quality import QualityCriteria, assess, criteria_from
from .quality import plot as quality_plot
from .quality import table_rows as quality_table_rows
from .sim import CoupledResult, CoupledSimulation, steps_to_cover
from .stats import ACCEPTED_RANGES, STAT_NAMES, check_ranges, en50318_statistics, in_window

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

#: ratio V / c above which a warning is issued: EN 50119 limits the line speed to 70 % of the CW wave speed
WARN_RATIO = 0.7
#: ratio above which the warning says the regime is near-critical
NEAR_CRITICAL_RATIO = 0.9


class CriticalSpeedWarning(UserWarning):
    """The train speed approaches the contact wire's wave propagation speed sqrt(T/rho)."""


class ContactLostWarning(UserWarning):
    """The pantograph left the wire for the whole statistics window (no contact to analyse)."""


def speed_regime(p: CatenaryParams, speed_ms: float) -> dict[str, Any]:
    """Wave speed, speed ratio and Doppler factor (c - V)/(c + V) of the contact wire; raises for V >= c and warns
    (CriticalSpeedWarning) above 70 % and 90 % of c."""
    c = p.cw_wave_speed
    ratio = speed_ms / c
    info = {"cw_wave_speed_ms": c, "cw_wave_speed_kmh": 3.6 * c, "speed_ratio": ratio,
            "doppler_factor": (c - speed_ms) / (c + speed_ms), "regime": "subcritical", "warnings": []}
    if ratio >= 1.0:
        raise ParameterError(
            f"speed {3.6 * speed_ms:.1f} km/h is at or above the contact wire wave speed sqrt(T/rho) = "
            f"{3.6 * c:.1f} km/h: the critical/supercritical regime has no steady solution in this "
            "small-displacement model")
    if ratio >= WARN_RATIO:
        info["regime"] = "near-critical" if ratio >= NEAR_CRITICAL_RATIO else "above EN 50119 limit"
        msg = (f"speed {3.6 * speed_ms:.1f} km/h is {100 * ratio:.1f} % of the contact wire wave speed "
               f"{3.6 * c:.1f} km/h (Doppler factor {info['doppler_factor']:.3f}); EN 50119 limits operation to "
               f"{100 * WARN_RATIO:.0f} %.")
        if ratio >= NEAR_CRITICAL_RATIO:
            msg += (" Near-critical regime: the wave ahead of the pantograph piles up, uplift and force variation grow"
                    " steeply and depend on mesh and time step; check convergence before using these numbers.")
        info["warnings"].append(msg)
        warnings.warn(msg, CriticalSpeedWarning, stacklevel=3)
    return info


def passage_size(p: CatenaryParams, speed_ms: float, dt: float) -> tuple[int, int]:
    """(FE elements, time steps) of a passage, computed from the parameters without building anything: each wire
    has at least ceil(length / element_length) elements (key points only add some), the pantograph moves
    x_end - x_start at speed_ms in steps of dt."""
    per_wire = math.ceil(p.length / p.element_length)
    steps = steps_to_cover(p.x_end - p.x_start, speed_ms, dt)
    return 2 * per_wire, steps


def check_size(p: CatenaryParams, speed_ms: float, dt: float, max_steps: float | None = None) -> None:
    """Refuse a passage whose elements x steps exceed `p.max_element_steps` (or whose steps exceed `max_steps`,
    the scene's solver.max_steps) with a `SceneError` naming the settings, before anything is allocated."""
    elements, steps = passage_size(p, speed_ms, dt)
    what = (f"a passage of {p.x_end - p.x_start:g} m at {3.6 * speed_ms:g} km/h with dt = {dt:g} s is {steps:,} "
            f"steps; element_length = {p.element_length:g} m gives about {elements:,} elements")
    if elements * steps > p.max_element_steps:
        raise SceneError(f"{what}: {float(elements) * steps:.3g} element-steps exceed params.max_element_steps = "
                         f"{p.max_element_steps:.3g}; enlarge element_length or timestep, or raise "
                         "max_element_steps if you mean it")
    if max_steps is not None and steps > max_steps:
        raise SceneError(f"{what}: exceeds solver.max_steps = {max_steps:.3g}; enlarge the timestep or raise "
                         "solver.max_steps (CLI: --max-steps) if you mean it")


def wave_courant(p: CatenaryParams, dt: float) -> Figure:
    """Health figure of the FE wave resolution: c dt / element_length, the elements a wire wave (c = the faster
    wire's sqrt(T/rho)) crosses per step; bound 1. The mesh resolves waves one element long; a longer step skips
    them (the trapezoidal rule stays stable but distorts them), and so does the pantograph, slower than the wave."""
    c = max(p.cw_wave_speed, p.mw_wave_speed)
    dt_max = p.element_length / c
    return Figure("wave_courant", float(c * dt / p.element_length), 1.0, "",
                  f"FE elements a wire wave (sqrt(T/rho) = {c:.1f} m/s) crosses per solver.timestep",
                  f"solver.timestep (--timestep) {dt:g} s is outside its valid range (0, {dt_max:.4g}] s = "
                  f"params.element_length / c = {p.element_length:g} m / {c:.1f} m/s: lower it, or enlarge "
                  "params.element_length")


def check_timestep(p: CatenaryParams, dt: float) -> None:
    """The hard bound of the catenary's time step, checked before anything is built: a positive dt below
    1 / (2 filter_cutoff) (the 20 Hz EN 50318 contact-force filter needs the record's Nyquist frequency above its
    cut-off; past it the statistics do not exist). A `ParameterError` names `solver.timestep` (CLI `--timestep`), the
    valid range and why; the accuracy bound (`wave_courant`) is `check_wave_resolution`'s."""
    if not (isinstance(dt, int | float) and not isinstance(dt, bool) and math.isfinite(dt) and dt > 0):
        raise ParameterError(f"solver.timestep (--timestep) must be a positive number of seconds, got {dt!r}")
    c = max(p.cw_wave_speed, p.mw_wave_speed)
    nyquist, courant = 1.0 / (2.0 * p.filter_cutoff), p.element_length / c
    if not dt < nyquist:
        raise ParameterError(
            f"solver.timestep (--timestep) = {dt:g} s is outside its valid range (0, {nyquist:.4g}) s: the "
            f"{p.filter_cutoff:g} Hz contact-force filter (params.filter_cutoff) needs the record's Nyquist frequency "
            f"1/(2 dt) above its cut-off (and the FE wave resolution asks for at most params.element_length / c = "
            f"{p.element_length:g} m / {c:.1f} m/s = {courant:.4g} s)")


def check_wave_resolution(p: CatenaryParams, dt: float, allow_inaccurate: bool = False) -> list[str]:
    """The FE wave resolution of a (valid) time step, judged before anything is built: `wave_courant` past its bound
    is an `AccuracyError` naming `solver.timestep` and its valid range, unless `allow_inaccurate` (then its warning
    is returned; the run's health figures carry it again)."""
    fig = wave_courant(p, dt)
    if fig.ok:
        return []
    if not allow_inaccurate:
        judge([fig], what="catenary passage")  # raises AccuracyError naming the figure, its bound and the fix
    return ["INACCURATE: " + fig.message("catenary passage")]


def health(run: CatenaryRun) -> list[Figure]:
    """Health figures of a passage: the train speed against the contact wire's wave speed (bound: the near-critical
    ratio, above which the model's own results depend on mesh and step; see `speed_regime`)."""
    return health_of_regime(run.speed_kmh / 3.6, run.params, run.dt)


def health_of_regime(speed_ms: float, p: CatenaryParams, dt: float | None = None) -> list[Figure]:
    """`health` from the speed (m/s), the catenary parameters and the time step (s; adds `wave_courant`) (used by
    single and train passages)."""
    c = p.cw_wave_speed
    figs = [Figure("speed_ratio", float(speed_ms / c), NEAR_CRITICAL_RATIO, "",
                   "train speed / contact wire wave speed sqrt(T/rho)",
                   f"lower input.speed below {3.6 * NEAR_CRITICAL_RATIO * c:.1f} km/h "
                   "or raise cw_tension; a near-critical passage needs its own mesh and step convergence study")]
    return figs + ([wave_courant(p, dt)] if dt is not None else [])


@dataclass
class CatenaryRun:
    """A coupled run with its EN 50318 statistics."""

    params: CatenaryParams
    speed_kmh: float
    dt: float
    dropper_law: str
    pantograph: str
    result: CoupledResult
    stats: dict
    filtered: np.ndarray
    regime: dict
    timing: dict
    ranges: dict | None = None
    warnings: list[str] = field(default_factory=list)
    static_force: float = 0.0
    engine_warnings: dict[str, int] = field(default_factory=dict)
    is_reference: bool = False  # the EN 50318 reference scene (2-mass pantograph, specification's parameters)
    engine: str = "reference"  # the pantograph's engine path (the catenary is always the FE reference code)


def simulate(p: CatenaryParams, speed_kmh: float, dt: float, dropper_law: str = "slack",
             pantograph: str | Pantograph = "reference2mass", contact: str = "unilateral",
             progress: Callable[[int, int], None] | None = None, fe: CatenaryFE | None = None,
             engine: str = "reference", pantograph_section: dict[str, Any] | None = None,
             max_steps: float | None = None, native: bool | None = None,
             allow_inaccurate: bool = False) -> CatenaryRun:
    """Build, run and analyse one pantograph passage (the EN 50318 procedure). `pantograph` is a name
    (the scene's `pantograph` effect, built on the engine path `engine` with the `[pantograph]` section
    `pantograph_section`; see `pantographs.build`) or an object of the pantograph protocol. The speed and the size of
    the job (`check_size`: elements x steps against `p.max_element_steps`, steps against `max_steps`) are checked
    before anything is built or integrated. `native`: the compiled step core (None: whenever it applies, see
    `CoupledSimulation.run`; False: the readable Python path)."""
    if not (isinstance(speed_kmh, int | float) and math.isfinite(speed_kmh) and speed_kmh > 0):
        raise ParameterError(f"speed must be a positive number of km/h, got {speed_kmh!r}")
    check_timestep(p, dt)
    V = speed_kmh / 3.6
    regime = speed_regime(p, V)
    check_size(p, V, dt, max_steps)
    step_warn = check_wave_resolution(p, dt, allow_inaccurate)
    t0, c0 = time.perf_counter(), time.process_time()
    fe = fe if fe is not None else assemble(p)
    if isinstance(pantograph, str):
        panto = build_pantograph(pantograph, p, engine=engine, dt=dt, section=pantograph_section, contact=contact)
    else:
        panto = pantograph
    sim = CoupledSimulation(fe, panto, V, dt, dropper_law=dropper_law, contact=contact)
    t1 = time.perf_counter()
    res = sim.run(p.x_start, p.x_end, progress=progress, native=native)
    t2 = time.perf_counter()
    stats, ff = en50318_statistics(res.t, res.x, res.force, res.uplift, res.support_x, dt, p)
    t3, c3 = time.perf_counter(), time.process_time()
    warn = list(regime["warnings"]) + step_warn
    w = in_window(res.x, p)
    if not np.any(res.force[w] > 0):
        msg = (f"the pantograph is off the wire for the whole window [{p.window_start}, {p.window_end}] m "
               f"(static uplift F0 = {p.F0} N): no contact force to analyse")
        warn.append(msg)
        warnings.warn(msg, ContactLostWarning, stacklevel=2)
        stats["contact_lost_entirely"] = True
    else:
        stats["contact_lost_entirely"] = False
    timing = {"build_s": t1 - t0, "integrate_s": t2 - t1, "statistics_s": t3 - t2, "total_s": t3 - t0,
              "cpu_s": c3 - c0,
              "steps": res.stats["steps"], "dofs": res.stats["dofs"],
              "us_per_step": 1e6 * (t2 - t1) / max(res.stats["steps"], 1),
              "native": bool(res.stats.get("native", False)),
              "method": "trapezoidal rule (Newmark beta=1/4), banded Cholesky factorised once, "
                        + ("compiled step core (native/catenary.c: block sweeps, fused mat-vec and recursions)"
                           if res.stats.get("native") else "LAPACK dpbtrs per step (Python path)")
                        + ", exact per-step contact/slack-dropper active set on precomputed influence columns"}
    name = pantograph if isinstance(pantograph, str) else getattr(pantograph, "name", "custom")
    eng_warn = panto.engine_warnings() if hasattr(panto, "engine_warnings") else {}
    if eng_warn:
        warn.append(f"MuJoCo warnings in the pantograph model: {eng_warn}")
    # the EN 50318 ranges apply to the reference scene only: 2-mass pantograph, specification's parameters
    is_reference = name == "reference2mass" and dataclasses.replace(
        p, element_length=1.0, max_element_steps=MAX_ELEMENT_STEPS) == CatenaryParams(element_length=1.0)
    return CatenaryRun(params=p, speed_kmh=float(speed_kmh), dt=float(dt), dropper_law=dropper_law,
                       pantograph=name, result=res, stats=stats, filtered=ff, regime=regime, timing=timing,
                       ranges=check_ranges(stats, speed_kmh) if is_reference else None, warnings=warn,
                       static_force=float(res.force[0]), engine_warnings=eng_warn, is_reference=is_reference,
                       engine=str(getattr(panto, "engine", "reference")))


# --- scene plumbing ---------------------------------------------------------------------------------------------
def scene_speed(scene, speed_kmh: float | None) -> float:
    """The passage speed (km/h): `speed_kmh` if given, else the scene's `input.speed`; SceneError if neither."""
    v = speed_kmh if speed_kmh is not None else scene.input.get("speed")
    if v is None:
        raise SceneError("no speed: give --speed KMH or [input] speed = ... (km/h) in the scene")
    return float(v)


def run_scene(scene, speed_kmh: float | None = None, progress=None, **overrides) -> CatenaryRun:
    """One passage of a catenary scene: its parameters (with `overrides`), speed, time step, effects, the pantograph
    its `pantograph` effect names on the path `solver.engine`, with the `[pantograph]` section."""
    p = scene.build_params()
    if overrides:
        p = dataclasses.replace(p, **overrides)
    return simulate(p, scene_speed(scene, speed_kmh), scene.solver.timestep, dropper_law=scene.effects["droppers"],
                    pantograph=scene.effects["pantograph"], contact=scene.effects["contact"], progress=progress,
                    engine=scene.solver.engine, pantograph_section=scene.sections.get("pantograph"),
                    max_steps=scene.solver.max_steps, allow_inaccurate=scene.solver.allow_inaccurate)


def to_simresult(run: CatenaryRun, scene) -> SimResult:
    """The run as a SimResult (`results.assemble`: the scene's output signals with the declared units). The declared
    signal `uplift` stands for one column per support, `uplift_<x>m` (x = the support's position), in its unit.
    `stats`: timings, the eight EN 50318 statistics, the static contact force, the pantograph engine's warnings and
    the quality verdicts (`quality_pass`, `quality_<criterion>_pass`, `quality_nq_pct`; limits from the scene's
    `[quality]` section, else the AC defaults);
    `events`: the contact losses in the window."""
    r = run.result
    signals = {"contact_force": r.force, "contact_force_filtered": run.filtered, "position": r.x,
               "head_height": r.head, "wire_height": r.wire, "slack_droppers": r.n_slack.astype(float)}
    q = quality_of(run, criteria_from(scene.sections.get("quality")))
    stats = {**{k: v for k, v in run.timing.items() if k != "method"}, **_scalar_stats(run),
             "static_contact_force": run.static_force, "warnings": dict(run.engine_warnings),
             "quality_pass": q["pass"], **{f"quality_{k}_pass": r["pass"] for k, r in q["rows"].items()},
             "quality_nq_pct": q["rows"]["arcing_nq"]["value"]}
    res = assemble_result(scene, r.t, signals, engine=run.engine, events=run.stats["loss_events"], stats=stats,
                          health=health(run))
    if "uplift" in scene.outputs:
        unit = scene.spec.outputs["uplift"]
        for j, xs in enumerate(r.support_x):
            res.signals[f"uplift_{xs:g}m"] = r.uplift[:, j]
            res.units[f"uplift_{xs:g}m"] = unit
    return res


def _scalar_stats(run: CatenaryRun) -> dict:
    return {k: run.stats[k] for k in STAT_NAMES}


def window_time(stats: dict, dt: float) -> float:
    """Time (s) the pantograph spent in the statistics window (its window samples times dt)."""
    return float(stats["n_samples_window"]) * dt


def quality_of(run: CatenaryRun, criteria: QualityCriteria) -> dict:
    """The current-collection quality assessment of a run (`quality.assess`, the one function for every pantograph
    under the wire)."""
    return assess(run.stats, run.speed_kmh, criteria, window_time(run.stats, run.dt))


def report(run: CatenaryRun, scene_dict: dict | None = None, extra_runs: list[CatenaryRun] | None = None,
           quality: QualityCriteria | None = None) -> Report:
    """Human table + JSON data + writer (CSV of filtered/unfiltered force, PNG plots) for one run (and optional
    companion runs shown beside it, e.g. the linear-dropper scene). `quality`: add the current-collection quality
    report of every run (table, JSON `quality`, plot `quality_<pantograph>_<speed>kmh.png`)."""
    runs = [run] + list(extra_runs or [])
    key = int(round(run.speed_kmh))
    rng = ACCEPTED_RANGES.get(key) if (abs(run.speed_kmh - key) < 1e-9 and run.ranges is not None) else None
    headers = ["statistic"] + [f"{r.dropper_law} droppers" for r in runs] + (
        ["EN 50318 range", f"ok ({run.dropper_law})"] if rng else [])
    rows = []
    for name, label in STAT_NAMES.items():
        row = [label] + [f"{r.stats[name]:.2f}" for r in runs]
        if rng:
            lo, hi = rng[name]
            row += [f"{lo:g} .. {hi:g}", "yes" if run.ranges[name]["inside"] else "NO"]
        rows.append(row)
    what = "EN 50318 reference scene" if run.is_reference else "catenary passage (EN 50318 statistics)"
    path = "" if run.engine == "reference" else f" ({run.engine} path)"
    lines = [f"{what}, {run.pantograph} pantograph{path}, {run.speed_kmh:g} km/h "
             f"(element {run.params.element_length:g} m, dt {run.dt:g} s)", format_table(headers, rows)]
    for r in runs:
        c = r.stats["loss_counts"]
        lines.append(f"[{r.dropper_law}] contact losses in window: {len(r.stats['loss_events'])} "
                     f"(<5 ms: {c['short_lt_5ms']}, 5-20 ms: {c['damaging_5_20ms']}, "
                     f">20 ms: {c['power_loss_gt_20ms']}); "
                     f"static contact force {r.static_force:.2f} N; run time {r.timing['total_s']:.2f} s wall, "
                     f"{r.timing['cpu_s']:.2f} s CPU "
                     f"({r.timing['steps']} steps, {r.timing['dofs']} DOFs, {r.timing['us_per_step']:.0f} us/step)")
        lines[-1] = textwrap.fill(lines[-1], 100, subsequent_indent="  ")
    lines.append(f"speed ratio V/c = {run.regime['speed_ratio']:.3f} (c = {run.regime['cw_wave_speed_kmh']:.1f} km/h), "
                 f"regime: {run.regime['regime']}")
    lines[-1] = textwrap.fill(lines[-1], 100, subsequent_indent="  ")
    for w in run.warnings:
        lines.append(textwrap.fill(f"WARNING: {w}", 100, subsequent_indent="  "))
    data = {"speed_kmh": run.speed_kmh, "pantograph": run.pantograph, "engine": run.engine,
            "element_length": run.params.element_length,
            "timestep": run.dt, "regime": {k: v for k, v in run.regime.items() if k != "warnings"},
            "warnings": run.warnings,
            "runs": {r.dropper_law: {"statistics": _scalar_stats(r), "ranges": r.ranges,
                                     "uplift_at_supports_mm": r.stats["uplift_at_supports_mm"],
                                     "loss_counts": r.stats["loss_counts"], "loss_events": r.stats["loss_events"],
                                     "contact_lost_entirely": r.stats["contact_lost_entirely"],
                                     "static_contact_force": r.static_force, "timing": r.timing} for r in runs}}
    if rng:
        data["all_inside_ranges"] = all(v["inside"] for v in run.ranges.values())
    assessments = []
    if quality is not None:
        for r in runs:
            q = quality_of(r, quality)
            assessments.append((f"{r.pantograph} ({r.dropper_law} droppers)", q))
            data["runs"][r.dropper_law]["quality"] = q
            lines.append(f"current-collection quality [{r.dropper_law} droppers], {quality.system} criteria, "
                         f"{r.speed_kmh:g} km/h: {'PASS' if q['pass'] else 'FAIL'}")
            lines.append(format_table(["criterion", "value", "limit", "verdict"], quality_table_rows(q)))
        data["quality_pass"] = all(q["pass"] for _, q in assessments)

    def write(out: Path) -> list[Path]:
        files = write_run_files(runs, out)
        if assessments:
            files.append(quality_plot(assessments, Path(out) / f"quality_{run.pantograph}_{run.speed_kmh:g}kmh.png"))
        return files

    return Report(data=data, table="\n".join(lines), write=write)


def write_run_files(runs: list[CatenaryRun], out: Path) -> list[Path]:
    """Write each run's contact-force record (`contact_force_<pantograph>_<droppers>_<speed>kmh.csv`, SI units in
    the header) and the force/uplift figure of all of them (`force_uplift_<pantograph>_<speed>kmh.png`); return the
    paths."""
    from ...plotting import save

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    files = []
    for r in runs:
        tag = f"{r.pantograph}_{r.dropper_law}_{r.speed_kmh:g}kmh"
        res = r.result
        files.append(write_csv(out / f"contact_force_{tag}.csv", [
            ("t", "s", res.t), ("x", "m", res.x), ("force", "N", res.force), ("force_filtered_20Hz", "N", r.filtered),
            ("head_height", "m", res.head), ("wire_height", "m", res.wire)]))
    files.append(save(force_uplift_figure(runs),
                      out / f"force_uplift_{runs[0].pantograph}_{runs[0].speed_kmh:g}kmh.png"))
    return files


def force_uplift_figure(runs: list[CatenaryRun]) -> MplFigure:
    """Contact force (unfiltered and 20 Hz low-pass), contact-wire height at the contact point and uplift at the
    steady arms of the statistics window, against the pantograph position; one colour per dropper law, the window
    shaded, the supports as vertical lines."""
    from ...plotting import figure

    p = runs[0].params
    fig, axes = figure(3, 1, size=(11, 10), sharex=True)
    colours = {"slack": "tab:blue", "linear": "tab:red"}
    styles = ("-", "--", ":", "-.")
    for r in runs:
        res = r.result
        c = colours.get(r.dropper_law, "tab:green")
        lab = f"{r.dropper_law} droppers"
        axes[0].plot(res.x, res.force, lw=0.4, alpha=0.4, color=c, label=f"{lab}: F, unfiltered")
        axes[0].plot(res.x, r.filtered, lw=1.2, color=c, label=f"{lab}: F, 20 Hz low-pass")
        axes[1].plot(res.x, 1000 * res.wire, lw=1.0, color=c, label=lab)
        inside = [(j, xs) for j, xs in enumerate(res.support_x) if p.window_start <= xs <= p.window_end]
        for (j, xs), ls in zip(inside, (styles * len(inside))[:len(inside)], strict=True):
            axes[2].plot(res.x, 1000 * res.uplift[:, j], lw=1.0, color=c, ls=ls,
                         label=f"{lab}: steady arm at x = {xs:g} m")
    for ax in axes:
        ax.set_xlim(p.x_start, p.x_end)
        ax.axvspan(p.window_start, p.window_end, color="0.9", zorder=-1)
        for k in range(p.n_spans + 1):
            if p.x_start <= k * p.span_length <= p.x_end:
                ax.axvline(k * p.span_length, color="0.7", lw=0.5, zorder=-1)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].set_ylabel("contact force F [N]")
    axes[1].set_ylabel("contact-wire height at the\ncontact point [mm]")
    axes[2].set_ylabel("contact-wire uplift at\nthe steady arm [mm]")
    axes[2].set_xlabel("pantograph position x [m] (thin vertical lines: supports)")
    what = "EN 50318 reference scene" if runs[0].is_reference else "catenary passage"
    path = "" if runs[0].engine == "reference" else f" ({runs[0].engine} path)"
    axes[0].set_title(f"{what}, {runs[0].pantograph} pantograph{path}, {runs[0].speed_kmh:g} km/h; heights and "
                      "uplift from the static state (grey: statistics window)", fontsize=10)
    return fig
