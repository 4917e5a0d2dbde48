"""Analyses of drives scenes: a scene on its path keeping the controller and the rotor system (`simulate_scene`),
efficiency sweeps (Eqs 3.21-3.24 corrected), the CoupledClutches check of both paths, the design tables."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path
from typing import Any

import numpy as np

from ...components.rotational.interfaces import RefResult, RotorSystem
from ...errors import SceneError
from ...results import Report, format_table, write_csv
from ...scenes import Scene
from ...trust.health import InaccurateResult, judge_estimate
from . import design as D
from . import drive, mujoco, reference

#: each path's simulation of a scene, returning (result, controller, rotor system) for the analyses: the runs behind
#: `SPEC.paths` ("reference" = `reference.run`, "mujoco" = `mujoco.run`) before their `SimResult` is assembled
SIMULATE = {"reference": reference.simulate, "mujoco": mujoco.simulate}


def simulate_scene(scene: Scene) -> tuple[RefResult, Any, RotorSystem]:
    """Run a scene on its path (`SIMULATE`); returns (result, controller, rotor system)."""
    return SIMULATE[scene.solver.engine](scene)


def steady_window(scene: Scene) -> float:
    """Start of the averaging window [s]: solver.t_settle, or half the run when it is 0."""
    return scene.solver.t_settle if scene.solver.t_settle > 0 else 0.5 * scene.solver.duration


def efficiency_point(scene: Scene) -> dict[str, Any]:
    """One open-loop run: averages over t >= t_settle of speeds, input/output power, losses (W), efficiency."""
    return _efficiency_point(scene, *simulate_scene(scene))


def _efficiency_point(scene: Scene, res: RefResult, ctrl: Any, system: RotorSystem) -> dict[str, Any]:
    """`efficiency_point` of a run already made."""
    t0 = steady_window(scene)
    i0 = int(np.searchsorted(res.t, t0 - drive.T0_TOL))  # the window of `drive.mean_speeds`
    T = res.t[-1] - res.t[i0]
    bal = drive.energy_balance(system, res, i0, -1)
    cs = drive.cycle_stats(res, ctrl, t0=t0) if ctrl is not None else {}
    means = drive.mean_speeds(res, t0)
    out = {
        "tau_l": float(scene.build_params().resolved()["tau_l"] or 0.0),
        "load_speed": means.get("mean_load_speed", float("nan")),
        "motor_speed": means.get("mean_motor_speed", float("nan")),
        "P_in": bal.input / T, "P_out": bal.output / T,
        "efficiency": bal.output / bal.input if bal.input > 0 else float("nan"),
        "losses_W": {k: v / T for k, v in bal.losses.items()},
        "balance_relative": bal.relative,
        "switching_rate": cs.get("switching_rate", float("nan")),
        "max_extension": cs.get("max_extension", float("nan")),
    }
    return out


#: short column names of the loss terms in the CLI table (the figure and the CSV use `plots.LOSS_LABELS` / the keys)
LOSS_SHORT = {"viscous_motor": "visc_m", "viscous_spring": "visc_s", "viscous_load": "visc_l",
              "motor_bearing": "coul_m", "spring_bearing": "coul_s", "load_bearing": "coul_l", "brake": "brake",
              "clutch": "clutch", "clutch_a": "clutch_a", "clutch_b": "clutch_b", "lock_impact": "lockup"}
#: columns of the efficiency table and CSV: (key of an efficiency point, CSV name, unit, table header, factor)
EFF_COLUMNS = (("tau_l", "tau_l", "N m", "tau_l [N m]", 1.0), ("load_speed", "w_load", "rad/s", "w_l [rad/s]", 1.0),
               ("motor_speed", "w_motor", "rad/s", "w_m [rad/s]", 1.0), ("P_in", "P_in", "W", "P_in [W]", 1.0),
               ("P_out", "P_out", "W", "P_out [W]", 1.0), ("efficiency", "efficiency", "%", "eta [%]", 100.0),
               ("switching_rate", "Sr", "1/s", "Sr [1/s]", 1.0),
               ("balance_relative", "balance_residual", "1", "balance [-]", 1.0))


#: the headlines (`accuracy.py`) of an efficiency curve's point: its count of events, cycle-mean speeds, efficiency
EFFICIENCY_HEADLINES = ("n_events", "mean_load_speed", "mean_motor_speed", "efficiency")


def efficiency_values(scene_d: dict) -> dict[str, float]:
    """The efficiency-curve headlines of one run of the scene `scene_d` (a `Scene.to_dict()`; module-level: the
    refined copies of `efficiency(..., error_estimate=True)` run it in worker processes)."""
    from ...scenes import scene_from_dict

    sc = scene_from_dict(scene_d)
    return _headlines_of(sc, *simulate_scene(sc), EFFICIENCY_HEADLINES)


def _headlines_of(scene: Scene, res: RefResult, ctrl: Any, system: RotorSystem,
                  names: tuple[str, ...] | None = None) -> dict[str, float]:
    """The scene's headline values (`accuracy.values`) of a run already made, all or only `names`."""
    from .accuracy import values
    from .scene_run import sim_result

    v = values(scene, sim_result(scene, res, ctrl, system))
    return {k: x for k, x in v.items() if names is None or k in names}


