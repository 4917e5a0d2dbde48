"""Runs side by side (`mbsuite compare A B [C ...]`): the headline outputs of two or more earlier runs, read from the
`summary.json` each wrote with `--out` (the file, or the directory holding it), their differences to the first, and
their signals overlaid on a common axis, read from the CSV files written beside each summary.

What compares. Two summaries compare when one command wrote them (`mbsuite catenary`, `run`, `freqresp`, ...; a
model group's command and its top-level alias are one: `pantograph freqresp` is `freqresp`), a `--vary` study only
with a study; else a `MbsuiteError` names both kinds (exit 2). The headlines are the numbers of the results: a summary
holding statistics (a time run's declared statistics, a catenary passage's EN 50318 statistics) or signal ranges
(a time run's min/max/final) compares those, and any number named as a declared statistic of its scene's model (the
static contact force); any other compares every number of its results (short lists: modes, peaks)
but bookkeeping (`BOOKKEEPING`: timings, solver counters, health figures, warnings, events). A headline's unit: the
unit the summary records beside it, else the model's declarations (statistics, the command's units table passed in
`units_for`, parameters, inputs, solver settings), else the unit its name spells (`results.unit_source`). A headline
in one summary and not in another is named; summaries sharing no headline are refused.

Signals. summary.json names no files: the CSV files beside it whose first row is all numbers are its signals
(`run.csv`, `freqresp.csv`, a passage's `contact_force_*.csv`: `name [unit]` headers). Files of one name pair up;
the others by the parts of their names (split at "_"): each file of the first summary with the file of another that
differs from it in the fewest parts (`contact_force_lumped_slack_250kmh.csv` with
`contact_force_eppinger_slack_250kmh.csv`). Each pair is drawn against its common axis: the position along the line
`x` where every file has it, else the first column (time `t`, frequency `f`). A file or a signal without partner is
named as missing."""

from __future__ import annotations

import csv
import json
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import MbsuiteError
from ..results import Report, format_table, names_of, numbers_in, unit_source, write_csv

#: keys of a summary's results that hold no physics to compare (at any depth)
BOOKKEEPING = frozenset({"timing", "stats", "health", "error_estimate", "warnings", "events", "loss_events",
                         "input", "solver", "inaccurate", "files", "versions", "checkout", "command", "scene"})
#: path names left out of a headline's displayed name (`runs.slack.statistics.Fm` reads `slack.Fm`)
SILENT = ("runs", "statistics", "signals", "value")
#: axis columns preferred for the overlay, in order: the position along the line, then time
AXES = ("x", "position", "t")
#: the axes in words
AXIS_WORDS = {"x": "position along the line", "position": "position along the line", "t": "time",
              "f": "forcing frequency"}
#: a first value at most this fraction of its row's largest magnitude is zero: no relative difference to it
NEAR_ZERO = 1e-9
#: at most this many signal panels in one figure
MAX_PANELS = 12


@dataclass
class SignalFile:
    """A CSV of signals beside a summary: its path and its columns (name, unit), the first the file's axis."""

    path: Path
    columns: list[tuple[str, str]]

    def unit(self, name: str) -> str:
        """The unit of column `name` ("" if the file has none of that name)."""
        return next((u for n, u in self.columns if n == name), "")

    def names(self) -> list[str]:
        """The columns' names."""
        return [n for n, _ in self.columns]


@dataclass
class Summary:
    """One summary.json as compared: its label (A, B, ...), file, kind (the command that wrote it), command line,
    scene, results, headlines (displayed name -> (value, unit)) and the signal files beside it."""

    label: str
    path: Path
    kind: str
    command: str
    scene: dict[str, Any] | None
    results: dict[str, Any]
    headlines: dict[str, tuple[float, str]] = field(default_factory=dict)
    files: list[SignalFile] = field(default_factory=list)


def summary_file(arg: str | Path) -> Path:
    """The summary.json an argument names: the file itself or the directory holding one (an error naming the
    argument otherwise)."""
    p = Path(arg)
    if p.is_dir():
        if not (p / "summary.json").is_file():
            raise MbsuiteError(f"{arg}: a directory without summary.json (give a directory an earlier command wrote "
                               "with --out, or its summary.json)")
        return p / "summary.json"
    if not p.exists():
        raise MbsuiteError(f"{arg}: no such file or directory (give a summary.json an earlier command wrote with "
                           "--out, or its directory)")
    return p


