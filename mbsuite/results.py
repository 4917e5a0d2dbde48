"""Result containers and writers (CSV with SI units in the header, summary.json with versions and scene, tables).

`SimResult` follows scipy's `solve_ivp` result: arrays plus metadata, nothing computed lazily.
"""

from __future__ import annotations

import csv
import json
import math
import platform
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np


@dataclass
class SimResult:
    """A time simulation. `signals[name]` is sampled at `t`; `units[name]` is its SI unit.
    `events` lists discrete events (e.g. contact losses: {"kind", "t_start", "duration"}); `statistics` the values of
    the model's declared statistics (`mbsuite.statistics`: name -> number or verdict, the unit, definition and window
    in `SPEC.statistics`); `stats` the solver's counters, timings and settings (steps, function evaluations, wall
    time: not physics)."""

    t: np.ndarray
    signals: dict[str, np.ndarray]
    units: dict[str, str]
    engine: str
    events: list[dict[str, Any]] = field(default_factory=list)
    stats: dict[str, Any] = field(default_factory=dict)
    scene: dict[str, Any] = field(default_factory=dict)
    health: list[Any] = field(default_factory=list)  # mbsuite.trust.health.Figure: the run's own accuracy figures
    warnings: list[str] = field(default_factory=list)  # accepted health violations (allow_inaccurate), loud
    error_estimate: Any = None  # trust.estimate.ErrorEstimate of the headline outputs (run(..., error_estimate=True))
    statistics: dict[str, Any] = field(default_factory=dict)
    statistic_units: dict[str, str] = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.signals[name]

    def summary(self) -> dict[str, Any]:
        """Per-signal min/max/final with units, the resolved inputs, events, stats, health figures and warnings."""
        out = {"engine": self.engine, "n_samples": int(self.t.size), "t_end": float(self.t[-1]) if self.t.size else 0.0}
        out["signals"] = {
            k: {"unit": self.units.get(k, ""), "min": float(np.min(v)), "max": float(np.max(v)), "final": float(v[-1])}
            for k, v in self.signals.items()
        }
        if self.scene:  # every resolved input, defaults included, so a result says what it was computed for
            out["input"] = dict(self.scene.get("input") or {})
            out["solver"] = dict(self.scene.get("solver") or {})
        out["events"] = self.events
        out["statistics"] = {k: {"value": v, "unit": self.statistic_units.get(k, "")}
                             for k, v in self.statistics.items()}
        out["stats"] = self.stats
        out["health"] = [f.to_dict() for f in self.health]
        if self.error_estimate is not None:
            out["error_estimate"] = self.error_estimate.to_dict()
        if self.warnings:
            out["warnings"] = list(self.warnings)
        return out

    def write_csv(self, path: str | Path) -> Path:
        """Write `t` and every signal as CSV (header `name [unit]`)."""
        cols = [("t", "s", self.t)] + [(k, self.units.get(k, ""), v) for k, v in self.signals.items()]
        return write_csv(path, cols)

    def to_pandas(self) -> Any:
        """The signals as a `pandas.DataFrame` indexed by time `t`, one column per signal named by the signal
        (`df["F1"]`); the SI units are in `df.attrs["units"]` (signal -> unit, and `t` -> "s"). Needs pandas:
        `pip install mbsuite[pandas]`."""
        try:
            import pandas as pd
        except ModuleNotFoundError as exc:
            raise ModuleNotFoundError("SimResult.to_pandas() needs pandas: pip install 'mbsuite[pandas]'") from exc
        df = pd.DataFrame({k: np.asarray(v) for k, v in self.signals.items()},
                          index=pd.Index(np.asarray(self.t), name="t"))
        df.attrs["units"] = {"t": "s", **{k: self.units.get(k, "") for k in self.signals}}
        return df

    def panels(self, signals: Sequence[str] | None = None, ratio: float = 10.0) -> list[list[str]]:
        """The signals grouped for plotting, so that no line reads as flat beside another: signals share a panel only
        if they have one unit and the panel's range (lowest to highest value of its signals) is at most `ratio`
        times each signal's own range, i.e. every line spans at least 1/`ratio` of its panel's height. A constant
        signal joins a panel whose range holds its value. Signals are taken in their order (`signals`, or the
        result's), each into the first panel it fits."""
        names = list(signals) if signals is not None else list(self.signals)
        lo = {k: float(np.nanmin(self.signals[k])) if np.size(self.signals[k]) else 0.0 for k in names}
        hi = {k: float(np.nanmax(self.signals[k])) if np.size(self.signals[k]) else 0.0 for k in names}
        groups: list[list[str]] = []

        def fits(group: list[str], k: str) -> bool:
            if self.units.get(group[0], "") != self.units.get(k, ""):
                return False
            members = [*group, k]
            span = max(hi[m] for m in members) - min(lo[m] for m in members)
            own = [hi[m] - lo[m] for m in members if hi[m] > lo[m]]
            return span == 0.0 or (bool(own) and span <= ratio * min(own))

        for k in names:
            group = next((g for g in groups if fits(g, k)), None)
            if group is None:
                groups.append([k])
            else:
                group.append(k)
        return groups

    def plot(self, signals: Sequence[str] | None = None, axes: Any = None) -> Any:
        """Time histories, one panel per group of signals of one unit whose lines each span at least a tenth of the
        panel (`panels`), so a 100 N force does not read as a flat line beside a 9 kN one. Draws on `axes` (a
        sequence of Axes, one per panel) if given, else returns a new `matplotlib.figure.Figure`."""
        from .plotting import figure

        groups = self.panels(signals)
        fig = None
        if axes is None:
            fig, axes = figure(len(groups), 1, size=(9.0, 1.8 + 1.7 * len(groups)), sharex=True, squeeze=False)
            axes = axes[:, 0]
        for ax, ks in zip(axes, groups, strict=True):
            unit = self.units.get(ks[0], "") or "-"
            for k in ks:
                ax.plot(self.t, self.signals[k], lw=0.9, label=k)
            ax.set_ylabel(f"{', '.join(ks) if len(ks) <= 2 else ks[0] + ', ...'} [{unit}]", fontsize=8)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7, loc="upper right")
        axes[-1].set_xlabel("t [s]")
        if fig is not None:
            model = self.scene.get("model", "")
            name = self.scene.get("name", "")
            fig.suptitle(f"{model}/{name} ({self.engine})" if model else self.engine, fontsize=9)
        return fig if fig is not None else axes

    def report(self) -> Report:
        """A CLI report: per-signal min/max/final, events, solver stats; `--out` writes run.csv."""
        import textwrap

        rows = [[k, self.units.get(k, ""), float(np.min(v)), float(np.max(v)), float(v[-1])]
                for k, v in self.signals.items()]
        table = format_table(["signal", "unit", "min", "max", "final"], rows, ".6g")
        if self.scene.get("input"):
            resolved = ", ".join(f"{k} = {_plain(v)}" for k, v in self.scene["input"].items())
            table = textwrap.fill(f"input (resolved, defaults included): {resolved}", 100,
                                  subsequent_indent="  ") + "\n" + table
        if self.events:
            kinds: dict[str, int] = {}
            for e in self.events:
                kinds[e.get("kind", "event")] = kinds.get(e.get("kind", "event"), 0) + 1
            table += (f"\nrecorded events (one per element and change): {len(self.events)}" if
                      set(kinds) == {"event"} else "\nrecorded events: " + ", ".join(
                          f"{k} x{n}" for k, n in sorted(kinds.items())))
            if isinstance(self.stats.get("events"), int | np.integer):  # the engine's own count differs in kind
                table += (f"; the engine's events = {self.stats['events']} below counts the instants its event "
                          "location stopped at (one instant may change several elements)")
        if self.statistics:
            table += "\n" + textwrap.fill("statistics: " + ", ".join(
                f"{k} = {_plain(v)}" + (f" {self.statistic_units[k]}" if self.statistic_units.get(k, "-") != "-"
                                        else "") for k, v in self.statistics.items()), 100, subsequent_indent="  ")
        stats = ", ".join(f"{k} = {_plain(v)}" for k, v in self.stats.items())
        table += "\n" + textwrap.fill(f"engine {self.engine}; {stats}", 100, subsequent_indent="  ")
        if self.health:
            table += "\n" + textwrap.fill("health: " + ", ".join(
                f"{f.name} {f.value:.3g} (bound {f.bound:.3g}{'' if f.ok else ', EXCEEDED'})" for f in self.health),
                100, subsequent_indent="  ")
        if self.error_estimate is not None:
            table += "\n" + self.error_estimate.table()
        for w in self.warnings:
            table += f"\n{w}"

        def write(out: Path) -> list[Path]:
            from .plotting import save

            return [self.write_csv(Path(out) / "run.csv"), save(self.plot(), Path(out) / "run.png")]

        return Report(self.summary(), table, write)


