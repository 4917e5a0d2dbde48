"""Mesh and time-step convergence of the EN 50318 statistics of the reference scene.

Runs the reference scene on the grid element length {0.5, 0.25, 0.125} m x time step {2e-4, 1e-4, 5e-5} s at each
speed and prints every statistic per grid point, then the largest change between the two finest levels (mesh at the
finest dt, dt at the finest mesh, and the diagonal). Writes CSV and JSON with --out.

    .venv/bin/python scripts/catenary_convergence.py --speeds 250 300 --out out/catenary_convergence [--workers 2]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.stats import STAT_NAMES
from mbsuite.results import format_table, to_jsonable, write_csv

MESHES = (0.5, 0.25, 0.125)
STEPS = (2e-4, 1e-4, 5e-5)
KEYS = list(STAT_NAMES)


def one(args):
    speed, h, dt, law = args
    p = dataclasses.replace(CatenaryParams(), element_length=h)
    t0 = time.perf_counter()
    run = simulate(p, speed, dt, dropper_law=law)
    return {"speed": speed, "element_length": h, "dt": dt, "droppers": law, "wall_s": time.perf_counter() - t0,
            "us_per_step": run.timing["us_per_step"], "dofs": run.timing["dofs"],
            **{k: run.stats[k] for k in KEYS}}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=float, nargs="+", default=[250.0, 300.0])
    ap.add_argument("--droppers", default="slack", choices=["slack", "linear"])
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    jobs = [(s, h, dt, a.droppers) for s in a.speeds for h in MESHES for dt in STEPS]
    if a.workers > 1:
        with ProcessPoolExecutor(a.workers) as ex:
            rows = list(ex.map(one, jobs))
    else:
        rows = [one(j) for j in jobs]
    summary = {}
    for s in a.speeds:
        rs = {(r["element_length"], r["dt"]): r for r in rows if r["speed"] == s}
        print(f"\n{s:g} km/h, {a.droppers} droppers")
        print(format_table(["h (m)", "dt (s)", *KEYS, "wall (s)"],
                           [[h, dt, *[f"{rs[h, dt][k]:.2f}" for k in KEYS], f"{rs[h, dt]['wall_s']:.1f}"]
                            for h in MESHES for dt in STEPS]))
        fine, fine2 = (MESHES[-1], STEPS[-1]), None
        changes = {
            "mesh 0.25->0.125 (dt 5e-5)": {k: abs(rs[MESHES[1], STEPS[-1]][k] - rs[fine][k]) for k in KEYS},
            "dt 1e-4->5e-5 (h 0.125)": {k: abs(rs[MESHES[-1], STEPS[1]][k] - rs[fine][k]) for k in KEYS},
            "diagonal (0.25, 1e-4)->(0.125, 5e-5)": {k: abs(rs[MESHES[1], STEPS[1]][k] - rs[fine][k]) for k in KEYS},
        }
        del fine2
        print(format_table(["change between the two finest levels", *KEYS, "max", "<= 0.5"],
                           [[name, *[f"{d[k]:.3f}" for k in KEYS], f"{max(d.values()):.3f}",
                             "yes" if max(d.values()) <= 0.5 else "NO"] for name, d in changes.items()]))
        summary[f"{s:g}"] = {"changes": changes}
    if a.out:
        out = Path(a.out)
        out.mkdir(parents=True, exist_ok=True)
        write_csv(out / f"convergence_{a.droppers}.csv",
                  [(k, "", [r[k] for r in rows]) for k in ["speed", "element_length", "dt", *KEYS, "wall_s"]])
        (out / f"convergence_{a.droppers}.json").write_text(json.dumps(to_jsonable({"rows": rows, **summary}),
                                                                        indent=2))


if __name__ == "__main__":
    main()