def kind_of(body: Mapping[str, Any]) -> tuple[str, str]:
    """(kind, command line) of a summary: the command that wrote it (a group's command as its alias: `pantograph
    freqresp` is `freqresp`), `... --vary study` for a study; written from Python (no command), `run` for a time
    run's results, else `results with keys ...`."""
    results = body.get("results") or {}
    command = body.get("command") if isinstance(body.get("command"), Mapping) else {}
    options = command.get("options") or {}
    argv = command.get("argv")
    line = "mbsuite " + " ".join(argv) if argv else ""
    kind = str(options.get("command") or "")
    sub = next((str(v) for k, v in options.items() if k.endswith("_command") and v), "")
    kind = sub or kind
    if not kind:
        kind = "run" if {"signals", "engine"} <= set(results) else f"results with keys {sorted(results)}"
    if {"axes", "points"} <= set(results):
        kind += " --vary study"
    return kind, line


def numbers(data: Any, prefix: str = "", unit: str = "") -> list[tuple[str, float, str]]:
    """Every number of `data` as (dotted path, value, the unit recorded beside it), `BOOKKEEPING` keys, booleans,
    strings and lists longer than `results.MAX_LIST` left out (`results.numbers_in`)."""
    return numbers_in(data, prefix, unit, BOOKKEEPING)


def display_name(path: str) -> str:
    """A headline's name in the table: its path without the names that only group (`SILENT`)."""
    parts = [p for p in path.split(".") if p.split("[")[0] not in SILENT or p.split("[")[0] != p]
    return ".".join(parts) or path


def declared_units(model: str | None, units_for: Callable[[str], Mapping[str, str]] | None) -> tuple[dict, dict]:
    """(the model's declared statistic units, every other unit it declares by name: the command's units table from
    `units_for`, its parameters, inputs and solver settings); empty for an unknown model."""
    import dataclasses

    from ..limits import limit_of
    from ..registry import models
    from ..settings import SOLVER_LIMITS
    from ..statistics import unit_of

    spec = models().get(model) if model else None
    if spec is None:
        return {}, {}
    stats = {k: unit_of(spec.statistics, k) for k in spec.statistics}
    named: dict[str, str] = {k: lim.unit for k, lim in SOLVER_LIMITS.items() if lim.unit}
    for keys in spec.inputs.values():
        named.update({k: lim.unit for k, lim in (keys or {}).items() if getattr(lim, "unit", "")})
    for f in dataclasses.fields(spec.params_cls):
        lim = limit_of(spec.params_cls, f.name)
        if lim is not None and lim.unit and lim.unit != "-":
            named[f.name] = lim.unit
    named.update(units_for(model) if units_for else {})
    return stats, named


def headlines_of(results: Mapping[str, Any], model: str | None,
                 units_for: Callable[[str], Mapping[str, str]] | None = None) -> dict[str, tuple[float, str]]:
    """A summary's headlines, displayed name -> (value, unit) (module docstring: which numbers, which unit)."""
    stats, named = declared_units(model, units_for)
    found = numbers(results)
    focus = [n for n in found if {"statistics", "signals"} & set(names_of(n[0]))]
    if focus:
        focus += [n for n in found if n not in focus and names_of(n[0])[-1:] and names_of(n[0])[-1] in stats]
    out: dict[str, tuple[float, str]] = {}
    for path, value, unit in focus or found:
        last = names_of(path)[-1] if names_of(path) else path
        if not unit:
            unit = stats.get(last) or named.get(last) or unit_source(path, {})[1]
        out[display_name(path)] = (value, unit)
    return out


def signal_files(folder: Path) -> list[SignalFile]:
    """The CSV files in `folder` whose header reads `name [unit]` columns and whose first row is all numbers."""
    out = []
    for p in sorted(folder.glob("*.csv")):
        with p.open(newline="") as fh:
            reader = csv.reader(fh)
            header, first = next(reader, None), next(reader, None)
        if not header or not first or len(first) != len(header):
            continue
        try:
            [float(x) for x in first]
        except ValueError:
            continue
        cols = []
        for h in header:
            m = re.fullmatch(r"(.*?) \[(.*)\]", h.strip())
            cols.append((m[1], m[2]) if m else (h.strip(), ""))
        out.append(SignalFile(p, cols))
    return out


