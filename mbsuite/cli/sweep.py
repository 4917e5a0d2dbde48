"""`mbsuite sweep SCENE --vary SECTION.KEY=VALUES ...`: a parameter study over the product grid of the axes, each point
a run of the scene (`scene_point`), tabulated per signal (min, max, mean) and written as CSV and a plot."""

from __future__ import annotations

import argparse
import functools
import itertools
from pathlib import Path
from typing import Any

from ..analysis.designspace import sections_for
from ..analysis.sweep import check_grid, parse_values, run_sweep, scene_point
from ..errors import MbsuiteError
from ..results import Report, format_table, write_csv
from ..scenes import Scene
from .options import apply_speed, check_workers, load, sweep_options
from .output import emit


def grid_axes(args: argparse.Namespace, scene: Scene, max_points: int) -> list[tuple[str, str, list]]:
    """(section, key, values) of each `--vary SECTION.KEY=VALUES` (read by the one rule, `options.overrides`; a
    KEY may reach into a section of the scene's model), the grid's size checked before it is built."""
    from .options import overrides, scene_sections, section_of

    axes = [(*section_of(o, scene_sections(scene)), parse_values(o.value, max_points=max_points))
            for o in overrides(args).values() if o.flag == "--vary"]
    if not axes:
        raise MbsuiteError("give at least one --vary SECTION.KEY=VALUES")
    check_grid([len(a[2]) for a in axes], max_points=max_points, what="--vary grid")
    return axes


def cmd_sweep(args: argparse.Namespace) -> None:
    """Run the scene (with `--set` applied) at every point of the grid, tabulate the chosen signals, emit the
    report."""
    from .study import apply_sets

    scene = apply_speed(apply_sets(load(args), getattr(args, "set_values", None)), args)
    check_workers(args.workers)
    options = sweep_options(args)
    axes = grid_axes(args, scene, options.max_points)
    combos = list(itertools.product(*[a[2] for a in axes]))
    points, engines = [], set()
    scene_d = scene.to_dict()
    for combo in combos:  # a dotted key nested into its section as by every command (options.resolve)
        sections = sections_for(scene_d, {f"{s}.{n}": v for (s, n, _), v in zip(axes, combo, strict=True)})
        engines.add(scene.replace(origin="on the command line (--vary)", **sections).solver.engine)  # validated
        points.append((scene_d, sections))
    # MuJoCo points run in C threads (the native core releases the GIL), the hand-derived paths in processes
    auto = "threads" if engines == {"mujoco"} else "local"
    estimate = getattr(args, "error_estimate", False)
    levels = LEVELS
    if estimate:
        if scene.spec.accuracy is None:
            raise MbsuiteError(f"model '{scene.model}' declares no headline outputs: no --error-estimate")
        if scene.spec.accuracy.refinement(scene).companions == "coarse":
            levels = COARSE_LEVELS
        points = [(*pt, level) for pt in points for level in levels]  # every point at levels 0, 1, 2 (or -1, -2)
    results = run_sweep(scene_point, points, workers=args.workers, desc="sweep",
                        executor=None if args.executor else auto, options=options)
    if estimate:
        results = point_estimates(scene, points, results, levels, workers=args.workers, options=options)
    rep = sweep_report(scene, axes, combos, results, args.signals)
    if estimate:
        warned = judge_points(scene, axes, combos, results)
        if warned:  # estimates above their tolerances: the sweep kept, flagged (exit 3) unless allowed
            rep.data["warnings"] = warned
            rep.table += "\n" + "\n".join(warned)
            if not scene.solver.allow_inaccurate:
                rep.flag_inaccurate(warned)
    emit(rep, args, scene.to_dict())


#: the levels of a point's error estimate: the run and its refined companions, or its coarse ones (the refined ones
#: then run for the points whose coarse ones fail their check)
LEVELS = (0, 1, 2)
COARSE_LEVELS = (0, -1, -2)


