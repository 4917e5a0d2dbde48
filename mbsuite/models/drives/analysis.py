"""Analyses returning `Report`s: efficiency sweeps (Eqs 3.21-3.24 corrected), path cross-checks, design tables."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ...errors import SceneError
from ...results import Report, format_table, write_csv
from ...scenes import Scene
from . import design as D
from . import drive
from .model import simulate_scene


def steady_window(scene: Scene) -> float:
    return scene.solver.t_settle if scene.solver.t_settle > 0 else 0.5 * scene.solver.duration


def efficiency_point(scene: Scene) -> dict[str, Any]:
    """One open-loop run: averages over t >= t_settle of speeds, input/output power, losses (W), efficiency."""
    res, ctrl, system = simulate_scene(scene)
    t0 = steady_window(scene)
    i0 = int(np.searchsorted(res.t, t0))
    T = res.t[-1] - res.t[i0]
    bal = drive.energy_balance(system, res, i0, -1)
    cs = drive.cycle_stats(res, ctrl, t0=t0) if ctrl is not None else {}
    out = {
        "tau_l": float(scene.build_params().resolved(scene.effects["param_set"])["tau_l"] or 0.0),
        "load_speed": float(np.mean(res.w[2, i0:])),
        "motor_speed": float(np.mean(res.w[0, i0:])),
        "P_in": bal.input / T, "P_out": bal.output / T,
        "efficiency": bal.output / bal.input if bal.input > 0 else float("nan"),
        "losses_W": {k: v / T for k, v in bal.losses.items()},
        "balance_relative": bal.relative,
        "switching_rate": cs.get("switching_rate", float("nan")),
        "max_extension": cs.get("max_extension", float("nan")),
    }
    return out


def efficiency(scene: Scene, loads: list[float], engine: str | None = None) -> Report:
    if scene.effects["mechanism"] == "coupled_clutches":
        raise SceneError("efficiency needs a drive scene (mechanism step_up or step_up_down)")
    if scene.effects.get("closed_loop"):
        raise SceneError("efficiency curves are open-loop runs: use a scene with closed_loop = false")
    pts = []
    for tl in loads:
        if tl < 0:
            raise SceneError(f"load torque must be >= 0, got {tl}")
        sc = scene.replace(params={"tau_l": float(tl)}, solver={"engine": engine} if engine else {})
        pts.append(efficiency_point(sc))
    labels = sorted({k for p in pts for k in p["losses_W"]})
    rows = [[p["tau_l"], p["load_speed"], p["motor_speed"], p["P_in"], p["P_out"], 100 * p["efficiency"],
             p["switching_rate"], p["balance_relative"]] + [p["losses_W"].get(k, 0.0) for k in labels] for p in pts]
    head = ["tau_l", "w_load", "w_motor", "P_in", "P_out", "eff_%", "Sr", "bal_rel"] + labels
    table = format_table(head, rows, ".4g")

    def write(out: Path) -> list[Path]:
        files = [write_csv(out / "efficiency.csv", [(h, "", [r[i] for r in rows]) for i, h in enumerate(head)])]
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(1, 2, figsize=(11, 4))
        sp = [abs(p["load_speed"]) for p in pts]
        ax[0].plot(sp, [100 * p["efficiency"] for p in pts], "o-")
        ax[0].set(xlabel="steady load speed |w_l| (rad/s)", ylabel="efficiency (%)", title=scene.name)
        bottom = np.zeros(len(pts))
        for k in labels:
            v = np.array([p["losses_W"].get(k, 0.0) for p in pts])
            ax[1].bar(range(len(pts)), v, bottom=bottom, label=k)
            bottom += v
        ax[1].set_xticks(range(len(pts)), [f"{s:.0f}" for s in sp], rotation=60)
        ax[1].set(xlabel="load speed (rad/s)", ylabel="loss (W)")
        ax[1].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(out / "efficiency.png", dpi=120)
        plt.close(fig)
        return files + [out / "efficiency.png"]

    return Report({"scene": scene.name, "points": pts}, table, write)


# ---- design tables ---------------------------------------------------------------------------------------------------
TABLE_5_2 = {5: (3.94e-4, 7.52, 11.5, 1.71, 113.07), 10: (2.03e-4, 15.07, 5.88, 3.43, 59.29),
             15: (1.32e-4, 22.63, 3.81, 5.36, 38.90), 20: (1.00e-4, 30.0, 2.86, 7.07, 28.91)}  # L1834-1840
TABLE_6_2 = {10: (7.3e-5, 14.20, 5.09, 0.98), 15: (4.8e-5, 21.20, 3.36, 1.48), 20: (3.5e-5, 28.32, 2.56, 1.95)}


def design_tables() -> Report:
    """Tables 5.2 and 6.2 (the CADJS families read at the chosen clutch torque), gains of Eq 6.1 and Sec. 5.4."""
    rows = []
    data: dict[str, Any] = {"table_5_2": [], "table_6_2": [], "gains": []}
    for sr, th in TABLE_5_2.items():
        d = D.at_clutch_torque(500, sr, 0, 500, 100, 20.0)
        ours = (d.J_s, d.Sr_max, d.x_max, d.K, d.capacity)
        for nm, o, t in zip(("J_s", "Sr_max", "x_max", "K", "capacity"), ours, th, strict=True):
            rows.append(["5.2", sr, nm, o, t, 100 * (o / t - 1)])
            data["table_5_2"].append({"Sr_min": sr, "quantity": nm, "ours": o, "thesis": t})
    for sr, th in TABLE_6_2.items():
        d = D.at_clutch_torque(100, sr, 0, 400, 96, 5.0)
        for nm, o, t in zip(("J_s", "Sr_max", "x_max", "K"), (d.J_s, d.Sr_max, d.x_max, d.K), th, strict=True):
            rows.append(["6.2", sr, nm, o, t, 100 * (o / t - 1)])
            data["table_6_2"].append({"Sr_min": sr, "quantity": nm, "ours": o, "thesis": t})
    kp, ki = D.gains(0.0023, 1 / 14.5, 2.5e-4, 0.15, 400.0)
    _, ki14 = D.gains(0.0023, 1 / 14.0, 2.5e-4, 0.15, 400.0)
    bt = D.b_total(500, 500, 0.8)
    kp5a, ki5 = D.gains(0.005, 1 / 30, bt, 0.8, 500.0)
    kp5b, _ = D.gains(0.005, 1 / 30, bt, 0.8, 50.0)
    for nm, o, t in (("Kp 100W (Sr 14.5)", kp, 0.00112), ("KI 100W (Sr 14.5)", ki, 0.0161),
                     ("KI 100W (Sr 14)", ki14, 0.0161), ("Kp 500W @500", kp5a, 0.00246),
                     ("Kp 500W @50", kp5b, 0.00222), ("KI 500W", ki5, 0.075)):
        rows.append(["gains", "", nm, o, t, 100 * (o / t - 1)])
        data["gains"].append({"quantity": nm, "ours": o, "thesis": t})
    table = format_table(["table", "Sr_min", "quantity", "ours", "thesis", "diff_%"], rows, ".4g")
    return Report(data, table)