def read_summary(arg: str | Path, label: str, units_for: Callable[[str], Mapping[str, str]] | None = None) -> Summary:
    """One summary.json (or the directory holding it), its kind, headlines and signal files."""
    path = summary_file(arg)
    try:
        body = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise MbsuiteError(f"{arg}: not a summary.json (not valid JSON: {exc})") from None
    if not isinstance(body, dict) or not isinstance(body.get("results"), dict):
        raise MbsuiteError(f"{arg}: not a summary.json an mbsuite command wrote (no results in it)")
    kind, line = kind_of(body)
    scene = body.get("scene") if isinstance(body.get("scene"), dict) else None
    s = Summary(label, path, kind, line, scene, body["results"])
    s.headlines = headlines_of(s.results, scene.get("model") if scene else None, units_for)
    s.files = signal_files(path.parent)
    return s


def _parts(p: Path) -> list[str]:
    return p.stem.split("_")


def pair_files(summaries: Sequence[Summary]) -> tuple[list[tuple[str, list[SignalFile | None]]], list[str]]:
    """The signal files paired across the summaries (module docstring), each pair named by its files' common name
    (`*` where they differ); and the files of later summaries left without partner."""
    used: list[set[Path]] = [set() for _ in summaries]
    pairs = []
    for f in summaries[0].files:
        row: list[SignalFile | None] = [f]
        for j, s in enumerate(summaries[1:], 1):
            free = [g for g in s.files if g.path not in used[j]]
            match = next((g for g in free if g.path.name == f.path.name), None)
            if match is None:
                same = [g for g in free if len(_parts(g.path)) == len(_parts(f.path))]
                scored = [(sum(a != b for a, b in zip(_parts(g.path), _parts(f.path), strict=True)), i, g)
                          for i, g in enumerate(same)]
                scored = [t for t in scored if t[0] < len(_parts(f.path))]  # at least one part in common
                match = min(scored, key=lambda t: t[:2])[2] if scored else None
            if match is not None:
                used[j].add(match.path)
            row.append(match)
        parts = [_parts(g.path) for g in row if g is not None]
        role = "_".join(p if all(q[i] == p for q in parts) else "*" for i, p in enumerate(parts[0])) + ".csv"
        pairs.append((role, row))
    left = [f"{s.label}: {g.path.name}" for j, s in enumerate(summaries[1:], 1) for g in s.files
            if g.path not in used[j]]
    return pairs, left


def axis_of(files: Sequence[SignalFile]) -> str:
    """The common axis of paired files: the first of `AXES` every file has, else the first file's first column."""
    return next((a for a in AXES if all(a in f.names() for f in files)), files[0].columns[0][0])


def signal_plan(summaries: Sequence[Summary]) -> tuple[list[dict[str, Any]], list[str]]:
    """What the overlay draws: per pair of files its name, axis, signals and files (None where missing), and the
    missing files and signals, each named."""
    pairs, left = pair_files(summaries)
    missing = [f"{x} has no partner beside {summaries[0].label}'s summary.json" for x in left]
    for s in summaries:
        if not s.files:
            missing.append(f"no signal file (CSV) beside {s.label}'s summary.json ({s.path.parent})")
    plan = []
    for role, row in pairs:
        present = [f for f in row if f is not None]
        for s, f in zip(summaries, row, strict=True):
            if f is None:
                missing.append(f"{role} (every signal of it) missing beside {s.label}'s summary.json")
        axis = axis_of(present)
        names = [n for n in dict.fromkeys(n for f in present for n in f.names())
                 if n != axis and not (n == "t" and axis != "t")]  # time beside a position axis is no signal
        for n in names:
            lack = [s.label for s, f in zip(summaries, row, strict=True) if f is not None and n not in f.names()]
            if lack:
                missing.append(f"signal '{n}' of {role} missing in {', '.join(lack)}")
        plan.append({"file": role, "axis": [axis, present[0].unit(axis)], "signals": names,
                     "files": [str(f.path) if f is not None else None for f in row]})
    return plan, missing


