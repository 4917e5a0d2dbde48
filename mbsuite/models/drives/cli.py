"""`mbsuite drive ...`: design tools, scene runs with cycle statistics, efficiency sweeps, CoupledClutches check."""

from __future__ import annotations

import argparse
import textwrap
import time
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from ...cli.options import SCENE_HELP, add_error_estimate, add_scene_options, scene_of
from ...cli.study import add_study_options, run_or_study
from ...errors import MbsuiteError, SceneError
from ...limits import Limit
from ...trust.health import InaccurateResult, judge, judge_estimate
from .params import BASE_SETS

if TYPE_CHECKING:  # the design tools, results and numpy are imported where the commands run: their --help loads none
    from ...results import Report

#: the commands `register` adds (read by the command line's light parser without importing the model)
CLI_COMMANDS = {"drive": "switched-mode drives: design tools, runs, efficiency",
                "drives": "switched-mode drives (as `mbsuite drive`)"}

#: names and units of the cycle statistics of a drive run (`drive.cycle_stats`)
CYCLE_QUANTITIES = {"n_cycles": ("energy cycles in the window t >= t_settle", ""),
                    "switching_rate": ("switching rate Sr (energy cycles per second)", "1/s"),
                    "mean_load_speed": ("mean load speed", "rad/s"), "mean_motor_speed": ("mean motor speed", "rad/s"),
                    "max_extension": ("largest spring twist", "rad"),
                    "efficiency": ("efficiency E_out / E_in over t >= t_settle", "1")}

#: the units of a `--vary` study's quantities by their last name (`mbsuite.cli.study`)
STUDY_UNITS = {**{k: u for k, (_, u) in CYCLE_QUANTITIES.items()}, "input": "J", "output": "J", "stored": "J",
               "residual": "J", "relative": "1", "duration": "s", "P_in": "W", "P_out": "W"}

#: most entries of a comma list option (--srmin, --js, --loads)
MAX_LIST = 1000

_POS = {"lo": 0.0, "lo_open": True}
#: valid range of every numeric option, by flag; checked before any work (finite, range; lists entry by entry)
OPTION_LIMITS: dict[str, Limit] = {
    "--P": Limit(**_POS, hi=1e7, unit="W", doc="drive power"),
    "--wmin": Limit(lo=0.0, hi=1e5, unit="rad/s", doc="lowest load speed"),
    "--wrip": Limit(**_POS, hi=1e5, unit="rad/s", doc="allowed speed ripple"),
    "--Jl": Limit(**_POS, hi=1e3, unit="kg m^2", doc="load inertia"),
    "--srmin": Limit(**_POS, hi=1e4, unit="1/s", doc="minimum switching rate"),
    "--wmax": Limit(**_POS, hi=1e5, unit="rad/s", doc="highest load speed"),
    "--vm": Limit(**_POS, hi=1e5, unit="rad/s", doc="motor speed"),
    "--js": Limit(**_POS, hi=1e3, unit="kg m^2", doc="spring-system inertia"),
    "--tau-c": Limit(**_POS, hi=1e5, unit="N m", doc="clutch torque"),
    "--K": Limit(**_POS, hi=1e6, unit="N m/rad", doc="spring rate"),
    "--xmax": Limit(**_POS, hi=1e4, unit="rad", doc="largest spring twist"),
    "--fatigue": Limit(**_POS, hi=1.0, doc="fatigue stress / ultimate tensile stress"),
    "--sigma-uts": Limit(**_POS, hi=1e11, unit="Pa", doc="ultimate tensile stress"),
    "--E": Limit(**_POS, hi=1e13, unit="Pa", doc="Young's modulus"),
    "--ts": Limit(**_POS, hi=1e3, unit="s", doc="energy-cycle period"),
    "--taul": Limit(lo=0.0, hi=1e5, unit="N m", doc="load torque"),
    "--w0": Limit(lo=-1e5, hi=1e5, unit="rad/s", doc="operating speed (not 0)"),
    "--btotal": Limit(lo=0.0, hi=1e5, unit="N m s", doc="total viscous coefficient"),
    "--duration": Limit(**_POS, hi=1e5, unit="s", doc="simulated time"),
    "--loads": Limit(lo=-1e4, hi=1e4, unit="N m", doc="load torque"),
    "--wop": Limit(lo=0.0, hi=1e5, unit="rad/s", doc="operating speed of the design's scene"),
    "--pmotor": Limit(**_POS, hi=1e7, unit="W", doc="largest motor power (at --vm)"),
    "--scene-duration": Limit(**_POS, hi=1e5, unit="s", doc="simulated time of the design's scene"),
}


