"""Parameter studies on every analysis: `--set SECTION.KEY=VALUE` changes the scene a command analyses, `--vary
SECTION.KEY=VALUES` (repeatable: the grid is the product) runs the command's analysis at every point of a grid with
the machinery of `mbsuite sweep` (`mbsuite.analysis.sweep.run_sweep`: executors, store, size guard) and reports every
number the analysis returns against the axes: a table, `study.csv`, `study.png` and summary.json.

    mbsuite modes pantograph --vary params.mh=10:16:1          # how the modes move with the head mass

A command takes part by naming its report function, `fn(scene, args) -> Report` at module level (`"module:name"`,
so a point pickles to any executor), and calling `run_or_study`. A command that reads no scene (its inputs are its
flags, e.g. `mbsuite coupler jacobian --gamma ...`) varies its options instead: `--vary option.gamma=0.25,0.3`
(the option's name as the command's flag, dashes as underscores); `fn` then gets `scene=None`."""

from __future__ import annotations

import argparse
import functools
import importlib
import itertools
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import MbsuiteError
from ..trust.health import InaccurateResult
from .options import SCENE_SECTIONS

if TYPE_CHECKING:
    from ..results import Report
    from ..scenes import Scene

SECTIONS = SCENE_SECTIONS
#: the key of a study point's result that holds its `INACCURATE:` lines (an error estimate above its tolerance)
INACCURATE = "_inaccurate"
MAX_LIST = 16  # a list of numbers longer than this is a curve or a time series, not a quantity of the study


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
    """The numbers of a report's data as `path -> value` (`reference[1].f_n`); booleans, strings and long lists (curves,
    time series) are left out."""
    out: dict[str, float] = {}
    if isinstance(data, dict):
        for k, v in data.items():
            out.update(flatten(v, f"{prefix}.{k}" if prefix else str(k)))
    elif isinstance(data, list | tuple):
        if len(data) <= MAX_LIST:
            for i, v in enumerate(data):
                out.update(flatten(v, f"{prefix}[{i}]"))
    elif isinstance(data, int | float) and not isinstance(data, bool):
        out[prefix] = float(data)
    return out


def study_point(target: str, options: dict[str, Any], job: tuple[dict | None, dict]) -> dict[str, float]:
    """One point of a study: the command's report function `target` ("module:name") on the scene `job = (scene_dict,
    sections)` (None: a command without a scene) with the command's options (`sections["option"]` overriding them),
    its data's numbers flattened. Module-level, so it pickles to any executor."""
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
    out: dict[str, Any] = flatten({k: v for k, v in to_jsonable(report.data).items()
                                   if k not in ("scene", "inaccurate")})  # the scene: the axes
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
                 parallel_inside: bool = False) -> None:
    """Emit the command's report for `scene` (with `--set` applied; None: a command without a scene) or, with
    `--vary`, the study over the grid. `units`: the SI unit of a quantity by its last name (`f_n` -> Hz).
    `parallel_inside`: the analysis runs its own workers, so the study's points run one after another."""
    from .options import overrides
    from .output import emit

    overrides(args)  # the one rule over every override flag (main applies it too)
    if scene is not None:
        scene = apply_sets(scene, getattr(args, "set_values", None))
    out = getattr(args, "emit", None) or emit
    scene_d = scene.to_dict() if scene is not None else None
    if not getattr(args, "vary", None):
        module, _, name = target.partition(":")
        try:
            rep = getattr(importlib.import_module(module), name)(scene, args)
        except InaccurateResult as exc:  # an error estimate above its tolerance: the result kept, flagged (exit 3)
            rep = exc.report()
        out(rep, args, scene_d)
        return
    out(study(args, scene, target, units=units or {}, parallel_inside=parallel_inside), args, scene_d)


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
          parallel_inside: bool = False) -> Report:
    """Run `target` at every point of the `--vary` grid (every scene point validated before anything runs) and
    report."""
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
    fn = functools.partial(study_point, target, point_options(args))
    results = run_sweep(fn, points, workers=workers, desc="study", options=options,
                        executor=None if options.executor else "local")
    return study_report(scene, axes, combos, results, units, target.partition(":")[2].removesuffix("_of"))