def compare(args: Sequence[str | Path], *, units_for: Callable[[str], Mapping[str, str]] | None = None) -> Report:
    """Compare two or more summaries (module docstring): the report's table lists each headline's values, unit and
    differences to the first; its data the same as JSON; its writer `compare.csv` and the signals' overlays
    (`compare_signals.png`, `compare_signals_2.png`, ... one per pair of files). `units_for(model)`: a model's
    units by name (the command line passes its commands' tables)."""
    if len(args) < 2:
        raise MbsuiteError(f"compare needs two summaries or more, got {len(args)}")
    labels = [chr(ord("A") + i) if i < 26 else f"S{i + 1}" for i in range(len(args))]
    summaries = [read_summary(a, lab, units_for) for a, lab in zip(args, labels, strict=True)]
    first = summaries[0]
    for s in summaries[1:]:
        if s.kind != first.kind:
            raise MbsuiteError(f"cannot compare {first.label} ({first.path}: written by `{first.kind}`) with "
                               f"{s.label} ({s.path}: written by `{s.kind}`): summaries of different kinds; "
                               "compare summaries one command wrote")
    names = list(dict.fromkeys(n for s in summaries for n in s.headlines))
    common = [n for n in names if all(n in s.headlines for s in summaries)]
    if not common:
        raise MbsuiteError("the summaries share no headline: " + "; ".join(
            f"{s.label} has {', '.join(list(s.headlines)[:8]) or 'none'}" for s in summaries))
    only = {s.label: [n for n in names if n in s.headlines and n not in common] for s in summaries}
    rows, heads = headline_rows(summaries, names)
    plan, missing = signal_plan(summaries)
    table = comparison_text(summaries, heads, rows, only, plan, missing)
    data = {"kind": first.kind,
            "summaries": [{"label": s.label, "path": str(s.path), "command": s.command,
                           "scene": f"{s.scene.get('model')}/{s.scene.get('name')}" if s.scene else None,
                           "ran": scene_label(s.scene)}
                          for s in summaries],
            "scene_differences": scene_differences(summaries),
            "headlines": [{"name": r["name"], "unit": r["unit"], "values": r["values"],
                           "differences": r["differences"], "relative": r["relative"]} for r in rows],
            "only_in": {k: v for k, v in only.items() if v}, "signals": plan, "missing_signals": missing}

    def write(out: Path) -> list[Path]:
        return write_comparison(Path(out), summaries, heads, rows, plan)

    return Report(data, table, write)


def headline_rows(summaries: Sequence[Summary], names: Sequence[str]) -> tuple[list[dict[str, Any]], list[str]]:
    """Each headline's values (None where a summary lacks it), its unit, its differences to the first and those
    relative to the first's magnitude (None where the first is near zero, |first| <= `NEAR_ZERO` x the largest
    magnitude of the row: the difference alone tells); and the table's column heads."""
    rows = []
    for n in names:
        vals = [s.headlines[n][0] if n in s.headlines else None for s in summaries]
        unit = next(s.headlines[n][1] for s in summaries if n in s.headlines)
        a = vals[0]
        diffs = [None if a is None or v is None else v - a for v in vals[1:]]
        scale = max((abs(v) for v in vals if v is not None), default=0.0)
        near_zero = a is not None and abs(a) <= NEAR_ZERO * scale  # 0, or rounding noise beside the others
        rel = [None if d is None or near_zero else d / abs(a) for d in diffs]
        rows.append({"name": n, "unit": unit, "values": vals, "differences": diffs, "relative": rel})
    first = summaries[0].label
    heads = (["headline", "unit", *[s.label for s in summaries]]
             + [f"{s.label} - {first}" for s in summaries[1:]]
             + [f"({s.label} - {first})/|{first}| (%)" for s in summaries[1:]])
    return rows, heads


