"""The pantograph's declared accuracy measured: for every shipped scene (and a step and a static input) on both paths,
each headline's value at the scene's defaults, its error estimate (the scene refined once and twice,
`mbsuite.analysis.errorestimate`), and its true error against much finer runs of both paths (MuJoCo at 1/16 of the
step, the event-exact reference at rtol 1e-11). The tolerances of `mbsuite/models/pantograph/accuracy.py` are set a
stated factor above the largest of these.

    python scripts/pantograph_accuracy.py                    # every scene, both paths (minutes; the reference is slow)
    python scripts/pantograph_accuracy.py --scenes lab --paths mujoco
    python scripts/pantograph_accuracy.py --json out/pantograph_accuracy.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import mbsuite
from mbsuite.analysis.errorestimate import error_estimate
from mbsuite.results import format_table
from mbsuite.scenes import scene_from_dict
from mbsuite.trust.estimate import declared

SCENES = ("lab", "unilateral", "nonlinear_cylinder", "step", "static")
#: the finest runs: MuJoCo at 1/16 of the scene's step (its own method refined) and the reference at rtol 1e-11
FINE_MUJOCO, FINE_RTOL = 16, 1e-11


def scene_of(name: str) -> mbsuite.Scene:
    """A shipped scene, or the lab scene under a step (1 mm at 0.1 s) or a static input."""
    if name in ("step", "static"):
        lab = mbsuite.load_scene("pantograph/lab").to_dict()
        inp = {"type": "step", "height": 1e-3, "t_step": 0.1} if name == "step" else {"type": "static"}
        return scene_from_dict({**lab, "input": inp})
    return mbsuite.load_scene(f"pantograph/{name}")


def fine_values(scene: mbsuite.Scene) -> dict[str, dict[str, float]]:
    """Headline values of the finest runs of both paths."""
    acc = scene.spec.accuracy
    s = scene.solver
    mj = scene.replace(solver={"engine": "mujoco", "timestep": s.timestep / FINE_MUJOCO,
                               "max_steps": s.max_steps * FINE_MUJOCO})
    ref = scene.replace(solver={"engine": "reference", "rtol": FINE_RTOL, "atol": FINE_RTOL * 1e-2})
    return {"mujoco_fine": dict(acc.values(mj, mbsuite.run(mj))),
            "reference_fine": dict(acc.values(ref, mbsuite.run(ref)))}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--paths", default="mujoco,reference")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", help="write every number to this file")
    args = ap.parse_args(argv)
    out: dict = {}
    for name in args.scenes.split(","):
        base = scene_of(name)
        t0 = time.perf_counter()
        fine = fine_values(base)
        out[name] = {"fine": fine}
        for path in args.paths.split(","):
            sc = base.replace(solver={"engine": path, "allow_inaccurate": True})
            est = error_estimate(sc, workers=args.workers)
            tol = {h.name: h.tol for h in declared(sc)}
            rows = []
            for r in est.rows:
                t_mj = abs(r.value - fine["mujoco_fine"][r.name])
                t_ref = abs(r.value - fine["reference_fine"][r.name])
                rows.append([r.name, r.unit, r.value, r.error, "-" if r.order is None else f"{r.order:.2f}",
                             t_mj, t_ref, tol[r.name], tol[r.name] / max(r.error, t_mj if path == "mujoco" else t_ref,
                                                                         1e-300)])
            out[name][path] = {"levels": est.settings, "rows": [dict(zip(
                ["name", "unit", "value", "estimate", "order", "true_vs_mujoco_fine", "true_vs_reference_fine",
                 "tol", "tol_over_max"], r, strict=True)) for r in rows]}
            print(f"\n== pantograph/{name} on {path} ({'; '.join(est.settings)})")
            print(format_table(["headline", "unit", "value", "estimate", "observed order", "|v - MuJoCo h/16|",
                                "|v - reference rtol 1e-11|", "tol", "tol / max(own)"], rows, ".3g"), flush=True)
        print(f"({time.perf_counter() - t0:.0f} s)", flush=True)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1, default=float)
    return 0


if __name__ == "__main__":
    sys.exit(main())