def point_estimates(scene: Scene, points: list[tuple], results: list[dict], levels: tuple[int, ...] = LEVELS, *,
                    workers: int = 0, options=None) -> list[dict]:
    """Fold the three levels of every point into the level-0 result with its `error_estimate`
    (mbsuite.trust.estimate). With `COARSE_LEVELS`, a point whose coarse companions fail (or are not in the
    asymptotic range) gets its refined ones run (all such points in one batch) and their estimate, with the
    fallback's reason."""
    from ..analysis.errorestimate import level_settings
    from ..analysis.sweep.points import FAILED
    from ..trust.estimate import declared, estimate

    out, redo = [], []
    n = len(levels)
    for i in range(0, len(points), n):
        sc = scene.replace(**points[i][1]) if points[i][1] else scene
        ref = sc.spec.accuracy.refinement(sc)
        vals = [r["headlines"] for r in results[i:i + n]]
        r0 = dict(results[i])
        out.append(r0)
        if levels == LEVELS:
            r0["error_estimate"] = estimate(vals, declared(sc), ref)
            continue
        failed = [v[FAILED] for v in vals[1:] if FAILED in v]
        if failed:
            redo.append((r0, i, sc, None, f"refined companions run instead of coarse ones: {failed[0]}"))
            continue
        est = estimate(vals, declared(sc), ref, level_settings(sc, [ref.refine(sc, k) for k in levels]), "coarse")
        if est.passed:
            r0["error_estimate"] = est
        else:
            redo.append((r0, i, sc, est, "refined companions run instead of coarse ones: the coarse companions "
                                         f"({'; '.join(est.settings[1:])}) are not in the asymptotic range for "
                                         f"{est.failure_text()}"))
    if redo:
        jobs = [(*points[i][:2], level) for _, i, _, _, _ in redo for level in LEVELS[1:]]
        fine = run_sweep(scene_point, jobs, workers=workers, desc="error estimate (refined companions)",
                         executor="local", options=options)
        for k, (r0, i, sc, coarse, why) in enumerate(redo):
            ref = sc.spec.accuracy.refinement(sc)
            vals = [results[i]["headlines"], *(r["headlines"] for r in fine[2 * k:2 * k + 2])]
            est = estimate(vals, declared(sc), ref, level_settings(sc, [ref.refine(sc, j) for j in LEVELS]))
            est.fallback, est.coarse = why, coarse
            r0["error_estimate"] = est
    return out


def judge_points(scene: Scene, axes: list[tuple[str, str, list]], combos: list[tuple], results: list[dict]
                 ) -> list[str]:
    """Every point's estimates against their tolerances (`trust.health.judge_estimate`): the `INACCURATE:` lines
    naming the point and headline of those past it (emitted as warnings with solver.allow_inaccurate /
    --allow-inaccurate)."""
    from ..trust.health import judge_estimate

    out = []
    for combo, r in zip(combos, results, strict=True):
        where = ", ".join(f"{s}.{n} = {v}" for (s, n, _), v in zip(axes, combo, strict=True))
        out += judge_estimate(r["error_estimate"].figures(), allow_inaccurate=scene.solver.allow_inaccurate,
                              what=f"sweep point {where}")
    return out