def scene_label(scene: Mapping[str, Any] | None) -> str:
    """What a summary ran, in words: "scene MODEL/NAME"; a line file run on its own (the command given the file: a
    scene named after its stem with `[line] file` naming it): "line file PATH (MODEL)"; a scene with a line file of
    another name: "scene MODEL/NAME, line file PATH"; "no scene"."""
    if not scene:
        return "no scene"
    line = scene.get("line")
    named = f"scene {scene.get('model')}/{scene.get('name')}"
    if isinstance(line, Mapping) and isinstance(line.get("file"), str):
        if Path(line["file"]).stem == scene.get("name"):
            return f"line file {line['file']} ({scene.get('model')})"
        return f"{named}, line file {line['file']}"
    return named


def _informative(model: str | None) -> tuple[str, ...]:
    """The scene keys `model` declares informative (`ModelSpec.extra["informative"]`); () for an unknown model."""
    from ..registry import models

    spec = models().get(model) if model else None
    return tuple(spec.extra.get("informative", ())) if spec is not None else ()


def scene_differences(summaries: Sequence[Summary]) -> dict[str, list[Any]]:
    """The scene entries (dotted keys) whose values differ between the summaries: what the runs were run with (a
    parameter a scene leaves unset taken at its model's default; None where a scene has no such entry); not the keys
    a model declares informative (`ModelSpec.extra["informative"]`: a catenary passage's `solver.duration`)."""
    flat = [_flat_scene(s.scene or {}) for s in summaries]
    skip = {k for s in summaries for k in _informative(s.scene.get("model") if s.scene else None)}
    keys = [k for k in dict.fromkeys(k for f in flat for k in f) if k not in skip]
    for s, f in zip(summaries, flat, strict=True):
        defaults = _param_defaults(s.scene.get("model") if s.scene else None)
        for k in keys:
            name = k.removeprefix("params.")
            if k not in f and k.startswith("params.") and name in defaults:
                f[k] = defaults[name]
    return {k: [f.get(k) for f in flat] for k in keys if len({json.dumps(f.get(k), sort_keys=True) for f in flat}) > 1}


def _param_defaults(model: str | None) -> dict[str, Any]:
    """A model's parameter defaults by name (plain values only; empty for an unknown model)."""
    import dataclasses

    from ..registry import models

    spec = models().get(model) if model else None
    if spec is None:
        return {}
    return {f.name: f.default for f in dataclasses.fields(spec.params_cls)
            if f.default is not dataclasses.MISSING and isinstance(f.default, int | float | str | bool)}


def _flat_scene(d: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in d.items():
        if k in ("description", "origin", "source"):
            continue
        key = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, Mapping):
            out.update(_flat_scene(v, key))
        else:
            out[key] = v
    return out


def _cell(v: float | None) -> Any:
    return "-" if v is None else v


def comparison_text(summaries: Sequence[Summary], heads: list[str], rows: list[dict[str, Any]],
                    only: Mapping[str, list[str]], plan: list[dict[str, Any]], missing: list[str]) -> str:
    """The report's table: who is compared, what differs in their scenes, the headlines with their differences,
    the headlines only some hold, the signals the overlay draws and those missing."""
    import textwrap

    lines = [f"compare: {len(summaries)} `{summaries[0].kind}` summaries, differences to {summaries[0].label}"]
    for s in summaries:
        scene = scene_label(s.scene)
        lines.append(textwrap.fill(f"{s.label} = {s.path}: {s.command or 'written from Python'} ({scene})", 100,
                                   subsequent_indent="    "))
    diff = scene_differences(summaries)
    if diff:
        text = "; ".join(f"{k}: " + ", ".join(f"{s.label} {'-' if v is None else v}"
                                              for s, v in zip(summaries, vals, strict=True))
                         for k, vals in list(diff.items())[:12])
        more = f" (and {len(diff) - 12} more)" if len(diff) > 12 else ""
        lines.append(textwrap.fill(f"scene differences: {text}{more}", 100, subsequent_indent="  "))
    body = [[r["name"], r["unit"] or "-", *map(_cell, r["values"]), *map(_cell, r["differences"]),
             *[_cell(None if x is None else 100.0 * x) for x in r["relative"]]] for r in rows]
    lines.append(format_table(heads, body, ".6g"))
    for label, names in only.items():
        if names:
            lines.append(textwrap.fill(f"only in {label}: {', '.join(names)}", 100, subsequent_indent="  "))
    for i, p in enumerate(plan):
        fig = "compare_signals.png" if i == 0 else f"compare_signals_{i + 1}.png"
        axis = f"{p['axis'][0]} [{p['axis'][1]}]" if p["axis"][1] else p["axis"][0]
        lines.append(textwrap.fill(f"signals of {p['file']} against {axis}: {', '.join(p['signals'])} (with --out: "
                                   f"{fig})", 100, subsequent_indent="  "))
    for m in missing:
        lines.append(textwrap.fill(f"missing: {m}", 100, subsequent_indent="  "))
    return "\n".join(lines)