def _help(flag: str, extra: str = "") -> str:
    """The help text of a numeric option: its meaning, unit and valid range (`OPTION_LIMITS`), then `extra`."""
    lim = OPTION_LIMITS[flag]
    lo = "(" if lim.lo_open else "["
    text = f"{lim.doc}, {lim.unit or '1'}; valid {lo}{lim.lo:g}, {lim.hi:g}]"
    return f"{text}; {extra}" if extra else text


def _floats(flag: str):
    """argparse `type` of the comma-list option `flag`: a list of floats; a non-number is an ArgumentTypeError naming
    the flag and the entry (ranges are checked after parsing by `_check_options`)."""

    def conv(text: str) -> list[float]:
        out = []
        for x in text.split(","):
            if not x.strip():
                continue
            try:
                out.append(float(x))
            except ValueError:
                raise argparse.ArgumentTypeError(f"{x.strip()!r} is not a number (expected a comma list of "
                                                 "numbers)") from None
        return out

    conv.__name__ = f"{flag} comma list of numbers"
    return conv


def _check_options(a: argparse.Namespace, *flags: str) -> None:
    """Check the given numeric options of a parsed command against `OPTION_LIMITS` (an unset option is skipped);
    raise MbsuiteError naming the flag, its value and the valid range (the CLI exits with status 2)."""
    for flag in flags:
        v = getattr(a, flag[2:].replace("-", "_"), None)
        if v is None:
            continue
        lim = OPTION_LIMITS[flag]
        if isinstance(v, list):
            if not v or len(v) > MAX_LIST:
                raise MbsuiteError(f"{flag} needs 1 to {MAX_LIST} numbers, got {len(v)}")
            for i, x in enumerate(v):
                lim.check(f"{flag} entry {i + 1}", x, MbsuiteError)
        else:
            lim.check(flag, v, MbsuiteError)


def _check_speed_range(wmin: float, wmax: float) -> None:
    """The load speed range of a design: --wmin must lie below --wmax."""
    if not wmin < wmax:
        raise MbsuiteError(f"--wmin {wmin:g} rad/s must be below --wmax {wmax:g} rad/s (the load speed range "
                           "[w_min, w_max] of the design)")


def _csv_writer(name: str, columns: list[tuple[str, str, list]], figure=None):
    """A `Report.write`: `name`.csv from `(column, unit, values)` and, if `figure` (a callable returning a Figure)
    is given, `name`.png."""
    return partial(_write_csv, name, columns, figure)


def _write_csv(name: str, columns: list[tuple[str, str, list]], figure, out: Path) -> list[Path]:
    """The files of a design command's `--out`: `name`.csv and, with a figure, `name`.png."""
    from ...plotting import save
    from ...results import write_csv

    files = [write_csv(Path(out) / f"{name}.csv", columns)]
    if figure is not None:
        files.append(save(figure(), Path(out) / f"{name}.png"))
    return files


def _quantity_table(items: list[tuple[str, str, float | str, str]]) -> str:
    """A transposed table: one row per quantity (name, symbol/meaning, value, unit)."""
    from ...results import format_table

    return format_table(["quantity", "meaning", "value", "unit"],
                        [[k, m, (f"{v:.6g}" if isinstance(v, float) else v), u] for k, m, v, u in items])


