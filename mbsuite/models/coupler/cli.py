"""`mbsuite coupler jacobian | fpp | criteria | dynamics` (JSON with --json, files with --out)."""

from __future__ import annotations

import argparse
import math
import warnings
from pathlib import Path

import numpy as np

from ...errors import ParameterError
from ...results import Report, format_table
from ...scenes import load_scene
from . import analysis
from .params import GAMMA_17DEG, CouplerParams


def mbsuite_run(scene):
    """`mbsuite.run` (imported late: the package imports this module's model while it loads)."""
    from ... import run

    return run(scene)


def _finite(name: str):
    def conv(s: str) -> float:
        try:
            v = float(s)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number, got {s!r}") from None
        if not math.isfinite(v):
            raise argparse.ArgumentTypeError(f"{name} must be finite, got {s!r}")
        return v

    return conv


def _geometry_args(p: argparse.ArgumentParser, ey_default: float) -> None:
    p.add_argument("--gamma", type=_finite("--gamma"), default=GAMMA_17DEG,
                   help="platform proportion angle [rad] (default 17 deg = 0.29671, reproduces Eq 15)")
    p.add_argument("--ey", type=_finite("--ey"), default=ey_default, help="axial shift e_y [R]")
    p.add_argument("--R", type=_finite("--R"), default=1.0, help="joint-circle radius (default 1)")


def _params(args: argparse.Namespace) -> CouplerParams:
    return CouplerParams(gamma=args.gamma, e_y=args.ey, R=args.R)


def _cmd_jacobian(emit):
    def run(args: argparse.Namespace) -> None:
        p = _params(args)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", analysis.SingularityWarning)
            rep = analysis.jacobian_report(p, args.phi_a, args.alpha_bx, args.alpha_bz, args.engine)
        msgs = [str(w.message) for w in caught if issubclass(w.category, analysis.SingularityWarning)]
        if msgs:
            rep.data["warnings"] = msgs
            rep.table = "WARNING: " + "\nWARNING: ".join(msgs) + "\n" + rep.table
        emit(rep, args, None)

    return run


#: default size guard of `coupler fpp`: samples per revolution (about 0.2 ms each; 1e5 take ~20 s); --max-n raises it
FPP_MAX_N = 100_000


def _count(name: str):
    def conv(s: str) -> int:
        try:
            v = float(s)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number, got {s!r}") from None
        if not math.isfinite(v) or v != int(v):
            raise argparse.ArgumentTypeError(f"{name} must be a whole number, got {s!r}")
        return int(v)

    return conv


def _cmd_fpp(emit):
    def run(args: argparse.Namespace) -> None:
        if not 3 <= args.n <= args.max_n:
            raise ParameterError(f"--n = {args.n} is invalid; valid: integer in [3, {args.max_n}] (the size guard "
                                 f"--max-n, default {FPP_MAX_N}; each sample is one FPP solve, ~0.2 ms)")
        emit(analysis.fpp_report(_params(args), args.alpha_bx, args.alpha_bz, args.n, args.engine), args, None)

    return run


def _cmd_criteria(emit):
    def run(args: argparse.Namespace) -> None:
        if args.quick:
            rep = analysis.criteria_report(gammas=(0.297,), eys=(0.1,), alphas=(0.0, 0.035, 0.07), zcs=(0.0, 0.05),
                                           lbs=(2.0,), n=61)
        else:
            rep = analysis.criteria_report()
        emit(rep, args, None)

    return run


def _cmd_dynamics(emit):
    def run(args: argparse.Namespace) -> None:
        scene = load_scene(args.scene)
        if args.engine:
            scene = scene.replace(solver={"engine": args.engine})
        res = mbsuite_run(scene)  # health figures judged (AccuracyError past a bound unless allowed)
        st = res.stats
        inputs = {k: v for k, v in scene.input.items()}  # resolved: declared defaults filled in by the scene loader
        table = ("input (resolved, defaults included): "
                 + ", ".join(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}" for k, v in inputs.items())
                 + "\n")
        rows = [[k, v] for k, v in st.items() if isinstance(v, int | float)]
        table += format_table(["quantity", "value"], rows, ".6g")
        if res.health:
            table += "\nhealth: " + ", ".join(f"{f.name} {f.value:.3g} {f.unit} (bound {f.bound:.3g})"
                                              for f in res.health)
        if st.get("warnings"):
            table += f"\nMuJoCo warnings: {st['warnings']}"
        if "link_force_mean" in st:
            table += "\nmean link forces (tension > 0) [N]: " + np.array2string(np.array(st["link_force_mean"]),
                                                                              precision=1)

        def write(out: Path) -> list[Path]:
            return [res.write_csv(out / "timeseries.csv")]

        emit(Report({"input": inputs, "scene": scene.to_dict(), "stats": st, "summary": res.summary()}, table, write),
             args, scene.to_dict())

    return run


def register(sub, add_common, emit) -> None:
    g = sub.add_parser("coupler", help="4-link coupler kinematics (Jacobian, FPP, criteria) and dynamics")
    gs = g.add_subparsers(dest="coupler_command", required=True)

    p = gs.add_parser("jacobian", help="mechanism Jacobian, singular values, rank, condition number, screws")
    _geometry_args(p, 0.0)
    p.add_argument("--phi-a", type=_finite("--phi-a"), default=0.0, help="input angle [rad]")
    p.add_argument("--alpha-bx", type=_finite("--alpha-bx"), default=0.0, help="inclination about x [rad]")
    p.add_argument("--alpha-bz", type=_finite("--alpha-bz"), default=0.0, help="inclination about z [rad]")
    p.add_argument("--engine", choices=["reference", "pinocchio"], default="reference")
    add_common(p)
    p.set_defaults(func=_cmd_jacobian(emit))

    p = gs.add_parser("fpp", help="single-coupler pose over one revolution of phi_a (continuation)")
    _geometry_args(p, 0.1)
    p.add_argument("--alpha-bx", type=_finite("--alpha-bx"), default=0.0525, help="inclination about x [rad]")
    p.add_argument("--alpha-bz", type=_finite("--alpha-bz"), default=0.0, help="inclination about z [rad]")
    p.add_argument("--n", type=_count("--n"), default=73, help="samples over the revolution (both ends included)")
    p.add_argument("--max-n", type=_count("--max-n"), default=FPP_MAX_N,
                   help=f"size guard: the largest --n accepted (default {FPP_MAX_N})")
    p.add_argument("--engine", choices=["reference", "pinocchio"], default="reference",
                   help="pinocchio: also solve with the URDF model and report the difference")
    add_common(p)
    p.set_defaults(func=_cmd_fpp(emit))

    p = gs.add_parser("criteria", help="c1-c4 (single) and c5 (double) tables; plots (Figs 6-10 style) with --out")
    p.add_argument("--quick", action="store_true", help="a small grid (for a smoke test)")
    add_common(p)
    p.set_defaults(func=_cmd_criteria(emit))

    p = gs.add_parser("dynamics", help="MuJoCo double-coupler run with agreement statistics")
    p.add_argument("scene", nargs="?", default="coupler", help="scene (default: coupler's default scene)")
    p.add_argument("--engine", choices=["mujoco", "reference"], help="override the scene's engine")
    add_common(p)
    p.set_defaults(func=_cmd_dynamics(emit))