def assemble(scene: Any, t: np.ndarray, signals: Mapping[str, np.ndarray], *, engine: str,
             events: Sequence[dict[str, Any]] = (), stats: Mapping[str, Any] | None = None,
             statistics: Mapping[str, Any] | None = None, always: Sequence[str] = (),
             health: Sequence[Any] = ()) -> SimResult:
    """The one place that turns a model's signals into a `SimResult`: keeps the signals the scene asks for (its
    `outputs`; all when it names none) plus `always`, takes their units from the model's declared output table
    (`scene.spec.outputs`, SI), checks the `statistics` against the model's declared ones (`scene.spec.statistics`,
    `mbsuite.statistics.checked`) and attaches the scene. A signal or statistic missing from its table is an error,
    not a unitless number. `stats`: counters, timings and settings of the solver."""
    from .statistics import checked, unit_of

    table = scene.spec.outputs
    wanted = set(scene.outputs) | set(always) if scene.outputs else set(signals)
    keep = {k: np.asarray(v) for k, v in signals.items() if k in wanted}
    missing = sorted(k for k in keep if k not in table)
    if missing:
        raise KeyError(f"model '{scene.model}' declares no unit for signal(s) {missing}; add them to its outputs")
    stat_table = scene.spec.statistics
    values = checked(statistics or {}, stat_table, scene.model)
    return SimResult(np.asarray(t), keep, {k: table[k] for k in keep}, engine, events=list(events),
                     stats=dict(stats or {}), scene=scene.to_dict(), health=list(health), statistics=values,
                     statistic_units={k: unit_of(stat_table, k) for k in values})


