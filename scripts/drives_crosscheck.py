"""Cross-check the hand-derived (event-exact) and MuJoCo paths on the drive scenes over >= 20 energy cycles:
lock-up/release times (paired in order; counts must be equal), controller commands, cycle-averaged load speed,
energy packets (`drive.energy_packets`: energy taken up per extraction), energy-balance residuals. The MuJoCo path runs
its state machine as the native core's stepper (C), the controller in Python at its samples; the same controller
class drives both paths.

Usage: .venv/bin/python scripts/drives_crosscheck.py [scene ...]   (default: the prototype scenes; about 30 s)
"""

from __future__ import annotations

import sys

import numpy as np

from mbsuite.models.drives import drive
from mbsuite.models.drives.analysis import simulate_scene
from mbsuite.results import format_table
from mbsuite.scenes import load_scene

DEFAULT = {"step_up_pwm": 5.0, "step_up_resonant_matched": 5.0, "susd_100w_design": 2.5, "susd_500w_open": 1.4,
           "susd_500w_step": 1.4}


def main(names: list[str]) -> None:
    rows = []
    for name in names or list(DEFAULT):
        dur = DEFAULT.get(name, 3.0)
        runs = {}
        for eng in ("reference", "mujoco"):
            sc = load_scene(f"drives/{name}").replace(solver={"engine": eng, "duration": dur, "t_settle": 0.3})
            runs[eng] = simulate_scene(sc)
        (ra, ca, sys_), (rb, cb, _) = runs["reference"], runs["mujoco"]
        sa, sb = drive.cycle_stats(ra, ca, 0.3), drive.cycle_stats(rb, cb, 0.3)
        els = [f.name for f in sys_.frictions if any(p.command for p in f.parts)]
        blips = drive.short_locks(rb, els, 2.0 * sc.solver.timestep)  # MuJoCo locks lasting < 2 steps
        cmp = drive.compare_events(ra, drive.without_events(rb, blips), els)
        counts_equal = all(v["n_a"] == v["n_b"] for v in cmp.values())
        max_dt = max(v["max_dt"] for v in cmp.values())
        med_dt = max(v["median_dt"] for v in cmp.values())
        n_over = sum(int(np.sum(np.abs(v["dt"]) > 1.0 / ca.fs + 1e-12)) for v in cmp.values() if v["dt"] is not None)
        cmd = drive.compare_commands(ca, cb)
        if sys_.springs[0].b < 0:  # step-up/step-down: energy packets (energy taken up per extraction)
            pa, pb = drive.energy_packets(sys_, ra, ca, 0.3), drive.energy_packets(sys_, rb, cb, 0.3)
            n = min(pa["stored"].size, pb["stored"].size)
            r = np.abs(pa["stored"][:n] / pb["stored"][:n] - 1)
            pk = (f"{n}: {np.median(pa['stored'][:n]):.2f} J; max {100 * r.max():.2f} / "
                  f"sum {100 * abs(pa['stored'][:n].sum() / pb['stored'][:n].sum() - 1):.3f} %") if n else "-"
        else:
            pk = "-"
        ba, bb = drive.energy_balance(sys_, ra), drive.energy_balance(sys_, rb)
        cmd_txt = (f"{len(cmd['flips'])}/{cmd['n']}" if cmd["same_sequence"]
                   else f"logs differ {cmd['n']}/{cmd['n_b']}")
        rows.append([name, dur, f"{sa['n_cycles']}/{sb['n_cycles']}", len(blips), "yes" if counts_equal else "NO",
                     cmd_txt, 1e3 * max_dt, 1e3 * med_dt, n_over, 1e3 / ca.fs,
                     100 * (sb["mean_load_speed"] / sa["mean_load_speed"] - 1), pk, ba.relative, bb.relative,
                     runs["mujoco"][0].stats["warnings"] or 0])
    print(format_table(["scene", "T_s", "cycles ref/mj", "mj locks < 2 steps", "event counts equal",
                        "commands 1 sample apart", "max_dt_ms", "median_dt_ms", "events > 1 sample", "sample_ms",
                        "load_speed_diff_%",
                        "packets n: median; max / sum diff", "balance_ref", "balance_mj", "mj_warnings"], rows, ".3g"))


if __name__ == "__main__":
    main(sys.argv[1:])
