"""The coupler's declared accuracy, measured: for every shipped scene on both paths, each headline's value at the
scene's default settings, its error estimate (`mbsuite run coupler/<scene> --error-estimate`: the run refined once and
twice), and its true error against a much refined run of another method (MuJoCo: RK4 at h/8 sampled every
sample_dt/16; the kinematic reference: sample_dt/16), with the declared tolerance (`coupler.accuracy.TOL`).

    python scripts/coupler_accuracy.py [--scenes double_lateral,...] [--engines mujoco,reference] [--json FILE]

The tolerances in `mbsuite/models/coupler/accuracy.py` are set from this table (a stated factor above the largest
estimate and true error); the slow test `tests/coupler/test_accuracy.py` asserts them against the same refined runs.
"""

from __future__ import annotations

import argparse
import json

import mbsuite
from mbsuite.models.coupler.accuracy import much_refined
from mbsuite.results import format_table
from mbsuite.trust.estimate import declared

SCENES = ("double_lateral", "double_massless", "double_inclined", "double_phibc90", "double_friction")


def measure(name: str, engine: str, workers: int = 2) -> list[dict]:
    """One row per headline of coupler/<name> on `engine`: value, estimate, observed order, true error, tol."""
    sc = mbsuite.load_scene(f"coupler/{name}").replace(solver={"engine": engine, "allow_inaccurate": True})
    res = mbsuite.run(sc, error_estimate=True, workers=workers)
    fine_sc = much_refined(sc)
    fine = sc.spec.accuracy.values(fine_sc, mbsuite.run(fine_sc))
    heads = {h.name: h for h in declared(sc)}
    return [{"scene": name, "engine": engine, "headline": r.name, "unit": r.unit, "value": r.value,
             "estimate": r.error, "order": r.order, "true": abs(r.value - fine[r.name]), "tol": heads[r.name].tol}
            for r in res.error_estimate.rows]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--engines", default="mujoco,reference")
    ap.add_argument("--json", help="also write the rows to this JSON file")
    args = ap.parse_args()
    rows = [r for s in args.scenes.split(",") for e in args.engines.split(",") for r in measure(s, e)]
    print(format_table(["scene", "engine", "headline", "unit", "value", "estimate", "order", "true error", "tol",
                        "tol / max"],
                       [[r["scene"], r["engine"], r["headline"], r["unit"], r["value"], r["estimate"],
                         "-" if r["order"] is None else f"{r['order']:.2f}", r["true"], r["tol"],
                         r["tol"] / max(r["estimate"], r["true"], 1e-300)] for r in rows], ".3g"))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