def _plain(v: Any) -> str:
    """A stats value for a table: numpy scalars as plain numbers, floats to 6 significant digits, an empty container
    as "none", a mapping as `k: v` pairs."""
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, Mapping | list | tuple) and not v:
        return "none"
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{k}: {_plain(x)}" for k, x in v.items()) + "}"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def write_csv(path: str | Path, columns: Sequence[tuple[str, str, Any]]) -> Path:
    """Write columns `(name, unit, values)` as CSV; the header reads `name [unit]`."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays = [np.asarray(c[2]) for c in columns]
    n = max(a.shape[0] for a in arrays)
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([f"{name} [{unit}]" if unit else name for name, unit, _ in columns])
        for i in range(n):
            w.writerow([_fmt(a[i]) if i < a.shape[0] else "" for a in arrays])
    return path


#: the unit a name's ending spells (`peaks_hz` -> Hz, `uplift_mm` -> mm), for reported numbers no table names
SUFFIX_UNITS = {"_hz": "Hz", "_m": "m", "_mm": "mm", "_s": "s", "_deg": "deg", "_rad": "rad", "_kmh": "km/h",
                "_pct": "%", "_rel": "1", "_ratio": "1", "_kg": "kg", "_count": "1", "_counts": "1"}
#: names that are counts (dimensionless) whatever reports them
COUNT_NAMES = {"evaluations": "1", "steps": "1", "dofs": "1", "n_samples": "1", "count": "1", "n": "1"}


#: a list of numbers longer than this is a curve or a time series, not a quantity of a report
MAX_LIST = 16


def numbers_in(data: Any, prefix: str = "", unit: str = "", skip: frozenset[str] = frozenset()
               ) -> list[tuple[str, float, str]]:
    """Every number of a report's data as (dotted path `reference[1].f_n`, value, the unit recorded beside it: a
    mapping's "unit" holds for its numbers); keys in `skip` (at any depth), booleans, strings and lists longer than
    `MAX_LIST` (curves, time series) left out."""
    out: list[tuple[str, float, str]] = []
    if isinstance(data, Mapping):
        own = data.get("unit")
        unit = own if isinstance(own, str) else unit
        for k, v in data.items():
            if k in skip or k == "unit":
                continue
            out += numbers_in(v, f"{prefix}.{k}" if prefix else str(k), unit, skip)
    elif isinstance(data, list | tuple):
        if len(data) <= MAX_LIST:
            for i, v in enumerate(data):
                out += numbers_in(v, f"{prefix}[{i}]", unit, skip)
    elif isinstance(data, int | float) and not isinstance(data, bool):
        out.append((prefix, float(data), unit))
    return out


def names_of(path: str) -> list[str]:
    """The names of a reported number's path, indices dropped (`peaks_hz.linear.F1[0]` -> peaks_hz, linear, F1)."""
    return [n.split("[")[0] for n in path.split(".") if n.split("[")[0]]


