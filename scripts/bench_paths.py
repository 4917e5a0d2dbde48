"""Benchmark (not a test): the MuJoCo path vs the hand-derived path at equal physics-metric accuracy.

For each scene the work-precision study (mbsuite.analysis.workprecision) is run once; for each relative physics-metric
tolerance the cheapest MuJoCo setting and the cheapest hand-derived setting reaching it are put side by side:
ratio = hand time / MuJoCo time (> 1: MuJoCo faster).

    python scripts/bench_paths.py [--repeats 5] [--quick] [scene ...]     (default: pantograph/lab drives/step_up_pwm)
"""

from __future__ import annotations

import argparse

from mbsuite import load_scene
from mbsuite.analysis.workprecision import Row, cheapest, workprecision
from mbsuite.results import format_table

TOLS = (1e-2, 1e-3, 1e-4, 1e-6)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", default=["pantograph/lab", "drives/step_up_pwm"])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    out = []
    for ref in a.scenes:
        rep = workprecision(load_scene(ref), repeats=a.repeats, quick=a.quick)
        rows = [Row(**{k: v for k, v in r.items()}) for r in rep.data["rows"]]
        for tol in TOLS:
            mj = [b for b in cheapest([r for r in rows if r.engine == "mujoco"], (tol,)) if b["engine"] == "any"][0]
            hd = [b for b in cheapest([r for r in rows if r.engine == "reference"], (tol,))
                  if b["engine"] == "any"][0]
            ratio = (hd["time_s"] / mj["time_s"]) if mj["time_s"] and hd["time_s"] else None
            out.append([ref, f"{tol:g}", mj["best_engine"] or "-", mj["setting"] if mj["setting"] is not None else "-",
                        mj["time_s"] if mj["time_s"] else "-", hd["best_engine"] or "-",
                        hd["setting"] if hd["setting"] is not None else "-", hd["time_s"] if hd["time_s"] else "-",
                        ratio if ratio else "-"])
    print(format_table(["scene", "tol", "MuJoCo", "h", "MuJoCo s", "hand path", "rtol", "hand s",
                        "hand / MuJoCo"], out, ".3g"))
    print(f"\nwall time = median of {a.repeats} runs; physics metric and reference: see docs/accuracy.md")


if __name__ == "__main__":
    main()
