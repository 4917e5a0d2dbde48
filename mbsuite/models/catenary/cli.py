"""`mbsuite catenary SCENE --speed KMH [--engine E] [--with-linear] [--json] [--out DIR]`: EN 50318 statistics."""

from __future__ import annotations

import argparse

from ...results import Progress
from ...scenes import load_scene


def register(sub, add_common, emit) -> None:
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
    emit(report(runs[0], scene.to_dict(), runs[1:]), args, scene.to_dict())
