"""Cross-check the hand-derived (event-exact) and MuJoCo paths on the drive scenes over >= 20 energy cycles:
lock-up/release times, cycle-averaged load speed, transferred energy packets, energy-balance residuals.

Usage: .venv/bin/python scripts/drives_crosscheck.py [scene ...]   (default: the prototype scenes; ~1 minute)
"""

from __future__ import annotations

import sys

import numpy as np

from mbsuite.models.drives import drive
from mbsuite.models.drives.model import simulate_scene
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
        cmp = drive.compare_events(ra, rb, els)
        max_dt = max(v["max_dt"] for v in cmp.values())
        med_dt = max(v["median_dt"] for v in cmp.values())
        pa, pb = drive.transferred_packets(sys_, ra, "", ca), drive.transferred_packets(sys_, rb, "", cb)
        n = min(pa.size, pb.size)
        pk = f"{100 * abs(pa[:n].sum() / pb[:n].sum() - 1):.2f} / {100 * np.median(np.abs(pa[:n] / pb[:n] - 1)):.2f}" \
            if n else "-"
        ba, bb = drive.energy_balance(sys_, ra), drive.energy_balance(sys_, rb)
        rows.append([name, dur, f"{sa['n_cycles']}/{sb['n_cycles']}", 1e3 * max_dt, 1e3 * med_dt,
                     1e3 / load_scene(f"drives/{name}").build_params().resolved(
                         load_scene(f"drives/{name}").effects["param_set"])["fs"],
                     100 * (sb["mean_load_speed"] / sa["mean_load_speed"] - 1), pk, ba.relative, bb.relative,
                     runs["mujoco"][0].stats["warnings"] or 0])
    print(format_table(["scene", "T_s", "cycles ref/mj", "max_dt_ms", "median_dt_ms", "sample_ms", "load_speed_diff_%",
                        "packets sum/median_%", "balance_ref", "balance_mj", "mj_warnings"], rows, ".3g"))


if __name__ == "__main__":
    main(sys.argv[1:])
