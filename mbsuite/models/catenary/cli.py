"""`mbsuite catenary SCENE --speed KMH [--engine E] [--with-linear] [--quality [--system S]] [--json] [--out DIR]`:
EN 50318 statistics and the current-collection quality report."""

from __future__ import annotations

import argparse

from ...errors import SceneError
from ...results import Progress
from ...scenes import Scene, load_scene

COMMAND = "catenary"


def register(sub, add_common, emit) -> str:
    """Add the `mbsuite catenary` command to the CLI's subparsers `sub`; returns its name."""
    p = sub.add_parser(COMMAND, help="pantograph passage under the FE catenary: EN 50318 statistics, plots, CSV")
    p.add_argument("scene", nargs="?", default="catenary",
                   help="scene TOML path, 'catenary' (default scene) or catenary/<scene>")
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
    add_common(p)
    p.set_defaults(func=cmd_catenary, emit=emit)
    return COMMAND


class _Percent:
    """A progress callback `(step, total)` that advances a 100-step `Progress` bar by whole percent."""

    def __init__(self, bar: Progress):
        self.bar, self.last = bar, 0

    def __call__(self, step: int, total: int) -> None:
        k = int(100 * step / total)
        if k > self.last:
            self.bar.update(k - self.last)
            self.last = k


def _scene(args: argparse.Namespace) -> Scene:
    """The command's catenary scene with the command line's overrides."""
    scene = load_scene(args.scene)
    if scene.model != "catenary":
        raise SceneError(f"scene {args.scene!r} is a '{scene.model}' scene; the catenary command needs a "
                         "catenary scene")
    if args.engine is not None:
        scene = scene.replace(solver={"engine": args.engine})
    if args.timestep is not None:
        scene = scene.replace(solver={"timestep": args.timestep})
    if args.element_length is not None:
        scene = scene.replace(params={"element_length": args.element_length})
    if args.speed is not None:
        scene = scene.replace(input={"speed": args.speed})
    if args.spacings is not None and "train" not in scene.sections:
        raise SceneError("--spacings needs a scene with a [train] section (e.g. catenary/en50318_two_pantographs)")
    return scene


def cmd_catenary(args: argparse.Namespace) -> None:
    """One passage (or a train's, with `[train]`) of the scene, and its report."""
    from .analysis import run_scene, run_train_scene
    from .reports import report, train_report

    scene = _scene(args)
    criteria = None
    if args.quality or args.system is not None:
        from .quality import criteria_from

        sec = dict(scene.sections.get("quality") or {})
        if args.system is not None:
            sec["system"] = args.system
        criteria = criteria_from(sec)
    if "train" in scene.sections:
        with Progress(100, desc="catenary train") as bar:
            run = run_train_scene(scene, progress=_Percent(bar), spacings=args.spacings)
        args.emit(train_report(run, quality=criteria), args, scene.to_dict())
        return
    variants = [scene]
    if args.with_linear and scene.effects["droppers"] != "linear":
        variants.append(scene.replace(effects={"droppers": "linear"}))
    runs = []
    for sc in variants:
        with Progress(100, desc=f"catenary {sc.effects['droppers']}") as bar:
            runs.append(run_scene(sc, progress=_Percent(bar)))
    args.emit(report(runs[0], scene.to_dict(), runs[1:], quality=criteria), args, scene.to_dict())