def estimate_points(scenes: list[Scene], bases: list[dict[str, float]], evaluate, names: tuple[str, ...] | None,
                    workers: int = 0) -> list[Any]:
    """The error estimate (`mbsuite.trust.estimate`) of several runs at once: every run's two refined copies in one
    parallel batch (`workers` local processes, 0 = all cores); `bases` are the runs' own headline values and
    `evaluate(scene_dict)` computes one refined copy's (module-level). Headlines restricted to `names` (None: all)."""
    from ...analysis.errorestimate import level_settings
    from ...analysis.sweep import run_sweep
    from ...trust.estimate import declared, estimate

    refs = [sc.spec.accuracy.refinement(sc) for sc in scenes]
    levels = [[r.refine(sc, k) for k in (0, 1, 2)] for sc, r in zip(scenes, refs, strict=True)]
    jobs = [lv[k].to_dict() for lv in levels for k in (2, 1)]  # the most refined first: the longest runs start first
    out = run_sweep(evaluate, jobs, workers=workers, desc="error estimate", executor="local")
    ests = []
    for i, (sc, ref, lv, base) in enumerate(zip(scenes, refs, levels, bases, strict=True)):
        heads = tuple(h for h in declared(sc) if names is None or h.name in names)
        ests.append(estimate([dict(base), dict(out[2 * i + 1]), dict(out[2 * i])], heads, ref,
                             settings=level_settings(sc, lv)))
    return ests


