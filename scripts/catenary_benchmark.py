"""Wall and CPU time of one EN 50318 reference run (shipped scene: 0.5 m elements, dt 2e-4 s) and of the finer
settings, median of --repeats runs, with the cost per step and of the banded solve alone; with --eppinger also one
passage of the Eppinger pantograph on each engine path (0.5 m, dt 1e-4 s: the eppinger_lab scene's setting), with the
cost per pantograph trial step.

    .venv/bin/python scripts/catenary_benchmark.py [--repeats 3] [--speeds 250 300] [--eppinger]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.pantographs import TwoMassPantograph
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.sim import CoupledSimulation
from mbsuite.results import format_table


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--speeds", type=float, nargs="+", default=[250.0, 300.0])
    ap.add_argument("--settings", nargs="+", default=["0.5,2e-4", "0.5,1e-4", "0.25,1e-4"])
    ap.add_argument("--eppinger", action="store_true", help="also time the Eppinger pantograph on both engine paths")
    a = ap.parse_args()
    rows = []
    for setting in a.settings:
        h, dt = (float(v) for v in setting.split(","))
        p = CatenaryParams(element_length=h)
        fe = assemble(p)
        sim = CoupledSimulation(fe, TwoMassPantograph(p.m1, p.k1, p.c1, p.m2, p.k2, p.c2, p.F0), 70.0, dt)
        b = np.random.default_rng(0).random(fe.n)
        t0 = time.perf_counter()
        for _ in range(2000):
            sim.lu.solve(b)
        solve_us = (time.perf_counter() - t0) / 2000 * 1e6
        for v in a.speeds:
            walls, cpus, steps = [], [], 0
            for _ in range(a.repeats):
                w0, c0 = time.perf_counter(), time.process_time()
                run = simulate(p, v, dt)
                walls.append(time.perf_counter() - w0)
                cpus.append(time.process_time() - c0)
                steps = run.timing["steps"]
            wall, cpu = statistics.median(walls), statistics.median(cpus)
            rows.append([h, dt, v, fe.n, steps, f"{wall:.2f}", f"{cpu:.2f}", f"{1e6 * cpu / steps:.0f}",
                         f"{solve_us:.0f}"])
    print(format_table(["h (m)", "dt (s)", "km/h", "DOFs", "steps", "wall (s)", "CPU (s)", "CPU us/step",
                        "solve us"], rows))
    if a.eppinger:
        rows = []
        p = CatenaryParams(element_length=0.5)
        for engine in ("reference", "mujoco"):
            for v in a.speeds:
                walls, cpus = [], []
                for _ in range(a.repeats):
                    w0, c0 = time.perf_counter(), time.process_time()
                    run = simulate(p, v, 1e-4, pantograph="eppinger", engine=engine)
                    walls.append(time.perf_counter() - w0)
                    cpus.append(time.process_time() - c0)
                steps, trials = run.timing["steps"], run.result.stats["local_solves"]
                cpu = statistics.median(cpus)
                rows.append([engine, v, steps, trials, f"{statistics.median(walls):.2f}", f"{cpu:.2f}",
                             f"{1e6 * cpu / steps:.0f}"])
        print()
        print(format_table(["Eppinger path", "km/h", "steps", "trial steps", "wall (s)", "CPU (s)", "CPU us/step"],
                           rows))


if __name__ == "__main__":
    main()
