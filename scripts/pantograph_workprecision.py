"""Work-precision study of the pantograph lab scene: what accuracy costs in time.

For each engine and method — MuJoCo timestep x integrator (euler, implicitfast, implicit, rk4, discrete) and the
hand-derived path with scipy methods x rtol — the error and the wall time (median of N runs, min-max shown).

Errors are measured against a reference solution from a *different* method (Radau, rtol 1e-12; its own accuracy is
checked against DOP853 at rtol 1e-12 and printed):
- state error: max over the trajectory of |F1, F2, HD, y_d - ref| / A (A = input amplitude, the characteristic scale
  of every output displacement), on a 1 ms grid after the start-up (t >= t_settle);
- physics metric: relative error of the F1 and HD amplitudes at the forcing frequency and their phase error (deg).

Coulomb friction is switched off for this study (--coulomb to keep it): MuJoCo's regularised frictionloss and the
reference's event-exact stick/slip are different models, whose ~0.5 % difference would be an error floor.

    python scripts/pantograph_workprecision.py [--repeats 5] [--frequency 4.25] [--duration 3] [--out out/wp]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from mbsuite import load_scene, run
from mbsuite.analysis.harmonic import fundamental
from mbsuite.results import format_table, to_jsonable, write_csv

SIGNALS = ("F1", "F2", "HD", "y_d")
MJ_INTEGRATORS = ("euler", "implicitfast", "implicit", "rk4", "discrete")
MJ_STEPS = (2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4, 5e-5)
SCIPY = {"DOP853": (1e-4, 1e-6, 1e-8, 1e-10), "RK45": (1e-4, 1e-6, 1e-8), "Radau": (1e-4, 1e-6, 1e-8, 1e-10),
         "LSODA": (1e-4, 1e-6, 1e-8, 1e-10), "BDF": (1e-4, 1e-6, 1e-8)}


def timed(scene, repeats: int):
    times, res = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = run(scene)
        times.append(time.perf_counter() - t0)
    return res, float(np.median(times)), float(min(times)), float(max(times))


def metrics(res, ref, f: float, A: float, ts: float) -> dict:
    grid = ref.t[ref.t >= ts]
    err = 0.0
    for s in SIGNALS:
        err = max(err, float(np.max(np.abs(np.interp(grid, res.t, res[s]) - ref[s][ref.t >= ts])) / A))
    out = {"state_error": err}
    for s in ("F1", "HD"):
        a, b = fundamental(res.t, res[s], f, ts), fundamental(ref.t, ref[s], f, ts)
        out[f"{s}_amp_rel"] = abs(abs(a) / abs(b) - 1.0)
        out[f"{s}_phase_deg"] = abs(math.degrees(np.angle(a / b)))
    out["physics_error"] = max(out["F1_amp_rel"], out["HD_amp_rel"],
                               math.radians(max(out["F1_phase_deg"], out["HD_phase_deg"])))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--frequency", type=float, default=4.25)
    ap.add_argument("--duration", type=float, default=3.0)
    ap.add_argument("--coulomb", action="store_true", help="keep Coulomb friction on")
    ap.add_argument("--out", default="out/pantograph_workprecision")
    args = ap.parse_args()
    f, T = args.frequency, args.duration
    ts = T / 2
    base = load_scene("pantograph").replace(
        effects={"coulomb": bool(args.coulomb)}, input={"frequency": f},
        solver={"duration": T, "t_settle": ts, "sample_dt": 1e-3, "max_step": 1.0 / (16 * f)})
    A = float(base.input["amplitude"])
    ref = run(base.replace(solver={"engine": "reference", "method": "Radau", "rtol": 1e-12, "atol": 1e-14}))
    chk = run(base.replace(solver={"engine": "reference", "method": "DOP853", "rtol": 1e-12, "atol": 1e-14}))
    ref_acc = metrics(chk, ref, f, A, ts)
    print(f"reference: Radau rtol 1e-12; vs DOP853 rtol 1e-12: state error {ref_acc['state_error']:.2e}, "
          f"physics error {ref_acc['physics_error']:.2e}")
    rows = []
    for integ in MJ_INTEGRATORS:
        for h in MJ_STEPS:
            sc = base.replace(solver={"engine": "mujoco", "integrator": integ, "timestep": h})
            try:
                res, tmed, tmin, tmax = timed(sc, args.repeats)
            except Exception as exc:  # a diverging setting is a data point, not a crash
                rows.append({"engine": "mujoco", "method": integ, "setting": h, "error": str(exc)})
                continue
            rows.append({"engine": "mujoco", "method": integ, "setting": h, "time_s": tmed, "time_min": tmin,
                         "time_max": tmax, **metrics(res, ref, f, A, ts)})
            print(f"mujoco {integ:12s} h={h:<8g} {tmed * 1e3:8.1f} ms  state {rows[-1]['state_error']:.2e}  "
                  f"physics {rows[-1]['physics_error']:.2e}", flush=True)
    for method, rtols in SCIPY.items():
        for rtol in rtols:
            sc = base.replace(solver={"engine": "reference", "method": method, "rtol": rtol, "atol": rtol * 1e-2})
            res, tmed, tmin, tmax = timed(sc, max(1, min(args.repeats, 5)))
            rows.append({"engine": "reference", "method": method, "setting": rtol, "time_s": tmed, "time_min": tmin,
                         "time_max": tmax, "nfev": res.stats["nfev"], **metrics(res, ref, f, A, ts)})
            print(f"scipy  {method:12s} rtol={rtol:<6g} {tmed * 1e3:8.1f} ms  state {rows[-1]['state_error']:.2e}"
                  f"  physics {rows[-1]['physics_error']:.2e}", flush=True)
    ok = [r for r in rows if "time_s" in r]
    print()
    print(format_table(["engine", "method", "h or rtol", "median s", "min s", "max s", "state err", "physics err"],
                       [[r["engine"], r["method"], r["setting"], r["time_s"], r["time_min"], r["time_max"],
                         r["state_error"], r["physics_error"]] for r in ok], ".3g"))
    print("\ncheapest setting reaching a relative physics-metric error (time in s):")
    head = []
    for tol in (1e-2, 1e-3, 1e-4, 1e-6):
        for key in sorted({(r["engine"], r["method"]) for r in ok}):
            cand = [r for r in ok if (r["engine"], r["method"]) == key and r["physics_error"] <= tol]
            best = min(cand, key=lambda r: r["time_s"]) if cand else None
            head.append([f"{tol:g}", *key, best["setting"] if best else "-", best["time_s"] if best else "-"])
    print(format_table(["tol", "engine", "method", "setting", "time s"], head, ".3g"))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "workprecision.json").write_text(json.dumps(to_jsonable({"reference_accuracy": ref_acc, "rows": rows}),
                                                       indent=2))
    write_csv(out / "workprecision.csv", [
        ("engine", "", [r["engine"] for r in ok]), ("method", "", [r["method"] for r in ok]),
        ("setting", "s or -", [r["setting"] for r in ok]), ("time_median", "s", [r["time_s"] for r in ok]),
        ("time_min", "s", [r["time_min"] for r in ok]), ("time_max", "s", [r["time_max"] for r in ok]),
        ("state_error", "-", [r["state_error"] for r in ok]), ("physics_error", "-", [r["physics_error"] for r in ok])])
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    for key in sorted({(r["engine"], r["method"]) for r in ok}):
        rr = sorted([r for r in ok if (r["engine"], r["method"]) == key], key=lambda r: r["time_s"])
        for ax, err in zip(axes, ("state_error", "physics_error"), strict=True):
            ax.errorbar([r["time_s"] for r in rr], [r[err] for r in rr],
                        xerr=[[r["time_s"] - r["time_min"] for r in rr], [r["time_max"] - r["time_s"] for r in rr]],
                        marker="o" if key[0] == "mujoco" else "s", ls="-" if key[0] == "mujoco" else "--",
                        label=f"{key[0]} {key[1]}", ms=4)
    for ax, title in zip(axes, ("state error (max |dy|/A)", "physics metric (amplitude/phase at f)"), strict=True):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time (s), median; bars min-max")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("error")
    axes[1].legend(fontsize=7, ncol=2)
    fig.suptitle(f"Pantograph lab scene at {f} Hz, {T} s simulated: work-precision")
    fig.tight_layout()
    fig.savefig(out / "workprecision.png", dpi=110)
    print(f"\nwrote {out}/workprecision.csv, .json, .png")


if __name__ == "__main__":
    main()
