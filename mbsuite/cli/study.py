"""Parameter studies on every analysis: `--set SECTION.KEY=VALUE` changes the scene a command analyses, `--vary
SECTION.KEY=VALUES` (repeatable: the grid is the product) runs the command's analysis at every point of a grid with
the machinery of `mbsuite sweep` (`mbsuite.analysis.sweep.run_sweep`: executors, store, size guard) and reports every
number the analysis returns against the axes: a table, `study.csv`, `study.png` and summary.json; an analysis that
returns curves (a frequency response) keeps them too: `study_curves.csv` (long form, units in every column name) and
one overlay figure per output, `study_curves_<output>.png`.

    mbsuite modes pantograph --vary params.mh=10:16:1          # how the modes move with the head mass

A command takes part by naming its report function, `fn(scene, args) -> Report` at module level (`"module:name"`,
so a point pickles to any executor), and calling `run_or_study`. A command that reads no scene (its inputs are its
flags, e.g. `mbsuite coupler jacobian --gamma ...`) varies its options instead: `--vary option.gamma=0.25,0.3`
(the option's name as the command's flag, dashes as underscores); `fn` then gets `scene=None`.

Every quantity of a study carries its unit: the command's `units` by the quantity's last name, else the unit a name
of its path spells (`unit_of`, `results.unit_source`: `peaks_hz.linear.F1[0]` is in Hz, `amplitude_input_m` in m).
A command may name its headline quantities (`wide`): the table then prints them wide (one row per point, one column
per quantity and unit) and the figure draws them. A command whose report holds curves names the function that lists
them (`curves`, "module:name", `fn(data) -> (curves, keys)`: the curves as `Curve` dictionaries and the data's keys
that hold them, left out of the study's numbers)."""

from __future__ import annotations

import argparse
import functools
import importlib
import itertools
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypedDict

from ..errors import MbsuiteError
from ..trust.health import InaccurateResult
from .options import SCENE_SECTIONS

if TYPE_CHECKING:
    from ..results import Report
    from ..scenes import Scene

SECTIONS = SCENE_SECTIONS
#: the key of a study point's result that holds its `INACCURATE:` lines (an error estimate above its tolerance)
INACCURATE = "_inaccurate"
#: the key of a study point's result that holds its curves (`Curve` dictionaries)
CURVES = "_curves"
#: at most this many value columns in one block of a wide table (a longer group is printed in several blocks)
WIDE_COLUMNS = 8


class Curve(TypedDict):
    """One curve of a study point, a plain dictionary (it travels through any executor and the sweep store as JSON):
    `output` (what it is of, e.g. "F1"), `title` (the output in words), `method` (how it was computed, "" when
    there is one), `x` = {"name", "unit", "label", "values"} (the abscissa, e.g. frequency in Hz) and `y` = a list of
    {"name", "unit", "label", "values"} plus optional "scale" ("log") and "period" (a phase: unwrapped by it in the
    figure); `label` names the quantity in words (the figure adds its unit)."""

    output: str
    title: str
    method: str
    x: dict[str, Any]
    y: list[dict[str, Any]]


def add_study_options(p: argparse.ArgumentParser, scene: bool = True) -> None:
    """`--set` and `--vary` (`scene=False`: a command without a scene varies its options: `--vary option.NAME=...`),
    plus the sweep's `--executor/--scheduler/--store/--max-points` and `--workers` where the command does not have
    them yet."""
    from .options import add_progress_options, add_sweep_options

    add_progress_options(p)
    if scene:
        p.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", dest="set_values",
                       help="change one value of the scene (SECTION: input, params, solver, effects or a model's own "
                            "section; a comma list sets a list), e.g. params.mh=14 (repeatable)")
        p.add_argument("--vary", action="append", metavar="SECTION.KEY=VALUES",
                       help="a study axis: comma list or start:stop:step, e.g. params.mh=10:16:1 (repeatable: the "
                            "grid is the product); the analysis runs at every point")
    else:
        p.add_argument("--vary", action="append", metavar="option.NAME=VALUES",
                       help="a study axis over one of this command's options (its flag's name, dashes as "
                            "underscores): comma list or start:stop:step, e.g. option.gamma=0.25:0.35:0.05 "
                            "(repeatable: the grid is the product); the analysis runs at every point")
    if "--executor" not in p._option_string_actions:
        add_sweep_options(p)
    if "--workers" not in p._option_string_actions:
        p.add_argument("--workers", type=int, default=0, help="local processes of a --vary study (0 = all cores)")


