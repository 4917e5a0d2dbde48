"""Choose the orifice's laminar band by convergence (pantograph/nonlinear_cylinder, reference path).

For each band width w = 1 - r_laminar the responses with w and w/10 are compared at every frequency of the sweep (F1,
F2, HD amplitude and phase) and during the start from P = Ps; the cost of each band is the cylinder pole of the
linearisation (stiffness), the reference path's RHS calls and wall time, and MuJoCo RK4's step count and wall time.

    python scripts/pantograph_orifice_band.py [--widths 1e-3,1e-4,1e-5,1e-6] [--f-min 1 --f-max 30 --df 0.5]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from mbsuite import load_scene, run
from mbsuite.models.pantograph import orifice_band
from mbsuite.models.pantograph.inputs import config_of, operating_height
from mbsuite.models.pantograph.linearise import stiffest_pole
from mbsuite.results import format_table


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="pantograph/nonlinear_cylinder")
    ap.add_argument("--widths", default="1e-3,1e-4,1e-5,1e-6")
    ap.add_argument("--f-min", type=float, default=1.0)
    ap.add_argument("--f-max", type=float, default=30.0)
    ap.add_argument("--df", type=float, default=0.5)
    ap.add_argument("--workers", type=int, default=0)
    a = ap.parse_args()
    scene = load_scene(a.scene)
    widths = [float(w) for w in a.widths.split(",")]
    freqs = np.round(np.arange(a.f_min, a.f_max + 0.5 * a.df, a.df), 10)
    res = orifice_band.study(scene, widths, freqs, workers=a.workers)
    rows = []
    for r in res["rows"]:
        sc = scene.replace(params={"r_laminar": r["r_laminar"]})
        p = sc.build_params()
        lam = stiffest_pole(p, config_of(sc), operating_height(sc, p))
        t0 = time.perf_counter()
        mj = run(sc)
        wall_mj = time.perf_counter() - t0
        rows.append([r["width"], r["max_amp_rel"], r["at_f_amp"], np.degrees(r["max_phase_rad"]), r["at_f_phase"],
                     r["start"], lam, lam * sc.solver.timestep, r["nfev"], r["wall_s"], mj.stats["steps"], wall_mj])
    print(format_table(["band 1-r", "amp change", "at f", "phase change (deg)", "at f", "start change",
                        "cylinder pole (1/s)", "h |pole| (RK4)", "ref RHS calls", "ref wall (s)", "MuJoCo steps",
                        "MuJoCo wall (s)"], rows, ".3g"))
    print(f"change from w to w/10 over {freqs[0]:g}-{freqs[-1]:g} Hz ({len(freqs)} frequencies); criterion "
          f"{orifice_band.TOLERANCE:g}")


if __name__ == "__main__":
    main()