def sweep_report(scene: Scene, axes: list[tuple[str, str, list]], combos: list[tuple], results: list[dict],
                 signals_arg: str | None) -> Report:
    """The table (one row per point and signal), the data (axes, units, points) and the CSV/PNG writer."""
    from .study import axis_unit  # study imports this module's neighbours; the unit lookup lives there

    signals = [x for x in (signals_arg.split(",") if signals_arg else []) if x] or \
        sorted(results[0]["signals"]) if results else []
    head = [f"{s}.{n}" for s, n, _ in axes]
    units = {h: axis_unit(scene, s, n) for h, (s, n, _) in zip(head, axes, strict=True)}
    sig_units = {sig: scene.spec.outputs.get(sig, "") for sig in signals}
    rows, cols = [], {h: [] for h in head}
    for combo, r in zip(combos, results, strict=True):
        for h, v in zip(head, combo, strict=True):
            cols[h].append(v)
        for sig in signals:
            st = r["signals"].get(sig)
            if st is None:
                raise MbsuiteError(f"signal {sig!r} not in the results; available: {sorted(r['signals'])}")
            rows.append([*combo, sig, sig_units[sig], st["min"], st["max"], st["mean"]])
            for k in ("min", "max", "mean"):
                cols.setdefault(f"{sig}_{k}", []).append(st[k])
    heads = [f"{h} [{units[h]}]" if units[h] else h for h in head]
    table = format_table([*heads, "signal", "unit", "min", "max", "mean"], rows, ".5g")
    if results and "error_estimate" in results[0]:
        est_rows = []
        for combo, r in zip(combos, results, strict=True):
            for e in r["error_estimate"].rows:
                est_rows.append([*combo, e.name, e.unit, e.value, e.error, e.tol,
                                 "-" if e.order is None else f"{e.order:.2f}", "ok" if e.ok else "EXCEEDED"])
                cols.setdefault(f"{e.name}_value", []).append(e.value)
                cols.setdefault(f"{e.name}_error", []).append(e.error)
                sig_units.setdefault(e.name, e.unit)
        first = results[0]["error_estimate"]
        est_head = [*heads, "headline", "unit", "value", "est. error", "tol", "observed order", ""]
        kinds = sorted({r["error_estimate"].companions for r in results})
        f = first.factor
        how = " or ".join(f"{first.setting} " + (f"coarsened by {f:g} and {f * f:g}" if k == "coarse" else
                                                 f"refined by {f:g} twice") for k in kinds)
        table += (f"\n\nerror estimate per point: {how} (nominal order {first.nominal_order:g})\n"
                  + format_table(est_head, est_rows, ".4g"))
        table += "".join(f"\n{', '.join(f'{h} = {v}' for h, v in zip(head, combo, strict=True))}: "
                         f"{r['error_estimate'].fallback}" for combo, r in zip(combos, results, strict=True)
                         if r["error_estimate"].fallback)
        results = [{**r, "error_estimate": r["error_estimate"].to_dict()} for r in results]
    data = {"axes": {h: a[2] for h, a in zip(head, axes, strict=True)}, "units": {**units, **sig_units},
            "points": [{"values": dict(zip(head, c, strict=True)), **r} for c, r in zip(combos, results, strict=True)]}
    write = functools.partial(write_sweep, head=head, units=units, combos=combos, results=results, signals=signals,
                              sig_units=sig_units, cols=cols)
    return Report(data, table, write)


def write_sweep(out: Path, *, head: list[str], units: dict, combos: list, results: list, signals: list[str],
                sig_units: dict, cols: dict[str, list[Any]]) -> list[Path]:
    """`sweep.csv` (SI units in the header) and `sweep.png` under `out`."""
    from ..plotting import save

    csv_cols = [(k, units[k] if k in units else sig_units.get(k.rsplit("_", 1)[0], ""), v) for k, v in cols.items()]
    return [write_csv(Path(out) / "sweep.csv", csv_cols),
            save(plot_sweep(head, units, combos, results, signals, sig_units), Path(out) / "sweep.png")]


def plot_sweep(head: list[str], units: dict, combos: list, results: list, signals: list[str], sig_units: dict):
    """Each signal's mean (line) and min-max (band) against the first swept key; one line per combination of the
    other keys (at most 8)."""
    from ..plotting import figure

    shown = signals[:6]
    fig, axs = figure(len(shown), 1, size=(8.0, 1.8 + 2.0 * len(shown)), sharex=True, squeeze=False)
    groups: dict = {}
    for i, c in enumerate(combos):
        groups.setdefault(tuple(c[1:]), []).append(i)
    numeric = all(isinstance(c[0], int | float) and not isinstance(c[0], bool) for c in combos)
    for ax, sig in zip(axs[:, 0], shown, strict=True):
        for rest, idx in list(groups.items())[:8]:
            x = [combos[i][0] if numeric else str(combos[i][0]) for i in idx]
            st = [results[i]["signals"][sig] for i in idx]
            label = ", ".join(f"{h} = {v}" for h, v in zip(head[1:], rest, strict=True)) or None
            line, = ax.plot(x, [s["mean"] for s in st], marker="o", ms=3, label=label)
            ax.fill_between(x, [s["min"] for s in st], [s["max"] for s in st], color=line.get_color(), alpha=0.15)
        ax.set_ylabel(f"{sig} [{sig_units[sig]}]" if sig_units[sig] else sig)
        ax.grid(True, alpha=0.3)
        if len(groups) > 1:
            ax.legend(fontsize=6)
    axs[-1, 0].set_xlabel(f"{head[0]} [{units[head[0]]}]" if units[head[0]] else head[0])
    fig.suptitle("sweep: mean (line) and min-max over the run (band)", fontsize=9)
    return fig