def register(sub, add_common, emit) -> str:
    """Add the `drive` command group (alias `drives`) to the top-level parser: design tools, scene runs, efficiency
    sweeps; returns the group's command name. Every command prints a table with units;
    `--out DIR` writes CSV (SI units in the header), a PNG where a figure makes sense and summary.json."""
    p = sub.add_parser("drive", aliases=["drives"],
                       help="switched-mode drives: design tools, runs, efficiency")
    dsub = p.add_subparsers(dest="drive_command", required=True)

    # -- design --------------------------------------------------------------------------------------------------
    pd = dsub.add_parser("design", help="Chapter 5 design tools")
    ds = pd.add_subparsers(dest="design_command", required=True)

    q = ds.add_parser("tables", help="reproduce Tables 5.2 and 6.2 and the controller gains")
    add_common(q)
    q.set_defaults(func=partial(design_tables_cmd, emit))

    q = ds.add_parser("srmin", help="Eq 5.1: minimum switching rate Sr_min = P / (w_min w_rip J_l)")
    for k in ("P", "wmin", "wrip", "Jl"):
        q.add_argument(f"--{k}", type=float, required=True, help=_help(f"--{k}"))
    add_common(q)
    q.set_defaults(func=partial(srmin_cmd, emit))

    q = ds.add_parser("cadjs", help="CADJS: K, clutch torque, x_max, Sr_max per J_s (Eqs 5.9-5.13 corrected); "
                      "--scene-out writes one design point as a runnable step-up/step-down scene")
    q.add_argument("--P", type=float, required=True, help=_help("--P", "P of Eqs 5.9-5.13"))
    q.add_argument("--srmin", type=_floats("--srmin"), required=True,
                   help=_help("--srmin", "comma list (Sr_min of Eq 5.1: drive design srmin)"))
    q.add_argument("--wmin", type=float, default=0.0, help=_help("--wmin", "w_min, default 0"))
    q.add_argument("--wmax", type=float, required=True, help=_help("--wmax", "w_max"))
    q.add_argument("--vm", type=float, required=True, help=_help("--vm", "V_m, the motor's running speed"))
    q.add_argument("--js", type=_floats("--js"), default=None,
                   help=_help("--js", "J_s, comma list (default 1e-5 ... 1e-4)"))
    q.add_argument("--tau-c", type=float, default=None,
                   help=_help("--tau-c", "read the family at this clutch torque (as Tables 5.2, 6.2)"))
    g = q.add_argument_group("design -> scene (with --scene-out; one --srmin and --tau-c or one --js)")
    g.add_argument("--scene-out", metavar="FILE", default=None,
                   help="write the design point as a step-up/step-down scene TOML (mbsuite drive run FILE runs it)")
    g.add_argument("--wop", type=float, default=None,
                   help=_help("--wop", "speed the scene's PI tracks, in [--wmin, --wmax]; default their middle"))
    g.add_argument("--Jl", type=float, default=None, help=_help("--Jl", "default: the base set's"))
    g.add_argument("--taul", type=float, default=None,
                   help=_help("--taul", "Coulomb load torque of the scene; default P / wop"))
    g.add_argument("--pmotor", type=float, default=None,
                   help=_help("--pmotor", "the App. J straight-line motor's largest power, at --vm; default 1.5 P"))
    g.add_argument("--base", default="design_100w", choices=list(BASE_SETS),
                   help="parameter set giving bearings, delays, controller rate, motor inertia (default design_100w)")
    g.add_argument("--scene-duration", type=float, default=6.0,
                   help=_help("--scene-duration", "default 6 (statistics over its second half)"))
    add_common(q)
    q.set_defaults(func=partial(cadjs_cmd, emit))

    q = ds.add_parser("springsz", help="SPRINGSZ: wire diameter, D*N and volume (Eqs 5.14-5.21)")
    q.add_argument("--K", type=float, required=True, help=_help("--K"))
    q.add_argument("--xmax", type=float, required=True, help=_help("--xmax"))
    q.add_argument("--fatigue", type=float, default=0.25, help=_help("--fatigue", "default 0.25"))
    q.add_argument("--sigma-uts", type=float, default=None,
                   help="ultimate tensile stress, Pa (default: calibrated to the thesis' 1.58e-4 m^3, not a material)")
    q.add_argument("--E", type=float, default=None, help="Young's modulus, Pa (default: implied by Table 6.3)")
    add_common(q)
    q.set_defaults(func=partial(springsz_cmd, emit))

    q = ds.add_parser("gains", help="gain selection (Eqs 5.32-5.37) and stability line (5.36)")
    for k in ("Jl", "ts", "taul", "w0"):
        q.add_argument(f"--{k}", type=float, required=True, help=_help(f"--{k}"))
    q.add_argument("--btotal", type=float, default=None, help=_help("--btotal", "default: Eq 5.38 from --P"))
    q.add_argument("--P", type=float, default=None, help=_help("--P", "for Eq 5.38"))
    add_common(q)
    q.set_defaults(func=partial(gains_cmd, emit))

    # -- run / efficiency ----------------------------------------------------------------------------------------
    q = dsub.add_parser("run", help="simulate a drive scene: cycle statistics, energy balance, lock events")
    q.add_argument("scene", help=SCENE_HELP)
    q.add_argument("--engine", choices=["reference", "mujoco"])
    q.add_argument("--duration", type=float)
    add_scene_options(q)
    add_error_estimate(q)
    add_study_options(q)
    add_common(q)
    q.set_defaults(func=partial(run_cmd, emit))

    q = dsub.add_parser("efficiency", help="open-loop efficiency vs steady load speed over load torques")
    q.add_argument("scene", help=SCENE_HELP)
    q.add_argument("--loads", type=_floats("--loads"), default=None, help="comma list of load torques (N m)")
    q.add_argument("--engine", choices=["reference", "mujoco"])
    q.add_argument("--duration", type=float)
    add_scene_options(q)
    add_error_estimate(q)
    add_study_options(q)
    add_common(q)
    q.set_defaults(func=partial(efficiency_cmd, emit))
    return "drive"


