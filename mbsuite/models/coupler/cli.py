"""`mbsuite coupler jacobian | fpp | criteria | dynamics` (JSON with --json, files with --out)."""

from __future__ import annotations

import argparse
import math
import textwrap
import warnings
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from ...cli.options import add_error_estimate, add_scene_options, scene_of
from ...cli.study import add_study_options, run_or_study
from ...errors import ParameterError, SceneError
from ...limits import Limit, limit_of
from ...trust.health import InaccurateResult
from .params import GAMMA_17DEG, CouplerParams

if TYPE_CHECKING:  # imported where the commands run: their --help loads no analysis, engine or numpy
    from ...results import Report
    from ...scenes import Scene

# the top-level commands `register` adds, with their help (read by `mbsuite --help` without importing the model)
CLI_COMMANDS = {"coupler": "4-link coupler kinematics (Jacobian, FPP, criteria) and dynamics"}


def mbsuite_run(scene, error_estimate: bool = False):
    """`mbsuite.run` (imported late: the package imports this module's model while it loads)."""
    from ... import run

    return run(scene, error_estimate=error_estimate)


def _finite_value(name: str, limit: Limit, s: str) -> float:
    """The option `name`'s value `s` checked by its declared `limit` (argparse type; ArgumentTypeError naming the
    option, the value and what is valid)."""
    try:
        return limit.check(name, float(s), argparse.ArgumentTypeError)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{name} = {s!r} is not a number; valid: {limit.describe()}") from None


def _finite(name: str, field: str | None = None) -> partial:
    """The argparse type of option `name`: the `Limit` of `CouplerParams` field `field`, or any finite number."""
    return partial(_finite_value, name, (limit_of(CouplerParams, field) if field else None) or Limit(unit="rad"))


def _geometry_args(p: argparse.ArgumentParser) -> None:
    """--gamma, --ey, --R with the defaults of `CouplerParams` (one default for the Python API and the CLI)."""
    d = CouplerParams()
    p.add_argument("--gamma", type=_finite("--gamma", "gamma"), default=d.gamma,
                   help=f"platform proportion angle [rad] (default 17 deg = {GAMMA_17DEG:.5f}, reproduces Eq 15)")
    p.add_argument("--ey", type=_finite("--ey", "e_y"), default=d.e_y, help=f"axial shift e_y [R] (default {d.e_y:g})")
    p.add_argument("--R", type=_finite("--R", "R"), default=d.R, help=f"joint-circle radius (default {d.R:g})")


#: units of the geometry options (a --vary option.NAME study's axes)
OPTION_UNITS = {"gamma": "rad", "phi_a": "rad", "alpha_bx": "rad", "alpha_bz": "rad"}


def _params(args: argparse.Namespace) -> CouplerParams:
    return CouplerParams(gamma=args.gamma, e_y=args.ey, R=args.R)


def jacobian_of(scene: None, args: argparse.Namespace) -> Report:
    """The single coupler's Jacobian report at the command's geometry, singularity warnings stated in it (the
    command's, or a point of its --vary study)."""
    from . import analysis

    p = _params(args)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", analysis.SingularityWarning)
        rep = analysis.jacobian_report(p, args.phi_a, args.alpha_bx, args.alpha_bz, args.engine)
    msgs = [str(w.message) for w in caught if issubclass(w.category, analysis.SingularityWarning)]
    if msgs:
        rep.data["warnings"] = msgs
        rep.table = "".join(textwrap.fill("WARNING: " + m, 100, subsequent_indent="  ") + "\n"
                            for m in msgs) + rep.table
    return rep


def cmd_jacobian(args: argparse.Namespace, emit) -> None:
    """`mbsuite coupler jacobian`: the single coupler's Jacobian report (or a --vary option.NAME study of it)."""
    args.emit = emit
    run_or_study(args, None, f"{__name__}:jacobian_of", units=OPTION_UNITS)


#: default size guard of `coupler fpp`: samples per revolution (about 0.2 ms each; 1e5 take ~20 s); --max-n raises it
FPP_MAX_N = 100_000


def _count_value(name: str, s: str) -> int:
    """The option `name`'s value `s` as a whole number (argparse type; ArgumentTypeError naming the option)."""
    try:
        v = float(s)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{name} must be a number, got {s!r}") from None
    if not math.isfinite(v) or v != int(v):
        raise argparse.ArgumentTypeError(f"{name} must be a whole number, got {s!r}")
    return int(v)


def _count(name: str) -> partial:
    """The argparse type of a whole number for option `name`."""
    return partial(_count_value, name)


