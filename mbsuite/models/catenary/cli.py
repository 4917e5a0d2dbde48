"""`mbsuite catenary SCENE --speed KMH [--engine E] [--with-linear] [--quality [--system S]] [--json] [--out DIR]`:
EN 50318 statistics and the current-collection quality report."""

from __future__ import annotations

import argparse

from ...results import Progress
from ...scenes import load_scene


def register(sub, add_common, emit) -> None:
    """Add the `mbsuite catenary` command to the CLI's subparsers `sub`."""
    p = sub.add_parser("catenary", help="pantograph passage under the FE catenary: EN 50318 statistics, plots, CSV")
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
    p.set_defaults(func=lambda args: _handler(args, emit))


def _handler(args: argparse.Namespace, emit) -> None:
    from .analysis import report, run_scene

    scene = load_scene(args.scene)
    if scene.model != "catenary":
        from ...errors import SceneError

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
    criteria = None
    if args.quality or args.system is not None:
        from .quality import criteria_from

        sec = dict(scene.sections.get("quality") or {})
        if args.system is not None:
            sec["system"] = args.system
        criteria = criteria_from(sec)
    if args.spacings is not None and "train" not in scene.sections:
        from ...errors import SceneError

        raise SceneError("--spacings needs a scene with a [train] section (e.g. catenary/en50318_two_pantographs)")
    if "train" in scene.sections:
        from .train import run_train_scene, train_report

        with Progress(100, desc="catenary train") as bar:
            last = [0]

            def tprog(step, total, bar=bar, last=last):
                k = int(100 * step / total)
                if k > last[0]:
                    bar.update(k - last[0])
                    last[0] = k

            run = run_train_scene(scene, progress=tprog, spacings=args.spacings)
        emit(train_report(run, quality=criteria), args, scene.to_dict())
        return
    runs = []
    variants = [scene]
    if args.with_linear and scene.effects["droppers"] != "linear":
        variants.append(scene.replace(effects={"droppers": "linear"}))
    for sc in variants:
        with Progress(100, desc=f"catenary {sc.effects['droppers']}") as bar:
            last = [0]

            def prog(step, total, bar=bar, last=last):
                k = int(100 * step / total)
                if k > last[0]:
                    bar.update(k - last[0])
                    last[0] = k

            runs.append(run_scene(sc, progress=prog))
    emit(report(runs[0], scene.to_dict(), runs[1:], quality=criteria), args, scene.to_dict())