def spelled_unit(name: str) -> str:
    """The unit a name's ending spells (`SUFFIX_UNITS`; the longest ending wins), else ""."""
    low = name.lower()
    return next((u for suffix, u in sorted(SUFFIX_UNITS.items(), key=lambda kv: -len(kv[0])) if low.endswith(suffix)),
                "")


def unit_source(path: str, units: Mapping[str, str]) -> tuple[str, str]:
    """(the name that gives a reported number its unit, the unit), the number named by its dotted `path`: its last
    name in `units` (or a count's, `COUNT_NAMES`), else the unit its last name's ending spells, else the nearest name
    of its path that spells one (`peaks_hz.linear.F1[0]` -> peaks_hz, Hz); (its last name, "") when none does."""
    names = names_of(path) or [path]
    last = names[-1]
    if last in units or last in COUNT_NAMES:
        return last, units.get(last, COUNT_NAMES.get(last, ""))
    for name in reversed(names):
        if spelled_unit(name):
            return name, spelled_unit(name)
    return last, ""


def _fmt(x: Any) -> str:
    if isinstance(x, float | np.floating):
        return repr(float(x))
    return str(x)


def versions() -> dict[str, str]:
    """The versions of mbsuite, its engines and Python, for summary.json."""
    import mujoco
    import pinocchio
    import scipy

    from .version import __version__

    return {
        "mbsuite": __version__,
        "mujoco": mujoco.__version__,
        "pinocchio": pinocchio.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "python": sys.version.split()[0],
        "platform": platform.platform(),
    }


