"""The README's remaining measured numbers: the thesis' velocity-band scheme against the exact path, the MuJoCo
timestep study of the 500 W drive, the brake slip with the rated brake torque, the Coulomb-load reversal cost.

Usage: .venv/bin/python scripts/drives_extras.py   (about 1 minute)
"""

from __future__ import annotations

import numpy as np

from mbsuite.components.rotational.event_exact import simulate_reference
from mbsuite.components.rotational.interfaces import Friction, Part, RotorSystem, Spring
from mbsuite.components.rotational.velocity_band import simulate_velocity_band
from mbsuite.models.drives import drive
from mbsuite.models.drives.analysis import simulate_scene
from mbsuite.models.drives.scene_run import setup
from mbsuite.models.rotational import coupled_clutches as cc
from mbsuite.results import format_table
from mbsuite.scenes import load_scene


def main() -> None:
    rows: list[list] = []
    # velocity band on CoupledClutches: w error against Dymola on the 0.1 s grid (exact path: see the CC script)
    ref = cc.load_reference()
    grid = np.round(np.arange(0.0, cc.T_END + 1e-9, 0.1), 10)
    j = [int(np.nonzero(np.isclose(ref["t"], tt))[0][-1]) for tt in grid]
    for label, res in (("exact", simulate_reference(cc.build_system(), cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)),
                       ("velocity band", simulate_velocity_band(cc.build_system(), cc.Q0, cc.W0, cc.T_END,
                                                                sample_dt=5e-4))):
        i = [int(np.argmin(np.abs(res.t - tt))) for tt in grid]
        err = np.max(np.abs(res.w[:, i] - ref["w"][:, j]))
        rows.append([f"CoupledClutches {label}: max |w - Dymola| (rad/s)", f"{err:.2g}"])
    # velocity band on the matched resonant step-up drive
    # (open loop: no speed reference acts, the scene gives none; its system and a fresh controller as the run uses)
    sc = load_scene("drives/step_up_resonant_matched")
    exact, ctrl_e, _ = simulate_scene(sc)
    run = setup(sc)
    sys_, ctrl = run.system, run.controller
    band = simulate_velocity_band(sys_, run.q0, run.w0, sc.solver.duration, controller=ctrl,
                                  sample_dt=run.sample_dt)
    se, sb = drive.cycle_stats(exact, ctrl_e, sc.solver.t_settle), drive.cycle_stats(band, ctrl, sc.solver.t_settle)
    rows.append(["step_up_resonant_matched: velocity band vs exact mean load speed",
                 f"{100 * (sb['mean_load_speed'] / se['mean_load_speed'] - 1):+.2f} %"])
    be, bb = drive.energy_balance(sys_, exact).relative, drive.energy_balance(sys_, band).relative
    rows.append(["step_up_resonant_matched: energy balance exact / velocity band", f"{be:.2g} / {bb:+.2g}"])
    # rated brake torque 1.1 N m with the added motor inertia: the brake slips
    for tb in (1.1, 1.7):
        s2 = load_scene("drives/step_up_added_inertia").replace(params={"tau_b": tb})
        res, ctrl2, sy = simulate_scene(s2)
        i0 = int(np.searchsorted(res.t, s2.solver.t_settle))
        bal = drive.energy_balance(sy, res, i0, -1)
        T = res.t[-1] - res.t[i0]
        rows.append([f"step_up_added_inertia, tau_b = {tb}: brake slip loss (W); max twist (rad)",
                     f"{bal.losses['brake'] / T:.3g}; {np.max(np.abs(res.q[0] - res.q[1])):.2f}"])
    # Coulomb load on a spring: reversals and function evaluations
    sysc = RotorSystem(names=["motor", "spring", "load"], J=np.array([1.0, 1.0, 1e-3]), B=np.zeros(3),
                       springs=[Spring("k", 2, -1, 1.0)],
                       frictions=[Friction("load_ground", 2, -1, [Part("load", 0.05, output=True)])])
    res = simulate_reference(sysc, [0, 0, 1.0], [0, 0, 0], 2.0, sample_dt=1e-3)
    n_rev = sum(1 for e in res.events if "stuck" not in (e["from"], e["to"]))
    rows.append(["Coulomb load on a spring, 2 s: reversals; function evaluations", f"{n_rev}; {res.stats['nfev']}"])
    # MuJoCo timestep study, 500 W open loop (mean load speed over t >= t_settle)
    s5 = load_scene("drives/susd_500w_open")
    ex, c5, _ = simulate_scene(s5)
    out = [f"exact {drive.cycle_stats(ex, c5, s5.solver.t_settle)['mean_load_speed']:.1f}"]
    for dt in (1e-4, 5e-5, 2e-5):
        r5, c5m, _ = simulate_scene(s5.replace(solver={"engine": "mujoco", "timestep": dt}))
        out.append(f"dt {dt:g}: {drive.cycle_stats(r5, c5m, s5.solver.t_settle)['mean_load_speed']:.1f}")
    rows.append(["susd_500w_open mean load speed (rad/s): MuJoCo timestep study", "; ".join(out)])
    print(format_table(["quantity", "value"], rows))


if __name__ == "__main__":
    main()
