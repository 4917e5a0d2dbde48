"""Convergence of the catenary's EN 50318 statistics: every shipped scene at its defaults against a refined solution.

For every shipped catenary scene, speed and pantograph, every statistic at:
- `default`: the scene as shipped (0.5 m elements with the point-load correction, the scene's time step);
- `plain`: the same resolution without the correction (the plain Hermite wires: the method before it);
- `ref`: the refined solution, the plain Hermite wires at 0.0625 m and dt 5e-5 s (a method that does not use the
  correction), with its own convergence shown by `ref_h` (0.125 m, dt 5e-5 s: the mesh halved) and `ref_dt`
  (0.0625 m, dt 1e-4 s: the step halved).
It prints per scene, speed and pantograph the errors |run - ref| of each statistic and the largest force error, and
writes every run (JSON) with --out, where each run is also kept as it completes (`rows.jsonl`: a study that stopped
resumes without running them again). `--grid` instead runs the element length x time step grid {0.5, 0.25, 0.125} m
x {2e-4, 1e-4, 5e-5} s of each scene with the shipped method (the README's convergence table). `--defects` prints
what the error source is made of: the point-load defect of the Hermite contact and messenger wires against the
continuous tensioned beam, what it does to the droppers, and the elements' wave dispersion. `--ablation` runs the
two-pantograph scene at 300 km/h at 0.5 m with no correction, the springs' only, the contact point's only and both,
against the corrected method at 0.125 m and dt 5e-5 s: the statistics and the filtered forces' differences.

    nice .venv/bin/python scripts/catenary_convergence.py --workers 2 --out out/catenary_convergence
    nice .venv/bin/python scripts/catenary_convergence.py --scenes catenary/en50318 --grid --out out/catenary_grid
    .venv/bin/python scripts/catenary_convergence.py --defects
    nice .venv/bin/python scripts/catenary_convergence.py --ablation
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
import warnings
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from mbsuite.models.catenary.analysis import scene_config
from mbsuite.models.catenary.config import CriticalSpeedWarning
from mbsuite.models.catenary.fe import PointCorrection, assemble, beam_mass, beam_stiffness, series
from mbsuite.models.catenary.params import CatenaryParams
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


def grid(scene_name: str, speeds: list[float], workers: int, store: Path | None) -> list[dict]:
    """The element length x time step grid of the scene with the shipped method, printed per speed."""
    jobs = [(f"h{h:g}_dt{dt:g}", scene_name, v, h, dt, True) for v in speeds for h in GRID_H for dt in GRID_DT]
    rows = _map(jobs, workers, store)
    for v in speeds:
        rs = {r["label"]: r for r in rows if r["speed"] == v}
        print(f"\n{scene_name} at {v:g} km/h, point-load correction, every statistic (pantograph 1)")
        print(format_table(["h (m)", "dt (s)", *KEYS, "CPU (s)"],
                           [[h, dt, *[f"{rs[f'h{h:g}_dt{dt:g}']['stats'][0][k]:.2f}" for k in KEYS],
                             f"{rs[f'h{h:g}_dt{dt:g}']['cpu_s']:.1f}"] for h in GRID_H for dt in GRID_DT]))
    return rows


def defects() -> None:
    """The point-load defect d (m/N) of each wire's Hermite mesh at a node and mid-element (`fe.PointCorrection`: the
    continuous tensioned beam's closed form minus the elements'), the droppers' effective stiffness with both wires'
    nodal defects in series, and the relative frequency error of the elements' waves (Bloch analysis of an infinite
    uniform mesh, consistent mass) against the tensioned beam's omega = k sqrt((T + EI k^2) / rho)."""
    p = CatenaryParams()
    rows = []
    for h in (1.0, 0.5, 0.25, 0.125, 0.0625):
        x = np.arange(41) * h
        cw, mw = PointCorrection.build(x, p.cw_tension, p.cw_EI), PointCorrection.build(x, p.mw_tension, p.mw_EI)
        dc, dm = cw.defect(20, 0.0), mw.defect(20, 0.0)
        kd = series(p.k_dropper, dc + dm)
        rows.append([h, f"{dc:.3g}", f"{cw.defect(20, 0.5):.3g}", f"{dm:.3g}", f"{mw.defect(20, 0.5):.3g}",
                     f"{kd:.0f}", f"{100 * (p.k_dropper / kd - 1):.2f}",
                     f"{100 * p.k_contact * cw.defect(20, 0.5):.2f}"])
    print(f"point-load defect (m/N); contact wire sqrt(EI/T) = {math.sqrt(p.cw_EI / p.cw_tension):.3f} m")
    print(format_table(["h (m)", "CW node", "CW mid", "MW node", "MW mid", "dropper k_eff (N/m)",
                        "plain dropper too stiff by (%)", "CW mid-element / contact compliance (%)"], rows))
    rows = []
    for h in (1.0, 0.5, 0.25, 0.125):
        Ke, Me = beam_stiffness(p.cw_EI, p.cw_tension, h), beam_mass(p.cw_mass, h)
        row = [h]
        for lam in (10.0, 5.0, 3.0, 2.0, 1.5):
            k = 2 * math.pi / lam
            ph = np.exp(1j * k * h)

            def bloch(A: np.ndarray, ph: complex = ph) -> np.ndarray:
                return A[:2, :2] + A[2:, 2:] + A[:2, 2:] * ph + A[2:, :2] / ph

            w = math.sqrt(sla.eigh(bloch(Ke), bloch(Me), eigvals_only=True)[0].real)
            exact = k * math.sqrt((p.cw_tension + p.cw_EI * k * k) / p.cw_mass)
            row.append(f"{w / exact - 1:.1e}")
        rows.append(row)
    print("\ncontact wire waves: relative frequency error of the Hermite elements at wavelength (m)")
    print(format_table(["h (m)", "10", "5", "3", "2", "1.5"], rows))