# ---- the commands (each takes the top-level `emit` and the parsed arguments) -----------------------------------------
def design_tables_cmd(emit, a: argparse.Namespace) -> None:
    """`drive design tables`: Tables 5.2 and 6.2 and the controller gains (`analysis.design_tables`)."""
    from .analysis import design_tables

    emit(design_tables(), a, None)


def _inputs(a: argparse.Namespace, *flags: str) -> dict:
    """The values of a design command's options as given (None: not given), by flag: the `inputs` of its
    summary.json, what reruns it."""
    return {flag: getattr(a, flag[2:].replace("-", "_"), None) for flag in flags}


def srmin_cmd(emit, a: argparse.Namespace) -> None:
    """`drive design srmin`: Eq 5.1."""
    from ...results import Report
    from . import design as D

    flags = ("--P", "--wmin", "--wrip", "--Jl")
    _check_options(a, *flags)
    v = D.srmin(a.P, a.wmin, a.wrip, a.Jl)
    items = [("P", "drive power", a.P, "W"), ("w_min", "lowest load speed", a.wmin, "rad/s"),
             ("w_rip", "allowed speed ripple", a.wrip, "rad/s"), ("J_l", "load inertia", a.Jl, "kg m^2"),
             ("Sr_min", "minimum switching rate (Eq 5.1)", v, "1/s")]
    emit(Report({"inputs": _inputs(a, *flags), "Sr_min": v}, _quantity_table(items),
                _csv_writer("srmin", [(k, u, [x]) for k, _, x, u in items])), a, None)


def cadjs_cmd(emit, a: argparse.Namespace) -> None:
    """`drive design cadjs`: the CADJS families (Eqs 5.9-5.13 corrected), or one read at --tau-c."""
    from ...results import Report, format_table
    from . import design as D
    from .design_scene import scene_toml
    from .plots import cadjs_figure

    flags = ("--P", "--srmin", "--wmin", "--wmax", "--vm", "--js", "--tau-c", "--wop", "--Jl", "--taul", "--pmotor",
             "--scene-duration")
    _check_options(a, *flags)
    _check_speed_range(a.wmin, a.wmax)
    scene = _design_scene(a) if a.scene_out else None
    rows, data = [], []
    for sr in a.srmin:
        ds_ = ([D.at_clutch_torque(a.P, sr, a.wmin, a.wmax, a.vm, a.tau_c)] if a.tau_c
               else D.cadjs(a.P, sr, a.wmin, a.wmax, a.vm, a.js))
        for d in ds_:
            rows.append([sr, d.J_s, d.K, d.tau_c, d.x_max, d.Sr_max, d.capacity])
            data.append({"Sr_min": sr, "J_s": d.J_s, "K": d.K, "tau_c": d.tau_c, "x_max": d.x_max,
                         "Sr_max": d.Sr_max, "capacity": d.capacity})
    units = ["1/s", "kg m^2", "N m/rad", "N m", "rad", "1/s", "J"]
    names = ["Sr_min", "J_s", "K", "tau_c", "x_max", "Sr_max", "capacity"]
    table = format_table([f"{n} [{u}]" for n, u in zip(names, units, strict=True)], rows, ".4g")
    table += "\n" + textwrap.fill(
        "Sr_min/Sr_max: lowest/highest switching rate; J_s: spring-system inertia; K: spring rate; tau_c: clutch "
        "torque; x_max: largest spring twist; capacity: spring energy 1/2 K x_max^2 (Eqs 5.9-5.13 corrected).", 100)
    fig = partial(cadjs_figure, data) if len(data) > len(a.srmin) else None
    cols = [(n, u, [r[i] for r in rows]) for i, (n, u) in enumerate(zip(names, units, strict=True))]
    inputs = _inputs(a, *flags, "--base", "--scene-out") if a.scene_out else _inputs(a, *flags[:7])
    if scene is not None:
        Path(a.scene_out).write_text(scene_toml(scene), encoding="utf-8")
        d = scene["design"]["derived"]
        msg = (f"wrote {a.scene_out}: the design at J_s = {d['J_s']:.4g} kg m^2 as a step-up/step-down scene, "
               f"closed loop at {d['w_op']:g} rad/s against tau_l = {d['tau_l']:.4g} N m (Sr = {d['Sr_op']:.4g} /s "
               f"there: K_p = {d['Kp']:.4g}, K_I = {d['Ki']:.4g}); run it: mbsuite drive run {a.scene_out}")
        table += "\n\n" + textwrap.fill(msg, 100, break_on_hyphens=False, break_long_words=False)
    emit(Report({"inputs": inputs, "designs": data, **({"scene_file": a.scene_out} if scene else {})}, table,
                _csv_writer("cadjs", cols, fig)), a, scene)


