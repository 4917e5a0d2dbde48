"""Command line: `mbsuite list | run | equilibrium | modes | freqresp | workprecision | hardcases` plus model-specific
groups.

Each analysis prints a human table by default, JSON with `--json`, and with `--out DIR` writes CSV (SI units in the
header), PNG plots and `summary.json` (versions + scene). A model package may add its own sub-commands by defining
`register(subparsers)` in its `cli` module.
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from . import registry
from .analysis.sweep import EXECUTORS, MAX_POINTS, SweepOptions, ambient_options, check_grid, parse_values
from .errors import MbsuiteError
from .limits import Limit
from .results import Report, SimResult, format_table, to_jsonable
from .scenes import DEFAULT_MAX_STEPS, load_scene


def _emit(report: Report, args: argparse.Namespace, scene_dict: dict | None) -> None:
    files = report.save(args.out, scene_dict) if getattr(args, "out", None) else []
    if args.json:
        payload = dict(report.data)
        if files:
            payload["files"] = [str(f) for f in files]
        print(json.dumps(to_jsonable(payload), indent=2))
    else:
        print(report.table)
        for f in files:
            print(f"wrote {f}")


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")
    p.add_argument("--out", metavar="DIR", help="write CSV/PNG/summary.json into DIR")


ANALYSES = ("run", "equilibrium", "modes", "freqresp", "view")
CLI_GROUPS: dict[str, str] = {}  # model -> its own command group (filled when the parser is built)


def _analyses(spec: registry.ModelSpec) -> list[str]:
    """The analyses a model offers: the generic hooks it implements, its own command group, the suite's studies."""
    hooks = {"run": spec.paths or None, "view": spec.mujoco_model}
    out = [a for a in ANALYSES if (hooks[a] if a in hooks else getattr(spec, a)) is not None]
    if spec.paths:
        out += ["sweep", "perturb"]
    if spec.cases:
        out += ["workprecision", "hardcases"]
    group = CLI_GROUPS.get(spec.name)
    if group:
        out.append(f"mbsuite {group} ...")
    return out


def _cmd_list(args: argparse.Namespace) -> None:
    rows = []
    data = {}
    blocks = []
    for name, spec in sorted(registry.models().items()):
        scenes = sorted(spec.scene_files())
        analyses = _analyses(spec)
        rows.append([name, spec.default_scene, len(scenes), "/".join(spec.engines)])
        data[name] = {"summary": spec.summary, "default_scene": spec.default_scene, "scenes": scenes,
                      "engines": list(spec.engines), "analyses": analyses,
                      "effects": {k: list(e.choices) for k, e in spec.effects.items()}}
        blocks.append(_wrap(f"{name}: {spec.summary}", indent="") + "\n" + _wrap("analyses: " + ", ".join(analyses))
                      + "\n" + _wrap("scenes: " + ", ".join(scenes)))
    table = format_table(["model", "default scene", "scenes", "engines"], rows) + "\n\n" + "\n\n".join(blocks)
    _emit(Report(data, table), args, None)


def _wrap(text: str, width: int = 100, indent: str = "  ") -> str:
    import textwrap

    return textwrap.fill(text, width=width, initial_indent=indent, subsequent_indent=indent + "  ")