def efficiency(scene: Scene, loads: list[float], engine: str | None = None, *, error_estimate: bool = False,
               workers: int = 0) -> Report:
    """Open-loop efficiency sweep over load torques (one `efficiency_point` per load): a table of the operating
    points and one of the mean loss powers; `--out` writes efficiency.csv (SI units in the header) and efficiency.png
    (`plots.efficiency_figure`: the curve ordered by load speed, non-switching points apart, losses as sorted bars).

    `error_estimate`: every point also runs refined once and twice (`mbsuite.trust.estimate`; all points' copies in one
    parallel batch) and its efficiency-curve headlines (`EFFICIENCY_HEADLINES`) get an estimated error: a table per
    point and `data["points"][i]["error_estimate"]`; an estimate past its tolerance keeps the report with a warning
    naming the point in `data["warnings"]` and, unless the scene allows inaccurate results, raises `InaccurateResult`
    carrying it (the command line prints it, writes its files and exits 3)."""
    if scene.effects.get("closed_loop"):
        raise SceneError("efficiency curves are open-loop runs: use a scene with closed_loop = false")
    pts, scenes, bases = [], [], []
    for tl in loads:
        if tl < 0:
            raise SceneError(f"load torque must be >= 0, got {tl}")
        sc = scene.replace(params={"tau_l": float(tl)}, solver={"engine": engine} if engine else {})
        run = simulate_scene(sc)
        pts.append(_efficiency_point(sc, *run))
        if error_estimate:
            scenes.append(sc)
            bases.append(_headlines_of(sc, *run, EFFICIENCY_HEADLINES))
    ests = estimate_points(scenes, bases, efficiency_values, EFFICIENCY_HEADLINES, workers) if error_estimate else []
    labels = sorted({k for p in pts for k in p["losses_W"]}, key=lambda k: list(LOSS_SHORT).index(k)
                    if k in LOSS_SHORT else len(LOSS_SHORT))

    rows = [[f * p[k] for k, _, _, _, f in EFF_COLUMNS] for p in pts]
    shown = [[("-" if isinstance(v, float) and math.isnan(v) else v) for v in r] for r in rows]
    table = format_table([c[3] for c in EFF_COLUMNS], shown, ".4g")
    table += "\n" + textwrap.fill(
        "Sr = switching rate (energy cycles per second over t >= t_settle; '-' = no complete cycle: the drive does not "
        "switch, that point is not on the efficiency curve); eta = P_out / P_in; balance = energy residual / turnover.",
        100)
    lrows = [[p["tau_l"]] + [_tidy(p["losses_W"].get(k, 0.0), p["P_in"]) for k in labels] for p in pts]
    table += "\n\nmean loss power [W] by term:\n" + format_table(
        ["tau_l [N m]"] + [LOSS_SHORT.get(k, k) for k in labels], lrows, ".3g")
    from .plots import loss_label

    table += "\n" + textwrap.fill("; ".join(f"{LOSS_SHORT.get(k, k)} = {loss_label(k)}" for k in labels), 100)
    for p, est in zip(pts if error_estimate else [], ests, strict=True):
        p["error_estimate"] = est.to_dict()
        table += f"\n\ntau_l = {p['tau_l']:g} N m: " + est.table()

    def write(out: Path) -> list[Path]:
        from ...plotting import save
        from .plots import efficiency_figure

        cols = [(name, unit, [r[i] for r in rows]) for i, (_, name, unit, _, _) in enumerate(EFF_COLUMNS)]
        cols += [(f"loss_{k}", "W", [p["losses_W"].get(k, 0.0) for p in pts]) for k in labels]
        fig = efficiency_figure(pts, scene.name)
        return [write_csv(out / "efficiency.csv", cols), save(fig, out / "efficiency.png")]

    data: dict[str, Any] = {"scene": scene.name, "points": pts}
    warned = []
    for p, est in zip(pts if error_estimate else [], ests, strict=True):  # past its tolerance: kept, flagged
        warned += judge_estimate(est.figures(), allow_inaccurate=scene.solver.allow_inaccurate,
                                 what=f"drives efficiency {scene.name} at tau_l = {p['tau_l']:g} N m")
    if warned:
        data["warnings"] = warned
        table += "\n\n" + "\n".join(warned)
    rep = Report(data, table, write)
    if warned and not scene.solver.allow_inaccurate:
        raise InaccurateResult(warned, rep)
    return rep


def _tidy(v: float, scale: float) -> float:
    """A loss power for the table: round-off (below 1e-9 of the input power) shown as 0."""
    return 0.0 if abs(v) < 1e-9 * max(abs(scale), 1e-300) else v


# ---- design tables ---------------------------------------------------------------------------------------------------
TABLE_5_2 = {5: (3.94e-4, 7.52, 11.5, 1.71, 113.07), 10: (2.03e-4, 15.07, 5.88, 3.43, 59.29),
             15: (1.32e-4, 22.63, 3.81, 5.36, 38.90), 20: (1.00e-4, 30.0, 2.86, 7.07, 28.91)}  # Sec. 5.4, Table 5.2
#: Table 6.2 (the 100 W design, Sec. 6.2)
TABLE_6_2 = {10: (7.3e-5, 14.20, 5.09, 0.98), 15: (4.8e-5, 21.20, 3.36, 1.48), 20: (3.5e-5, 28.32, 2.56, 1.95)}


