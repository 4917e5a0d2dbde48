"""The PWM storage time in controller samples: the step-up drive at duty 0.35, t_l = 0.2 s (hand path).

At 500 Hz the storage phase is duty x t_l x fs = 35 samples; 0.35 * 0.2 * 500 = 34.99999999999999 in binary floating
point, which a plain int() truncates to 34. `commands.time_to_samples` rounds a duration to the nearest sample.
Prints the storage count the controller uses and the mean motor speed, load/motor speed ratio and input energy.

Usage: .venv/bin/python scripts/drives_storage_time.py [--json FILE]   (about 20 s)
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from mbsuite.models.drives import drive
from mbsuite.models.drives.analysis import simulate_scene
from mbsuite.scenes import load_scene


def figures(duty: float = 0.35, t_l: float = 0.2) -> dict[str, float]:
    sc = load_scene("drives/step_up_pwm").replace(params={"duty": duty, "t_l": t_l})
    res, ctrl, _ = simulate_scene(sc)
    t0 = sc.solver.t_settle
    st = drive.cycle_stats(res, ctrl, t0)
    m = res.t >= t0
    return {"duty": duty, "t_l": t_l, "fs": ctrl.fs,
            "storage_samples": int(ctrl.tk_samples),
            "mean_motor_speed": st["mean_motor_speed"], "mean_load_speed": st["mean_load_speed"],
            "load_motor_ratio": st["mean_load_speed"] / st["mean_motor_speed"],
            "E_in_total": float(res.energy["source"][-1]),
            "E_in_window": float(res.energy["source"][-1] - res.energy["source"][np.argmax(m)])}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json")
    a = ap.parse_args()
    out = figures()
    for k, v in out.items():
        print(f"{k:20s} {v:.6g}" if isinstance(v, float) else f"{k:20s} {v}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
