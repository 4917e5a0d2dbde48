"""The generic commands: `list`, `run`, `view`, `render`, `workprecision`, `hardcases`, `perturb`. Each reads its
options, calls the suite's API and hands the result to `emit`; none of them does physics."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from .. import registry
from ..errors import MbsuiteError
from ..limits import Limit
from ..results import Report, format_table
from ..scenes import load_scene
from ..statistics import describe
from ..trust.health import InaccurateResult
from .options import MAX_REPEATS, apply_speed, load, scene_of
from .output import emit, wrap
from .study import apply_sets

#: the numbers of the generic commands' flags, declared once (`Limit.check` names the flag)
FLAGS = {"--width": Limit(lo=16, hi=8192, kind=int, unit="pixels", doc="image width or height"),
         "--repeats": Limit(lo=1, hi=MAX_REPEATS, kind=int, doc="runs per setting; the wall time is their median"),
         "--draws": Limit(lo=1, hi=MAX_REPEATS, kind=int, doc="perturbed copies per eps"),
         "--eps": Limit(lo=0.0, hi=1e-3, lo_open=True, hi_open=True, doc="a relative perturbation"),
         "--duration": Limit(lo=0.0, lo_open=True, unit="s", doc="shortened run")}

ANALYSES = ("run", "equilibrium", "modes", "freqresp", "view", "render")


def analyses(spec: registry.ModelSpec, group: str | None) -> list[str]:
    """The analyses a model offers: the generic hooks it implements, its own command group, the suite's studies."""
    hooks = {"run": spec.paths or None, "view": spec.mujoco_model, "render": spec.mujoco_model}
    out = [a for a in ANALYSES if (hooks[a] if a in hooks else getattr(spec, a)) is not None]
    if spec.paths:
        out += ["sweep", "perturb"]
    if spec.accuracy is not None:
        out += ["sensitivity", "optimise"]
    if spec.cases:
        out += ["workprecision", "hardcases"]
    if group:
        out.append(f"mbsuite {group} ...")
    return out


def cmd_list(args: argparse.Namespace) -> None:
    """`mbsuite list`: each model, its scenes, its paths (key, label, what it is) and what it offers."""
    groups: dict[str, str] = getattr(args, "cli_groups", None) or {}
    rows = []
    data = {}
    blocks = []
    for name, spec in sorted(registry.models().items()):
        scenes = sorted(spec.scene_files())
        offered = analyses(spec, groups.get(name))
        paths = {k: {"label": p.label, "what": p.what} for k, p in spec.paths.items()}
        rows.append([name, spec.default_scene, len(scenes), "/".join(spec.engines)])
        data[name] = {"summary": spec.summary, "default_scene": spec.default_scene, "scenes": scenes,
                      "engines": list(spec.engines), "analyses": offered,
                      "effects": {k: list(e.choices) for k, e in spec.effects.items()}, "paths": paths}
        path_lines = [wrap(f"path {k}" + (f" ({p['label']})" if p["label"] != k else "") + f": {p['what']}")
                      for k, p in paths.items()]
        st = spec.studies
        studies = {"objective": st.objective, "against": st.against, "threads": list(st.threads),
                   "band": None if st.band is None else {"name": st.band.name, "output": st.band.output,
                                                         "systems": list(st.band.systems), "doc": st.band.doc}}
        data[name]["studies"] = studies
        data[name]["statistics"] = describe(spec.statistics)
        if st.objective or st.band:
            band = f"; --band: {st.band.output} in the {st.band.name} ({', '.join(st.band.systems)})" if st.band else ""
            path_lines.append(wrap(f"studies: objective {st.objective}, against {st.against}{band}"))
        blocks.append("\n".join([wrap(f"{name}: {spec.summary}", indent=""), *path_lines,
                                 wrap("analyses: " + ", ".join(offered)), wrap("scenes: " + ", ".join(scenes))]))
    table = format_table(["model", "default scene", "scenes", "engines"], rows) + "\n\n" + "\n\n".join(blocks)
    emit(Report(data, table), args, None)


def cmd_run(args: argparse.Namespace) -> None:
    """`mbsuite run SCENE`: the scene's time simulation on its path (health judged by `mbsuite.run`)."""
    from .. import run

    scene = apply_speed(apply_sets(load(args), args.set_values), args)
    from ..progress import OverBudget

    try:
        rep = run(scene, error_estimate=args.error_estimate).report()
    except InaccurateResult as exc:  # an error estimate above its tolerance: the result kept, flagged (exit 3)
        rep = exc.report()
    except OverBudget as exc:  # an error estimate over the budget: the run shown and written, then the error (exit 2)
        if exc.result is not None:
            emit(exc.result.report(), args, scene.to_dict())
        raise
    emit(rep, args, scene.to_dict())