def split_key(text: str, flag: str, sections: tuple[str, ...]) -> tuple[str, str, str]:
    """`SECTION.KEY=VALUE` as (section, key, value text), read by the one override reader (`options.parse_override`:
    KEY may be dotted into a model's section); an error naming the flag and the valid sections."""
    from .options import parse_override, section_of

    o = parse_override(flag, text)
    return (*section_of(o, sections), o.value)


def apply_sets(scene: Scene, sets: list[str] | None) -> Scene:
    """The scene with every `--set SECTION.KEY=VALUE` applied (values parsed as `mbsuite sweep` parses them; a
    comma list is a list; a dotted KEY reaches into a model's section: `pantograph.params.F0=100`), composed and
    resolved by the one rule (`options.compose`, `options.resolve`); errors name the key, the value and the command
    line."""
    from ..analysis.sweep import parse_values
    from .options import compose, parse_override, resolve

    if not sets:
        return scene
    values = {}
    for o in compose(parse_override("--set", text) for text in sets).values():
        parsed = parse_values(o.value)
        values[o] = parsed[0] if len(parsed) == 1 else parsed
    return scene.replace(origin=f"on the command line (--set {', '.join(sets)})", **resolve(scene, values))


def flatten(data: Any, prefix: str = "") -> dict[str, float]:
    """The numbers of a report's data as `path -> value` (`reference[1].f_n`; `results.numbers_in`): booleans,
    strings and long lists (curves, time series) left out."""
    from ..results import numbers_in

    return {path: value for path, value, _ in numbers_in(data, prefix)}


def study_point(target: str, options: dict[str, Any], job: tuple[dict | None, dict],
                curves: str | None = None) -> dict[str, Any]:
    """One point of a study: the command's report function `target` ("module:name") on the scene `job = (scene_dict,
    sections)` (None: a command without a scene) with the command's options (`sections["option"]` overriding them),
    its data's numbers flattened; with `curves` ("module:name", `fn(data) -> (curves, keys)`) also its curves (under
    `CURVES`), their data keys left out of the numbers. Module-level, so it pickles to any executor."""
    from ..results import to_jsonable
    from ..scenes import scene_from_dict

    module, _, name = target.partition(":")
    scene_d, sections = job
    sections = dict(sections)
    options = {**options, **sections.pop("option", {})}
    scene = None
    if scene_d is not None:
        scene = scene_from_dict(scene_d)
        scene = scene.replace(origin="on the command line (--vary)", **sections) if sections else scene
    try:
        report = getattr(importlib.import_module(module), name)(scene, argparse.Namespace(**options))
    except InaccurateResult as exc:  # an error estimate above its tolerance: the point kept, flagged
        report = exc.report()
    drop = {"scene", "inaccurate"}  # the scene: the axes
    found: list = []
    if curves:
        cmodule, _, cname = curves.partition(":")
        found, keys = getattr(importlib.import_module(cmodule), cname)(report.data)
        drop |= set(keys)
    out: dict[str, Any] = flatten({k: v for k, v in to_jsonable(report.data).items() if k not in drop})
    if found:
        out[CURVES] = to_jsonable(found)
    if report.inaccurate:
        out[INACCURATE] = list(report.inaccurate)
    return out


def point_options(args: argparse.Namespace) -> dict[str, Any]:
    """The command's options a point needs (plain values only; the study's own store and grid stay with the
    study)."""
    drop = {"func", "emit", "cli_groups", "argv", "vary", "set_values", "store", "out", "json"}
    return {k: v for k, v in vars(args).items()
            if k not in drop and (v is None or isinstance(v, str | int | float | bool | list))}


