"""`mbsuite catenary SCENE --speed KMH [--engine E] [--with-linear] [--quality [--system S]] [--error-estimate]
[--allow-inaccurate] [--json] [--out DIR]`: EN 50318 statistics, the current-collection quality report and the
statistics' estimated errors (`accuracy.py`)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import TYPE_CHECKING

from ...cli.options import add_error_estimate, add_scene_options, check_workers, scene_of
from ...cli.study import add_study_options, run_or_study
from ...errors import SceneError
from ...progress import Progress

if TYPE_CHECKING:  # imported where the command runs: its --help loads no model module
    from ...results import Report
    from ...scenes import Scene

COMMAND = "catenary"
# the top-level commands `register` adds, with their help (read by `mbsuite --help` without importing the model)
CLI_COMMANDS = {"catenary": "pantograph passage under the FE catenary: EN 50318 statistics, plots, CSV"}


def register(sub, add_common, emit) -> str:
    """Add the `mbsuite catenary` command to the CLI's subparsers `sub`; returns its name."""
    p = sub.add_parser(COMMAND, help=CLI_COMMANDS[COMMAND])
    p.add_argument("scene", nargs="?", default="catenary",
                   help="scene TOML path, 'catenary' (default scene), catenary/<scene>, or a line file (TOML with "
                        "[[wires]]: run under the default scene; model README 'Lines of your own', 'A line in a file')")
    p.add_argument("--speed", type=float, default=None, help="train speed (km/h); default: the scene's input.speed")
    p.add_argument("--timestep", type=float, default=None, help="override solver.timestep (s)")
    p.add_argument("--element-length", type=float, default=None, help="override params.element_length (m)")
    p.add_argument("--engine", choices=["reference", "mujoco"], default=None,
                   help="pantograph path (mujoco: only with the eppinger pantograph)")
    p.add_argument("--with-linear", action="store_true",
                   help="also run the same scene with linear (bilateral) droppers and report it beside")
    p.add_argument("--quality", action="store_true",
                   help="current-collection quality report (EN 50367 / TSI Energy shape): Fm against the target "
                        "curve, sigma <= 0.3 Fm, Fm - 3 sigma > 0, contact loss, arcing NQ, uplift; pass/fail per "
                        "criterion (limits: the scene's [quality] section, else the system's defaults)")
    p.add_argument("--system", choices=["AC", "DC3kV", "DC1.5kV"], default=None,
                   help="electrification system of the quality criteria' defaults (default: [quality] system, "
                        "else AC)")
    p.add_argument("--spacings", type=float, nargs="+", default=None,
                   help="distances (m) between consecutive pantographs of a [train] scene (overrides the scene)")
    p.add_argument("--workers", type=int, default=0,
                   help="local processes for the companion passages of --error-estimate (0 = all cores)")
    add_error_estimate(p)
    add_scene_options(p)
    add_study_options(p)
    add_common(p)
    p.set_defaults(func=cmd_catenary, emit=_recording(emit))
    return COMMAND


#: the solver settings a catenary passage reads (the rest, MuJoCo's integrator and the equations path's, it does not)
SOLVER_READ = ("engine", "timestep", "duration", "allow_inaccurate", "max_steps")


def recorded_scene(scene_dict: dict, data: dict) -> dict:
    """The scene summary.json records of a passage whose report data is `data`: only the solver settings a catenary
    passage reads (`SOLVER_READ`; a rerun fills the others with their defaults, which it does not read) and the
    [params] the passage actually used pinned (the run's x_start/x_end, the statistics window and the element length:
    a rerun takes them as given, whatever default made them)."""
    out = dict(scene_dict)
    if isinstance(out.get("solver"), dict):
        out["solver"] = {k: v for k, v in out["solver"].items() if k in SOLVER_READ}
    if "window" in data and "x_range" in data:
        (x0, x1), (w0, w1) = data["x_range"], data["window"]
        out["params"] = {**(out.get("params") or {}), "x_start": x0, "x_end": x1, "window_start": w0,
                         "window_end": w1, "element_length": data["element_length"]}
    return out


def _recording(emit):
    """The CLI's `emit` with the scene it records (summary.json) as `recorded_scene` makes it."""

    def out(report, args, scene_dict):
        if scene_dict is not None:
            scene_dict = recorded_scene(scene_dict, report.data)
        return emit(report, args, scene_dict)

    return out