def _design_scene(a: argparse.Namespace) -> dict:
    """The scene of `drive design cadjs ... --scene-out FILE` (checked before any file is written): one design point,
    at --tau-c or at a single --js (`design_scene.design_scene`)."""
    from ...scenes import scene_from_dict
    from .design_scene import DesignInputs, design_scene

    if len(a.srmin) != 1:
        raise MbsuiteError(f"--scene-out writes one design: give one --srmin, got {len(a.srmin)} ({a.srmin})")
    if (a.tau_c is None) == (a.js is None or len(a.js) != 1):
        raise MbsuiteError("--scene-out writes one design point: give --tau-c, or a single --js (got "
                           f"--tau-c {a.tau_c}, --js {a.js})")
    if a.wop is not None and not a.wmin <= a.wop <= a.wmax:
        raise MbsuiteError(f"--wop {a.wop:g} rad/s must lie in the design's speed band [--wmin, --wmax] = "
                           f"[{a.wmin:g}, {a.wmax:g}] rad/s")
    out = Path(a.scene_out)
    if out.suffix != ".toml":
        raise MbsuiteError(f"--scene-out {a.scene_out}: a scene file ends in .toml")
    try:  # made like --out's directory
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MbsuiteError(f"--scene-out {a.scene_out}: directory {out.parent} cannot be made ({exc.strerror or exc})"
                           ) from None
    inp = DesignInputs(P=a.P, Sr_min=a.srmin[0], w_min=a.wmin, w_max=a.wmax, V_m=a.vm, tau_c=a.tau_c,
                       J_s=a.js[0] if a.tau_c is None else None, J_l=a.Jl, w_op=a.wop, tau_l=a.taul,
                       P_motor=a.pmotor, base=a.base, duration=a.scene_duration)
    scene = design_scene(inp, name=out.stem)
    scene_from_dict(scene, source=str(out))  # the loader accepts it (a SceneError here, not when run)
    return scene


def springsz_cmd(emit, a: argparse.Namespace) -> None:
    """`drive design springsz`: SPRINGSZ (Eqs 5.14-5.21)."""
    from ...results import Report
    from . import design as D

    if a.sigma_uts is None:
        a.sigma_uts = D.SIGMA_UTS_CALIBRATED
    if a.E is None:
        a.E = D.E_TABLE_6_3
    _check_options(a, "--K", "--xmax", "--fatigue", "--sigma-uts", "--E")
    r = dict(D.springsz(a.K, a.xmax, a.fatigue, sigma_uts=a.sigma_uts, E=a.E))
    items = [("K", "spring rate", a.K, "N m/rad"), ("x_max", "largest twist", a.xmax, "rad"),
             ("fatigue", "allowed / ultimate tensile stress", a.fatigue, "1"),
             ("sigma_uts", "ultimate tensile stress", a.sigma_uts, "Pa"), ("E", "Young's modulus", a.E, "Pa"),
             ("d", "wire diameter (Eq 5.21)", r["d"], "m"),
             ("DN", "coil diameter x number of turns (Eq 5.14)", r["DN"], "m"),
             ("V", "spring volume (Eq 5.19)", r["V"], "m^3"),
             ("V_check", "pi^2 DN d^2 (same volume from d, DN)", r["V_check"], "m^3")]
    emit(Report({"inputs": _inputs(a, "--K", "--xmax", "--fatigue", "--sigma-uts", "--E"), **r},
                _quantity_table(items), _csv_writer("springsz", [(k, u, [x]) for k, _, x, u in items])),
         a, None)


