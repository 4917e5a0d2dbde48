"""Speed x head mass x static force grid of the EN 50318 reference pantograph (design sweep through the sweep API's
process pool): 5 speeds (150-320 km/h) x 4 head masses (m1) x 2 static uplift forces (F0) = 40 passages, with the
wall time of the whole grid, a CSV/JSON of every point and the plot of sigma/Fm, Fm - 3 sigma and contact loss.

    .venv/bin/python scripts/catenary_design_sweep.py [--workers 2] [--out out/catenary_design]
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import mbsuite
from mbsuite.models.catenary.design import design_grid, plot_grid
from mbsuite.results import format_table, write_csv


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--scene", default="catenary")
    ap.add_argument("--speeds", type=float, nargs="+", default=[150.0, 200.0, 250.0, 300.0, 320.0])
    ap.add_argument("--m1", type=float, nargs="+", default=[5.4, 7.2, 9.0, 10.8])
    ap.add_argument("--F0", type=float, nargs="+", default=[100.0, 140.0])
    ap.add_argument("--out", default="out/catenary_design")
    a = ap.parse_args()
    scene = mbsuite.load_scene(a.scene)
    load0 = os.getloadavg()[0]
    w0 = time.perf_counter()
    grid = design_grid(scene, a.speeds, {"m1": a.m1, "F0": a.F0}, workers=a.workers, progress=False)
    wall = time.perf_counter() - w0
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    pts = grid["points"]
    cols = ["speed_kmh", "m1", "F0", "Fm", "sigma", "sigma_over_Fm", "stat_min", "max", "min", "uplift_mm",
            "loss_pct", "quality_pass"]
    write_csv(out / "design_grid.csv", [(c, "", [float(p[c]) for p in pts]) for c in cols])
    (out / "design_grid.json").write_text(json.dumps({**grid, "wall_s": wall}, indent=1))
    plot_grid(grid, out)
    print(format_table(cols, [[f"{p[c]:.3g}" if isinstance(p[c], float) else str(p[c]) for c in cols] for p in pts]))
    cpu = sum(p["cpu_s"] for p in pts)
    print(f"{len(pts)} points on {a.workers} workers: {wall:.1f} s wall (load average {load0:.1f} before, "
          f"{os.getloadavg()[0]:.1f} after, on {os.cpu_count()} cores); the points' CPU time sums to {cpu:.1f} s, "
          f"i.e. {cpu / a.workers:.1f} s of wall on {a.workers} otherwise idle cores")


if __name__ == "__main__":
    main()