def check_summary_line(path: str) -> None:
    """Before `mbsuite catenary summary.json` reruns it: a SceneError where a file of the line it recorded (the line
    file, the tables it reads, the irregularity profile) no longer has the recorded content (`marks.line_changed`):
    the rerun would not be the run it records."""
    import json

    from .marks import line_changed

    try:
        results = json.loads(Path(path).read_text()).get("results") or {}
    except (OSError, ValueError, AttributeError):
        return  # not readable as a summary: `scene_of` says why
    line = results.get("line") if isinstance(results, dict) else None
    changed = line_changed(line) if isinstance(line, dict) else []
    if changed:
        raise SceneError(f"{path}: the line's file(s) {', '.join(changed)} changed (or went) since the run it records "
                         "(SHA-256 differs): a rerun would not be that run; run a scene on the files as they are now")


class _Percent:
    """A progress callback `(step, total)` that advances a 100-step `Progress` bar by whole percent."""

    def __init__(self, bar: Progress):
        self.bar, self.last = bar, 0

    def __call__(self, step: int, total: int) -> None:
        k = int(100 * step / total)
        if k > self.last:
            self.bar.update(k - self.last)
            self.last = k


def line_scene(path: str) -> Scene:
    """The default scene (`catenary/en50318`: 2-mass reference pantograph, 250 km/h) on the line of a line file: the
    statistics window the line's default (`marks.default_window`, on its supports) and the run from 0 to 0.7 L (L:
    its length; the EN 50318 scene's 420 of 600 m), or on to the middle of the span after the window where that lies
    further (the uplift at the window's last steady arm is seen as the pantograph passes it); a scene of your own
    (`[line] file = ...`) sets them."""
    from ...scenes import load_scene, scene_from_dict
    from .linefile import read_line_file
    from .marks import default_window

    line = read_line_file(path)[0]
    L = line.length
    a, b = default_window(line)
    after = min((s.x for s in line.supports if s.x > b), default=L)
    d = load_scene("catenary/en50318").to_dict()
    d.update(name=Path(path).stem, description=f"the line of {path} under the scene catenary/en50318",
             line={"file": str(Path(path).resolve())},
             params={"x_start": 0.0, "x_end": min(L, max(0.7 * L, 0.5 * (b + after))), "window_start": a,
                     "window_end": b})
    return scene_from_dict(d, source=str(path))


def _scene(args: argparse.Namespace) -> Scene:
    """The command's catenary scene with the command line's overrides."""
    from .linefile import is_line_file

    if str(args.scene).endswith(".json"):
        check_summary_line(args.scene)
    scene = line_scene(args.scene) if is_line_file(args.scene) else scene_of(args.scene)
    if scene.model != "catenary":
        raise SceneError(f"scene {args.scene!r} is a '{scene.model}' scene; the catenary command needs a "
                         "catenary scene")
    old = scene.input.get("speed")
    flags = [("--engine", "solver", "engine", args.engine), ("--timestep", "solver", "timestep", args.timestep),
             ("--element-length", "params", "element_length", args.element_length),
             ("--speed", "input", "speed", args.speed),
             ("--allow-inaccurate", "solver", "allow_inaccurate", True if args.allow_inaccurate else None),
             ("--max-steps", "solver", "max_steps", getattr(args, "max_steps", None))]
    for flag, section, key, value in flags:
        if value is not None:
            scene = scene.replace(origin=f"on the command line ({flag})", **{section: {key: value}})
    new = scene.input.get("speed")
    if args.speed is not None and old is not None and old != new and f"{old:g} km/h" in scene.description:
        # the description names the scene's speed: say the speed this run is at
        scene = scene.replace(description=scene.description.replace(f"{old:g} km/h", f"{new:g} km/h"))
    if args.spacings is not None:
        if "train" not in scene.sections:
            raise SceneError("--spacings needs a scene with a [train] section (e.g. catenary/en50318_two_pantographs)")
        scene = scene.replace(train={"spacings": list(args.spacings)}, origin="on the command line (--spacings)")
    return scene