def _sweep_args(p: argparse.ArgumentParser) -> None:
    """Where the command's sweep runs (the one sweep API, mbsuite.analysis.sweep)."""
    p.add_argument("--executor", choices=EXECUTORS, default=None,
                   help="local: processes on all cores; threads: C threads of the native core (MuJoCo work); dask: a "
                        "Dask distributed cluster (default: threads for MuJoCo points, processes for the rest)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="Dask scheduler address (tcp://HOST:PORT) for --executor dask")
    p.add_argument("--store", metavar="FILE", help="stream finished points to FILE (JSON lines) and resume from it")
    p.add_argument("--max-points", type=int, default=None, metavar="N",
                   help=f"size guard: most points of one sweep (default {MAX_POINTS})")


def _sweep_options(args: argparse.Namespace) -> SweepOptions:
    max_points = getattr(args, "max_points", None)
    return SweepOptions(executor=getattr(args, "executor", None), scheduler=getattr(args, "scheduler", None),
                        store=getattr(args, "store", None), max_points=MAX_POINTS if max_points is None else max_points)


def _sweeping(args: argparse.Namespace):
    return ambient_options(_sweep_options(args))


MAX_REPEATS = 100


def _cmd_workprecision(args: argparse.Namespace) -> None:
    from .analysis.workprecision import workprecision

    scene = load_scene(args.scene)
    if not 1 <= args.repeats <= MAX_REPEATS:
        raise MbsuiteError(f"--repeats {args.repeats} is invalid; valid: integer in [1, {MAX_REPEATS}] (runs per "
                           "setting; the wall time is their median)")
    progress = (lambda msg: print(msg, file=sys.stderr, flush=True)) if args.verbose else None
    report = workprecision(scene, repeats=args.repeats, quick=args.quick, progress=progress)
    _emit(report, args, scene.to_dict())


def _cmd_hardcases(args: argparse.Namespace) -> None:
    from . import hardcases

    cases = hardcases.cases(args.model, include_slow=not args.no_slow)
    if args.name:
        cases = [hardcases.get(n) for n in args.name]
    data: dict = {"cases": []}
    rows = []
    outcomes = {}
    if args.run:
        for c in cases:
            outcomes[c.name] = hardcases.run_case(c)
    for c in cases:
        d = {"name": c.name, "model": c.model, "hard": c.hard, "scene": c.scene, "asserts": c.asserts,
             "slow": c.slow, "known": c.known or None, "expected_failure": c.expected_failure or None}
        status = ""
        if c.name in outcomes:
            o = outcomes[c.name]
            status = "PASS" if o.passed else ("KNOWN FAIL" if c.expected_failure else "FAIL")
            d.update(passed=o.passed, error=o.error,
                     checks=[{"what": k.what, "ok": k.ok, "value": k.value, "bound": k.bound} for k in o.checks])
        data["cases"].append(d)
        rows.append([c.name, c.model, "slow" if c.slow else "", status, c.hard])
    counts: dict[str, int] = {}
    for c in cases:
        counts[c.model] = counts.get(c.model, 0) + 1
    data["counts"] = {"total": len(cases), "by_model": counts}
    table = format_table(["case", "model", "", "result" if args.run else "", "what makes it hard"], rows)
    table += "\n" + f"{len(cases)} hard cases: " + ", ".join(f"{m} {n}" for m, n in sorted(counts.items()))
    if args.run:
        n_ok = sum(o.passed for o in outcomes.values())
        n_known = sum(1 for n, o in outcomes.items() if not o.passed and hardcases.get(n).expected_failure)
        data["counts"].update(passed=n_ok, known_failures=n_known)
        table += (f"; {n_ok}/{len(outcomes)} pass, {n_known} known failure(s)\n\n"
                  + "\n".join(o.text() for o in outcomes.values()))
    else:
        table += "\n" + "\n".join(f"- {c.name}: scene {c.scene}; asserts {c.asserts}" +
                                   (f"; KNOWN: {c.known}" if c.known else "")
                                   + (f"; FAILS TODAY: {c.expected_failure}" if c.expected_failure else "")
                                   for c in cases)
    _emit(Report(data, table), args, None)
    bad = [n for n, o in outcomes.items() if not o.passed and not hardcases.get(n).expected_failure]
    if bad:
        raise MbsuiteError("hard case(s) failed: " + ", ".join(bad))


def _cmd_perturb(args: argparse.Namespace) -> None:
    from . import hardcases, perturbation

    try:
        epsilons = [float(e) for e in args.eps.split(",")]
    except ValueError as exc:
        raise MbsuiteError(f"--eps {args.eps!r} is not a comma list of numbers, e.g. 1e-12,1e-9") from exc
    for e in epsilons:
        if not (math.isfinite(e) and 0.0 < e < 1e-3):
            raise MbsuiteError(f"--eps {e!r} is invalid; valid: (0, 1e-3) (a relative perturbation)")
    if not 1 <= args.draws <= MAX_REPEATS:
        raise MbsuiteError(f"--draws {args.draws} is invalid; valid: integer in [1, {MAX_REPEATS}]")
    if args.duration is not None and not (math.isfinite(args.duration) and args.duration > 0):
        raise MbsuiteError(f"--duration {args.duration!r} is invalid; valid: (0, inf) s")
    scenes = []
    if not args.hardcases_only:
        names = args.target or sorted(registry.models())
        for t in names:
            if "/" in t or t.endswith(".toml"):
                scenes.append(load_scene(t))
            else:
                scenes += [load_scene(f"{t}/{s}") for s in registry.get_model(t).scene_files()]
    cases = []
    if args.hardcases or args.hardcases_only:
        models = {t.split("/")[0] for t in args.target} if args.target else None
        cases = [c for c in hardcases.cases(include_slow=not args.no_slow)
                 if (models is None or c.model in models) and not c.expected_failure]
    reports = []
    targets = [(perturbation.check_scene, perturbation.shortened(sc, args.duration)) for sc in scenes]
    for check, target in targets + [(perturbation.check_case, c) for c in cases]:
        base = None  # the unperturbed run, made once for every eps
        for e in epsilons:
            reports.append(check(target, eps=e, draws=args.draws, seed=args.seed, base=base))
            base = reports[-1].base
            if args.verbose:
                print(" ".join(map(str, reports[-1].row())), file=sys.stderr, flush=True)
    _emit(perturbation.report(reports), args, None)
    bad = sorted({r.target for r in reports if not r.ok})
    if bad:
        raise MbsuiteError("unstable under perturbation: " + ", ".join(bad))


def _cmd_sweep(args: argparse.Namespace) -> None:
    import itertools

    from .analysis.sweep import run_sweep, scene_point
    from .results import write_csv

    scene = _load(args)
    if args.workers < 0:
        raise MbsuiteError(f"--workers {args.workers} must be >= 0 (0: all cores)")
    axes = []
    for spec in args.vary or []:
        key, sep, vals = spec.partition("=")
        section, dot, name = key.partition(".")
        if not sep or not dot or section not in ("input", "params", "solver", "effects"):
            raise MbsuiteError(f"--vary {spec!r}: expected SECTION.KEY=VALUES with SECTION in input, params, solver, "
                               "effects (e.g. input.frequency=1:30:0.5 or params.k_s=1e5,2e5)")
        axes.append((section, name, parse_values(vals, max_points=args.max_points)))
    if not axes:
        raise MbsuiteError("give at least one --vary SECTION.KEY=VALUES")
    check_grid([len(a[2]) for a in axes], max_points=args.max_points, what="--vary grid")
    combos = list(itertools.product(*[a[2] for a in axes]))
    points, engines = [], set()
    for combo in combos:
        sections: dict = {}
        for (section, name, _), v in zip(axes, combo, strict=True):
            sections.setdefault(section, {})[name] = v
        engines.add(scene.replace(**sections).solver.engine)  # validate every point before anything runs
        points.append((scene.to_dict(), sections))
    # MuJoCo points run in C threads (the native core releases the GIL), the hand-derived paths in processes
    auto = "threads" if engines == {"mujoco"} else "local"
    results = run_sweep(scene_point, points, workers=args.workers, desc="sweep",
                        executor=None if args.executor else auto, options=_sweep_options(args))
    signals = [x for x in (args.signals.split(",") if args.signals else []) if x] or \
        sorted(results[0]["signals"]) if results else []
    head = [f"{s}.{n}" for s, n, _ in axes]
    units = {h: _axis_unit(scene, s, n) for h, (s, n, _) in zip(head, axes, strict=True)}
    sig_units = {sig: scene.spec.outputs.get(sig, "") for sig in signals}
    rows, cols = [], {h: [] for h in head}
    for combo, r in zip(combos, results, strict=True):
        for h, v in zip(head, combo, strict=True):
            cols[h].append(v)
        for sig in signals:
            st = r["signals"].get(sig)
            if st is None:
                raise MbsuiteError(f"signal {sig!r} not in the results; available: {sorted(r['signals'])}")
            rows.append([*combo, sig, sig_units[sig], st["min"], st["max"], st["mean"]])
            for k in ("min", "max", "mean"):
                cols.setdefault(f"{sig}_{k}", []).append(st[k])
    heads = [f"{h} [{units[h]}]" if units[h] else h for h in head]
    table = format_table([*heads, "signal", "unit", "min", "max", "mean"], rows, ".5g")
    data = {"axes": {h: a[2] for h, a in zip(head, axes, strict=True)}, "units": {**units, **sig_units},
            "points": [{"values": dict(zip(head, c, strict=True)), **r} for c, r in zip(combos, results, strict=True)]}

    def write(out: Path) -> list[Path]:
        from .plotting import save

        csv_cols = [(k, units[k] if k in units else sig_units[k.rsplit("_", 1)[0]], v) for k, v in cols.items()]
        return [write_csv(Path(out) / "sweep.csv", csv_cols),
                save(_plot_sweep(head, units, combos, results, signals, sig_units), Path(out) / "sweep.png")]

    _emit(Report(data, table, write), args, scene.to_dict())


def _axis_unit(scene, section: str, name: str) -> str:
    """The SI unit of a swept key, from its declaration (parameter field, input key or solver setting)."""
    from .limits import limit_of
    from .scenes import SOLVER_LIMITS

    lim = None
    if section == "params":
        try:
            lim = limit_of(scene.spec.params_cls, name)
        except (KeyError, TypeError):
            lim = None
    elif section == "input":
        lim = (scene.spec.inputs.get(scene.input.get("type"), {}) or {}).get(name)
    elif section == "solver":
        lim = SOLVER_LIMITS.get(name)
    return getattr(lim, "unit", "") or ""


def _plot_sweep(head: list[str], units: dict, combos: list, results: list, signals: list[str], sig_units: dict):
    """Each signal's mean (line) and min-max (band) against the first swept key; one line per combination of the
    other keys (at most 8)."""
    from .plotting import figure

    shown = signals[:6]
    fig, axs = figure(len(shown), 1, size=(8.0, 1.8 + 2.0 * len(shown)), sharex=True, squeeze=False)
    groups: dict = {}
    for i, c in enumerate(combos):
        groups.setdefault(tuple(c[1:]), []).append(i)
    numeric = all(isinstance(c[0], int | float) and not isinstance(c[0], bool) for c in combos)
    for ax, sig in zip(axs[:, 0], shown, strict=True):
        for rest, idx in list(groups.items())[:8]:
            x = [combos[i][0] if numeric else str(combos[i][0]) for i in idx]
            st = [results[i]["signals"][sig] for i in idx]
            label = ", ".join(f"{h} = {v}" for h, v in zip(head[1:], rest, strict=True)) or None
            line, = ax.plot(x, [s["mean"] for s in st], marker="o", ms=3, label=label)
            ax.fill_between(x, [s["min"] for s in st], [s["max"] for s in st], color=line.get_color(), alpha=0.15)
        ax.set_ylabel(f"{sig} [{sig_units[sig]}]" if sig_units[sig] else sig)
        ax.grid(True, alpha=0.3)
        if len(groups) > 1:
            ax.legend(fontsize=6)
    axs[-1, 0].set_xlabel(f"{head[0]} [{units[head[0]]}]" if units[head[0]] else head[0])
    fig.suptitle("sweep: mean (line) and min-max over the run (band)", fontsize=9)
    return fig


def _cmd_view(args: argparse.Namespace) -> None:
    """Open MuJoCo's interactive viewer on the scene's MuJoCo model (its effects active, its initial state)."""
    scene = _load(args)
    if scene.spec.mujoco_model is None:
        raise MbsuiteError(f"model '{scene.model}' has no MuJoCo model to view")
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY") or sys.platform == "darwin"):
        raise MbsuiteError("mbsuite view needs a display (no DISPLAY or WAYLAND_DISPLAY is set); on a headless "
                           "machine render offscreen instead (MUJOCO_GL=egl, mujoco.Renderer)")
    import mujoco.viewer

    model, data = scene.spec.mujoco_model(scene)
    mujoco.viewer.launch(model, data)


def _scene_opts(p: argparse.ArgumentParser) -> None:
    p.add_argument("--allow-inaccurate", action="store_true",
                   help="keep a result whose health figures exceed their bounds (with a loud warning) instead of an "
                        "error")
    p.add_argument("--max-steps", type=float, metavar="N",
                   help=f"size guard: most steps a run may take (default {DEFAULT_MAX_STEPS:.0e})")


def _load(args: argparse.Namespace):
    """The command's scene with the command-line solver overrides applied (and validated)."""
    scene = load_scene(args.scene)
    solver: dict = {}
    if getattr(args, "engine", None):
        solver["engine"] = args.engine
    if getattr(args, "allow_inaccurate", False):
        solver["allow_inaccurate"] = True
    if getattr(args, "max_steps", None) is not None:
        solver["max_steps"] = args.max_steps
    return scene.replace(solver=solver) if solver else scene


FREQ_LIMITS = {
    "--f-min": Limit(lo=1e-3, hi=1e3, unit="Hz"),
    "--f-max": Limit(lo=1e-3, hi=1e3, unit="Hz"),
    "--df": Limit(lo=1e-3, hi=1e3, unit="Hz"),
}
MAX_FREQUENCIES = 2000


def _freq_args(args: argparse.Namespace) -> dict:
    f_min, f_max, df = (lim.check(flag, getattr(args, flag[2:].replace("-", "_")), MbsuiteError)
                        for flag, lim in FREQ_LIMITS.items())
    if f_max < f_min:
        raise MbsuiteError(f"--f-max {f_max:g} Hz is below --f-min {f_min:g} Hz")
    n = int((f_max - f_min) / df) + 1
    if n > MAX_FREQUENCIES:
        raise MbsuiteError(f"--f-min/--f-max/--df give {n} frequencies; at most {MAX_FREQUENCIES} (enlarge --df)")
    methods = [m for m in args.methods.split(",") if m]
    bad = sorted(set(methods) - {"linear", "mujoco", "reference"})
    if bad or not methods:
        raise MbsuiteError(f"--methods {args.methods!r}: valid methods are linear, mujoco, reference")
    if args.workers < 0:
        raise MbsuiteError(f"--workers {args.workers} must be >= 0 (0: all cores)")
    return {"f_min": f_min, "f_max": f_max, "df": df, "methods": args.methods, "workers": args.workers}


def _hook_command(hook: str):
    def run(args: argparse.Namespace) -> None:
        from . import run as run_scene

        scene = _load(args)
        fn = run_scene if hook == "run" else getattr(scene.spec, hook)  # run: judges the run's health figures
        if fn is None:
            raise MbsuiteError(f"model '{scene.model}' does not support '{hook}'")
        kwargs = _freq_args(args) if hook == "freqresp" else {}
        if hook == "modes" and getattr(args, "height", None) is not None:
            kwargs = {"height": args.height}
        with _sweeping(args):
            report = fn(scene, **kwargs)
        if isinstance(report, SimResult):
            report = report.report()
        _emit(report, args, scene.to_dict())

    return run


def build_parser() -> argparse.ArgumentParser:
    """The `mbsuite` argument parser: the generic commands plus each model's own command group."""
    from . import __version__

    ap = _Parser(
        prog="mbsuite", description="Cross-checked multibody models of railway mechanisms on Pinocchio and MuJoCo: "
        "run scenes, sweeps, frequency responses, work-precision studies and hard cases; `mbsuite list` shows the "
        "models and what each offers.")
    ap.add_argument("--version", action="version", version=f"mbsuite {__version__}")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)

    p = sub.add_parser("list", help="models and their shipped scenes")
    _common(p)
    p.set_defaults(func=_cmd_list)

    for hook, helptext in [
        ("run", "time simulation of a scene"),
        ("equilibrium", "static equilibrium of a scene"),
        ("modes", "linearised natural frequencies and damping ratios"),
        ("freqresp", "frequency response (linearisation, reference and MuJoCo time simulations)"),
    ]:
        p = sub.add_parser(hook, help=helptext)
        p.add_argument("scene", help="scene TOML path, model name (default scene) or model/scene")
        _common(p)
        if hook in ("run", "freqresp"):
            _scene_opts(p)
        if hook == "modes":
            p.add_argument("--height", type=float,
                           help="ram height (m) to linearise at (default: the mean of the scene's input)")
        if hook == "run":
            p.add_argument("--engine", choices=["mujoco", "reference"], help="override the scene's engine")
        if hook == "freqresp":
            p.add_argument("--f-min", type=float, default=1.0, help="lowest frequency (Hz)")
            p.add_argument("--f-max", type=float, default=30.0, help="highest frequency (Hz)")
            p.add_argument("--df", type=float, default=0.5, help="frequency step (Hz)")
            p.add_argument("--methods", default="linear,mujoco,reference",
                           help="comma list of linear, mujoco, reference")
            p.add_argument("--workers", type=int, default=0, help="parallel processes (0 = all cores)")
            _sweep_args(p)
        p.set_defaults(func=_hook_command(hook))

    p = sub.add_parser("view", help="open MuJoCo's viewer on a scene's model, its effects active")
    p.add_argument("scene", help="scene TOML path, model name (default scene) or model/scene")
    p.set_defaults(func=_cmd_view)

    p = sub.add_parser("sweep", help="parameter study: run a scene over a grid of inputs/parameters/settings")
    p.add_argument("scene", help="scene TOML path, model name (default scene) or model/scene")
    p.add_argument("--vary", action="append", metavar="SECTION.KEY=VALUES",
                   help="a grid axis: comma list or start:stop:step, e.g. input.frequency=1:30:0.5 (repeatable: "
                        "the grid is the product)")
    p.add_argument("--signals", help="comma list of output signals to tabulate (default: all)")
    p.add_argument("--workers", type=int, default=0, help="local processes (0 = all cores)")
    _sweep_args(p)
    _scene_opts(p)
    _common(p)
    p.set_defaults(func=_cmd_sweep)

    p = sub.add_parser("workprecision", help="what accuracy costs: error vs wall time for every engine and method")
    p.add_argument("scene", help="scene TOML path, model name (default scene) or model/scene")
    p.add_argument("--repeats", type=int, default=5, help="runs per setting; wall time = median (default 5)")
    p.add_argument("--quick", action="store_true", help="a few settings and short runs (smoke test)")
    p.add_argument("--verbose", action="store_true", help="print each setting as it finishes (stderr)")
    _common(p)
    p.set_defaults(func=_cmd_workprecision)

    p = sub.add_parser("perturb", help="stability under perturbation: every parameter, input and initial state "
                                       "changed by a relative eps; invariants, sensitivities, jumps")
    p.add_argument("target", nargs="*", help="scenes (model/scene or TOML path) or models (all their scenes); "
                                             "default: every shipped scene")
    p.add_argument("--eps", default="1e-12,1e-9", help="comma list of relative perturbations (default 1e-12,1e-9)")
    p.add_argument("--draws", type=int, default=2, help="perturbed copies per eps (seeded; default 2)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first draw (default 0)")
    p.add_argument("--duration", type=float, help="shorten longer runs to this many seconds (s)")
    p.add_argument("--hardcases", action="store_true", help="also run the hard cases (of the targets' models)")
    p.add_argument("--hardcases-only", action="store_true", help="only the hard cases")
    p.add_argument("--no-slow", action="store_true", help="leave out the slow hard cases")
    p.add_argument("--verbose", action="store_true", help="print each row as it finishes (stderr)")
    _common(p)
    p.set_defaults(func=_cmd_perturb)

    p = sub.add_parser("hardcases", help="the hard-case registry: what is hard, the scene, what is asserted")
    p.add_argument("--run", action="store_true", help="run the cases and report each assertion (exit 2 on failure)")
    p.add_argument("--model", help="only this model's cases")
    p.add_argument("--name", action="append", help="only this case (repeatable)")
    p.add_argument("--no-slow", action="store_true", help="leave out the slow cases")
    _common(p)
    p.set_defaults(func=_cmd_hardcases)

    for name in sorted(registry.models()):
        try:
            mod = importlib.import_module(f"mbsuite.models.{name}.cli")
        except ModuleNotFoundError as exc:
            if exc.name != f"mbsuite.models.{name}.cli":
                raise
            continue
        before = set(sub.choices)
        mod.register(sub, _common, _emit)
        for group in sorted(set(sub.choices) - before):
            CLI_GROUPS[name] = group
    return ap


class _UsageError(Exception):
    """A command line argparse refuses (unknown command or option, a value of the wrong type)."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: `mbsuite: error: <what>` naming the argument, and where to read the usage."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise _UsageError(f"{message} (usage: {self.prog} --help)")


def _fail(message: str, as_json: bool, kind: str) -> int:
    """One line on stderr (and, under --json, a JSON object on stdout); exit status 2."""
    message = " ".join(message.split())  # messages quoting a solver's text may hold line breaks
    if as_json:
        print(json.dumps({"error": {"type": kind, "message": message}}))
    print(f"mbsuite: error: {message}", file=sys.stderr)
    return 2


def _check_out(out: str | None) -> None:
    """`--out DIR` must be a directory we can write, checked before any work is done."""
    if not out:
        return
    path = Path(out)
    if path.exists() and not path.is_dir():
        raise MbsuiteError(f"--out {out}: exists and is not a directory")
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / ".mbsuite-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise MbsuiteError(f"--out {out}: cannot write there ({exc.strerror or exc})") from exc


def _quiet_stdout() -> None:
    """After a closed pipe: send the rest of stdout to /dev/null so the interpreter's final flush stays quiet."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line. Exit status: 0 success, 2 any error (one line naming the input; under --json also a JSON
    object `{"error": {...}}` on stdout), 130 interrupted (Ctrl-C). A closed output pipe ends the command quietly."""
    ap = build_parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = ap.parse_args(argv)
    except _UsageError as exc:
        return _fail(str(exc), "--json" in argv, "UsageError")
    except SystemExit as exc:  # --help / --version
        return int(exc.code or 0)
    as_json = bool(getattr(args, "json", False))
    try:
        _check_out(getattr(args, "out", None))
        args.func(args)
    except MbsuiteError as exc:
        return _fail(str(exc), as_json, type(exc).__name__)
    except KeyboardInterrupt:
        store = getattr(args, "store", None)
        saved = f"finished points are kept in {store} (rerun the command to resume)" if store else "nothing was saved"
        print(f"mbsuite: interrupted; {saved}", file=sys.stderr)
        return 130
    except BrokenPipeError:
        _quiet_stdout()
        return 0
    except MemoryError:
        return _fail("out of memory: the job is too large for this machine; make it smaller (fewer points, shorter "
                     "run, larger step)", as_json, "MemoryError")
    except OSError as exc:
        name = f" {exc.filename}" if exc.filename else ""
        return _fail(f"cannot access{name}: {exc.strerror or exc}", as_json, "OSError")
    except Exception as exc:  # a defect in mbsuite: still one line, the traceback on request
        if os.environ.get("MBSUITE_DEBUG"):
            raise
        return _fail(f"internal error ({type(exc).__name__}: {exc}); this is a bug in mbsuite, please report it with "
                     "the command line (MBSUITE_DEBUG=1 prints the traceback)", as_json, "InternalError")
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_stdout()
    return 0


if __name__ == "__main__":
    sys.exit(main())
