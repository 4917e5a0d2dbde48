"""Convergence of the catenary's EN 50318 statistics: every shipped scene at its defaults against a refined solution.

For every shipped catenary scene, speed and pantograph, every statistic at:
- `default`: the scene as shipped (0.5 m elements with the point-load correction, the scene's time step);
- `plain`: the same resolution without the correction (the plain Hermite wires: the method before it);
- `ref`: the refined solution, the plain Hermite wires at 0.0625 m and dt 5e-5 s (a method that does not use the
  correction), with its own convergence shown by `ref_h` (0.125 m, dt 5e-5 s: the mesh halved) and `ref_dt`
  (0.0625 m, dt 1e-4 s: the step halved).
It prints per scene, speed and pantograph the errors |run - ref| of each statistic and the largest force error, and
writes every run (CSV/JSON) with --out. `--grid` instead runs the element length x time step grid {0.5, 0.25, 0.125} m
x {2e-4, 1e-4, 5e-5} s of one scene with the shipped method (the README's convergence table).

    nice .venv/bin/python scripts/catenary_convergence.py --workers 2 --out out/catenary_convergence
    nice .venv/bin/python scripts/catenary_convergence.py --scenes catenary --grid --out out/catenary_grid
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from mbsuite.models.catenary.analysis import scene_config
from mbsuite.models.catenary.config import CriticalSpeedWarning
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.stats import STAT_NAMES
from mbsuite.models.catenary.train import run_passage
from mbsuite.results import format_table, to_jsonable
from mbsuite.scenes import load_scene

SCENES = ("catenary/en50318", "catenary/en50318_linear", "catenary/en50318_two_pantographs",
          "catenary/en50318_eppinger", "catenary/eppinger_lab")
KEYS = list(STAT_NAMES)
FORCE = [k for k in KEYS if k not in ("uplift_mm", "loss_pct")]
#: label -> (element length or None for the scene's, time step or None for the scene's, point correction)
LEVELS = {"default": (None, None, True), "plain": (None, None, False), "ref": (0.0625, 5e-5, False),
          "ref_h": (0.125, 5e-5, False), "ref_dt": (0.0625, 1e-4, False)}
GRID_H, GRID_DT = (0.5, 0.25, 0.125), (2e-4, 1e-4, 5e-5)


def passage(scene_name: str, speed: float, h: float | None, dt: float | None, correction: bool) -> dict:
    """Statistics of every pantograph of one passage of the scene (its `[train]`, on its path) and its CPU time."""
    scene = load_scene(scene_name)
    p = scene.build_params()
    over = {"max_element_steps": 1e13} if h is None else {"element_length": h, "max_element_steps": 1e13}
    sc = scene.replace(params=over, solver={"timestep": dt or scene.solver.timestep, "max_steps": 1e9,
                                           "allow_inaccurate": True})
    c0 = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CriticalSpeedWarning)
        cfg = scene_config(sc, sc.solver.engine, speed_kmh=speed)
        run = run_passage(cfg, fe=assemble(cfg.params, point_correction=correction))
    return {"scene": scene_name, "speed": speed, "element_length": cfg.params.element_length, "dt": cfg.dt,
            "correction": correction, "cpu_s": time.process_time() - c0, "default_h": p.element_length,
            "stats": [{k: float(s[k]) for k in KEYS} for s in run.stats]}


def _job(args: tuple) -> dict:
    label, scene_name, speed, h, dt, corr = args
    return {"label": label, **passage(scene_name, speed, h, dt, corr)}


def _errors(a: dict, b: dict) -> dict[str, float]:
    return {k: abs(a[k] - b[k]) for k in KEYS}


def report(rows: list[dict]) -> dict:
    """Per scene, speed and pantograph: the default's, the plain method's and the reference checks' errors against
    the reference; printed, and returned for the JSON."""
    out: dict = {}
    for scene in dict.fromkeys(r["scene"] for r in rows):
        for v in sorted({r["speed"] for r in rows if r["scene"] == scene}):
            rs = {r["label"]: r for r in rows if r["scene"] == scene and r["speed"] == v}
            if "ref" not in rs:
                continue
            ref = rs["ref"]["stats"]
            table = []
            for k, rstat in enumerate(ref):
                for label in ("default", "plain", "ref_h", "ref_dt"):
                    if label not in rs:
                        continue
                    e = _errors(rs[label]["stats"][k], rstat)
                    out.setdefault(scene, {}).setdefault(f"{v:g}", {}).setdefault(f"p{k + 1}", {})[label] = e
                    table.append([f"p{k + 1}", label, *[f"{e[s]:.3f}" for s in KEYS],
                                  f"{max(e[s] for s in FORCE):.3f}", f"{rs[label]['cpu_s']:.1f}"])
                table.append([f"p{k + 1}", "ref value", *[f"{rstat[s]:.2f}" for s in KEYS], "",
                              f"{rs['ref']['cpu_s']:.1f}"])
            print(f"\n{scene} at {v:g} km/h: |statistic - ref| (ref: plain Hermite wires, 0.0625 m, dt 5e-5 s)")
            print(format_table(["pantograph", "run", *KEYS, "max force", "CPU (s)"], table))
    return out


def grid(scene_name: str, speeds: list[float], workers: int) -> list[dict]:
    """The element length x time step grid of the scene with the shipped method, printed per speed."""
    jobs = [(f"h{h:g}_dt{dt:g}", scene_name, v, h, dt, True) for v in speeds for h in GRID_H for dt in GRID_DT]
    rows = _map(jobs, workers)
    for v in speeds:
        rs = {r["label"]: r for r in rows if r["speed"] == v}
        print(f"\n{scene_name} at {v:g} km/h, point-load correction, every statistic (pantograph 1)")
        print(format_table(["h (m)", "dt (s)", *KEYS, "CPU (s)"],
                           [[h, dt, *[f"{rs[f'h{h:g}_dt{dt:g}']['stats'][0][k]:.2f}" for k in KEYS],
                             f"{rs[f'h{h:g}_dt{dt:g}']['cpu_s']:.1f}"] for h in GRID_H for dt in GRID_DT]))
    return rows


def _map(jobs: list[tuple], workers: int) -> list[dict]:
    if workers > 1:
        with ProcessPoolExecutor(workers) as ex:
            return list(ex.map(_job, jobs))
    return [_job(j) for j in jobs]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=list(SCENES))
    ap.add_argument("--speeds", type=float, nargs="+", default=[250.0, 300.0])
    ap.add_argument("--levels", nargs="+", default=list(LEVELS), choices=list(LEVELS))
    ap.add_argument("--grid", action="store_true", help="the element length x time step grid of each scene")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    if a.grid:
        rows = [r for s in a.scenes for r in grid(s, a.speeds, a.workers)]
        summary = {}
    else:
        # the costliest runs first, so that the pool ends together
        jobs = [(lab, s, v, *LEVELS[lab]) for lab in ("ref", "ref_dt", "ref_h", "plain", "default")
                if lab in a.levels for s in a.scenes for v in a.speeds]
        rows = _map(jobs, a.workers)
        summary = report(rows)
    if a.out:
        out = Path(a.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / ("grid.json" if a.grid else "convergence.json")).write_text(
            json.dumps(to_jsonable({"rows": rows, "errors": summary}), indent=1))


if __name__ == "__main__":
    main()
