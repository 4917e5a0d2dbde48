"""`mbsuite pantograph equilibrium | modes | freqresp | fit-lumped [SCENE]`: the pantograph's analyses (its SPEC hooks,
and the lumped and transfer-function fit of `lumped_study.py`) and their options. `mbsuite equilibrium | modes |
freqresp SCENE` with the same options are aliases of the first three."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

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
from .freq_grid import DEFAULTS, LIMITS, METHODS, check_grid

if TYPE_CHECKING:
    from ...scenes import Scene

MODEL = "pantograph"
COMMANDS = {
    "equilibrium": "static equilibrium of a scene (every path)",
    "modes": "linearised natural frequencies and damping ratios",
    "freqresp": "frequency response (linearisation, reference and MuJoCo time simulations)",
    "fit-lumped": "2- or 3-stage lumped and transfer-function pantographs fitted to the linearised driving-point "
                  "receptance; their parameters as catenary scenes",
}
#: the group's commands without a top-level alias
GROUP_ONLY = ("fit-lumped",)
# the top-level commands `register` adds, with their help (read by `mbsuite --help` without importing the model)
CLI_COMMANDS = {
    "pantograph": "the pantograph's analyses: equilibrium, modes, frequency response, lumped fit",
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
        if name in GROUP_ONLY:
            continue
        p = sub.add_parser(name, help=CLI_COMMANDS[name])
        p.add_argument("scene", help=SCENE_HELP)
        _add_options(p, name, add_common, emit)
    return MODEL


def _add_options(p: argparse.ArgumentParser, name: str, add_common, emit) -> None:
    add_common(p)
    if name == "fit-lumped":
        _add_fit_options(p)
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


def _add_fit_options(p: argparse.ArgumentParser) -> None:
    from .fit_defaults import BAND, DEFAULT_ORDER, DF, STARTS

    p.add_argument("--stages", type=int, default=2, help="stages of the lumped pantograph (1 to 6; default 2)")
    p.add_argument("--band", default=f"{BAND[0]:g}:{BAND[1]:g}", metavar="LO:HI",
                   help=f"fitted band (Hz; default {BAND[0]:g}:{BAND[1]:g})")
    p.add_argument("--df", type=float, default=DF, help=f"frequency spacing of the band (Hz; default {DF:g})")
    p.add_argument("--height", type=float, default=None,
                   help="working (ram/wire) height above the base pivot (m) to linearise at (default: params.y_op)")
    p.add_argument("--order", type=int, default=DEFAULT_ORDER,
                   help=f"order of the transfer function (denominator degree, 2 to 16; default {DEFAULT_ORDER})")
    p.add_argument("--starts", type=int, default=STARTS,
                   help=f"starts of the lumped fit's multi-start (default {STARTS})")
    p.add_argument("--seed", type=int, default=0, help="seed of the starts (default 0)")
    p.add_argument("--base-spring", choices=["static", "fitted"], default="static",
                   help="the lumped pantograph's spring to the base: held at the model's static stiffness at the head "
                        "(default; may be negative) or fitted as the others (positive)")


def fit_args(args: argparse.Namespace) -> dict:
    """`--stages/--band/--df/--height/--order/--starts/--seed/--base-spring` as `lumped_study.fit_report`'s keyword
    arguments, each checked (MbsuiteError naming the flag)."""
    lo, sep, hi = str(args.band).partition(":")
    try:
        band = (float(lo), float(hi))
    except ValueError:
        band = None
    if not sep or band is None:
        raise MbsuiteError(f"--band {args.band!r}: give LO:HI in Hz, e.g. 0:20")
    if not 1 <= args.stages <= 6:
        raise MbsuiteError(f"--stages {args.stages}: 1 to 6")
    if not 2 <= args.order <= 16:
        raise MbsuiteError(f"--order {args.order}: 2 to 16")
    if not 1 <= args.starts <= 1000:
        raise MbsuiteError(f"--starts {args.starts}: 1 to 1000")
    return {"stages": args.stages, "band": band, "df": args.df, "height": args.height, "order": args.order,
            "starts": args.starts, "seed": args.seed, "base_spring": args.base_spring}


def fit_lumped_of(scene: Scene, args: argparse.Namespace):
    """The lumped and transfer-function fit of `scene` (`lumped_study.fit_report`)."""
    from .lumped_study import fit_report

    return fit_report(scene, **fit_args(args))


def cmd_fit_lumped(args: argparse.Namespace) -> None:
    """The lumped and transfer-function pantographs fitted to the scene's driving-point receptance."""
    scene = load(args)
    if scene.model != MODEL:
        raise MbsuiteError(f"`mbsuite {MODEL} fit-lumped` takes a {MODEL} scene, not a '{scene.model}' one")
    run_or_study(args, scene, f"{__name__}:fit_lumped_of", units=UNITS)


def _scene(args: argparse.Namespace, hook: str) -> Scene:
    """The command's scene; a scene of another model is refused."""
    scene = load(args)
    if scene.model != MODEL or getattr(scene.spec, hook) is None:
        raise MbsuiteError(f"model '{scene.model}' does not support '{hook}' (`mbsuite {MODEL} {hook}` takes a "
                           f"{MODEL} scene)")
    return scene


# the units of the numbers the analyses report, by their names (a --vary study's table, CSV and figure)
# (names ending in _hz, _m, _deg, _rel, ... take the unit they spell: `mbsuite.cli.study.unit_source`)
UNITS = {"f_n": "Hz", "f_d": "Hz", "tau": "s", "zeta": "1", "linearised_at_height_m": "m", "theta1": "rad",
         "theta2": "rad", "thetah": "rad", "theta_e": "rad", "elbow_windup": "rad", "y_d": "m", "contact_force": "N",
         "dtheta_e_dtheta1": "1", "mujoco": "rad", "pinocchio": "rad",
         # freqresp: amplitude ratios of the response (a height, m) to the ram input (m)
         "amplitude": "m/m", "with": "m/m", "without": "m/m", "at_f_amp": "Hz", "at_f_phase": "Hz"}
#: the quantities in words (the axes of a study's figure)
WORDS = {"f_n": "natural frequency", "f_d": "damped natural frequency", "zeta": "damping ratio",
         "tau": "time constant", "peaks_hz": "peak (resonance) frequency of the response"}
#: the headline quantities a study of each analysis prints wide and draws (by a name of their path)
WIDE = {"modes": ("f_n", "zeta"), "freqresp": ("peaks_hz", "f_n", "zeta")}


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
    run_or_study(args, _scene(args, "modes"), f"{__name__}:modes_of", units=UNITS, wide=WIDE["modes"], words=WORDS)


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
    """The frequency response (or a --vary study of it: its points one after another, each on all workers; every
    point's curves kept, `freqresp.study_curves`)."""
    run_or_study(args, _scene(args, "freqresp"), f"{__name__}:freqresp_of", units=UNITS, parallel_inside=True,
                 wide=WIDE["freqresp"], words=WORDS, curves="mbsuite.models.pantograph.freqresp:study_curves")


COMMAND_FUNCS = {"equilibrium": cmd_equilibrium, "modes": cmd_modes, "freqresp": cmd_freqresp,
                 "fit-lumped": cmd_fit_lumped}