def gains_cmd(emit, a: argparse.Namespace) -> None:
    """`drive design gains`: gain selection (Eqs 5.32-5.37), closed-loop poles and the stability line (5.36)."""
    from ...results import Report
    from . import design as D

    _check_options(a, "--Jl", "--ts", "--taul", "--w0", "--btotal", "--P")
    inputs = _inputs(a, "--Jl", "--ts", "--taul", "--w0", "--btotal", "--P")
    if a.btotal is None:
        if a.P is None:
            raise SceneError("give --btotal or --P (Eq 5.38)")
        a.btotal = D.b_total(a.P, a.w0, a.taul)
    kp, ki = D.gains(a.Jl, a.ts, a.btotal, a.taul, a.w0)
    poles = D.closed_loop_poles(kp, ki, a.Jl, a.ts, a.btotal, a.taul, a.w0)
    kp_crit = D.stability_kp(ki, a.Jl, a.ts, a.btotal, a.taul, a.w0)
    data = {"inputs": inputs, "B_total": a.btotal, "Kp": kp, "KI": ki, "poles": [complex(x).real for x in poles],
            "Kp_stability_line": kp_crit}
    items = [("J_l", "load inertia", a.Jl, "kg m^2"), ("t_s", "energy-cycle period", a.ts, "s"),
             ("tau_l", "load torque", a.taul, "N m"), ("w0", "operating speed", a.w0, "rad/s"),
             ("B_total", "total viscous coefficient (Eq 5.38 if not given)", a.btotal, "N m s"),
             ("Kp", "proportional gain (Eqs 5.32-5.37)", kp, "kg m^2"),
             ("KI", "integral gain", ki, "kg m^2/s")]
    items += [(f"pole_{i + 1}", "closed-loop pole in z (real part)", float(x), "1")
              for i, x in enumerate(data["poles"])]
    items += [("Kp_stability_line", "K_p on the stability line (Eq 5.36)", kp_crit, "kg m^2")]
    emit(Report(data, _quantity_table(items), _csv_writer("gains", [(k, u, [x]) for k, _, x, u in items])),
         a, None)


def run_cmd(emit, a: argparse.Namespace) -> None:
    """`drive run`: a scene on its path with cycle statistics, energy balance and lock events (`run_of`); with
    `--vary` a study of them over a grid (`mbsuite.cli.study`)."""
    a.emit = emit
    run_or_study(a, _scene(a), f"{__name__}:run_of", units=STUDY_UNITS)


def run_of(sc, a: argparse.Namespace) -> Report:
    """The report of `drive run` on scene `sc` (the command's, or a study point's): health figures judged as by
    `mbsuite.run` (with `--error-estimate` the estimated error of every headline, `accuracy.py`)."""
    import numpy as np

    from ...analysis.errorestimate import error_estimate
    from ...results import Report
    from . import accuracy
    from .analysis import simulate_scene
    from .plots import loss_label
    from .scene_run import sim_result

    t0 = time.perf_counter()
    res = sim_result(sc, *simulate_scene(sc))
    took = time.perf_counter() - t0
    what = f"drives scene {sc.name or sc.source or ''}".strip()
    res.warnings.extend(judge(res.health, allow_inaccurate=sc.solver.allow_inaccurate, what=what))
    inaccurate = []
    if a.error_estimate:  # an estimate above its tolerance keeps the report, flagged (exit 3) unless allowed
        res.error_estimate = error_estimate(sc, base=accuracy.values(sc, res), base_seconds=took)
        res.health.extend(res.error_estimate.figures())
        inaccurate = judge_estimate(res.error_estimate.figures(), allow_inaccurate=sc.solver.allow_inaccurate,
                                    what=what)
        res.warnings.extend(inaccurate)
    eb = res.stats["energy_balance"]
    cyc = res.statistics
    rows = [["engine", "path that ran", res.engine, ""], ["duration", "simulated time", float(res.t[-1]), "s"],
            ["events", "clutch/brake mode changes", len(res.events), ""]]
    rows += [[k, *CYCLE_QUANTITIES.get(k, (k, ""))[:1], v, CYCLE_QUANTITIES.get(k, (k, ""))[1]]
             for k, v in cyc.items()]
    rows += [["E_in", "input energy", eb["input"], "J"], ["E_out", "output energy", eb["output"], "J"],
             ["stored", "change of stored energy", eb["stored"], "J"],
             ["balance", "energy residual / turnover", eb["relative"], "1"]]
    rows += [[f"loss_{k}", loss_label(k), v, "J"] for k, v in eb["losses"].items()]
    table = _quantity_table([(k, m, float(v) if isinstance(v, float | np.floating) else str(v), u)
                             for k, m, v, u in rows])
    if res.error_estimate is not None:
        table += "\n\n" + res.error_estimate.table()
    if res.warnings:
        table += "\n\n" + "\n".join(res.warnings)
    summary = {k: v for k, v in res.summary().items() if k not in ("stats", "statistics", "input", "solver")}  # once
    rep = Report({"options": _options(a), "summary": summary, "statistics": res.statistics, "stats": res.stats},
                 table, partial(_write_run, res))
    if inaccurate and not sc.solver.allow_inaccurate:
        raise InaccurateResult(inaccurate, rep)
    return rep


