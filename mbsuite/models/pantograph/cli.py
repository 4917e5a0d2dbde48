"""`mbsuite pantograph equilibrium | modes | freqresp [SCENE]`: the pantograph's analyses (its SPEC hooks) and their
options. `mbsuite equilibrium | modes | freqresp SCENE` with the same options are aliases of these commands."""

from __future__ import annotations

import argparse

from ...cli.options import SCENE_HELP, add_scene_options, add_sweep_options, check_workers, load, sweep_options
from ...errors import MbsuiteError
from ...limits import Limit
from ...scenes import Scene

MODEL = "pantograph"
FREQ_LIMITS = {
    "--f-min": Limit(lo=1e-3, hi=1e3, unit="Hz"),
    "--f-max": Limit(lo=1e-3, hi=1e3, unit="Hz"),
    "--df": Limit(lo=1e-3, hi=1e3, unit="Hz"),
}
MAX_FREQUENCIES = 2000
METHODS = ("linear", "mujoco", "reference")
COMMANDS = {
    "equilibrium": "static equilibrium of a scene (every path)",
    "modes": "linearised natural frequencies and damping ratios",
    "freqresp": "frequency response (linearisation, reference and MuJoCo time simulations)",
}


def register(sub: argparse._SubParsersAction, add_common, emit) -> str:
    """Add the `pantograph` command group and its top-level aliases to the CLI's subparsers `sub`."""
    g = sub.add_parser("pantograph", help="the pantograph's analyses: equilibrium, modes, frequency response")
    gs = g.add_subparsers(dest="pantograph_command", required=True)
    for name, helptext in COMMANDS.items():
        p = gs.add_parser(name, help=helptext)
        p.add_argument("scene", nargs="?", default=MODEL, help=SCENE_HELP + " (default: the pantograph's)")
        _add_options(p, name, add_common, emit)
        p = sub.add_parser(name, help=f"{helptext} (as `mbsuite pantograph {name}`)")
        p.add_argument("scene", help=SCENE_HELP)
        _add_options(p, name, add_common, emit)
    return MODEL


def _add_options(p: argparse.ArgumentParser, name: str, add_common, emit) -> None:
    add_common(p)
    if name == "modes":
        p.add_argument("--height", type=float,
                       help="ram height (m) to linearise at (default: the mean of the scene's input)")
    if name == "freqresp":
        add_scene_options(p)
        p.add_argument("--f-min", type=float, default=1.0, help="lowest frequency (Hz)")
        p.add_argument("--f-max", type=float, default=30.0, help="highest frequency (Hz)")
        p.add_argument("--df", type=float, default=0.5, help="frequency step (Hz)")
        p.add_argument("--methods", default=",".join(METHODS), help="comma list of " + ", ".join(METHODS))
        p.add_argument("--workers", type=int, default=0, help="parallel processes (0 = all cores)")
        add_sweep_options(p)
    p.set_defaults(func=COMMAND_FUNCS[name], emit=emit)


def _scene(args: argparse.Namespace, hook: str) -> Scene:
    """The command's scene; a scene of another model is refused."""
    scene = load(args)
    if scene.model != MODEL or getattr(scene.spec, hook) is None:
        raise MbsuiteError(f"model '{scene.model}' does not support '{hook}' (`mbsuite {MODEL} {hook}` takes a "
                           f"{MODEL} scene)")
    return scene


def cmd_equilibrium(args: argparse.Namespace) -> None:
    """The static equilibrium of the scene in every path."""
    scene = _scene(args, "equilibrium")
    args.emit(scene.spec.equilibrium(scene), args, scene.to_dict())


def cmd_modes(args: argparse.Namespace) -> None:
    """The linearised modes, at `--height` or at the mean of the scene's input."""
    scene = _scene(args, "modes")
    kwargs = {"height": args.height} if args.height is not None else {}
    args.emit(scene.spec.modes(scene, **kwargs), args, scene.to_dict())


def freq_args(args: argparse.Namespace) -> dict:
    """`--f-min/--f-max/--df/--methods/--workers`, each checked, as the freqresp hook's keyword arguments."""
    f_min, f_max, df = (lim.check(flag, getattr(args, flag[2:].replace("-", "_")), MbsuiteError)
                        for flag, lim in FREQ_LIMITS.items())
    if f_max < f_min:
        raise MbsuiteError(f"--f-max {f_max:g} Hz is below --f-min {f_min:g} Hz")
    n = int((f_max - f_min) / df) + 1
    if n > MAX_FREQUENCIES:
        raise MbsuiteError(f"--f-min/--f-max/--df give {n} frequencies; at most {MAX_FREQUENCIES} (enlarge --df)")
    methods = [m for m in args.methods.split(",") if m]
    bad = sorted(set(methods) - set(METHODS))
    if bad or not methods:
        raise MbsuiteError(f"--methods {args.methods!r}: valid methods are {', '.join(METHODS)}")
    return {"f_min": f_min, "f_max": f_max, "df": df, "methods": args.methods, "workers": check_workers(args.workers)}


def cmd_freqresp(args: argparse.Namespace) -> None:
    """The frequency response; its sweeps run where `--executor/--scheduler/--store/--max-points` say."""
    scene = _scene(args, "freqresp")
    report = scene.spec.freqresp(scene, **freq_args(args), options=sweep_options(args),
                                 time_histories=getattr(args, "out", None) is not None)  # only the figure needs them
    args.emit(report, args, scene.to_dict())


COMMAND_FUNCS = {"equilibrium": cmd_equilibrium, "modes": cmd_modes, "freqresp": cmd_freqresp}