def run_or_study(args: argparse.Namespace, scene: Scene | None, target: str, *, units: dict[str, str] | None = None,
                 parallel_inside: bool = False, wide: tuple[str, ...] = (), words: dict[str, str] | None = None,
                 curves: str | None = None) -> None:
    """Emit the command's report for `scene` (with `--set` applied; None: a command without a scene) or, with
    `--vary`, the study over the grid. `units`: the SI unit of a quantity by its last name (`f_n` -> Hz).
    `parallel_inside`: the analysis runs its own workers, so the study's points run one after another. `wide`: the
    study's headline quantities, by a name of their path (`f_n`, `peaks_hz`), printed wide and drawn; `words`: a
    quantity's name in words for the figure's axes; `curves`: the function listing the report's curves
    ("module:name", see the module's docstring), kept by the study."""
    from .options import overrides
    from .output import emit

    overrides(args)  # the one rule over every override flag (main applies it too)
    if scene is not None:
        scene = apply_sets(scene, getattr(args, "set_values", None))
    out = getattr(args, "emit", None) or emit
    scene_d = scene.to_dict() if scene is not None else None
    if not getattr(args, "vary", None):
        module, _, name = target.partition(":")
        from ..progress import OverBudget

        try:
            rep = getattr(importlib.import_module(module), name)(scene, args)
        except InaccurateResult as exc:  # an error estimate above its tolerance: the result kept, flagged (exit 3)
            rep = exc.report()
        except OverBudget as exc:  # an error estimate over the budget: its run kept, shown, then the error (exit 2)
            if exc.result is not None:
                out(exc.result, args, scene_d)
            raise
        out(rep, args, scene_d)
        return
    out(study(args, scene, target, units=units or {}, parallel_inside=parallel_inside, wide=wide, words=words,
              curves=curves), args, scene_d)


def study_axes(args: argparse.Namespace, scene: Scene | None, max_points: int) -> list[tuple[str, str, list]]:
    """(section, key, values) of each `--vary`: scene sections, or `option` (a command without a scene: one of its
    options by name); the grid's size checked before it is built."""
    from ..analysis.sweep import check_grid, parse_values
    from .options import overrides, scene_sections, section_of

    sections = scene_sections(scene) if scene is not None else ("option",)
    meta = {"command", "executor", "scheduler", "max_points", "workers", "max_n"}
    options = {k for k in point_options(args) if k not in meta and not k.endswith("_command")}
    axes = []
    for o in overrides(args).values():
        if o.flag != "--vary":
            continue
        section, name = section_of(o, sections)
        if section == "option" and name not in options:
            raise MbsuiteError(f"{o}: this command has no option {name!r}; valid: {sorted(options)}")
        axes.append((section, name, parse_values(o.value, max_points=max_points)))
    check_grid([len(a[2]) for a in axes], max_points=max_points, what="--vary grid")
    return axes


def study(args: argparse.Namespace, scene: Scene | None, target: str, *, units: dict[str, str],
          parallel_inside: bool = False, wide: tuple[str, ...] = (), words: dict[str, str] | None = None,
          curves: str | None = None) -> Report:
    """Run `target` at every point of the `--vary` grid (every scene point validated before anything runs) and
    report (`run_or_study` names the keywords)."""
    from ..analysis.designspace import sections_for
    from ..analysis.sweep import run_sweep
    from .options import check_workers, sweep_options

    options = sweep_options(args)
    axes = study_axes(args, scene, options.max_points)
    combos = list(itertools.product(*[a[2] for a in axes]))
    points = []
    scene_d = scene.to_dict() if scene is not None else None
    for combo in combos:  # a dotted key nested into its section as by every command (options.resolve)
        sections = sections_for(scene_d or {}, {f"{s}.{n}": v for (s, n, _), v in zip(axes, combo, strict=True)})
        if scene is not None:
            scene.replace(origin="on the command line (--vary)", **sections)  # validate every point first
        points.append((scene_d, sections))
    workers = 1 if parallel_inside else check_workers(getattr(args, "workers", 0) or 0)
    fn = functools.partial(study_point, target, point_options(args), **({"curves": curves} if curves else {}))
    results = run_sweep(fn, points, workers=workers, desc="study", options=options,
                        executor=None if options.executor else "local")
    return study_report(scene, axes, combos, results, units, target.partition(":")[2].removesuffix("_of"),
                        wide=wide, words=words or {})