def to_jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays and nested containers to JSON types; non-finite floats become null."""
    if isinstance(obj, Mapping):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return to_jsonable(obj.item())
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def git_commit() -> dict[str, Any] | None:
    """The commit of the checkout mbsuite runs from (`commit`, and `dirty`: tracked files changed since), or None
    when it runs from an installed package or git is missing."""
    import subprocess

    root = Path(__file__).resolve().parent.parent
    if not (root / ".git").exists():
        return None
    try:
        commit = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True,
                                timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return {"commit": commit, "dirty": bool(dirty)}


def write_summary(out_dir: str | Path, scene: Mapping[str, Any] | None, results: Mapping[str, Any],
                  command: Mapping[str, Any] | None = None) -> Path:
    """Write `summary.json` into `out_dir`: the versions (mbsuite, engines, Python; the git commit when run from a
    checkout), the command that made it (`command`: its argv and options), the full scene as run (every default
    resolved: `mbsuite run summary.json` runs it again) and the results."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    p = out / "summary.json"
    body = {"versions": versions(), "checkout": git_commit(), "command": dict(command) if command else None,
            "scene": scene, "results": results}
    p.write_text(json.dumps(to_jsonable(body), indent=2))
    return p


def read_summary_scene(path: str | Path) -> dict[str, Any]:
    """The scene a `summary.json` records (what `mbsuite run summary.json` reruns); a SceneError naming the file
    when it is no summary or holds no scene."""
    from .errors import SceneError

    p = Path(path)
    try:
        data = json.loads(p.read_text())
    except OSError as exc:
        raise SceneError(f"cannot read {p}: {exc.strerror or exc}") from exc
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise SceneError(f"{p} is not a summary.json (not valid JSON: {exc})") from exc
    scene = data.get("scene") if isinstance(data, dict) else None
    if not isinstance(scene, dict):
        raise SceneError(f"{p} records no scene (the command that wrote it ran none); rerun that command instead"
                         + (f": mbsuite {' '.join(data['command']['argv'])}" if isinstance(data, dict)
                            and isinstance(data.get("command"), dict) and data["command"].get("argv") else ""))
    return scene


def format_table(headers: Sequence[str], rows: Sequence[Sequence[Any]], floatfmt: str = ".6g") -> str:
    """A plain-text table with right-aligned numbers."""

    def cell(v: Any) -> str:
        if isinstance(v, float | np.floating):
            return format(float(v), floatfmt)
        return str(v)

    body = [[cell(v) for v in r] for r in rows]
    widths = [max(len(str(h)), *(len(r[i]) for r in body)) if body else len(str(h)) for i, h in enumerate(headers)]
    lines = ["  ".join(str(h).rjust(w) for h, w in zip(headers, widths, strict=True))]
    lines.append("  ".join("-" * w for w in widths))
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)) for r in body]
    return "\n".join(lines)


@dataclass
class Report:
    """What an analysis returns to the CLI: JSON-able `data`, a human `table`, and an optional writer that puts
    CSV/PNG files into a directory (called only with `--out`). Analyses never print; the CLI never does physics."""

    data: dict[str, Any]
    table: str
    write: Any = None  # Callable[[Path], list[Path]] | None
    inaccurate: list[str] = field(default_factory=list)  # error estimates above their tolerance, kept (flag_inaccurate)

    def flag_inaccurate(self, messages: Sequence[str]) -> None:
        """Flag the report as kept although error estimates exceed their tolerances (`messages`, the `INACCURATE:`
        lines, already in its warnings): `data["inaccurate"]` holds them and the table ends with the verdict; the
        command line exits with status 3 after printing it and writing its files (`trust.health.InaccurateResult`)."""
        if self.inaccurate or not messages:
            return
        self.inaccurate = list(messages)
        self.data["inaccurate"] = list(messages)
        self.table += (f"\nINACCURATE RESULT, kept: {len(messages)} error estimate(s) above their tolerance (above); "
                       "exit status 3; --allow-inaccurate accepts it")

    def save(self, out_dir: str | Path, scene: Mapping[str, Any] | None,
             command: Mapping[str, Any] | None = None) -> list[Path]:
        """Write the report's files and summary.json (`write_summary`: with the scene and the command) into
        `out_dir`; return their paths."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        files = list(self.write(out)) if self.write else []
        files.append(write_summary(out, scene, self.data, command))
        return files