#: SI units of the design quantities (K_p, K_I: the energy-packet PI maps a speed-squared error [rad^2/s^2] to an
#: energy packet [J], Eqs 5.32-5.37)
DESIGN_UNITS = {"J_s": "kg m^2", "Sr_max": "1/s", "x_max": "rad", "K": "N m/rad", "capacity": "J", "Kp": "kg m^2",
                "KI": "kg m^2/s"}


def design_tables() -> Report:
    """Tables 5.2 and 6.2 (the CADJS families read at the chosen clutch torque), gains of Eq 6.1 and Sec. 5.4, each
    against the thesis' printed value; `--out` writes design_tables.csv and design_tables.png (relative differences)."""
    rows = []
    data: dict[str, Any] = {"table_5_2": [], "table_6_2": [], "gains": []}
    for sr, th in TABLE_5_2.items():
        d = D.at_clutch_torque(500, sr, 0, 500, 100, 20.0)
        ours = (d.J_s, d.Sr_max, d.x_max, d.K, d.capacity)
        for nm, o, t in zip(("J_s", "Sr_max", "x_max", "K", "capacity"), ours, th, strict=True):
            rows.append(["5.2", sr, nm, DESIGN_UNITS[nm], o, t, 100 * (o / t - 1)])
            data["table_5_2"].append({"Sr_min": sr, "quantity": nm, "unit": DESIGN_UNITS[nm], "ours": o, "thesis": t})
    for sr, th in TABLE_6_2.items():
        d = D.at_clutch_torque(100, sr, 0, 400, 96, 5.0)
        for nm, o, t in zip(("J_s", "Sr_max", "x_max", "K"), (d.J_s, d.Sr_max, d.x_max, d.K), th, strict=True):
            rows.append(["6.2", sr, nm, DESIGN_UNITS[nm], o, t, 100 * (o / t - 1)])
            data["table_6_2"].append({"Sr_min": sr, "quantity": nm, "unit": DESIGN_UNITS[nm], "ours": o, "thesis": t})
    kp, ki = D.gains(0.0023, 1 / 14.5, 2.5e-4, 0.15, 400.0)
    _, ki14 = D.gains(0.0023, 1 / 14.0, 2.5e-4, 0.15, 400.0)
    bt = D.b_total(500, 500, 0.8)
    kp5a, ki5 = D.gains(0.005, 1 / 30, bt, 0.8, 500.0)
    kp5b, _ = D.gains(0.005, 1 / 30, bt, 0.8, 50.0)
    for nm, o, t in (("Kp 100W (Sr 14.5)", kp, 0.00112), ("KI 100W (Sr 14.5)", ki, 0.0161),
                     ("KI 100W (Sr 14)", ki14, 0.0161), ("Kp 500W @500", kp5a, 0.00246),
                     ("Kp 500W @50", kp5b, 0.00222), ("KI 500W", ki5, 0.075)):
        unit = DESIGN_UNITS[nm.split()[0]]
        rows.append(["gains", "", nm, unit, o, t, 100 * (o / t - 1)])
        data["gains"].append({"quantity": nm, "unit": unit, "ours": o, "thesis": t})
    head = ["table", "Sr_min [1/s]", "quantity", "unit", "ours", "thesis", "diff [%]"]
    table = format_table(head, rows, ".4g")

    def write(out: Path) -> list[Path]:
        from ...plotting import save
        from .plots import design_tables_figure

        cols = [("table", "", [r[0] for r in rows]), ("Sr_min", "1/s", [r[1] for r in rows]),
                ("quantity", "", [r[2] for r in rows]), ("unit", "", [r[3] for r in rows]),
                ("ours", "", [r[4] for r in rows]), ("thesis", "", [r[5] for r in rows]),
                ("diff", "%", [r[6] for r in rows])]
        fig = design_tables_figure([{"label": f"Table {r[0]}, Sr_min {r[1]}: {r[2]} [{r[3]}]" if r[1] != ""
                                     else f"{r[2]} [{r[3]}]", "ours": r[4], "thesis": r[5]} for r in rows])
        return [write_csv(out / "design_tables.csv", cols), save(fig, out / "design_tables.png")]

    return Report(data, table + "\n'ours' and 'thesis' are in the unit of the row.", write)