# the units of the numbers a passage reports, by their names (a --vary study's table, CSV and figure)
UNITS = {"Fm": "N", "sigma": "N", "stat_max": "N", "stat_min": "N", "max": "N", "min": "N",
         "static_contact_force": "N", "uplift_mm": "mm", "loss_pct": "%", "speed_kmh": "km/h", "speed": "km/h",
         "cw_wave_speed_kmh": "km/h", "cw_wave_speed_ms": "m/s", "speed_ratio": "1", "doppler_factor": "1",
         "element_length": "m", "timestep": "s", "build_s": "s", "cpu_s": "s", "integrate_s": "s",
         "statistics_s": "s", "total_s": "s", "us_per_step": "us"}


def cmd_catenary(args: argparse.Namespace) -> None:
    """One passage (or a train's, with `[train]`) of the scene, and its report (or a --vary study of it)."""
    run_or_study(args, _scene(args), f"{__name__}:catenary_of", units=UNITS, parallel_inside=bool(args.error_estimate))


def catenary_of(scene: Scene, args: argparse.Namespace) -> Report:
    """The report of one passage (or a train's) of `scene`: the command's, or a study point's."""
    from .analysis import run_scene, run_train_scene
    from .reports import report, train_report

    criteria = None
    if getattr(args, "quality", False) or getattr(args, "system", None) is not None:
        from .quality import criteria_from

        sec = dict(scene.sections.get("quality") or {})
        if args.system is not None:
            sec["system"] = args.system
        criteria = criteria_from(sec)
    workers = check_workers(args.workers)
    if args.error_estimate:  # the compiled core built (once per machine) before the run whose time scales the plan
        from .native_core import library

        library()
    t0 = time.perf_counter()
    if "train" in scene.sections:
        with Progress(100, desc="catenary train") as bar:
            run = run_train_scene(scene, progress=_Percent(bar))
        rep = train_report(run, quality=criteria, scene_dict=scene.to_dict())
        if args.error_estimate:
            add_estimate(rep, scene, run.stats, workers, time.perf_counter() - t0)
        return rep
    variants = [scene]
    if args.with_linear and scene.effects["droppers"] != "linear":
        variants.append(scene.replace(effects={"droppers": "linear"}))
    runs, took = [], []
    for sc in variants:
        t0 = time.perf_counter()
        with Progress(100, desc=f"catenary {sc.effects['droppers']}") as bar:
            runs.append(run_scene(sc, progress=_Percent(bar)))
        took.append(time.perf_counter() - t0)
    rep = report(runs[0], scene.to_dict(), runs[1:], quality=criteria)
    if args.error_estimate:
        add_estimate(rep, scene, [runs[0].stats], workers, took[0])
    return rep


def add_estimate(rep: Report, scene: Scene, stats: list[dict], workers: int = 0,
                 seconds: float | None = None) -> None:
    """Estimate the error of every pantograph's statistics of the passage `stats` (the scene's own run, leading
    pantograph first) from its companions (`accuracy.refinement`: coarsened once and twice, else refined once and
    twice; run in parallel), judge each estimate against its tolerance and add the table, `error_estimate` and the
    warnings to the report. An estimate above its tolerance keeps the report: a warning where the scene allows
    inaccurate results, else `InaccurateResult` carrying the report (the command prints it, writes its files and
    exits 3). `seconds`: the run's wall time, from which the companions' time is estimated (and checked against the
    budget) before they start."""
    from ...analysis.errorestimate import error_estimate
    from ...progress import OverBudget
    from ...trust.health import InaccurateResult, judge_estimate
    from .accuracy import passage_values, stats_values

    try:
        est = error_estimate(scene, base=stats_values(stats), evaluate=passage_values, workers=workers,
                             base_seconds=seconds)
    except OverBudget as exc:  # the run is kept: printed and written, then the command stops (exit 2)
        rep.table = "\n".join([rep.table, f"error estimate not run: {exc}"])
        rep.data["error_estimate"] = {"not_run": str(exc)}
        exc.result = rep
        raise
    warned = judge_estimate(est.figures(), allow_inaccurate=scene.solver.allow_inaccurate,
                            what=f"catenary scene {scene.name or scene.source or ''}".strip())
    rep.data["error_estimate"] = est.to_dict()
    rep.data["warnings"] = list(rep.data.get("warnings", [])) + warned
    rep.table = "\n".join([rep.table, est.table(), *warned])
    if warned and not scene.solver.allow_inaccurate:
        raise InaccurateResult(warned, rep)