def unit_of(quantity: str, units: dict[str, str]) -> str:
    """A quantity's unit by its last name (`reference[1].f_n` -> units["f_n"])."""
    return units.get(quantity.rsplit(".", 1)[-1].split("[")[0], "")


def study_report(scene: Scene | None, axes: list[tuple[str, str, list]], combos: list[tuple], results: list[dict],
                 units: dict[str, str], what: str) -> Report:
    """One row per point and quantity (the axes, the quantity, its unit, its value); the data: axes, units, points."""
    from ..results import Report, format_table

    head = [f"{s}.{n}" for s, n, _ in axes]
    axis_units = {h: axis_unit(scene, s, n) if scene is not None else units.get(n, "")
                  for h, (s, n, _) in zip(head, axes, strict=True)}
    flagged = [(combo, r[INACCURATE]) for combo, r in zip(combos, results, strict=True) if INACCURATE in r]
    results = [{q: v for q, v in r.items() if q != INACCURATE} for r in results]
    quantities = list(dict.fromkeys(q for r in results for q in r))
    rows = [[*combo, q, unit_of(q, units), r[q]] for combo, r in zip(combos, results, strict=True)
            for q in quantities if q in r]
    heads = [f"{h} [{axis_units[h]}]" if axis_units[h] else h for h in head]
    table = format_table([*heads, "quantity", "unit", "value"], rows, ".6g")
    table += f"\n{what} at {len(combos)} point(s) of {' x '.join(head)}; study.csv holds one column per quantity"
    data = {"analysis": what, "axes": {h: a[2] for h, a in zip(head, axes, strict=True)},
            "units": {**axis_units, **{q: unit_of(q, units) for q in quantities}},
            "points": [{"values": dict(zip(head, c, strict=True)), "results": r}
                       for c, r in zip(combos, results, strict=True)]}
    write = functools.partial(write_study, head=head, axis_units=axis_units, combos=combos, results=results,
                              quantities=quantities, units=units, what=what)
    rep = Report(data, table, write)
    if flagged:  # points whose error estimate exceeds its tolerance: the study kept, flagged (exit 3)
        lines = [f"at {', '.join(f'{h} = {v}' for h, v in zip(head, combo, strict=True))}: {m}"
                 for combo, msgs in flagged for m in msgs]
        rep.table += "\n" + "\n".join(lines)
        rep.flag_inaccurate(lines)
    return rep


def write_study(out: Path, *, head: list[str], axis_units: dict[str, str], combos: list[tuple], results: list[dict],
                quantities: list[str], units: dict[str, str], what: str) -> list[Path]:
    """`study.csv` (one column per axis and quantity, SI units in the header) and `study.png`."""
    from ..plotting import save
    from ..results import write_csv

    nan = float("nan")
    cols = [(h, axis_units[h], [c[i] for c in combos]) for i, h in enumerate(head)]
    cols += [(q, unit_of(q, units), [r.get(q, nan) for r in results]) for q in quantities]
    return [write_csv(Path(out) / "study.csv", cols),
            save(plot_study(head, axis_units, combos, results, quantities, units, what), Path(out) / "study.png")]


def plot_study(head: list[str], axis_units: dict[str, str], combos: list[tuple], results: list[dict],
               quantities: list[str], units: dict[str, str], what: str):
    """The quantities that change over the study (not those that only repeat an axis' value) against the first
    axis, one panel per kind of quantity (its last name: every `f_n` in one panel), one line per quantity and
    combination of the other axes (at most 6 panels)."""
    from ..plotting import figure

    def echo(q: str) -> bool:  # a quantity that only repeats an axis' value (the input, reported back)
        return any(all(r.get(q) == c[i] for r, c in zip(results, combos, strict=True)) for i in range(len(head)))

    changing = [q for q in quantities if len({r.get(q) for r in results}) > 1 and not echo(q)] or quantities[:1]
    kinds: dict[str, list[str]] = {}
    for q in changing:
        kinds.setdefault(q.rsplit(".", 1)[-1].split("[")[0], []).append(q)
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
        unit = units.get(kind, "")
        ax.set_ylabel(f"{kind} [{unit}]" if unit else kind)
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