def _write_run(res, out: Path) -> list[Path]:
    """The files of `drive run --out`: the time series (run.csv, as `mbsuite run --out`) and the run figure."""
    from ...plotting import save
    from .plots import run_figure

    return [res.write_csv(Path(out) / "run.csv"), save(run_figure(res), Path(out) / "run.png")]


def efficiency_cmd(emit, a: argparse.Namespace) -> None:
    """`drive efficiency`: open-loop efficiency over load torques (`efficiency_of`); with `--vary` a study."""
    _check_options(a, "--loads")
    a.emit = emit
    run_or_study(a, _scene(a), f"{__name__}:efficiency_of", units=STUDY_UNITS)


def efficiency_of(sc, a: argparse.Namespace) -> Report:
    """The report of `drive efficiency` on scene `sc` (`analysis.efficiency`)."""
    import numpy as np

    from .analysis import efficiency

    loads = a.loads if a.loads is not None else list(np.round(np.linspace(0.0, 0.3, 7), 4))
    try:
        rep = efficiency(sc, loads, engine=a.engine, error_estimate=a.error_estimate)
    except InaccurateResult as exc:  # kept, flagged: the command prints it and exits 3
        exc.result.data = {"options": _options(a), **exc.result.data}
        raise
    rep.data = {"options": _options(a), **rep.data}
    return rep


def _options(a: argparse.Namespace) -> dict:
    """The options of a scene command as given (`--loads`, `--engine`, `--duration`,
    `--error-estimate`, `--allow-inaccurate`, `--max-steps`; None: not given): with the scene, what reruns it."""
    return {flag: getattr(a, flag[2:].replace("-", "_")) for flag in (
        "--loads", "--engine", "--duration", "--error-estimate", "--allow-inaccurate",
        "--max-steps") if hasattr(a, flag[2:].replace("-", "_"))}


def _scene(a: argparse.Namespace):
    _check_options(a, "--duration")
    sc = scene_of(a.scene)  # a TOML, model/scene, or the summary.json of an earlier run (the scene it ran)
    if sc.model != "drives":
        raise SceneError(f"scene {a.scene!r} is a '{sc.model}' scene, not a drives scene")
    upd = {}
    if getattr(a, "engine", None):
        upd["engine"] = a.engine
    if getattr(a, "duration", None) is not None:
        upd["duration"] = a.duration
        if sc.solver.t_settle >= a.duration:
            upd["t_settle"] = 0.5 * a.duration
    # the scene's solver checks duration / timestep against solver.max_steps (the size guard), in one replace with
    # --max-steps
    return _solver_options(sc, a, upd)


def _solver_options(sc, a: argparse.Namespace, upd: dict | None = None):
    """The scene with the solver overrides `upd` and `--allow-inaccurate`, `--max-steps` applied (one replace, so
    the size guard sees the new duration and the new max_steps together; `mbsuite.cli.options.add_scene_options`)."""
    upd = dict(upd or {})
    if getattr(a, "allow_inaccurate", False):
        upd["allow_inaccurate"] = True
    if getattr(a, "max_steps", None) is not None:
        upd["max_steps"] = a.max_steps
    return sc.replace(solver=upd) if upd else sc
