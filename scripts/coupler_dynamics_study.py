"""MuJoCo double-coupler study: every shipped scene against the kinematics, the closure residual vs solref time
constant (residual ~ tau^2), convergence of the massless-link limit, and time-series plots of the default scene.

Every MuJoCo run is one call of mbsuite's native core (the step loop in C, the GIL released), so the runs of each table
go through `engines.core.map_threads` and use all cores; the results are those of a serial loop.

    .venv/bin/python scripts/coupler_dynamics_study.py [OUT_DIR]      (default out/coupler_dynamics)
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import mbsuite
from mbsuite.engines.core import map_threads
from mbsuite.models.coupler import SPEC
from mbsuite.models.coupler.plots import dynamics_figure
from mbsuite.plotting import save
from mbsuite.results import format_table
from mbsuite.scenes import load_scene
from mbsuite.trust.estimate import declared

KEYS = ("phi_c_err_max", "phi_c_kin_fluctuation_pp", "closure_residual_max", "torque_in_mean", "torque_in_ripple_pp",
        "link_force_max_abs")


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/coupler_dynamics")
    out.mkdir(parents=True, exist_ok=True)
    names = sorted(SPEC.scene_files())
    scenes = {n: load_scene(f"coupler/{n}") for n in names}
    runs = map_threads(lambda name: (mbsuite.run(scenes[name]), mbsuite.run(scenes[name], engine="reference")), names)

    def pm(sc, res, key: str) -> str:  # value +- the declared tolerance of the path's headline (if it is one)
        tol = {h.name: h.tol for h in declared(sc.replace(solver={"engine": res.engine}))}.get(key)
        return f"{res.statistics[key]:.6g}" + ("" if tol is None else f" ± {tol:.2g}")

    rows = [[name, *(pm(scenes[name], r, k) for k in KEYS), pm(scenes[name], rr, "torque_in_ripple_pp"),
             len(r.stats["warnings"])] for name, (r, rr) in zip(names, runs, strict=True)]
    print("shipped scenes (window after t_settle; reference = rigid shafts, massless links, no gravity/friction;\n"
          "± the declared tolerance where the number is a headline, mbsuite/models/coupler/accuracy.py)")
    print(format_table(["scene", *KEYS, "ripple_ref", "warnings"], rows, ".4g"))

    # the studies below push the closures past the health bound on purpose (tau = 8 ms tears them open in the ramp)
    base = load_scene("coupler/double_lateral").replace(effects={"gravity": False}, solver={"allow_inaccurate": True})
    taus = (1e-3, 2e-3, 4e-3, 8e-3)
    runs = map_threads(lambda tau: mbsuite.run(base.replace(params={"solref_timeconst": tau})), taus)
    rows = [[tau, *(r.statistics[k] for k in ("closure_residual_max", "phi_c_err_max", "torque_in_ripple_pp"))]
            for tau, r in zip(taus, runs, strict=True)]
    print("\nsolref time constant (timestep 5e-4 s, dampratio 1): residual scales ~ tau^2")
    print(format_table(["timeconst", "closure_res_max", "phi_c_err_max", "ripple_pp"], rows, ".4g"))

    facs = (1.0, 0.3, 0.1, 0.05)
    runs = map_threads(lambda fac: mbsuite.run(base.replace(effects={"link_inertia": "massless"}, params={
        "massless_factor": fac, "solref_timeconst": 1e-3})), facs)
    rows = []
    for fac, r in zip(facs, runs, strict=True):
        f = np.array(r.statistics["link_force_mean"])
        rows.append([fac, r.statistics["torque_in_ripple_pp"], float(np.mean(np.abs(f))), float(np.ptp(np.abs(f))),
                     r.statistics["closure_residual_max"]])
    print("\nmassless-link limit (link mass x factor, no gravity): |mean link force| spread -> 0")
    print(format_table(["factor", "ripple_pp", "mean|F|", "spread|F|", "closure_res"], rows, ".4g"))

    r = mbsuite.run(load_scene("coupler/double_lateral"))
    path = save(dynamics_figure(r), out / "double_lateral_timeseries.png")
    print(f"\nwrote {path}")

if __name__ == "__main__":
    main()