def unit_of(quantity: str, units: dict[str, str]) -> str:
    """A quantity's unit by its last name (`reference[1].f_n` -> units["f_n"]), else as a name of its path spells it
    (`results.unit_source`)."""
    from ..results import unit_source

    return unit_source(quantity, units)[1]


def study_report(scene: Scene | None, axes: list[tuple[str, str, list]], combos: list[tuple], results: list[dict],
                 units: dict[str, str], what: str, *, wide: tuple[str, ...] = (),
                 words: dict[str, str] | None = None) -> Report:
    """The study's report: with `wide` (headline names), one row per point and one column per headline quantity
    and unit (`wide_table`), else one row per point and quantity (the axes, the quantity, its unit, its value); the
    data: axes, units, points (each with its curves, if the analysis returns any)."""
    from ..results import Report, format_table

    head = [f"{s}.{n}" for s, n, _ in axes]
    axis_units = {h: axis_unit(scene, s, n) if scene is not None else units.get(n, "")
                  for h, (s, n, _) in zip(head, axes, strict=True)}
    flagged = [(combo, r[INACCURATE]) for combo, r in zip(combos, results, strict=True) if INACCURATE in r]
    curves = [list(r.get(CURVES) or []) for r in results]
    results = [{q: v for q, v in r.items() if q not in (INACCURATE, CURVES)} for r in results]
    quantities = list(dict.fromkeys(q for r in results for q in r))
    qunits = {q: unit_of(q, units) for q in quantities}
    heads = [f"{h} [{axis_units[h]}]" if axis_units[h] else h for h in head]
    shown = headlines(quantities, wide)
    where = f"{what} at {len(combos)} point(s) of {' x '.join(head)}"
    if shown:
        table = wide_table(heads, combos, results, shown, qunits)
        table += (f"\n{where}; shown: {len(shown)} headline quantities of {len(quantities)} per point (study.csv and "
                  "--json hold every one, its unit in the column name)")
    else:
        rows = [[*combo, q, qunits[q], r[q]] for combo, r in zip(combos, results, strict=True)
                for q in quantities if q in r]
        table = format_table([*heads, "quantity", "unit", "value"], rows, ".6g")
        table += f"\n{where}; study.csv holds one column per quantity, its unit in the column name"
    if any(curves):
        outputs = list(dict.fromkeys(c["output"] for cs in curves for c in cs))
        table += (f"\ncurves kept: {sum(map(len, curves))} over {len(combos)} point(s) ({', '.join(outputs)}); with "
                  "--out, study_curves.csv (long form) and one overlay figure per output, study_curves_<output>.png")
    data = {"analysis": what, "axes": {h: a[2] for h, a in zip(head, axes, strict=True)},
            "units": {**axis_units, **qunits},
            "points": [{"values": dict(zip(head, c, strict=True)), "results": r, **({"curves": cv} if cv else {})}
                       for c, r, cv in zip(combos, results, curves, strict=True)]}
    write = functools.partial(write_study, head=head, axis_units=axis_units, combos=combos, results=results,
                              quantities=shown or quantities, all_quantities=quantities, units=units, what=what,
                              curves=curves, words=words or {})
    rep = Report(data, table, write)
    if flagged:  # points whose error estimate exceeds its tolerance: the study kept, flagged (exit 3)
        lines = [f"at {', '.join(f'{h} = {v}' for h, v in zip(head, combo, strict=True))}: {m}"
                 for combo, msgs in flagged for m in msgs]
        rep.table += "\n" + "\n".join(lines)
        rep.flag_inaccurate(lines)
    return rep


