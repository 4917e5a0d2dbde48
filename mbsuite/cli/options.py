"""Options several commands share, added to a parser and read back checked: the scene and its solver overrides
(`add_scene_options`, `load`), where a sweep runs (`add_sweep_options`, `sweep_options`), worker and repeat counts,
and the one rule that composes the flags changing a scene (`overrides`). Model command groups use them too.

The rule (`overrides`, applied by `mbsuite.cli.main` to every command before it runs): every flag that changes the
scene a command reads is declared below, either as `SECTION.KEY=VALUE` entries (`--set`, `--vary`, `--over`) or as a
flag that sets one scene key (`--speed` sets input.speed, `--engine` solver.engine, ...). All of a command's flags
are read into one mapping dotted key -> `Override` (the flag and its value); a key given twice (by one flag or two,
even with the same value) or a key together with a key inside it (`pantograph.params` and `pantograph.params.F0`) is
an error naming both flags. A dotted key reaches into a scene section by one function (`resolve`: the section must
be the scene's, the rest of the key is nested into it as the design studies do), so every command takes every key
the scene has."""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from ..analysis.sweep.options import EXECUTORS, MAX_POINTS
from ..errors import MbsuiteError
from ..overrides import SCENE_SECTIONS, Override, compose, parse_override, section_of  # noqa: F401 (the rule's names)
from ..progress import BUDGET

if TYPE_CHECKING:
    from ..analysis.sweep import SweepOptions
    from ..scenes import Scene

#: the scene sections every model has (a model adds its own: `ModelSpec.sections`)
#: flags of `SECTION.KEY=VALUE` entries (repeatable): argparse dest -> flag
ENTRY_FLAGS = {"set_values": "--set", "vary": "--vary", "over": "--over"}
#: flags that set one scene key: argparse dest -> (flag, the dotted key it sets); given when not None and not False
SCENE_FLAGS = {"engine": ("--engine", "solver.engine"), "max_steps": ("--max-steps", "solver.max_steps"),
               "allow_inaccurate": ("--allow-inaccurate", "solver.allow_inaccurate"),
               "timestep": ("--timestep", "solver.timestep"), "duration": ("--duration", "solver.duration"),
               "element_length": ("--element-length", "params.element_length"),
               "speed": ("--speed", "input.speed"), "spacings": ("--spacings", "train.spacings")}
#: `--start SECTION.KEY=VALUE` (optimise): a start value per key, composed on its own (each key once)
START_FLAG = ("start", "--start")


def overrides(args: argparse.Namespace) -> dict[str, Override]:
    """Every scene override of a command line (`ENTRY_FLAGS`, `SCENE_FLAGS`) composed by the one rule (`compose`),
    and `--start` composed on its own; an error naming both flags of any conflict."""
    items = [parse_override(flag, text) for dest, flag in ENTRY_FLAGS.items()
             for text in getattr(args, dest, None) or []]
    for dest, (flag, key) in SCENE_FLAGS.items():
        v = getattr(args, dest, None)
        if v is not None and v is not False:
            shown = flag if v is True else f"{flag} {' '.join(map(str, v)) if isinstance(v, list) else v}"
            items.append(Override(flag, key, v, shown))
    compose(parse_override(START_FLAG[1], t) for t in getattr(args, START_FLAG[0], None) or [])
    return compose(items)


def scene_sections(scene: Scene) -> tuple[str, ...]:
    """The sections a key of `scene` may name: every model's and the model's own."""
    return (*SCENE_SECTIONS, *scene.spec.sections)


def resolve(scene: Scene, values: Mapping[Override, Any]) -> dict[str, Any]:
    """The one resolution of dotted keys into scene sections: `Scene.replace` sections setting each override's key
    to its value (`designspace.sections_for`: a dotted key's enclosing tables copied from the scene so that only the
    named value changes); an error naming the flag if a key's section is not one of the scene's."""
    from ..analysis.designspace import sections_for

    for o in values:
        section_of(o, scene_sections(scene))
    return sections_for(scene.to_dict(), {o.key: v for o, v in values.items()})


MAX_REPEATS = 100
SCENE_HELP = "scene TOML path, model name (default scene), model/scene or a summary.json (the scene it ran)"


def add_scene_options(p: argparse.ArgumentParser) -> None:
    """`--allow-inaccurate` and `--max-steps`: solver overrides of the scene a command runs."""
    p.add_argument("--allow-inaccurate", action="store_true",
                   help="keep a result whose health figures exceed their bounds (with a loud warning) instead of an "
                        "error")
    p.add_argument("--max-steps", type=float, metavar="N",
                   help="size guard: most steps a run may take (default: the scene's solver.max_steps)")


