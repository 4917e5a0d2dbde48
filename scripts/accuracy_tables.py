"""Study (not a test): the work-precision tables of docs/accuracy.md, printed as Markdown.

For every scene given (default: the scenes of docs/accuracy.md) the model's work-precision study runs
(`mbsuite.analysis.workprecision.workprecision`, medians of `--repeats` runs), and the script prints the headline table
(the cheapest setting reaching 1e-2, 1e-4, 1e-6 relative physics error: overall, on MuJoCo, on the other paths) and
one section per scene with its reference, its cheapest settings and all its settings.

    python scripts/accuracy_tables.py [--repeats 5] [scene ...] > tables.md
"""

from __future__ import annotations

import argparse
import sys

from mbsuite import load_scene
from mbsuite.analysis.workprecision import TOLS, Row, workprecision

SCENES = ("pantograph/lab", "pantograph/unilateral", "pantograph/nonlinear_cylinder", "coupler/double_lateral",
          "coupler/double_massless", "coupler/double_inclined", "coupler/double_phibc90", "coupler/double_friction",
          "drives/coupled_clutches", "drives/step_up_pwm", "drives/step_up_resonant_matched",
          "drives/susd_100w_design", "drives/susd_500w_open", "iftomm/fourbar")


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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", default=list(SCENES))
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    headline, sections = [], []
    for ref in a.scenes:
        print(f"running {ref} ...", file=sys.stderr, flush=True)
        rep = workprecision(load_scene(ref), repeats=a.repeats)
        d = rep.data
        rows = [Row(**r) for r in d["rows"]]
        for tol in TOLS:
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
        for tol in TOLS:
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
        sections.append("\n".join(sec))
    print("| scene | tol | cheapest overall (s) | cheapest MuJoCo (s) | cheapest hand path / FPP (s) |")
    print("|---|---|---|---|---|")
    print("\n".join(headline))
    print()
    print("\n".join(sections))


if __name__ == "__main__":
    main()