def headlines(quantities: list[str], wide: tuple[str, ...]) -> list[str]:
    """The quantities a name of whose path is one of `wide` (`f_n` picks `reference[1].f_n`)."""
    from ..results import names_of

    return [q for q in quantities if set(names_of(q)) & set(wide)] if wide else []


def short_name(quantity: str, group: str) -> str:
    """A quantity's name inside its group's table: the path after the group's name, a list index moved behind
    the name it indexes (`reference[1].f_n` in group `reference` -> `f_n[1]`)."""
    import re

    rest = quantity[len(group):] if quantity.startswith(group) else quantity
    m = re.fullmatch(r"\[(\d+)\]\.(.+)", rest)
    if m:
        return f"{m[2]}[{m[1]}]"
    return rest.lstrip(".") or quantity


def wide_table(heads: list[str], combos: list[tuple], results: list[dict], shown: list[str],
               qunits: dict[str, str]) -> str:
    """One block per group of quantities (the first name of their path: `reference`, `mujoco`, `peaks_hz`), one row
    per point, one column per quantity with its unit (at most `WIDE_COLUMNS` per block)."""
    from ..results import format_table, names_of

    groups: dict[str, list[str]] = {}
    for q in shown:
        groups.setdefault(names_of(q)[0], []).append(q)
    blocks = []
    for group, qs in groups.items():
        for i in range(0, len(qs), WIDE_COLUMNS):
            chunk = qs[i:i + WIDE_COLUMNS]
            cols = [f"{short_name(q, group)} [{qunits[q]}]" if qunits[q] else short_name(q, group) for q in chunk]
            rows = [[*combo, *[r.get(q, float("nan")) for q in chunk]] for combo, r in zip(combos, results,
                                                                                             strict=True)]
            blocks.append(f"{group}:\n" + format_table([*heads, *cols], rows, ".6g"))
    return "\n".join(blocks)


def write_study(out: Path, *, head: list[str], axis_units: dict[str, str], combos: list[tuple], results: list[dict],
                quantities: list[str], units: dict[str, str], what: str, all_quantities: list[str] | None = None,
                curves: list[list[Curve]] | None = None, words: dict[str, str] | None = None) -> list[Path]:
    """`study.csv` (one column per axis and quantity, SI units in the header), `study.png` (the `quantities`) and,
    when the points hold curves, `study_curves.csv` and `study_curves_<output>.png` (`write_curves`)."""
    from ..plotting import save
    from ..results import write_csv

    nan = float("nan")
    cols = [(h, axis_units[h], [c[i] for c in combos]) for i, h in enumerate(head)]
    cols += [(q, unit_of(q, units), [r.get(q, nan) for r in results]) for q in (all_quantities or quantities)]
    files = [write_csv(Path(out) / "study.csv", cols),
             save(plot_study(head, axis_units, combos, results, quantities, units, what, words or {}),
                  Path(out) / "study.png")]
    if curves and any(curves):
        files += write_curves(Path(out), head, axis_units, combos, curves)
    return files


