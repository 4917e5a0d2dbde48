"""`mbsuite drive ...`: design tools, scene runs with cycle statistics, efficiency sweeps, CoupledClutches check."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ...errors import MbsuiteError, SceneError
from ...limits import Limit
from ...results import Report, format_table
from ...scenes import DEFAULT_MAX_STEPS, load_scene
from . import design as D

#: most time steps of `drive coupled-clutches` (scene runs are guarded by the scene's solver.max_steps)
MAX_STEPS = DEFAULT_MAX_STEPS
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
    "--timestep": Limit(**_POS, hi=1e-2, unit="s", doc="MuJoCo timestep"),
}


def _floats(text: str) -> list[float]:
    try:
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError as exc:
        raise SceneError(f"expected a comma-separated list of numbers, got {text!r}") from exc


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


def _check_steps(flag: str, duration: float, dt: float) -> None:
    """Size guard: duration / dt time steps (or samples) at most MAX_STEPS."""
    n = duration / dt
    if n > MAX_STEPS:
        raise MbsuiteError(f"{flag}: {duration:g} s at a step of {dt:g} s is {n:.3g} steps; at most {MAX_STEPS:.3g} "
                           "(shorten the run or enlarge the step)")


def register(sub, add_common, emit) -> None:
    p = sub.add_parser("drive", help="switched-mode drives: design tools, runs, efficiency, CoupledClutches")
    dsub = p.add_subparsers(dest="drive_command", required=True)

    # -- design --------------------------------------------------------------------------------------------------
    pd = dsub.add_parser("design", help="Chapter 5 design tools")
    ds = pd.add_subparsers(dest="design_command", required=True)

    q = ds.add_parser("tables", help="reproduce Tables 5.2 and 6.2 and the controller gains")
    add_common(q)
    q.set_defaults(func=lambda a: emit(__import__(f"{__package__}.analysis", fromlist=["x"]).design_tables(), a, None))

    q = ds.add_parser("srmin", help="Eq 5.1: minimum switching rate")
    for k in ("P", "wmin", "wrip", "Jl"):
        q.add_argument(f"--{k}", type=float, required=True)
    add_common(q)

    def _srmin(a):
        _check_options(a, "--P", "--wmin", "--wrip", "--Jl")
        v = D.srmin(a.P, a.wmin, a.wrip, a.Jl)
        emit(Report({"Sr_min": v}, f"Sr_min = {v:.6g} cycles/s"), a, None)

    q.set_defaults(func=_srmin)

    q = ds.add_parser("cadjs", help="CADJS: K, clutch torque, x_max, Sr_max per J_s (Eqs 5.9-5.13 corrected)")
    q.add_argument("--P", type=float, required=True)
    q.add_argument("--srmin", type=_floats, required=True, help="comma list")
    q.add_argument("--wmin", type=float, default=0.0)
    q.add_argument("--wmax", type=float, required=True)
    q.add_argument("--vm", type=float, required=True)
    q.add_argument("--js", type=_floats, default=None, help="comma list (default 1e-5 ... 1e-4)")
    q.add_argument("--tau-c", type=float, default=None, help="read the family at this clutch torque")
    add_common(q)

    def _cadjs(a):
        _check_options(a, "--P", "--srmin", "--wmin", "--wmax", "--vm", "--js", "--tau-c")
        rows, data = [], []
        for sr in a.srmin:
            ds_ = ([D.at_clutch_torque(a.P, sr, a.wmin, a.wmax, a.vm, a.tau_c)] if a.tau_c
                   else D.cadjs(a.P, sr, a.wmin, a.wmax, a.vm, a.js))
            for d in ds_:
                rows.append([sr, d.J_s, d.K, d.tau_c, d.x_max, d.Sr_max, d.capacity])
                data.append({"Sr_min": sr, "J_s": d.J_s, "K": d.K, "tau_c": d.tau_c, "x_max": d.x_max,
                             "Sr_max": d.Sr_max, "capacity": d.capacity})
        emit(Report({"designs": data}, format_table(["Sr_min", "J_s", "K", "tau_c", "x_max", "Sr_max", "capacity_J"],
                                                    rows, ".4g")), a, None)

    q.set_defaults(func=_cadjs)

    q = ds.add_parser("springsz", help="SPRINGSZ: wire diameter, D*N and volume (Eqs 5.14-5.21)")
    q.add_argument("--K", type=float, required=True)
    q.add_argument("--xmax", type=float, required=True)
    q.add_argument("--fatigue", type=float, default=0.25)
    q.add_argument("--sigma-uts", type=float, default=D.SIGMA_UTS_CALIBRATED,
                   help="ultimate tensile stress, Pa (default: calibrated to the thesis' 1.58e-4 m^3, not a material)")
    q.add_argument("--E", type=float, default=D.E_TABLE_6_3, help="Young's modulus, Pa (default: implied by Table 6.3)")
    add_common(q)

    def _spr(a):
        _check_options(a, "--K", "--xmax", "--fatigue", "--sigma-uts", "--E")
        r = D.springsz(a.K, a.xmax, a.fatigue, sigma_uts=a.sigma_uts, E=a.E)
        emit(Report(r, format_table(list(r), [list(r.values())], ".4g")), a, None)

    q.set_defaults(func=_spr)

    q = ds.add_parser("gains", help="gain selection (Eqs 5.32-5.37) and stability line (5.36)")
    for k in ("Jl", "ts", "taul", "w0"):
        q.add_argument(f"--{k}", type=float, required=True)
    q.add_argument("--btotal", type=float, default=None, help="default: Eq 5.38 from --P")
    q.add_argument("--P", type=float, default=None)
    add_common(q)

    def _gains(a):
        _check_options(a, "--Jl", "--ts", "--taul", "--w0", "--btotal", "--P")
        if a.btotal is None:
            if a.P is None:
                raise SceneError("give --btotal or --P (Eq 5.38)")
            a.btotal = D.b_total(a.P, a.w0, a.taul)
        kp, ki = D.gains(a.Jl, a.ts, a.btotal, a.taul, a.w0)
        poles = D.closed_loop_poles(kp, ki, a.Jl, a.ts, a.btotal, a.taul, a.w0)
        kp_crit = D.stability_kp(ki, a.Jl, a.ts, a.btotal, a.taul, a.w0)
        data = {"B_total": a.btotal, "Kp": kp, "KI": ki, "poles": [complex(x).real for x in poles],
                "Kp_stability_line": kp_crit}
        emit(Report(data, format_table(list(data), [[str(v) for v in data.values()]])), a, None)

    q.set_defaults(func=_gains)

    # -- run / efficiency ----------------------------------------------------------------------------------------
    q = dsub.add_parser("run", help="simulate a drive scene: cycle statistics, energy balance, lock events")
    q.add_argument("scene", help="scene TOML, or drives/<scene>")
    q.add_argument("--engine", choices=["reference", "mujoco"])
    q.add_argument("--duration", type=float)
    add_common(q)

    def _run(a):
        sc = _scene(a)
        res = sc.spec.run(sc)
        eb = res.stats["energy_balance"]
        cyc = res.stats.get("cycles", {})
        rows = [["engine", res.engine], ["duration_s", float(res.t[-1])], ["events", len(res.events)]]
        rows += [[k, v] for k, v in cyc.items()]
        rows += [["E_in_J", eb["input"]], ["E_out_J", eb["output"]], ["stored_J", eb["stored"]],
                 ["balance_residual_rel", eb["relative"]]] + [[f"loss_{k}_J", v] for k, v in eb["losses"].items()]
        rep = Report({"summary": res.summary(), "stats": res.stats}, format_table(["quantity", "value"], rows),
                     lambda out: [res.write_csv(Path(out) / "timeseries.csv")])
        emit(rep, a, sc.to_dict())

    q.set_defaults(func=_run)

    q = dsub.add_parser("efficiency", help="open-loop efficiency vs steady load speed over load torques")
    q.add_argument("scene")
    q.add_argument("--loads", type=_floats, default=None, help="comma list of load torques (N m)")
    q.add_argument("--engine", choices=["reference", "mujoco"])
    q.add_argument("--duration", type=float)
    add_common(q)

    def _eff(a):
        from .analysis import efficiency

        _check_options(a, "--loads")
        sc = _scene(a)
        loads = a.loads if a.loads is not None else list(np.round(np.linspace(0.0, 0.3, 7), 4))
        emit(efficiency(sc, loads, engine=a.engine), a, sc.to_dict())

    q.set_defaults(func=_eff)

    q = dsub.add_parser("coupled-clutches", help="Modelica CoupledClutches: both paths vs the Dymola reference")
    q.add_argument("--timestep", type=float, default=1e-4)
    add_common(q)

    def _cc(a):
        from . import coupled_clutches as cc
        from .model import coupled_clutches_table

        _check_options(a, "--timestep")
        _check_steps("--timestep", cc.T_END, a.timestep)
        d = coupled_clutches_table(timestep=a.timestep)
        rows = []
        for i, r in enumerate(d["reference"]["events"]):
            m = d["mujoco"]["events"][i]
            rows.append([r["element"], r["from"], r["to"], r["t_ref"], r["t"], m["t"],
                         None if r["t"] is None else r["t"] - r["t_ref"], None if m["t"] is None else m["t"] - r["t"]])
        t1 = format_table(["clutch", "from", "to", "t_dymola", "t_hand", "t_mujoco", "hand-dymola", "mujoco-hand"],
                          rows, ".10g")
        rows2 = [[g] + list(np.round(wr, 6)) + list(np.round(wh, 6)) + list(np.round(wm, 6)) for g, wr, wh, wm in
                 zip(d["grid"], d["w_ref"], d["reference"]["w"], d["mujoco"]["w"], strict=True)]
        t2 = format_table(["t"] + [f"{s}{k}" for s in ("dym_w", "hand_w", "mj_w") for k in range(1, 5)], rows2, ".6g")
        emit(Report(d, t1 + "\n\n" + t2), a, None)

    q.set_defaults(func=_cc)


def _scene(a: argparse.Namespace):
    _check_options(a, "--duration")
    sc = load_scene(a.scene)
    if sc.model != "drives":
        raise SceneError(f"scene {a.scene!r} is a '{sc.model}' scene, not a drives scene")
    upd = {}
    if getattr(a, "engine", None):
        upd["engine"] = a.engine
    if getattr(a, "duration", None) is not None:
        upd["duration"] = a.duration
        if sc.solver.t_settle >= a.duration:
            upd["t_settle"] = 0.5 * a.duration
    # the scene's solver checks duration / timestep against solver.max_steps (the size guard)
    return sc.replace(solver=upd) if upd else sc