def fpp_of(scene: None, args: argparse.Namespace) -> Report:
    """The single coupler's pose over one revolution at the command's geometry (size-guarded sample count)."""
    from . import analysis

    if not 3 <= args.n <= args.max_n:
        raise ParameterError(f"--n = {args.n} is invalid; valid: integer in [3, {args.max_n}] (the size guard "
                             f"--max-n, default {FPP_MAX_N}; each sample is one FPP solve, ~0.2 ms)")
    return analysis.fpp_report(_params(args), args.alpha_bx, args.alpha_bz, args.n, args.engine)


def cmd_fpp(args: argparse.Namespace, emit) -> None:
    """`mbsuite coupler fpp`: the single coupler's pose over one revolution (or a --vary option.NAME study)."""
    args.emit = emit
    run_or_study(args, None, f"{__name__}:fpp_of", units=OPTION_UNITS)


def cmd_criteria(args: argparse.Namespace, emit) -> None:
    """`mbsuite coupler criteria`: c1-c5 over the design grid (a small grid with --quick)."""
    from . import analysis

    if args.quick:
        rep = analysis.criteria_report(gammas=(0.297,), eys=(0.1,), alphas=(0.0, 0.035, 0.07), zcs=(0.0, 0.05),
                                       lbs=(2.0,), n=61)
    else:
        rep = analysis.criteria_report()
    emit(rep, args, None)


#: units of the solver counters a dynamics run reports beside its declared statistics (`SimResult.statistics`)
COUNTER_UNITS = {"steps": "-", "timestep": "s"}


def _plain(v: object) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def dynamics_table(scene_input: dict, res) -> str:
    """The human table of `coupler dynamics`: resolved input, statistics with units, health, link forces."""
    from ...results import format_table

    st = {**res.statistics, **res.stats}
    units = {**COUNTER_UNITS, **{k: (u or "-") for k, u in res.statistic_units.items()}}
    inp_units = {"omega": "rad/s", "load_torque": "N m", "alpha_cx": "rad", "alpha_cz": "rad", "x_c": "m",
                 "z_c": "m", "t_ramp": "s"}
    table = textwrap.fill("input (resolved, defaults included): " + ", ".join(
        f"{k} = {_plain(v)}" + (f" {inp_units[k]}" if k in inp_units else "") for k, v in scene_input.items()),
        100, subsequent_indent="  ") + "\n"
    rows = [[k, units.get(k, "?"), float(v) if isinstance(v, float) else v] for k, v in st.items()
            if isinstance(v, int | float) and not isinstance(v, bool)]
    table += format_table(["quantity", "unit", "value"], rows, ".6g")
    if st.get("integrator"):
        table += f"\nintegrator {st['integrator']}"
    if "solref" in st:
        table += f", closure solref = ({st['solref'][0]:g} s, {st['solref'][1]:g})"
    if res.health:
        table += "\n" + textwrap.fill("health: " + ", ".join(
            f"{f.name} {f.value:.3g} {f.unit} (bound {f.bound:.3g} {f.unit}{'' if f.ok else ', EXCEEDED'})"
            for f in res.health), 100, subsequent_indent="  ")
    table += "\nMuJoCo warnings: " + (", ".join(f"{k} x{n}" for k, n in st["warnings"].items())
                                      if st.get("warnings") else "none") if "warnings" in st else ""
    if "link_force_mean" in st:
        table += "\nmean link forces over the statistics window (tension > 0):\n" + format_table(
            [f"link {k + 1} [N]" for k in range(len(st["link_force_mean"]))], [st["link_force_mean"]], ".1f")
    return table


def write_dynamics(res, out: Path) -> list[Path]:
    """The files of `coupler dynamics --out`: the run's time series (CSV) and its figure."""
    from ...plotting import save
    from .plots import dynamics_figure

    return [res.write_csv(out / "run.csv"), save(dynamics_figure(res), out / "run.png")]


def _dynamics_scene(args: argparse.Namespace) -> Scene:
    """The command's coupler scene with the command line's solver overrides."""
    scene = scene_of(args.scene)
    if scene.model != "coupler":
        raise SceneError(f"scene {args.scene!r} is a '{scene.model}' scene; coupler dynamics needs a coupler scene "
                         "('coupler' or coupler/<scene>, e.g. coupler/double_friction)")
    solver: dict = {"engine": args.engine} if args.engine else {}
    if args.allow_inaccurate:
        solver["allow_inaccurate"] = True
    if args.max_steps is not None:
        solver["max_steps"] = args.max_steps
    if solver:
        scene = scene.replace(solver=solver, origin="on the command line (--engine/--allow-inaccurate/--max-steps)")
    return scene