def curve_columns(head: list[str], axis_units: dict[str, str], combos: list[tuple],
                  curves: list[list[Curve]]) -> list[tuple[str, str, Any]]:
    """The curves of every point in long form, as `write_csv` columns: the axes, `output`, the abscissa, each
    ordinate (one column per name and unit: a curve without it leaves it empty) and `method`; one row per point,
    curve and abscissa value. Numbers stay floats (written exactly)."""
    import numpy as np

    xkeys = list(dict.fromkeys((c["x"]["name"], c["x"]["unit"]) for cs in curves for c in cs))
    ykeys = list(dict.fromkeys((y["name"], y["unit"]) for cs in curves for c in cs for y in c["y"]))
    axis_vals: list[list] = [[] for _ in head]
    outputs, methods = [], []
    xs: dict[tuple, list] = {k: [] for k in xkeys}
    ys: dict[tuple, list] = {k: [] for k in ykeys}
    for combo, cs in zip(combos, curves, strict=True):
        for c in cs:
            n = len(c["x"]["values"])
            for j, v in enumerate(combo):
                axis_vals[j] += [v] * n
            outputs += [c["output"]] * n
            methods += [c.get("method", "")] * n
            for k in xkeys:
                xs[k] += list(c["x"]["values"]) if k == (c["x"]["name"], c["x"]["unit"]) else [""] * n
            own = {(y["name"], y["unit"]): y["values"] for y in c["y"]}
            for k in ykeys:
                ys[k] += [float("nan") if v is None else v for v in own[k]] if k in own else [""] * n

    def column(values: list) -> Any:
        if all(isinstance(v, float | int) and not isinstance(v, bool) for v in values):
            return np.asarray(values, dtype=float)
        return np.array(values, dtype=object)

    cols = [(h, axis_units[h], column(axis_vals[j])) for j, h in enumerate(head)]
    cols.append(("output", "", np.array(outputs, dtype=object)))
    cols += [(name, unit, column(xs[(name, unit)])) for name, unit in xkeys]
    cols += [(name, unit, column(ys[(name, unit)])) for name, unit in ykeys]
    cols.append(("method", "", np.array(methods, dtype=object)))
    return cols


def write_curves(out: Path, head: list[str], axis_units: dict[str, str], combos: list[tuple],
                 curves: list[list[Curve]]) -> list[Path]:
    """`study_curves.csv` (`curve_columns`) and one overlay figure per output, `study_curves_<output>.png`
    (`plot_curves`)."""
    import re

    from ..plotting import save
    from ..results import write_csv

    files = [write_csv(out / "study_curves.csv", curve_columns(head, axis_units, combos, curves))]
    for output in dict.fromkeys(c["output"] for cs in curves for c in cs):
        fig = plot_curves(output, head, axis_units, combos, curves)
        files.append(save(fig, out / f"study_curves_{re.sub(r'[^A-Za-z0-9_.-]', '_', output)}.png"))
    return files


def point_label(head: list[str], axis_units: dict[str, str], combo: tuple) -> str:
    """A point's values with their units: `params.kh = 1500 N m/rad`."""
    def value(v: Any) -> str:
        return f"{v:g}" if isinstance(v, float | int) and not isinstance(v, bool) else str(v)

    return ", ".join(f"{h} = {value(v)}" + (f" {axis_units[h]}" if axis_units[h] else "")
                     for h, v in zip(head, combo, strict=True))


def plot_curves(output: str, head: list[str], axis_units: dict[str, str], combos: list[tuple],
                curves: list[list[Curve]]):
    """The curves of one output at every point, overlaid: one panel per ordinate (amplitude, phase, ...: its name in
    words and its unit on the axis), one colour per point, one line style per method; a phase (`period`) unwrapped."""
    import numpy as np

    from ..plotting import figure

    mine = [(i, c) for i, cs in enumerate(curves) for c in cs if c["output"] == output]
    ynames = list(dict.fromkeys(y["name"] for _, c in mine for y in c["y"]))
    methods = list(dict.fromkeys(c.get("method", "") for _, c in mine))
    fig, axs = figure(len(ynames), 1, size=(8.5, 1.6 + 2.6 * len(ynames)), sharex=True, squeeze=False)
    for i, c in mine:
        x = np.asarray(c["x"]["values"], dtype=float)
        style = ("-", "--", ":", "-.")[methods.index(c.get("method", "")) % 4]
        label = point_label(head, axis_units, combos[i]) + (f" ({c['method']})" if len(methods) > 1 else "")
        for ax, name in zip(axs[:, 0], ynames, strict=True):
            y = next((y for y in c["y"] if y["name"] == name), None)
            if y is None:
                continue
            v = np.asarray([np.nan if u is None else u for u in y["values"]], dtype=float)
            if y.get("period"):
                v = np.unwrap(v, period=float(y["period"]))
            ax.plot(x, v, style, color=f"C{i % 10}", lw=1.1, label=label)
            ax.set_ylabel(f"{y['label']} [{y['unit']}]" if y["unit"] else y["label"], fontsize=8)
            if y.get("scale") == "log":
                ax.set_yscale("log")
    for ax in axs[:, 0]:
        ax.grid(True, alpha=0.3)
    axs[0, 0].legend(fontsize=7)
    xs = mine[0][1]["x"]
    axs[-1, 0].set_xlabel(f"{xs['label']} [{xs['unit']}]" if xs["unit"] else xs["label"])
    fig.suptitle(f"{mine[0][1].get('title', output)}: {len(combos)} point(s) of {', '.join(head)}", fontsize=9)
    return fig


