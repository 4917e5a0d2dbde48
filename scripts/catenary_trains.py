"""Two pantographs on one train: the shipped scene `catenary/en50318_two_pantographs` (14 spans, 200 m apart) at
250 and 300 km/h with the 2-mass reference pantographs (dt 2e-4 s) and with two Eppinger pantographs on each engine
path (dt 1e-4 s, the Eppinger scenes' step; Table 3-I pressure), each pantograph's eight statistics and its quality
verdict (AC criteria), printed and written as JSON.

    .venv/bin/python scripts/catenary_trains.py [--speeds 250 300] [--spacing 200] [--out out/catenary_trains]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.quality import QualityCriteria, assess
from mbsuite.models.catenary.reports import STAT_KEYS
from mbsuite.models.catenary.train import simulate_train
from mbsuite.results import format_table


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=float, nargs="+", default=[250.0, 300.0])
    ap.add_argument("--spacing", type=float, default=200.0)
    ap.add_argument("--cases", nargs="+", default=["2mass", "eppinger-reference", "eppinger-mujoco"])
    ap.add_argument("--out", default="out/catenary_trains")
    ap.add_argument("--convergence", action="store_true",
                    help="instead: mesh/step convergence of both 2-mass pantographs' statistics at (0.5 m, 2e-4 s), "
                         "(0.25 m, 1e-4 s), (0.125 m, 5e-5 s)")
    a = ap.parse_args()
    if a.convergence:
        convergence(a)
        return
    p = CatenaryParams(element_length=0.5, n_spans=14)
    crit = QualityCriteria()
    rows, data = [], []
    for case in a.cases:
        for v in a.speeds:
            if case == "2mass":
                names, eng, dt = ["reference2mass", "reference2mass"], "reference", 2e-4
            else:
                names, eng, dt = ["eppinger", "eppinger"], case.split("-")[1], 1e-4
            c0 = time.process_time()
            run = simulate_train(p, v, dt, names, [a.spacing], engine=eng)
            cpu = time.process_time() - c0
            for k, s in enumerate(run.stats):
                q = assess(s, v, crit, s["n_samples_window"] * dt)
                role = "leading" if k == 0 else "trailing"
                rows.append([case, v, role, *[f"{s[key]:.2f}" for key in STAT_KEYS], f"{run.static_forces[k]:.2f}",
                             "pass" if q["pass"] else "FAIL: " + ",".join(n for n, r in q["rows"].items()
                                                                           if not r["pass"]), f"{cpu:.1f}"])
                data.append({"case": case, "speed_kmh": v, "role": role, "engine": run.engines[k],
                             "statistics": {key: s[key] for key in STAT_KEYS},
                             "static_force": run.static_forces[k], "quality": q, "cpu_s": cpu})
            print(rows[-2], rows[-1], flush=True)
    print(format_table(["case", "km/h", "pantograph", *STAT_KEYS, "static F (N)", "quality (AC)", "CPU (s)"], rows))
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "trains.json").write_text(json.dumps(data, indent=1, default=float))


def convergence(a: argparse.Namespace) -> None:
    rows = []
    for v in a.speeds:
        for h, dt in ((0.5, 2e-4), (0.25, 1e-4), (0.125, 5e-5)):
            p = CatenaryParams(element_length=h, n_spans=14)
            c0 = time.process_time()
            run = simulate_train(p, v, dt, ["reference2mass", "reference2mass"], [a.spacing])
            cpu = time.process_time() - c0
            for k, s in enumerate(run.stats):
                rows.append([v, h, dt, "leading" if k == 0 else "trailing", *[f"{s[key]:.2f}" for key in STAT_KEYS],
                             f"{cpu:.1f}"])
            print(rows[-2], rows[-1], flush=True)
    print(format_table(["km/h", "h (m)", "dt (s)", "pantograph", *STAT_KEYS, "CPU (s)"], rows))


if __name__ == "__main__":
    main()
