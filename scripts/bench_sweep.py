"""Benchmark (not a test): sweep scaling on this machine, measured side by side in one run.

1. process pool (scenes with Python callbacks): N pantograph frequency points (lab scene, MuJoCo path) with
   workers = 1 and workers = all cores -> speed-up;
2. mujoco.rollout C threads (scenes without callbacks): a batch of IFToMM four-bar trajectories with 1 thread and all
   cores -> speed-up;
3. Dask: the same frequency points on a LocalCluster (one single-threaded worker per core) vs the local pool, results
   compared for identity;
4. the 59-point pantograph frequency sweep (1-30 Hz, 0.5 Hz, 10 s each, MuJoCo path) through `freqresp`, wall time.

    python scripts/bench_sweep.py [--points 8] [--duration 10] [--skip-dask] [--skip-59]
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

from mbsuite import load_scene
from mbsuite.analysis.sweep import get_state, n_workers, rollout_sweep, run_sweep, scene_point
from mbsuite.models.iftomm.mechanisms import initial_velocity, mujoco_model
from mbsuite.results import format_table


def wall(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=8, help="frequency points for the pool/Dask comparison")
    ap.add_argument("--duration", type=float, default=10.0, help="simulated seconds per frequency point")
    ap.add_argument("--batch", type=int, default=16, help="rollout trajectories")
    ap.add_argument("--steps", type=int, default=20000, help="rollout steps per trajectory")
    ap.add_argument("--skip-dask", action="store_true")
    ap.add_argument("--skip-59", action="store_true")
    a = ap.parse_args()
    nc = n_workers(0)
    rows = []

    sc = load_scene("pantograph").replace(solver={"duration": a.duration, "t_settle": a.duration / 2})
    jobs = [(sc.to_dict(), {"input": {"frequency": float(f)}}) for f in np.linspace(2.0, 12.0, a.points)]
    run_sweep(scene_point, jobs[:1], workers=1)  # warm-up (imports, model files)
    serial, t1 = wall(lambda: run_sweep(scene_point, jobs, workers=1))
    pooled, tn = wall(lambda: run_sweep(scene_point, jobs, workers=nc))
    rows.append([f"process pool, {a.points} pantograph points x {a.duration:g} s", t1, tn, t1 / tn,
                 "identical" if pooled == serial else "DIFFERENT"])

    m = mujoco_model("fourbar", 1e-3, "rk4", 0.004, 9.81)
    d = mujoco.MjData(m)
    x0 = []
    for rate in np.linspace(2.0, 8.0, a.batch):
        mujoco.mj_resetData(m, d)
        d.qvel[:] = initial_velocity(m, rate)
        x0.append(get_state(m, d))
    x0 = np.array(x0)
    ctrl = np.zeros((a.batch, a.steps, m.nu))
    rollout_sweep(m, x0[:2], ctrl[:2, :100], workers=1)  # warm-up
    (s1, _), r1 = wall(lambda: rollout_sweep(m, x0, ctrl, workers=1))
    (sn, _), rn = wall(lambda: rollout_sweep(m, x0, ctrl, workers=nc))
    rows.append([f"mujoco.rollout, {a.batch} four-bar trajectories x {a.steps} steps", r1, rn, r1 / rn,
                 "identical" if np.array_equal(s1, sn) else "DIFFERENT"])

    if not a.skip_dask:
        import distributed

        with distributed.LocalCluster(n_workers=nc, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cl:
            run_sweep(scene_point, jobs[:nc], executor="dask", scheduler=cl.scheduler_address)  # warm-up workers
            dk, td = wall(lambda: run_sweep(scene_point, jobs, executor="dask", scheduler=cl.scheduler_address))
        rows.append([f"Dask LocalCluster ({nc} workers) vs serial", t1, td, t1 / td,
                     "identical to local" if dk == serial else "DIFFERENT"])

    print(f"{nc} cores available")
    print(format_table(["sweep", "1 worker (s)", f"{nc} workers (s)", "speed-up", "results"], rows, ".3g"))

    if not a.skip_59:
        from mbsuite.models.pantograph.analysis import _point, freqresp

        lab = load_scene("pantograph")
        freqs = np.round(np.arange(1.0, 30.0 + 0.25, 0.5), 10)
        jobs59 = [(lab.to_dict(), float(f), "mujoco") for f in freqs]
        _, t59 = wall(lambda: run_sweep(_point, jobs59, workers=0, desc="freqresp"))
        _, t59_1 = wall(lambda: run_sweep(_point, jobs59, workers=1, desc="freqresp"))
        print(f"\npantograph frequency sweep: {len(freqs)} points (1-30 Hz, 0.5 Hz), {lab.solver.duration:g} s each, "
              f"MuJoCo path ({lab.solver.integrator}, h = {lab.solver.timestep:g} s): {t59:.2f} s wall on {nc} cores "
              f"({t59_1:.2f} s on 1 core, speed-up {t59_1 / t59:.2f})")
        rep, tf = wall(lambda: freqresp(lab, f_min=1.0, f_max=30.0, df=0.5, methods=("mujoco",), workers=0))
        n_sim = len(rep.data["response"]) * len(freqs) - (len(freqs) if "linear" in rep.data["response"] else 0)
        print(f"`freqresp pantograph --methods mujoco` (the scene has Coulomb friction, so the command also runs the "
              f"sweep without it: {n_sim} simulations, plus the linearisation): {tf:.2f} s wall on {nc} cores")


if __name__ == "__main__":
    main()