def plot_study(head: list[str], axis_units: dict[str, str], combos: list[tuple], results: list[dict],
               quantities: list[str], units: dict[str, str], what: str, words: dict[str, str] | None = None):
    """The quantities that change over the study (not those that only repeat an axis' value) against the first
    axis, one panel per kind of quantity (the name that gives it its unit, `unit_source`: every `f_n` in one panel,
    every `peaks_hz.*` in another; its words from `words` on the axis), one line per quantity and combination of
    the other axes (at most 6 panels)."""
    from ..plotting import figure
    from ..results import unit_source

    def echo(q: str) -> bool:  # a quantity that only repeats an axis' value (the input, reported back)
        return any(all(r.get(q) == c[i] for r, c in zip(results, combos, strict=True)) for i in range(len(head)))

    words = words or {}
    changing = [q for q in quantities if len({r.get(q) for r in results}) > 1 and not echo(q)] or quantities[:1]
    kinds: dict[str, list[str]] = {}
    for q in changing:
        kinds.setdefault(unit_source(q, units)[0], []).append(q)
    shown = list(kinds.items())[:6]
    fig, axs = figure(max(len(shown), 1), 1, size=(8.0, 1.8 + 2.2 * max(len(shown), 1)), sharex=True,
                      squeeze=False)
    numeric = all(isinstance(c[0], int | float) and not isinstance(c[0], bool) for c in combos)
    groups: dict[tuple, list[int]] = {}
    for i, c in enumerate(combos):
        groups.setdefault(tuple(c[1:]), []).append(i)
    styles: dict[str, str] = {}
    for ax, (kind, qs) in zip(axs[:, 0], shown, strict=False):
        for rest, idx in list(groups.items())[:4]:
            x = [combos[i][0] if numeric else str(combos[i][0]) for i in idx]
            tail = ", ".join(f"{h} = {v}" for h, v in zip(head[1:], rest, strict=True))
            for q in qs[:10]:  # a path's lines share a style: "reference" solid, "mujoco" dashed, ...
                style = styles.setdefault(q.split(".")[0].split("[")[0], ("-", "--", ":", "-.")[len(styles) % 4])
                ax.plot(x, [results[i].get(q, float("nan")) for i in idx], style, marker="o", ms=3,
                        label=f"{q}{', ' + tail if tail else ''}")
        unit = unit_of(qs[0], units)
        name = f"{words[kind]} {kind}" if kind in words else kind
        ax.set_ylabel(f"{name} [{unit}]" if unit else name, fontsize=8)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=6, ncol=2)
    axs[-1, 0].set_xlabel(f"{head[0]} [{axis_units[head[0]]}]" if axis_units[head[0]] else head[0])
    fig.suptitle(f"{what} against {head[0]}", fontsize=9)
    return fig
def axis_unit(scene, section: str, name: str) -> str:
    """The SI unit of a swept key, from its declaration (parameter field, input key or solver setting)."""
    from ..limits import limit_of
    from ..settings import SOLVER_LIMITS

    lim = None
    if section == "params":
        try:
            lim = limit_of(scene.spec.params_cls, name)
        except (KeyError, TypeError):
            lim = None
    elif section == "input":
        lim = (scene.spec.inputs.get(scene.input.get("type"), {}) or {}).get(name)
    elif section == "solver":
        lim = SOLVER_LIMITS.get(name)
    return getattr(lim, "unit", "") or ""
