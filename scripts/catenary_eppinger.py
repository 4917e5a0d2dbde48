"""The Eppinger (Brecknell-Willis) pantograph under the EN 50318 reference catenary (issue #6).

1. Speed sweep 100-300 km/h in 25 km/h steps: contact-force statistics and contact loss (count, durations < 5 ms,
   5-20 ms, > 20 ms) of the Eppinger pantograph (hand-derived ODE path and MuJoCo path) beside the 2-mass reference
   pantograph, all on the same catenary (slack droppers). The Eppinger static uplift follows from its supply pressure.
2. Design study at 250 km/h: head mass mh and head suspension stiffness kh vs contact-force sigma.

Writes CSV + PNG per study into --out and prints tables.

    .venv/bin/python scripts/catenary_eppinger.py --out out/catenary_eppinger [--workers 2] [--paths reference mujoco]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.eppinger import EppingerMujoco, EppingerReference
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.pantograph.params import PantographParams
from mbsuite.results import format_table, to_jsonable, write_csv

SPEEDS = [100, 125, 150, 175, 200, 225, 250, 275, 300]
FACTORS = [0.5, 0.75, 1.0, 1.5, 2.0]
KEYS = ["Fm", "sigma", "stat_max", "stat_min", "max", "min", "uplift_mm", "loss_pct"]


def one(job):
    kind, speed, h, dt, overrides = job
    p = dataclasses.replace(CatenaryParams(), element_length=h)
    if kind == "reference2mass":
        panto = "reference2mass"
    elif kind == "eppinger":
        panto = EppingerReference(overrides)
    else:
        panto = EppingerMujoco(overrides, timestep=dt)
    t0 = time.perf_counter()
    run = simulate(p, speed, dt, pantograph=panto)
    c = run.stats["loss_counts"]
    return {"pantograph": kind, "speed": speed, **{k: run.stats[k] for k in KEYS},
            "static_force": run.static_force, "n_loss": len(run.stats["loss_events"]),
            "loss_lt_5ms": c["short_lt_5ms"], "loss_5_20ms": c["damaging_5_20ms"],
            "loss_gt_20ms": c["power_loss_gt_20ms"],
            "overrides": overrides, "wall_s": time.perf_counter() - t0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/catenary_eppinger")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--element-length", type=float, default=0.5)
    ap.add_argument("--timestep", type=float, default=1e-4)
    ap.add_argument("--paths", nargs="+", default=["eppinger", "eppinger_mujoco"],
                    choices=["eppinger", "eppinger_mujoco"])
    ap.add_argument("--study-path", default="eppinger_mujoco", choices=["eppinger", "eppinger_mujoco"])
    ap.add_argument("--speeds", type=int, nargs="+", default=SPEEDS)
    ap.add_argument("--skip-study", action="store_true")
    a = ap.parse_args()
    h, dt = a.element_length, a.timestep
    base = PantographParams()
    jobs = [(k, s, h, dt, {}) for s in a.speeds for k in ["reference2mass", *a.paths]]
    if not a.skip_study:
        jobs += [(a.study_path, 250, h, dt, {"mh": f * base.mh}) for f in FACTORS if f != 1.0]
        jobs += [(a.study_path, 250, h, dt, {"kh": f * base.kh}) for f in FACTORS if f != 1.0]
        if 250 not in a.speeds or a.study_path not in a.paths:
            jobs.append((a.study_path, 250, h, dt, {}))
    t0 = time.perf_counter()
    if a.workers > 1:
        with ProcessPoolExecutor(a.workers) as ex:
            rows = list(ex.map(one, jobs))
    else:
        rows = [one(j) for j in jobs]
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    sweep = [r for r in rows if not r["overrides"]]
    cols = ["pantograph", "speed", "static_force", *KEYS, "n_loss", "loss_lt_5ms", "loss_5_20ms", "loss_gt_20ms",
            "wall_s"]
    print(format_table(cols, [[r[c] if isinstance(r[c], str | int) else f"{r[c]:.2f}" for c in cols] for r in sweep]))
    write_csv(out / "speed_sweep.csv", [(c, "", [r[c] for r in sweep]) for c in cols])
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    for kind in sorted({r["pantograph"] for r in sweep}):
        rs = sorted((r for r in sweep if r["pantograph"] == kind), key=lambda r: r["speed"])
        v = [r["speed"] for r in rs]
        axes[0].plot(v, [r["Fm"] for r in rs], "o-", label=f"{kind} Fm")
        axes[0].plot(v, [r["max"] for r in rs], "^--", label=f"{kind} max")
        axes[0].plot(v, [r["min"] for r in rs], "v--", label=f"{kind} min")
        axes[1].plot(v, [r["sigma"] for r in rs], "o-", label=kind)
        axes[2].plot(v, [r["loss_pct"] for r in rs], "o-", label=kind)
    axes[0].set_ylabel("contact force (N)")
    axes[1].set_ylabel("sigma (N)")
    axes[2].set_ylabel("contact loss (%)")
    for ax in axes:
        ax.set_xlabel("speed (km/h)")
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "speed_sweep.png", dpi=120)
    plt.close(fig)
    result = {"speed_sweep": sweep}
    if not a.skip_study:
        study = [r for r in rows if r["pantograph"] == a.study_path and r["speed"] == 250]
        srows = []
        for name, nominal, unit in (("mh", base.mh, "kg"), ("kh", base.kh, "N m/rad")):
            for r in study:
                ov = r["overrides"]
                if not ov or name in ov:
                    val = ov.get(name, nominal)
                    srows.append({"parameter": name, "value": val, "factor": val / nominal, "unit": unit,
                                  **{k: r[k] for k in ("Fm", "sigma", "min", "max", "n_loss", "static_force")}})
        srows.sort(key=lambda r: (r["parameter"], r["value"]))
        scols = ["parameter", "value", "factor", "Fm", "sigma", "min", "max", "n_loss", "static_force"]
        print()
        print(format_table(scols, [[r[c] if isinstance(r[c], str | int) else f"{r[c]:.3g}" for c in scols]
                                   for r in srows]))
        write_csv(out / "head_study_250kmh.csv", [(c, "", [r[c] for r in srows]) for c in scols])
        fig, ax = plt.subplots(figsize=(6, 4.5))
        for name in ("mh", "kh"):
            rs = [r for r in srows if r["parameter"] == name]
            ax.plot([r["factor"] for r in rs], [r["sigma"] for r in rs], "o-", label=f"{name} (nominal "
                    f"{rs[0]['value'] / rs[0]['factor']:g} {rs[0]['unit']})")
        ax.set_xscale("log", base=2)
        ax.set_xlabel("factor on the Table 3-I value")
        ax.set_ylabel("contact-force sigma at 250 km/h (N)")
        ax.grid(True, lw=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(out / "head_study_250kmh.png", dpi=120)
        plt.close(fig)
        result["head_study_250kmh"] = srows
    (out / "summary.json").write_text(json.dumps(to_jsonable({**result, "element_length": h, "timestep": dt,
                                                              "wall_s": time.perf_counter() - t0}), indent=2))
    print(f"\nwrote {out}  ({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
