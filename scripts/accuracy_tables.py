"""Study (not a test): the work-precision tables of docs/accuracy.md, printed as Markdown.

For every scene given (default: the scenes of docs/accuracy.md) the model's work-precision study runs
(`mbsuite.analysis.workprecision.workprecision`, medians of `--repeats` runs), and the script prints the headline table
(the cheapest setting reaching 1e-2, 1e-4, 1e-6 relative physics error: overall, on MuJoCo, on the other paths; the
catenary's physics error is in units of its declared tolerance, so its levels are 1, 0.1 and 0.01 of it) and one
section per scene with its reference, its cheapest settings and all its settings (the catenary's also per speed and
pantograph, in N and mm).

    python scripts/accuracy_tables.py [--repeats 5] [--cache out/workprecision] [scene ...] > tables.md
    python scripts/accuracy_tables.py --summaries DIR/summary.json ... > tables.md  # of `mbsuite workprecision --out`

`--cache DIR` keeps the catenary's reference passages (its finest meshes) in DIR, keyed by the scene, the resolution
and the catenary's code, so that a rerun with unchanged code does not recompute them.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from mbsuite import load_scene
from mbsuite.analysis.workprecision import TOLS, Row, workprecision

SCENES = ("pantograph/lab", "pantograph/unilateral", "pantograph/nonlinear_cylinder", "coupler/double_lateral",
          "coupler/double_massless", "coupler/double_inclined", "coupler/double_phibc90", "coupler/double_friction",
          "rotational/coupled_clutches", "drives/step_up_pwm", "drives/step_up_resonant_matched",
          "drives/susd_100w_design", "drives/susd_500w_open", "iftomm/fourbar", "catenary/en50318",
          "catenary/en50318_two_pantographs")
#: tolerance levels of a model whose physics error is not relative (the catenary's: in units of its declared
#: tolerance, 1 N / 0.5 mm / 0.05 % + 10 % of the loss)
MODEL_TOLS = {"catenary": (1.0, 0.1, 0.01)}


def _s(x) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def _best(rows: list[Row], tol: float, engines: set[str] | None, exclude: set[str] | None = None) -> Row | None:
    ok = [r for r in rows if r.error is None and r.physics_error <= tol and (engines is None or r.engine in engines)
          and (exclude is None or r.engine not in exclude)]
    return min(ok, key=lambda r: r.time_s) if ok else None


def _cell(r: Row | None, with_engine: bool = True, with_err: bool = False) -> str:
    if r is None:
        return "not reached"
    head = f"{r.engine} {r.method} {_s(r.setting)}" if with_engine else f"{r.method} {_s(r.setting)}"
    return f"{head} ({r.time_s:.3g}" + (f"; {r.physics_error:.1e})" if with_err else ")")


def _per_speed(rows: list[Row], d: dict) -> list[str]:
    """The catenary's errors per speed and pantograph (the details `<speed>kmh_p<k>_force_N` / `_uplift_mm` /
    `_loss_pct` of each row), the reference's check first; nothing for a study without them."""
    ok = [r for r in rows if r.error is None]
    if not ok or not any(k.endswith("_force_N") for k in ok[0].details):
        return []
    keys = [k[: -len("_force_N")] for k in ok[0].details if k.endswith("_force_N")]
    head = "| setting | median s | " + " | ".join(f"{k.replace('kmh_', ' km/h ')} F (N) / uplift (mm) / loss (%)"
                                                   for k in keys) + " |"
    out = ["Errors per speed and pantograph (largest force-statistic error, uplift error, contact-loss error):", "",
           head, "|---|---|" + "---|" * len(keys)]

    def cells(det: dict) -> str:
        return " | ".join(f"{det[k + '_force_N']:.2g} / {det[k + '_uplift_mm']:.2g} / {det[k + '_loss_pct']:.2g}"
                          for k in keys)

    for c in d.get("checks", []):
        out.append(f"| check: {c['check']} (against the reference) | – | {cells(c['details'])} |")
    for r in ok:
        out.append(f"| {r.method}, {_s(r.setting)} | {r.time_s:.3g} | {cells(r.details)} |")
    return [*out, ""]