def write_comparison(out: Path, summaries: Sequence[Summary], heads: list[str], rows: list[dict[str, Any]],
                     plan: list[dict[str, Any]]) -> list[Path]:
    """`compare.csv` (one row per headline: its unit, values, differences and relative differences) and one overlay
    figure per pair of signal files."""
    import numpy as np

    from ..plotting import save

    nan = float("nan")
    n = len(summaries)

    def col(values: list) -> Any:
        return np.asarray([nan if v is None else v for v in values], dtype=float)

    cols: list[tuple[str, str, Any]] = [("headline", "", np.array([r["name"] for r in rows], dtype=object)),
                                        ("unit", "", np.array([r["unit"] for r in rows], dtype=object))]
    cols += [(heads[2 + i], "", col([r["values"][i] for r in rows])) for i in range(n)]
    cols += [(heads[2 + n + i], "", col([r["differences"][i] for r in rows])) for i in range(n - 1)]
    cols += [(heads[1 + 2 * n + i], "", col([None if r["relative"][i] is None else 100.0 * r["relative"][i]
                                             for r in rows])) for i in range(n - 1)]
    files = [write_csv(out / "compare.csv", cols)]
    for i, p in enumerate(plan):
        name = "compare_signals.png" if i == 0 else f"compare_signals_{i + 1}.png"
        files.append(save(plot_signals(p, summaries), out / name))
    return files


def _read_columns(path: Path) -> dict[str, Any]:
    """A signal file's columns by name (floats)."""
    import numpy as np

    with path.open(newline="") as fh:
        header = next(csv.reader(fh))
    values = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {re.sub(r" \[.*\]$", "", h.strip()): values[:, i] for i, h in enumerate(header)}


def plot_signals(plan: Mapping[str, Any], summaries: Sequence[Summary]):
    """One pair of signal files overlaid: one panel per signal (its unit on the axis; at most `MAX_PANELS`), one line
    per summary, against the pair's common axis in words with its unit."""
    from ..plotting import figure

    axis, axis_unit = plan["axis"]
    data = [_read_columns(Path(f)) if f else None for f in plan["files"]]
    diff = list(scene_differences(summaries).items())[:3]  # the legend: what the runs differ in, else their commands
    legend = [f"{s.label}: " + (", ".join(f"{k} = {vals[i]}" for k, vals in diff) if diff else s.command or str(s.path))
              for i, s in enumerate(summaries)]
    shown = plan["signals"][:MAX_PANELS]
    fig, axs = figure(max(len(shown), 1), 1, size=(9.0, 1.6 + 1.9 * max(len(shown), 1)), sharex=True,
                      squeeze=False)
    units = {}
    for s, f in zip(summaries, plan["files"], strict=True):
        if f:
            units.update({n: u for n, u in next(g for g in s.files if str(g.path) == f).columns if n not in units})
    for ax, name in zip(axs[:, 0], shown, strict=False):
        for label, cols in zip(legend, data, strict=True):
            if cols is not None and name in cols and axis in cols:
                ax.plot(cols[axis], cols[name], lw=0.8, label=label[:90])
        ax.set_ylabel(f"{name} [{units.get(name) or '-'}]", fontsize=8)
        ax.grid(True, alpha=0.3)
    axs[0, 0].legend(fontsize=6, loc="upper right")
    words = AXIS_WORDS.get(axis, axis)
    axs[-1, 0].set_xlabel(f"{words} {axis} [{axis_unit}]" if axis_unit else f"{words} {axis}")
    more = len(plan["signals"]) - len(shown)
    fig.suptitle(f"{plan['file']}: {', '.join(s.label for s in summaries)} overlaid"
                 + (f" ({more} more signals in the files, not drawn)" if more > 0 else ""), fontsize=9)
    return fig
