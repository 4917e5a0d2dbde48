"""Study (not a test): the declared accuracy of the drives and of the Modelica Rotational examples (the model
`rotational`, on the same rotor library) measured on every shipped scene and both paths.

For each scene and path: the headline values at the scene's settings (level 0) and refined once and twice (the
error estimate of `mbsuite.trust.estimate`: hand path rtol / 10 per level, MuJoCo step / 2 per level), and a much finer
run for the true error (hand path rtol 1e-12, atol 1e-14; MuJoCo the step / FINE). One Markdown row per headline:
value, declared tolerance, estimated error, observed order, true error, estimate / true error. The tolerances of
`mbsuite/models/drives/accuracy.py` and `mbsuite/models/rotational/accuracy.py` are set a stated factor above the
largest numbers of this table. A scene is `model/scene` (a bare name is a drives scene).

    nice .venv/bin/python scripts/drives_accuracy.py [scene ...] [--engines reference mujoco] [--workers 2] \
        [--json out/drives_accuracy.jsonl]
    .venv/bin/python scripts/drives_accuracy.py --summary out/drives_accuracy.jsonl   # the README's table

`--summary` condenses the JSON lines to one row per scene and path: per headline kind (event count, speeds,
efficiency, lock-up times, end speeds) the largest estimate and the largest true error.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time

from mbsuite import load_scene
from mbsuite.analysis.errorestimate import error_estimate, run_values
from mbsuite.trust.estimate import declared

#: how much finer than the scene's step the MuJoCo "true" run is
FINE = 16


def fine_scene(sc):
    """The much finer run of the scene's path (the true error's reference)."""
    if sc.solver.engine == "mujoco":
        return sc.replace(solver={"timestep": sc.solver.timestep / FINE, "max_steps": sc.solver.max_steps * FINE})
    return sc.replace(solver={"rtol": 1e-12, "atol": 1e-14})


#: headline kinds of the summary: name prefix -> column
KINDS = {"n_events": "events", "mean_": "speeds (rad/s)", "efficiency": "efficiency", "t_lock": "lock-ups (s)",
         "w_end": "end speeds (rad/s)"}


def _kind(name: str) -> str:
    return next(v for k, v in KINDS.items() if name.startswith(k))


def summary(path: str) -> None:
    """One Markdown row per scene and path from the JSON lines of a run of this script: per kind the largest
    estimate / the largest true error (events: the counts' spread)."""
    rows: dict[tuple[str, str], dict[str, list[float]]] = {}
    for line in open(path):
        r = json.loads(line)
        d = rows.setdefault((r["scene"], r["engine"]), {})
        k = _kind(r["name"])
        e, t = d.get(k, [0.0, 0.0])
        d[k] = [max(e, r["error"]), max(t, r["true_error"])]
    kinds = list(KINDS.values())
    print("| scene | path | " + " | ".join(f"{k}: est. / true" for k in kinds) + " |")
    print("|---|---|" + "---|" * len(kinds))
    for (scene, eng), d in rows.items():
        cells = [("–" if k not in d else (f"{d[k][0]:.0f} / {d[k][1]:.0f}" if k == "events"
                                         else f"{d[k][0]:.2g} / {d[k][1]:.2g}")) for k in kinds]
        print(f"| {scene} | {eng} | " + " | ".join(cells) + " |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*")
    ap.add_argument("--engines", nargs="*", default=["reference", "mujoco"])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", default=None, help="also write every row as JSON lines to this file")
    ap.add_argument("--summary", default=None, metavar="JSONL", help="only condense a previous run's JSON lines")
    a = ap.parse_args()
    if a.summary:
        summary(a.summary)
        return
    names = [n if "/" in n else f"drives/{n}" for n in a.scenes] or [
        f"{model}/{n}" for model in ("drives", "rotational") for n in sorted(load_scene(model).spec.scene_files())]
    out = open(a.json, "a") if a.json else None  # noqa: SIM115 - appended row by row
    print("| scene | path | headline | value | tol | est. error | observed order | true error | est / true |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in names:
        for eng in a.engines:
            sc = load_scene(name).replace(solver={"engine": eng, "allow_inaccurate": True})
            t0 = time.perf_counter()
            est = error_estimate(sc, workers=a.workers)
            t1 = time.perf_counter()
            fine = run_values(fine_scene(sc).to_dict())
            t2 = time.perf_counter()
            tol = {h.name: h.tol for h in declared(sc)}
            for r in est.rows:
                true = abs(r.value - fine[r.name])
                ratio = r.error / true if true > 0 else math.inf
                order = "-" if r.order is None else f"{r.order:.2f}"
                print(f"| {name} | {eng} | {r.name} | {r.value:.10g} | {tol[r.name]:.3g} | {r.error:.3g} | {order} | "
                      f"{true:.3g} | {ratio:.3g} |", flush=True)
                if out:
                    out.write(json.dumps({"scene": name, "engine": eng, **r.to_dict(), "fine": fine[r.name],
                                          "true_error": true, "levels": est.settings}) + "\n")
                    out.flush()
            print(f"{name} {eng}: estimate {t1 - t0:.1f} s, fine run {t2 - t1:.1f} s", file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
