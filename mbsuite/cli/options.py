"""Options several commands share, added to a parser and read back checked: the scene and its solver overrides
(`add_scene_options`, `load`), where a sweep runs (`add_sweep_options`, `sweep_options`), worker and repeat counts.
Model command groups use them too."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from ..analysis.sweep.options import EXECUTORS, MAX_POINTS
from ..errors import MbsuiteError

if TYPE_CHECKING:
    from ..analysis.sweep import SweepOptions
    from ..scenes import Scene

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
    """`--error-estimate`: run refined copies and report each headline output's estimated error (mbsuite.accuracy)."""
    p.add_argument("--error-estimate", action="store_true",
                   help="also run the scene refined once and twice (the path's step, tolerance or mesh; in parallel "
                        "on the local cores) and report per headline output the estimated error, the observed order "
                        "and the declared tolerance; an estimate above its tolerance is an error unless "
                        "--allow-inaccurate")


def load(args: argparse.Namespace) -> Scene:
    """The command's scene with the command-line solver overrides applied (and validated); `--engine` may name a
    path by its key or its label (`mbsuite list`)."""
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

    max_points = getattr(args, "max_points", None)
    return SweepOptions(executor=getattr(args, "executor", None), scheduler=getattr(args, "scheduler", None),
                        store=getattr(args, "store", None), max_points=MAX_POINTS if max_points is None else max_points)


def check_workers(workers: int) -> int:
    """`--workers N`: processes or threads, 0 = all cores."""
    if workers < 0:
        raise MbsuiteError(f"--workers {workers} must be >= 0 (0: all cores)")
    return workers
