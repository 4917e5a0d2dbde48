"""Benchmark (not a test): sweeps on this machine, measured side by side in one run.

1. the 59-point pantograph frequency sweep (lab scene, 1-30 Hz every 0.5 Hz, 10 s each, MuJoCo path: RK4 1 ms with
   its engine plugins) as `freqresp` runs it: one compiled model, native-core runs in C threads; 1 thread and all
   cores, results compared for identity;
2. the same 59 trajectories through `mujoco.rollout` (MuJoCo's own threaded batch loop) with 1 and all threads;
3. the generic scene sweep (`run_sweep(scene_point, ...)`, the `mbsuite sweep` command) with the thread executor and
   with the process pool, against one worker;
4. optionally Dask: the same scene points on a LocalCluster.

    python scripts/bench_sweep.py [--repeats 5] [--points 8] [--skip-dask]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from mbsuite import load_scene
from mbsuite.analysis.sweep import get_state, rollout_sweep, run_sweep, scene_point
from mbsuite.engines.core import n_workers
from mbsuite.models.pantograph.freqresp import mujoco_sweep
from mbsuite.models.pantograph.mujoco import MujocoPantograph, hold_offset
from mbsuite.results import format_table


def median_wall(fn, repeats: int):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return out, statistics.median(times), min(times), max(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--points", type=int, default=8, help="scene points of the generic sweep")
    ap.add_argument("--skip-dask", action="store_true")
    a = ap.parse_args()
    nc = n_workers(0)
    lab = load_scene("pantograph")
    freqs = np.round(np.arange(1.0, 30.0 + 0.25, 0.5), 10)
    rows = []

    mujoco_sweep(lab, freqs[:2], workers=1)  # warm-up: native library, model cache
    one, t1, *_ = median_wall(lambda: mujoco_sweep(lab, freqs, workers=1), a.repeats)
    all_, tn, tmin, tmax = median_wall(lambda: mujoco_sweep(lab, freqs, workers=nc), a.repeats)
    same = all(x["F1"] == y["F1"] and x["HD"] == y["HD"] for x, y in zip(one, all_, strict=True))
    rows.append([f"pantograph sweep, {freqs.size} points x {lab.solver.duration:g} s (freqresp, MuJoCo)", t1, tn,
                 t1 / tn, "identical" if same else "DIFFERENT"])

    s = lab.solver
    mp = MujocoPantograph(lab.build_params(), None, s.integrator, s.timestep)
    mp.set_static(mp.equilibrium(), mp.p.y_op)
    x0 = get_state(mp.model, mp.data)
    n = int(round(s.duration / s.timestep))
    tk = (np.arange(n) + hold_offset(s.integrator)) * s.timestep
    ctrl = np.zeros((freqs.size, n, mp.model.nu))
    amp = float(lab.input.get("amplitude", 1.85e-3))
    ctrl[:, :, mp.i_cat] = mp.p.y_op + amp * (1 - np.cos(2 * np.pi * freqs[:, None] * tk[None, :]))
    x0s = np.tile(x0, (freqs.size, 1))
    rollout_sweep(mp.model, x0s[:2], ctrl[:2, :100], workers=1)  # warm-up
    (r1, _), tr1, *_ = median_wall(lambda: rollout_sweep(mp.model, x0s, ctrl, workers=1), a.repeats)
    (rn, _), trn, *_ = median_wall(lambda: rollout_sweep(mp.model, x0s, ctrl, workers=nc), a.repeats)
    rows.append([f"mujoco.rollout, the same {freqs.size} trajectories", tr1, trn, tr1 / trn,
                 "identical" if np.array_equal(r1, rn) else "DIFFERENT"])

    short = lab.replace(solver={"duration": 2.0, "t_settle": 1.0})
    jobs = [(short.to_dict(), {"input": {"frequency": float(f)}}) for f in np.linspace(2.0, 12.0, a.points)]
    run_sweep(scene_point, jobs[:1], workers=1)
    serial, ts, *_ = median_wall(lambda: run_sweep(scene_point, jobs, workers=1), a.repeats)
    thr, tt, *_ = median_wall(lambda: run_sweep(scene_point, jobs, workers=nc, executor="threads"), a.repeats)
    proc, tp, *_ = median_wall(lambda: run_sweep(scene_point, jobs, workers=nc), a.repeats)
    rows.append([f"scene sweep, {a.points} pantograph scenes x 2 s, threads", ts, tt, ts / tt,
                 "identical" if thr == serial else "DIFFERENT"])
    rows.append([f"scene sweep, {a.points} pantograph scenes x 2 s, processes", ts, tp, ts / tp,
                 "identical" if proc == serial else "DIFFERENT"])

    if not a.skip_dask:
        import distributed

        with distributed.LocalCluster(n_workers=nc, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cl:
            run_sweep(scene_point, jobs[:nc], executor="dask", scheduler=cl.scheduler_address)  # warm-up
            dk, td, *_ = median_wall(lambda: run_sweep(scene_point, jobs, executor="dask",
                                                       scheduler=cl.scheduler_address), a.repeats)
        rows.append([f"scene sweep on a Dask LocalCluster ({nc} workers)", ts, td, ts / td,
                     "identical" if dk == serial else "DIFFERENT"])

    print(f"{nc} cores available; medians of {a.repeats}")
    print(format_table(["sweep", "1 worker (s)", f"{nc} workers (s)", "speed-up", "results"], rows, ".3g"))
    print(f"\nthe {freqs.size}-point pantograph frequency sweep (MuJoCo path): {tn:.2f} s wall on {nc} cores "
          f"(min {tmin:.2f}, max {tmax:.2f})")


if __name__ == "__main__":
    main()