def _studies(a: argparse.Namespace):
    """(scene, study data) of each scene: read from the given summaries, or run here."""
    if a.summaries:
        for f in a.summaries:
            d = json.loads(f.read_text())["results"]
            yield (d["scene"] if "/" in d["scene"] else f"{d['model']}/{d['scene']}"), d
        return
    for ref in a.scenes:
        print(f"running {ref} ...", file=sys.stderr, flush=True)
        yield ref, workprecision(load_scene(ref), repeats=a.repeats, quick=a.quick).data


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", default=list(SCENES))
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="each study's quick settings (a check of the tables)")
    ap.add_argument("--cache", type=Path, default=None, help="directory for the catenary's reference passages")
    ap.add_argument("--summaries", type=Path, nargs="+", default=None,
                    help="instead of running: the summary.json files of `mbsuite workprecision SCENE --out DIR` runs")
    a = ap.parse_args()
    if a.cache is not None:
        from mbsuite.models.catenary.cases import CatenaryStudy

        CatenaryStudy.reference_cache = a.cache
    headline, sections = [], []
    for ref, d in _studies(a):
        tols = MODEL_TOLS.get(d["model"], TOLS)
        rows = [Row(**r) for r in d["rows"]]
        for tol in tols:
            headline.append(f"| {ref} | {tol:g} | {_cell(_best(rows, tol, None))} | "
                            f"{_cell(_best(rows, tol, {'mujoco'}), False, True)} | "
                            f"{_cell(_best(rows, tol, None, {'mujoco'}), False, True)} |")
        sec = [f"### {ref}", ""]
        line = f"Reference: {d.get('reference')}."
        if "check_physics_error" in d:
            line += (f" Its own accuracy ({d['check']}): state {d['check_state_error']:.1e}, "
                     f"physics {d['check_physics_error']:.1e}.")
        sec += [line, f"State error: {d['state_error']}. Physics metric: {d['physics_error']}.", "",
                "| tol | cheapest overall | median s | physics err | cheapest MuJoCo | median s | cheapest other | "
                "median s |", "|---|---|---|---|---|---|---|---|"]
        for tol in tols:
            b, m, o = (_best(rows, tol, None), _best(rows, tol, {"mujoco"}), _best(rows, tol, None, {"mujoco"}))

            def name(r):
                return f"{r.engine} {r.method} {_s(r.setting)}" if r else "not reached"

            sec.append(f"| {tol:g} | {name(b)} | {f'{b.time_s:.3g}' if b else '–'} | "
                       f"{f'{b.physics_error:.1e}' if b else '–'} | {name(m)} | {f'{m.time_s:.3g}' if m else '–'} | "
                       f"{name(o)} | {f'{o.time_s:.3g}' if o else '–'} |")
        sec += ["", "<details><summary>all settings</summary>", "",
                "| engine | method | h / rtol / setting | median s | min–max s | state err | physics err |",
                "|---|---|---|---|---|---|---|"]
        for r in rows:
            if r.error is None:
                sec.append(f"| {r.engine} | {r.method} | {_s(r.setting)} | {r.time_s:.3g} | "
                           f"{r.time_min:.3g}–{r.time_max:.3g} | {r.state_error:.1e} | {r.physics_error:.1e} |")
            else:
                sec.append(f"| {r.engine} | {r.method} | {_s(r.setting)} | diverged: {r.error[:60]} | | | |")
        sec += ["", "</details>", ""]
        sec += _per_speed(rows, d)
        sections.append("\n".join(sec))
    print("| scene | tol | cheapest overall (s) | cheapest MuJoCo (s) | cheapest hand path / FPP (s) |")
    print("|---|---|---|---|---|")
    print("\n".join(headline))
    print()
    print("\n".join(sections))


if __name__ == "__main__":
    main()