def dynamics_of(scene: Scene, args: argparse.Namespace) -> Report:
    """The double-coupler run of `scene` with its statistics and health (the command's, or a study point's)."""
    # health figures judged (AccuracyError past a bound unless allowed); an error estimate above its tolerance keeps
    # the result, flagged (InaccurateResult carrying the report: the command prints it and exits 3)
    from ...results import Report

    inaccurate = None
    try:
        res = mbsuite_run(scene, error_estimate=bool(getattr(args, "error_estimate", False)))
    except InaccurateResult as exc:
        res, inaccurate = exc.result, exc.messages
    inputs = dict(scene.input.items())  # resolved: declared defaults filled in by the scene loader
    table = dynamics_table(inputs, res)
    if res.error_estimate is not None:
        table += "\n" + res.error_estimate.table()
    if inaccurate:
        table += "".join(f"\n{w}" for w in inaccurate)
    rep = Report({"input": inputs, "scene": scene.to_dict(), "statistics": res.statistics, "stats": res.stats,
                  "summary": res.summary()}, table, partial(write_dynamics, res))
    if inaccurate:
        raise InaccurateResult(inaccurate, rep)
    return rep


def cmd_dynamics(args: argparse.Namespace, emit) -> None:
    """`mbsuite coupler dynamics`: a double-coupler run of a coupler scene with its statistics and health (or a
    --vary study of them)."""
    args.emit = emit
    run_or_study(args, _dynamics_scene(args), f"{__name__}:dynamics_of")


def register(sub, add_common, emit) -> str:
    """Add the `mbsuite coupler jacobian | fpp | criteria | dynamics` commands to the parser `sub`; return the group's
    command name."""
    g = sub.add_parser("coupler", help=CLI_COMMANDS["coupler"])
    gs = g.add_subparsers(dest="coupler_command", required=True)

    p = gs.add_parser("jacobian", help="mechanism Jacobian, singular values, rank, condition number, screws")
    _geometry_args(p)
    p.add_argument("--phi-a", type=_finite("--phi-a"), default=0.0, help="input angle [rad]")
    p.add_argument("--alpha-bx", type=_finite("--alpha-bx"), default=0.0, help="inclination about x [rad]")
    p.add_argument("--alpha-bz", type=_finite("--alpha-bz"), default=0.0, help="inclination about z [rad]")
    p.add_argument("--engine", choices=["reference", "pinocchio"], default="reference")
    add_study_options(p, scene=False)
    add_common(p)
    p.set_defaults(func=partial(cmd_jacobian, emit=emit))

    p = gs.add_parser("fpp", help="single-coupler pose over one revolution of phi_a (continuation)")
    _geometry_args(p)
    p.add_argument("--alpha-bx", type=_finite("--alpha-bx"), default=0.0525, help="inclination about x [rad]")
    p.add_argument("--alpha-bz", type=_finite("--alpha-bz"), default=0.0, help="inclination about z [rad]")
    p.add_argument("--n", type=_count("--n"), default=73, help="samples over the revolution (both ends included)")
    p.add_argument("--max-n", type=_count("--max-n"), default=FPP_MAX_N,
                   help=f"size guard: the largest --n accepted (default {FPP_MAX_N})")
    p.add_argument("--engine", choices=["reference", "pinocchio"], default="reference",
                   help="pinocchio: also solve with the URDF model and report the difference")
    add_study_options(p, scene=False)
    add_common(p)
    p.set_defaults(func=partial(cmd_fpp, emit=emit))

    p = gs.add_parser("criteria", help="c1-c4 (single) and c5 (double) tables; plots (Figs 6-10 style) with --out")
    p.add_argument("--quick", action="store_true", help="a small grid (for a smoke test)")
    add_common(p)
    p.set_defaults(func=partial(cmd_criteria, emit=emit))

    p = gs.add_parser("dynamics", help="MuJoCo double-coupler run with agreement statistics")
    p.add_argument("scene", nargs="?", default="coupler", help="scene (default: coupler's default scene)")
    p.add_argument("--engine", choices=["mujoco", "reference"], help="override the scene's engine")
    add_scene_options(p)
    add_error_estimate(p)
    add_study_options(p)
    add_common(p)
    p.set_defaults(func=partial(cmd_dynamics, emit=emit))
    return "coupler"