def add_error_estimate(p: argparse.ArgumentParser) -> None:
    """`--error-estimate`: run the scene's companions and report each headline output's estimated error
    (mbsuite.trust.estimate)."""
    p.add_argument("--error-estimate", action="store_true",
                   help="also run the scene's companions (the path's step, tolerance or mesh refined once and twice; "
                        "the catenary's coarsened once and twice first; in parallel on the local cores) and report "
                        "per headline output the estimated error, the observed order and the declared tolerance; an "
                        "estimate above its tolerance keeps the result, flagged inaccurate, with exit status 3 (0 "
                        "with --allow-inaccurate)")
    add_progress_options(p)


def add_progress_options(p: argparse.ArgumentParser) -> None:
    """`--yes` and `--budget`: the cost check of a command that may run many simulations (`mbsuite.progress`);
    `--quiet` comes with every command (`output.add_common`)."""
    if "--yes" in p._option_string_actions:
        return
    p.add_argument("--budget", type=float, metavar="SECONDS",
                   help=f"wall time a study may take without asking: above it (estimated from the first finished "
                        f"run) it stops, naming --yes and a cheaper setting (default {BUDGET:g} s)")
    p.add_argument("--yes", action="store_true", help="run a study whose estimated time exceeds --budget")


def add_speed_option(p: argparse.ArgumentParser) -> None:
    """`--speed KMH`: the train speed of a scene that has one (sets input.speed, as on `catenary` and `optimise`)."""
    p.add_argument("--speed", metavar="KMH", type=float,
                   help="train speed, km/h: sets input.speed (a scene whose model has a speed: catenary)")


def apply_speed(scene: Scene, args: argparse.Namespace) -> Scene:
    """The scene at `--speed` (input.speed; unchanged without it), resolved by the one rule (`resolve`); the rule has
    already checked it against every other flag (`overrides`)."""
    v = getattr(args, "speed", None)
    if v is None:
        return scene
    o = Override("--speed", "input.speed", v, f"--speed {v:g}")
    return scene.replace(origin=f"on the command line (--speed {v:g})", **resolve(scene, {o: float(v)}))


def load(args: argparse.Namespace) -> Scene:
    """The command's scene with the command-line solver overrides applied (and validated); `--engine` may name a
    path by its key or its label (`mbsuite list`). The command line's overrides are composed first (`overrides`)."""
    overrides(args)
    scene = scene_of(args.scene)
    solver: dict = {}
    engine = getattr(args, "engine", None)
    if engine:
        spec = scene.spec
        valid = sorted({*spec.paths, *(p.label for p in spec.paths.values())})
        if spec.path_key(engine) not in spec.paths:
            raise MbsuiteError(f"--engine {engine!r} is not a path of model '{spec.name}'; valid: {valid}")
        solver["engine"] = engine
    if getattr(args, "allow_inaccurate", False):
        solver["allow_inaccurate"] = True
    if getattr(args, "max_steps", None) is not None:
        solver["max_steps"] = args.max_steps
    flags = "/".join(f for f, k in (("--engine", "engine"), ("--allow-inaccurate", "allow_inaccurate"),
                                     ("--max-steps", "max_steps")) if k in solver)
    return scene.replace(solver=solver, origin=f"on the command line ({flags})") if solver else scene


def scene_of(ref: str) -> Scene:
    """The scene a command line names: a TOML path, a model name, model/scene, or a `summary.json` an earlier
    command wrote (the full scene it ran, every default resolved: the same run again)."""
    from ..scenes import load_scene, scene_from_dict

    if str(ref).endswith(".json"):
        from ..results import read_summary_scene

        return scene_from_dict(read_summary_scene(ref), source=str(ref))
    return load_scene(ref)


def add_sweep_options(p: argparse.ArgumentParser) -> None:
    """Where the command's sweep runs (the one sweep API, mbsuite.analysis.sweep)."""
    p.add_argument("--executor", choices=EXECUTORS, default=None,
                   help="local: processes on all cores; threads: C threads of the native core (MuJoCo work); dask: a "
                        "Dask distributed cluster (default: threads for MuJoCo points, processes for the rest)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="Dask scheduler address (tcp://HOST:PORT) for --executor dask")
    p.add_argument("--store", metavar="FILE", help="stream finished points to FILE (JSON lines) and resume from it")
    p.add_argument("--max-points", type=int, default=None, metavar="N",
                   help=f"size guard: most points of one sweep (default {MAX_POINTS})")


def sweep_options(args: argparse.Namespace) -> SweepOptions:
    """The `SweepOptions` of `--executor/--scheduler/--store/--max-points` (checked here, once)."""
    from ..analysis.sweep import SweepOptions
    from ..analysis.sweep.options import check_max_points

    max_points = getattr(args, "max_points", None)
    return SweepOptions(executor=getattr(args, "executor", None), scheduler=getattr(args, "scheduler", None),
                        store=getattr(args, "store", None),
                        max_points=MAX_POINTS if max_points is None else check_max_points(max_points, "--max-points"))


def check_workers(workers: Any) -> int:
    """`--workers N`: processes or threads, 0 = all cores (an integer, numpy's too)."""
    from ..limits import Limit

    return Limit(lo=0, kind=int, doc="processes or threads, 0 = all cores").check("--workers", workers, MbsuiteError)