def cmd_view(args: argparse.Namespace) -> None:
    """Open MuJoCo's interactive viewer on the scene's MuJoCo model (its effects active, its initial state)."""
    scene = load(args)
    if scene.spec.mujoco_model is None:
        raise MbsuiteError(f"model '{scene.model}' has no MuJoCo model to view")
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY") or sys.platform == "darwin"):
        raise MbsuiteError("mbsuite view needs a display (no DISPLAY or WAYLAND_DISPLAY is set); on a headless "
                           f"machine render offscreen instead: mbsuite render {args.scene} --out scene.png")
    import mujoco.viewer

    model, data = scene.spec.mujoco_model(scene)
    mujoco.viewer.launch(model, data)


def cmd_render(args: argparse.Namespace) -> None:
    """`mbsuite render SCENE --out PNG`: the scene's MuJoCo model in its initial state, rendered offscreen (EGL unless
    MUJOCO_GL says otherwise; no display needed) from its first camera, else MuJoCo's free camera, to a PNG."""
    late = "mujoco" in sys.modules and "MUJOCO_GL" not in os.environ  # its GL backend was chosen already
    os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is imported: it picks its GL backend once
    path = Path(args.image)
    if path.suffix.lower() != ".png":
        raise MbsuiteError(f"--out {args.image}: give a .png file")
    for flag, v in (("--width", args.width), ("--height", args.height)):
        FLAGS["--width"].check(flag, v, MbsuiteError)
    scene = apply_sets(load(args), args.set_values)
    if scene.spec.mujoco_model is None:
        raise MbsuiteError(f"model '{scene.model}' has no MuJoCo model to render")
    import mujoco

    model, data = scene.spec.mujoco_model(scene)
    mujoco.mj_forward(model, data)
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, args.width)
    model.vis.global_.offheight = max(model.vis.global_.offheight, args.height)
    try:
        with mujoco.Renderer(model, args.height, args.width) as renderer:
            renderer.update_scene(data, camera=0 if model.ncam else -1)
            image = renderer.render()
    except Exception as exc:  # no GL context: say how to get one
        why = ("mujoco was imported in this process before MUJOCO_GL was set, so it chose its default (windowed) "
               "backend" if late else f"MUJOCO_GL={os.environ.get('MUJOCO_GL')!r}")
        raise MbsuiteError(f"offscreen rendering failed ({type(exc).__name__}: {exc}); {why}: set MUJOCO_GL=egl "
                           "(GPU or software EGL) or osmesa before mbsuite or mujoco is imported") from exc
    from matplotlib.image import imsave

    path.parent.mkdir(parents=True, exist_ok=True)
    imsave(path, image)
    data_out = {"scene": scene.name, "model": scene.model, "image": str(path), "width": args.width,
                "height": args.height, "camera": model.camera(0).name if model.ncam else "free"}
    emit(Report(data_out, f"wrote {path} ({args.width} x {args.height}, camera {data_out['camera'] or 0})"), args,
         None)


def print_progress(msg: str) -> None:
    """A progress line on stderr (`--verbose`)."""
    print(msg, file=sys.stderr, flush=True)


def cmd_workprecision(args: argparse.Namespace) -> None:
    """`mbsuite workprecision SCENE`: error against wall time for every engine and method."""
    from ..analysis.workprecision import workprecision

    scene = scene_of(args.scene)
    FLAGS["--repeats"].check("--repeats", args.repeats, MbsuiteError)
    progress = print_progress if args.verbose else None
    emit(workprecision(scene, repeats=args.repeats, quick=args.quick, progress=progress), args, scene.to_dict())


def cmd_hardcases(args: argparse.Namespace) -> None:
    """`mbsuite hardcases`: the hard-case registry, and with `--run` each case's assertions (exit 2 on a failure)."""
    from .. import hardcases

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
    emit(Report(data, table), args, None)
    bad = [n for n, o in outcomes.items() if not o.passed and not hardcases.get(n).expected_failure]
    if bad:
        raise MbsuiteError("hard case(s) failed: " + ", ".join(bad))


def cmd_perturb(args: argparse.Namespace) -> None:
    """`mbsuite perturb`: stability under relative perturbations of every scene or hard case given."""
    from .. import hardcases
    from ..trust import robustness as stability

    try:
        epsilons = [float(e) for e in args.eps.split(",")]
    except ValueError as exc:
        raise MbsuiteError(f"--eps {args.eps!r} is not a comma list of numbers, e.g. 1e-12,1e-9") from exc
    for e in epsilons:
        FLAGS["--eps"].check("--eps", e, MbsuiteError)
    FLAGS["--draws"].check("--draws", args.draws, MbsuiteError)
    if args.duration is not None:
        FLAGS["--duration"].check("--duration", args.duration, MbsuiteError)
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
    targets = [(stability.check_scene, stability.shortened(sc, args.duration)) for sc in scenes]
    for check, target in targets + [(stability.check_case, c) for c in cases]:
        base = None  # the unperturbed run, made once for every eps
        for e in epsilons:
            reports.append(check(target, eps=e, draws=args.draws, seed=args.seed, base=base))
            base = reports[-1].base
            if args.verbose:
                print(" ".join(map(str, reports[-1].row())), file=sys.stderr, flush=True)
    emit(stability.report(reports), args, None)
    bad = sorted({r.target for r in reports if not r.ok})
    if bad:
        raise MbsuiteError("unstable under perturbation: " + ", ".join(bad))