def ablation() -> None:
    """The two-pantograph scene at 300 km/h, 0.5 m, dt 1e-4 s: no correction, the springs' (droppers, steady arms,
    messenger supports) only, the contact point's only, both; against the corrected method at 0.125 m, dt 5e-5 s.
    Per pantograph: the largest statistic error (N) and the filtered force's rms and largest difference in the window
    (the finer record sampled at the coarser's steps)."""
    from mbsuite.models.catenary.train import simulate_train

    def run(h: float, dt: float, fe_of):
        p = CatenaryParams(n_spans=14, element_length=h)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CriticalSpeedWarning)
            return simulate_train(p, 300.0, dt, ["reference2mass", "reference2mass"], [200.0], fe=fe_of(p))

    def springs_only(p):
        fe = assemble(p)
        return dataclasses.replace(fe, contact=PointCorrection.none(fe.x.size - 1, p.cw_tension))

    def contact_only(p):
        return dataclasses.replace(assemble(p, point_correction=False), contact=assemble(p).contact)

    ref = run(0.125, 5e-5, assemble)
    variants = {"none": lambda p: assemble(p, point_correction=False), "springs only": springs_only,
                "contact only": contact_only, "both (shipped)": assemble}
    rows = []
    for name, fe_of in variants.items():
        r = run(0.5, 1e-4, fe_of)
        for k in range(2):
            x = r.results[k].x
            win = (x >= r.params.window_start) & (x <= r.params.window_end)
            d = r.filtered[k] - ref.filtered[k][::2][:x.size]
            err = max(abs(r.stats[k][s] - ref.stats[k][s]) for s in FORCE)
            rows.append([name, ["leading", "trailing"][k], f"{err:.2f}",
                         f"{abs(r.stats[k]['uplift_mm'] - ref.stats[k]['uplift_mm']):.3f}",
                         f"{np.sqrt(np.mean(d[win] ** 2)):.2f}", f"{np.max(np.abs(d[win])):.2f}"])
    print("two pantographs, 300 km/h, 0.5 m, dt 1e-4 s against the corrected method at 0.125 m, dt 5e-5 s")
    print(format_table(["correction", "pantograph", "max |force statistic error| (N)", "uplift error (mm)",
                        "filtered force rms diff (N)", "max diff (N)"], rows))


def _map(jobs: list[tuple], workers: int, store: Path | None = None) -> list[dict]:
    """Every job's row; with `store` (a JSON-lines file) each row is appended as it completes and a job whose row
    is already there is not run again (a long study resumes where it stopped)."""
    done: dict[str, dict] = {}
    if store is not None and store.exists():
        for line in store.read_text().splitlines():
            row = json.loads(line)
            done[row["job"]] = row
    todo = [j for j in jobs if json.dumps(j) not in done]

    def keep(job: tuple, row: dict) -> None:
        row["job"] = json.dumps(job)
        done[row["job"]] = row
        if store is not None:
            with store.open("a") as fh:
                fh.write(json.dumps(to_jsonable(row)) + "\n")

    if workers > 1 and len(todo) > 1:
        with ProcessPoolExecutor(workers) as ex:
            futures = {ex.submit(_job, j): j for j in todo}
            for fut in as_completed(futures):
                keep(futures[fut], fut.result())
    else:
        for j in todo:
            keep(j, _job(j))
    return [done[json.dumps(j)] for j in jobs]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=list(SCENES))
    ap.add_argument("--speeds", type=float, nargs="+", default=[250.0, 300.0])
    ap.add_argument("--levels", nargs="+", default=list(LEVELS), choices=list(LEVELS))
    ap.add_argument("--grid", action="store_true", help="the element length x time step grid of each scene")
    ap.add_argument("--defects", action="store_true", help="the point-load defects and the elements' dispersion")
    ap.add_argument("--ablation", action="store_true", help="each part of the correction alone (two pantographs)")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    if a.defects:
        return defects()
    if a.ablation:
        return ablation()
    out = Path(a.out) if a.out else None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    store = None if out is None else out / ("grid_rows.jsonl" if a.grid else "rows.jsonl")
    if a.grid:
        rows = [r for s in a.scenes for r in grid(s, a.speeds, a.workers, store)]
        summary = {}
    else:
        # the costliest runs first, so that the pool ends together
        jobs = [(lab, s, v, *LEVELS[lab]) for lab in ("ref", "ref_dt", "ref_h", "plain", "default")
                if lab in a.levels for s in a.scenes for v in a.speeds]
        rows = _map(jobs, a.workers, store)
        summary = report(rows)
    if out is not None:
        (out / ("grid.json" if a.grid else "convergence.json")).write_text(
            json.dumps(to_jsonable({"rows": rows, "errors": summary}), indent=1))


if __name__ == "__main__":
    main()
