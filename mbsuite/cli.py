"""Command line: `mbsuite list | run | equilibrium | modes | freqresp` plus model-specific groups.

Each analysis prints a human table by default, JSON with `--json`, and with `--out DIR` writes CSV (SI units in the
header), PNG plots and `summary.json` (versions + scene). A model package may add its own sub-commands by defining
`register(subparsers)` in its `cli` module.
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys
from collections.abc import Sequence

from . import registry
from .errors import MbsuiteError
from .results import Report, SimResult, format_table, to_jsonable
from .scenes import load_scene


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


def _cmd_list(args: argparse.Namespace) -> None:
    rows = []
    data = {}
    for name, spec in sorted(registry.models().items()):
        scenes = sorted(spec.scene_files())
        rows.append([name, spec.default_scene, ", ".join(scenes), ", ".join(spec.engines), spec.summary])
        data[name] = {"summary": spec.summary, "default_scene": spec.default_scene, "scenes": scenes,
                      "engines": list(spec.engines), "effects": {k: list(e.choices) for k, e in spec.effects.items()}}
    _emit(Report(data, format_table(["model", "default", "scenes", "engines", "summary"], rows)), args, None)


def _hook_command(hook: str):
    def run(args: argparse.Namespace) -> None:
        scene = load_scene(args.scene)
        if getattr(args, "engine", None):
            scene = scene.replace(solver={"engine": args.engine})
        fn = getattr(scene.spec, hook)
        if fn is None:
            raise MbsuiteError(f"model '{scene.model}' does not support '{hook}'")
        kwargs = {}
        if hook == "freqresp":
            kwargs = {"f_min": args.f_min, "f_max": args.f_max, "df": args.df, "methods": args.methods,
                      "workers": args.workers}
        report = fn(scene, **kwargs)
        if isinstance(report, SimResult):
            report = report.report()
        _emit(report, args, scene.to_dict())

    return run


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="mbsuite", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)

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
        if hook == "run":
            p.add_argument("--engine", choices=["mujoco", "reference"], help="override the scene's engine")
        if hook == "freqresp":
            p.add_argument("--f-min", type=float, default=1.0, help="lowest frequency (Hz)")
            p.add_argument("--f-max", type=float, default=30.0, help="highest frequency (Hz)")
            p.add_argument("--df", type=float, default=0.5, help="frequency step (Hz)")
            p.add_argument("--methods", default="linear,mujoco,reference",
                           help="comma list of linear, mujoco, reference")
            p.add_argument("--workers", type=int, default=0, help="parallel processes (0 = all cores)")
        p.set_defaults(func=_hook_command(hook))

    for name in sorted(registry.models()):
        try:
            mod = importlib.import_module(f"mbsuite.models.{name}.cli")
        except ModuleNotFoundError as exc:
            if exc.name != f"mbsuite.models.{name}.cli":
                raise
            continue
        mod.register(sub, _common, _emit)
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    ap = build_parser()
    args = ap.parse_args(argv)
    try:
        args.func(args)
    except MbsuiteError as exc:
        print(f"mbsuite: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
