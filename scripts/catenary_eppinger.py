"""The Eppinger (Brecknell-Willis) pantograph under the EN 50318 reference catenary.

The Eppinger pantograph is the registry model "pantograph", run under the wire as the catenary's `eppinger`
pantograph on an engine path (`simulate(..., pantograph="eppinger", engine=..., pantograph_section={"params": ...})`,
the same as a catenary scene with a `[pantograph]` section).

1. Speed sweep 100-300 km/h in 25 km/h steps on the same catenary (slack droppers): contact-force statistics and
   contact loss (count; durations < 5 ms, 5-20 ms, > 20 ms) of
   - the 2-mass reference pantograph (F0 = 120 N),
   - the Eppinger pantograph at its Table 3-I supply pressure (hand-derived ODE path and MuJoCo path),
   - the Eppinger pantograph (MuJoCo path) with the supply pressure raised to give the reference's 120 N static force.
2. Design study at 250 km/h (MuJoCo path): head mass mh and head suspension stiffness kh x {0.5, 0.75, 1, 1.5, 2} vs
   contact-force sigma, the supply pressure re-solved for each variant so the static contact force stays at its
   Table 3-I value (otherwise mh changes the mean force through the head's weight).

Prints each run as it finishes; writes speed_sweep.csv/png, head_study_250kmh.csv/png and summary.json into --out.

    .venv/bin/python scripts/catenary_eppinger.py --out out/catenary_eppinger [--workers 2]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from mbsuite.errors import MbsuiteError
from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.pantograph.params import PantographParams
from mbsuite.models.pantograph.under_wire import pressure_for_static_force, static_force
from mbsuite.results import format_table, to_jsonable, write_csv

SPEEDS = [100, 125, 150, 175, 200, 225, 250, 275, 300]
FACTORS = [0.5, 0.75, 1.0, 1.5, 2.0]
KEYS = ["Fm", "sigma", "stat_max", "stat_min", "max", "min", "uplift_mm", "loss_pct"]
COLS = ["label", "speed", "static_force", *KEYS, "n_loss", "loss_lt_5ms", "loss_5_20ms", "loss_gt_20ms", "wall_s",
        "cpu_s"]


def one(job):
    """One passage: (label, pantograph, engine, speed, element length, time step, pantograph parameter overrides)."""
    label, kind, engine, speed, h, dt, overrides = job
    p = dataclasses.replace(CatenaryParams(), element_length=h)
    t0, c0 = time.perf_counter(), time.process_time()
    row = {"label": label, "pantograph": kind, "engine": engine, "speed": speed, "overrides": overrides}
    try:
        run = simulate(p, speed, dt, pantograph=kind, engine=engine,
                       pantograph_section={"params": overrides} if overrides else None)
    except MbsuiteError as exc:
        row.update({k: float("nan") for k in COLS if k not in row and k != "label"})
        row.update({"error": str(exc), "wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0})
        print(f"{label} {speed} km/h: ERROR {exc}", flush=True)
        return row
    c = run.stats["loss_counts"]
    row.update({**{k: run.stats[k] for k in KEYS}, "static_force": run.static_force,
                "n_loss": len(run.stats["loss_events"]), "loss_lt_5ms": c["short_lt_5ms"],
                "loss_5_20ms": c["damaging_5_20ms"], "loss_gt_20ms": c["power_loss_gt_20ms"],
                "wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0, "error": ""})
    print(f"{label:>24s} {speed:3d} km/h  F0 {row['static_force']:7.2f}  Fm {row['Fm']:7.2f}  "
          f"sigma {row['sigma']:6.2f}  min {row['min']:7.2f}  max {row['max']:7.2f}  "
          f"loss {row['loss_pct']:5.2f} % ({row['n_loss']})  "
          f"{row['cpu_s']:.0f} s CPU", flush=True)
    return row


def _fmt(v):
    return v if isinstance(v, str | int) else f"{v:.2f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/catenary_eppinger")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--element-length", type=float, default=0.5)
    ap.add_argument("--timestep", type=float, default=1e-4)
    ap.add_argument("--speeds", type=int, nargs="+", default=SPEEDS)
    ap.add_argument("--skip-reference-path", action="store_true", help="MuJoCo path only for the Eppinger sweep")
    ap.add_argument("--skip-study", action="store_true")
    a = ap.parse_args()
    h, dt = a.element_length, a.timestep
    base = PantographParams()
    f_nominal = static_force()
    pg_120 = pressure_for_static_force(120.0)
    jobs = []
    for s in a.speeds:
        jobs.append(("reference2mass", "reference2mass", "reference", s, h, dt, {}))
        if not a.skip_reference_path:
            jobs.append(("eppinger (reference)", "eppinger", "reference", s, h, dt, {}))
        jobs.append(("eppinger (mujoco)", "eppinger", "mujoco", s, h, dt, {}))
        jobs.append(("eppinger (mujoco) @120N", "eppinger", "mujoco", s, h, dt, {"Pg": pg_120}))
    study_jobs = []
    if not a.skip_study:
        for name in ("mh", "kh"):
            for f in FACTORS:
                ov = {name: f * getattr(base, name)}
                ov["Pg"] = pressure_for_static_force(f_nominal, ov)
                study_jobs.append((f"study {name} x{f:g}", "eppinger", "mujoco", 250, h, dt, ov))
    t0 = time.perf_counter()
    print(f"Eppinger static contact force at the Table 3-I supply pressure {base.Pg:.0f} Pa: {f_nominal:.2f} N; "
          f"120 N needs {pg_120:.0f} Pa", flush=True)
    alljobs = jobs + study_jobs
    if a.workers > 1:
        with ProcessPoolExecutor(a.workers) as ex:
            rows = list(ex.map(one, alljobs))
    else:
        rows = [one(j) for j in alljobs]
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    sweep = rows[: len(jobs)]
    print()
    print(format_table(COLS, [[_fmt(r[c]) for c in COLS] for r in sweep]))
    write_csv(out / "speed_sweep.csv", [(c, "", [r[c] for r in sweep]) for c in COLS])
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    for label in dict.fromkeys(r["label"] for r in sweep):
        rs = sorted((r for r in sweep if r["label"] == label and not r["error"]), key=lambda r: r["speed"])
        v = [r["speed"] for r in rs]
        (ln,) = axes[0].plot(v, [r["Fm"] for r in rs], "o-", label=f"{label}: Fm, max, min")
        axes[0].plot(v, [r["max"] for r in rs], "^--", color=ln.get_color())
        axes[0].plot(v, [r["min"] for r in rs], "v--", color=ln.get_color())
        axes[1].plot(v, [r["sigma"] for r in rs], "o-", label=label)
        axes[2].plot(v, [r["loss_pct"] for r in rs], "o-", label=label)
    axes[0].set_ylabel("contact force (N), 20 Hz filtered")
    axes[1].set_ylabel("sigma (N)")
    axes[2].set_ylabel("contact loss (% of time in window)")
    for ax in axes:
        ax.set_xlabel("speed (km/h)")
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("EN 50318 reference catenary: 2-mass reference vs Eppinger pantograph")
    fig.tight_layout()
    fig.savefig(out / "speed_sweep.png", dpi=120)
    plt.close(fig)
    result = {"static_force_table3I_N": f_nominal, "Pg_for_120N_Pa": pg_120, "speed_sweep": sweep}
    if study_jobs:
        srows = []
        for r, job in zip(rows[len(jobs):], study_jobs, strict=True):
            ov = job[6]
            name = "mh" if "mh" in ov else "kh"
            nominal = getattr(base, name)
            srows.append({"parameter": name, "value": ov[name], "factor": ov[name] / nominal,
                          "Pg": ov["Pg"], "static_force_at_table_Pg": static_force({name: ov[name]}),
                          **{k: r[k] for k in ("static_force", "Fm", "sigma", "min", "max", "loss_pct", "n_loss",
                                               "error")}})
        scols = ["parameter", "value", "factor", "Pg", "static_force_at_table_Pg", "static_force", "Fm", "sigma",
                 "min", "max", "loss_pct", "n_loss"]
        print()
        print(format_table(scols, [[_fmt(r[c]) for c in scols] for r in srows]))
        write_csv(out / "head_study_250kmh.csv", [(c, "", [r[c] for r in srows]) for c in scols])
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        for name, unit in (("mh", "kg"), ("kh", "N m/rad")):
            rs = [r for r in srows if r["parameter"] == name and not r["error"]]
            ax.plot([r["factor"] for r in rs], [r["sigma"] for r in rs], "o-",
                    label=f"{name} (Table 3-I: {getattr(base, name):g} {unit})")
        ax.set_xscale("log", base=2)
        ax.set_xlabel(f"factor on the Table 3-I value (static force held at {f_nominal:.1f} N by Pg)")
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
