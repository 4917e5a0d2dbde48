"""`mbsuite pantograph equilibrium | modes | freqresp [SCENE]`: the pantograph's analyses (its SPEC hooks) and their
options. `mbsuite equilibrium | modes | freqresp SCENE` with the same options are aliases of these commands."""

from __future__ import annotations

import argparse

from ...cli.options import (
    SCENE_HELP,
    add_error_estimate,
    add_scene_options,
    add_sweep_options,
    check_workers,
    load,
    sweep_options,
)
from ...cli.study import add_study_options, run_or_study
from ...errors import MbsuiteError
from ...scenes import Scene
from .freqresp import DEFAULTS, LIMITS, METHODS, check_grid

MODEL = "pantograph"
COMMANDS = {
    "equilibrium": "static equilibrium of a scene (every path)",
    "modes": "linearised natural frequencies and damping ratios",
    "freqresp": "frequency response (linearisation, reference and MuJoCo time simulations)",
}
# the top-level commands `register` adds, with their help (read by `mbsuite --help` without importing the model)
CLI_COMMANDS = {
    "pantograph": "the pantograph's analyses: equilibrium, modes, frequency response",
    "equilibrium": "static equilibrium of a scene (every path) (as `mbsuite pantograph equilibrium`)",
    "modes": "linearised natural frequencies and damping ratios (as `mbsuite pantograph modes`)",
    "freqresp": "frequency response (linearisation, reference and MuJoCo time simulations) (as `mbsuite pantograph "
                "freqresp`)",
}


def register(sub: argparse._SubParsersAction, add_common, emit) -> str:
    """Add the `pantograph` command group and its top-level aliases to the CLI's subparsers `sub`."""
    g = sub.add_parser(MODEL, help=CLI_COMMANDS[MODEL])
    gs = g.add_subparsers(dest="pantograph_command", required=True)
    for name, helptext in COMMANDS.items():
        p = gs.add_parser(name, help=helptext)
        p.add_argument("scene", nargs="?", default=MODEL, help=SCENE_HELP + " (default: the pantograph's)")
        _add_options(p, name, add_common, emit)
        p = sub.add_parser(name, help=CLI_COMMANDS[name])
        p.add_argument("scene", help=SCENE_HELP)
        _add_options(p, name, add_common, emit)
    return MODEL


def _add_options(p: argparse.ArgumentParser, name: str, add_common, emit) -> None:
    add_common(p)
    if name != "freqresp":
        add_scene_options(p)
    if name == "modes":
        p.add_argument("--height", type=float,
                       help="ram height (m) to linearise at (default: the mean of the scene's input)")
    if name == "freqresp":
        add_scene_options(p)
        for key in ("f_min", "f_max", "df", "peak_tol"):  # the defaults are freqresp's (one per question)
            p.add_argument("--" + key.replace("_", "-"), type=float, default=DEFAULTS[key],
                           help=f"{LIMITS[key].doc} (Hz; default {DEFAULTS[key]:g})")
        p.add_argument("--methods", default=",".join(DEFAULTS["methods"]),
                       help=f"comma list of {', '.join(METHODS)} (default {','.join(DEFAULTS['methods'])})")
        p.add_argument("--workers", type=int, default=0, help="parallel processes (0 = all cores)")
        add_error_estimate(p)
        add_sweep_options(p)
    add_study_options(p)
    p.set_defaults(func=COMMAND_FUNCS[name], emit=emit)


def _scene(args: argparse.Namespace, hook: str) -> Scene:
    """The command's scene; a scene of another model is refused."""
    scene = load(args)
    if scene.model != MODEL or getattr(scene.spec, hook) is None:
        raise MbsuiteError(f"model '{scene.model}' does not support '{hook}' (`mbsuite {MODEL} {hook}` takes a "
                           f"{MODEL} scene)")
    return scene


# the units of the numbers the analyses report, by their names (a --vary study's table, CSV and figure)
UNITS = {"f_n": "Hz", "f_d": "Hz", "tau": "s", "zeta": "1", "linearised_at_height_m": "m", "theta1": "rad",
         "theta2": "rad", "thetah": "rad", "theta_e": "rad", "elbow_windup": "rad", "y_d": "m", "contact_force": "N",
         "dtheta_e_dtheta1": "1", "mujoco": "rad", "pinocchio": "rad"}


def equilibrium_of(scene: Scene, args: argparse.Namespace):
    """The equilibrium report of `scene` (the command's, or a study point's)."""
    return scene.spec.equilibrium(scene)


def modes_of(scene: Scene, args: argparse.Namespace):
    """The modes report of `scene`, at `--height` or at the mean of its input."""
    height = getattr(args, "height", None)
    return scene.spec.modes(scene, **({"height": height} if height is not None else {}))


def cmd_equilibrium(args: argparse.Namespace) -> None:
    """The static equilibrium of the scene in every path (or a --vary study of it)."""
    run_or_study(args, _scene(args, "equilibrium"), f"{__name__}:equilibrium_of", units=UNITS)


def cmd_modes(args: argparse.Namespace) -> None:
    """The linearised modes, at `--height` or at the mean of the scene's input (or a --vary study of them)."""
    run_or_study(args, _scene(args, "modes"), f"{__name__}:modes_of", units=UNITS)


def freq_args(args: argparse.Namespace) -> dict:
    """`--f-min/--f-max/--df/--peak-tol/--methods/--workers/--error-estimate`, each checked (`freqresp.check_grid`:
    the Python entry's own checks), as the freqresp hook's keyword arguments."""
    try:
        _, methods = check_grid(args.f_min, args.f_max, args.df, args.peak_tol, args.methods, MbsuiteError)
    except MbsuiteError as exc:
        raise MbsuiteError(f"--f-min/--f-max/--df/--peak-tol/--methods: {exc}") from None
    return {"f_min": args.f_min, "f_max": args.f_max, "df": args.df, "peak_tol": args.peak_tol,
            "methods": methods, "workers": check_workers(args.workers),
            "error_estimate": bool(getattr(args, "error_estimate", False))}


def freqresp_of(scene: Scene, args: argparse.Namespace):
    """The frequency-response report of `scene`; its sweeps run where `--executor/--scheduler/--store/--max-points`
    say (the time histories only when a figure is written)."""
    return scene.spec.freqresp(scene, **freq_args(args), options=sweep_options(args),
                               time_histories=getattr(args, "out", None) is not None)


def cmd_freqresp(args: argparse.Namespace) -> None:
    """The frequency response (or a --vary study of it: its points one after another, each on all workers)."""
    run_or_study(args, _scene(args, "freqresp"), f"{__name__}:freqresp_of", units=UNITS, parallel_inside=True)


COMMAND_FUNCS = {"equilibrium": cmd_equilibrium, "modes": cmd_modes, "freqresp": cmd_freqresp}
