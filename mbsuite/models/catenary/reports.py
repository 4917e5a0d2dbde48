"""What a passage gives: the SimResult of a scene's run on a path (`passage_result`, the run functions of
`reference.py` and `mujoco.py`; `to_simresult`, `train_to_simresult`), and the CLI's table, JSON data and writers
(`report`, `train_report`: CSV records, the figures of `plots.py`, the quality plot). Nothing here simulates: every
number comes from the runs handed in."""

from __future__ import annotations

import textwrap
from pathlib import Path
from types import SimpleNamespace
from typing import Any

from ...results import Report, SimResult, format_table, write_csv
from ...results import assemble as assemble_result
from .analysis import CatenaryRun, scene_config, single
from .config import health_of_regime
from .marks import file_sha256, line_identity, line_label
from .plots import force_uplift_figure, train_figure
from .quality import QualityCriteria, assess, criteria_from
from .quality import plot as quality_plot
from .quality import table_rows as quality_table_rows
from .stats import ACCEPTED_RANGES, STAT_NAMES
from .train import TrainRun, run_passage


def passage_result(scene, engine: str) -> SimResult:
    """A scene's passage with its pantographs on the engine path `engine` as a SimResult: a `[train]` scene's
    (`train_to_simresult`), else one pantograph's (`to_simresult`)."""
    run = run_passage(scene_config(scene, engine))
    if "train" in scene.sections:
        return train_to_simresult(run, scene)
    return to_simresult(single(run), scene)


def to_simresult(run: CatenaryRun, scene) -> SimResult:
    """The run as a SimResult (`results.assemble`: the scene's output signals with the declared units). The declared
    signal `uplift` stands for one column per support, `uplift_<x>m` (x = the support's position), in its unit.
    `statistics` (declared in `stats.STATISTICS`): the eight EN 50318 statistics, the static contact force and the
    quality verdicts (`quality_pass`, `quality_<criterion>_pass`, `quality_nq_pct`; limits from the scene's
    `[quality]` section, else the AC defaults); `stats`: timings, the pantograph engine's warnings and, with an
    `[aerodynamics]` section, the uplift (`aerodynamics`: case, coefficients, forces);
    `events`: the contact losses in the window."""
    r = run.result
    signals = {"contact_force": r.force, "contact_force_filtered": run.filtered, "position": r.x,
               "head_height": r.head, "wire_height": r.wire, "slack_droppers": r.n_slack.astype(float)}
    q = quality_of(run, criteria_from(scene.sections.get("quality")))
    stats = {**{k: v for k, v in run.timing.items() if k != "method"}, "warnings": dict(run.engine_warnings)}
    if run.aerodynamics is not None:  # the uplift the statistics include (N, at this speed)
        stats["aerodynamics"] = run.aerodynamics.as_dict()
    if "windows" in run.stats:  # further windows: their statistics and a route's contact wires' own
        stats["windows"] = {n: {"statistics": {k: s[k] for k in STAT_NAMES},
                                "wires": {w: {k: v for k, v in d.items() if k != "loss_events"}
                                          for w, d in s.get("wires", {}).items()}}
                            for n, s in run.stats["windows"].items()}
    if "insulators" in run.stats:  # the contact force at the line's section insulators
        stats["insulators"] = run.stats["insulators"]
    statistics = {**_scalar_stats(run), "static_contact_force": run.static_force, "quality_pass": q["pass"],
                  **{f"quality_{k}_pass": r["pass"] for k, r in q["rows"].items()},
                  "quality_nq_pct": q["rows"]["arcing_nq"]["value"]}
    res = assemble_result(scene, r.t, signals, engine=run.engine, events=run.stats["loss_events"], stats=stats,
                          statistics=statistics, health=health_of_regime(run.speed_kmh / 3.6, run.params, run.dt))
    if "uplift" in scene.outputs:
        unit = scene.spec.outputs["uplift"]
        names = r.support_names or [f"{xs:g}" for xs in r.support_x]
        for j, name in enumerate(names):
            res.signals[f"uplift_{name}m"] = r.uplift[:, j]
            res.units[f"uplift_{name}m"] = unit
    return res


def _scalar_stats(run: CatenaryRun) -> dict:
    return {k: run.stats[k] for k in STAT_NAMES}


def rerun_record(p, scene_dict: dict | None) -> dict[str, Any]:
    """What a rerun needs besides the scene (summary.json's results): the statistics `window` and the run's `x_range`
    actually used ([start, end] m) and the `line`'s identity (`marks.line_identity`: its name; a line file's path and
    SHA-256, and the SHA-256 of each table it reads and of the scene's [line.irregularity] profile)."""
    section = (scene_dict or {}).get("line") or {}
    ident = line_identity(p, section.get("file"))
    irr = section.get("irregularity")
    if isinstance(irr, dict) and isinstance(irr.get("file"), str):
        ident["files"] = {**ident.get("files", {}), irr["file"]: file_sha256(irr["file"])}
    return {"window": [p.window_start, p.window_end], "x_range": [p.x_start, p.x_end], "line": ident}


def window_time(stats: dict, dt: float) -> float:
    """Time (s) the pantograph spent in the statistics window (its window samples times dt)."""
    return float(stats["n_samples_window"]) * dt


def quality_of(run: CatenaryRun, criteria: QualityCriteria) -> dict:
    """The current-collection quality assessment of a run (`quality.assess`, the one function for every pantograph
    under the wire)."""
    return assess(run.stats, run.speed_kmh, criteria, window_time(run.stats, run.dt))


def report(run: CatenaryRun, scene_dict: dict | None = None, extra_runs: list[CatenaryRun] | None = None,
           quality: QualityCriteria | None = None) -> Report:
    """Human table + JSON data + writer (CSV of filtered/unfiltered force, PNG plots) for one run (and optional
    companion runs shown beside it, e.g. the linear-dropper scene). `quality`: add the current-collection quality
    report of every run (table, JSON `quality`, plot `quality_<pantograph>_<speed>kmh.png`)."""
    runs = [run] + list(extra_runs or [])
    key = int(round(run.speed_kmh))
    rng = ACCEPTED_RANGES.get(key) if (abs(run.speed_kmh - key) < 1e-9 and run.ranges is not None) else None
    headers = ["statistic"] + [f"{r.dropper_law} droppers" for r in runs] + (
        ["EN 50318 range", f"ok ({run.dropper_law})"] if rng else [])
    rows = []
    for name, label in STAT_NAMES.items():
        row = [label] + [f"{r.stats[name]:.2f}" for r in runs]
        if rng:
            lo, hi = rng[name]
            row += [f"{lo:g} .. {hi:g}", "yes" if run.ranges[name]["inside"] else "NO"]
        rows.append(row)
    what = "EN 50318 reference scene" if run.is_reference else "catenary passage (EN 50318 statistics)"
    path = "" if run.engine == "reference" else f" ({run.engine} path)"
    lines = [f"{what} on the {line_label(run.params)}, {run.pantograph} pantograph{path}, {run.speed_kmh:g} km/h "
             f"(element {run.params.element_length:g} m, dt {run.dt:g} s, window [{run.params.window_start:g}, "
             f"{run.params.window_end:g}] m)", format_table(headers, rows)]
    for r in runs:
        c = r.stats["loss_counts"]
        lines.append(f"[{r.dropper_law}] contact losses in window: {len(r.stats['loss_events'])} "
                     f"(<5 ms: {c['short_lt_5ms']}, 5-20 ms: {c['damaging_5_20ms']}, "
                     f">20 ms: {c['power_loss_gt_20ms']}); "
                     f"static contact force {r.static_force:.2f} N; run time {r.timing['total_s']:.2f} s wall, "
                     f"{r.timing['cpu_s']:.2f} s CPU "
                     f"({r.timing['steps']} steps, {r.timing['dofs']} DOFs, {r.timing['us_per_step']:.0f} us/step)")
        lines[-1] = textwrap.fill(lines[-1], 100, subsequent_indent="  ")
    lines.append(f"speed ratio V/c = {run.regime['speed_ratio']:.3f} (c = {run.regime['cw_wave_speed_kmh']:.1f} km/h), "
                 f"regime: {run.regime['regime']}")
    lines[-1] = textwrap.fill(lines[-1], 100, subsequent_indent="  ")
    if run.aerodynamics is not None:  # [aerodynamics]: the statistics and the quality check include the uplift
        lines.append(textwrap.fill(run.aerodynamics.describe(), 100, subsequent_indent="  "))
    for w in run.warnings:
        lines.append(textwrap.fill(f"WARNING: {w}", 100, subsequent_indent="  "))
    data = {"speed_kmh": run.speed_kmh, "pantograph": run.pantograph, "engine": run.engine,
            "element_length": run.params.element_length,
            "timestep": run.dt, **rerun_record(run.params, scene_dict),
            "regime": {k: v for k, v in run.regime.items() if k != "warnings"},
            "warnings": run.warnings,
            "aerodynamics": None if run.aerodynamics is None else run.aerodynamics.as_dict(),
            "runs": {r.dropper_law: {"statistics": _scalar_stats(r), "ranges": r.ranges,
                                     "uplift_at_supports_mm": r.stats["uplift_at_supports_mm"],
                                     "loss_counts": r.stats["loss_counts"], "loss_events": r.stats["loss_events"],
                                     "contact_lost_entirely": r.stats["contact_lost_entirely"],
                                     "static_contact_force": r.static_force, "timing": r.timing} for r in runs}}
    if rng:
        data["all_inside_ranges"] = all(v["inside"] for v in run.ranges.values())
    if any("insulators" in r.stats for r in runs):  # the contact force at the line's section insulators
        lines += insulator_lines([(f"{r.dropper_law} droppers", r.stats) for r in runs])
        for r in runs:
            data["runs"][r.dropper_law]["insulators"] = r.stats.get("insulators", {})
    if "windows" in run.stats:  # further windows (a route: its sections alone and its overlaps)
        lines += window_lines(run, quality)
        data["overlaps"] = overlaps(run.params)
        data["windows"] = window_data(run, quality)
    assessments = []
    if quality is not None:
        for r in runs:
            q = quality_of(r, quality)
            assessments.append((f"{r.pantograph} ({r.dropper_law} droppers)", q))
            data["runs"][r.dropper_law]["quality"] = q
            aero = "" if r.aerodynamics is None else " (Fm with the aerodynamic uplift)"
            lines.append(f"current-collection quality [{r.dropper_law} droppers], {quality.system} criteria, "
                         f"{r.speed_kmh:g} km/h{aero}: {'PASS' if q['pass'] else 'FAIL'}")
            lines.append(format_table(["criterion", "value", "limit", "verdict"], quality_table_rows(q)))
        data["quality_pass"] = all(q["pass"] for _, q in assessments)

    def write(out: Path) -> list[Path]:
        files = write_run_files(runs, out)
        if assessments:
            files.append(quality_plot(assessments, Path(out) / f"quality_{run.pantograph}_{run.speed_kmh:g}kmh.png",
                                      line_label(run.params)))
        return files

    return Report(data=data, table="\n".join(lines), write=write)


def overlaps(p) -> list[list[float]]:
    """The overlaps of the line of `p` (m): where two or more contact wires are under the pantograph
    (`marks.line_marks`)."""
    from .marks import line_marks
    from .mesh import line_of

    return [[a, b] for a, b in line_marks(line_of(p))["overlaps"]]


def _overlap_of(p, a: float, b: float) -> bool:
    return any(lo < b and a < hi for lo, hi in overlaps(p))


def window_data(run: CatenaryRun, quality: QualityCriteria | None) -> dict[str, dict]:
    """The JSON of each further window (`stats.window_statistics`): its statistics, whether it holds an overlap, its
    contact wires' own records and (with `quality`) its current-collection quality."""
    out = {}
    for name, s in run.stats["windows"].items():
        a, b = (float(v) for v in name.split("-"))
        d = {"window": [a, b], "overlap": _overlap_of(run.params, a, b),
             "statistics": {k: s[k] for k in STAT_NAMES}, "uplift_at_supports_mm": s["uplift_at_supports_mm"],
             "loss_events": s["loss_events"], "wires": s.get("wires", {})}
        if quality is not None:
            d["quality"] = assess(s, run.speed_kmh, quality, window_time(s, run.dt))
        out[name] = d
    return out


def window_lines(run: CatenaryRun, quality: QualityCriteria | None) -> list[str]:
    """The table of the further windows (one column each; an overlap marked) and, per window, each contact wire's own
    force through it; with `quality` each window's EN 50367 verdict, the overlap marked."""
    ws = run.stats["windows"]
    names = list(ws)
    heads = [f"[{n}] m" + (" overlap" if _overlap_of(run.params, *(float(v) for v in n.split("-"))) else "")
             for n in names]
    rows = [[label] + [f"{ws[n][key]:.2f}" for n in names] for key, label in STAT_NAMES.items()]
    out = ["statistics per window (the same filtered force; uplift at the steady arms of every contact wire at the "
           "window's supports):", format_table(["statistic", *heads], rows)]
    wrows = []
    for n in names:
        for wname, w in ws[n].get("wires", {}).items():
            first = "-" if w["x_first_contact"] is None else f"{w['x_first_contact']:.1f}"
            last = "-" if w["x_last_contact"] is None else f"{w['x_last_contact']:.1f}"
            wrows.append([f"[{n}] m", wname, f"{w['Fm']:.2f}", f"{w['sigma']:.2f}", f"{w['max']:.2f}",
                          f"{w['min']:.2f}", f"{w['contact_pct']:.1f}", f"{first} .. {last}",
                          str(len(w["loss_events"]))])
    if wrows:
        out.append("each contact wire's own contact force (filtered, on the wire's samples in the window):")
        out.append(format_table(["window", "wire", "Fm (N)", "sigma (N)", "max (N)", "min (N)", "in contact (%)",
                                 "contact x (m)", "losses"], wrows))
        out.append("(a wire's force is 0 off contact: its 20 Hz low-pass dips below 0 next to where its contact begins "
                   "and ends, the min column; losses: its own contact losses once it has carried the head, the "
                   "last where it leaves for good)")
    if quality is not None:
        for n, h in zip(names, heads, strict=True):
            q = assess(ws[n], run.speed_kmh, quality, window_time(ws[n], run.dt))
            out.append(f"current-collection quality, window {h}, {quality.system} criteria: "
                       f"{'PASS' if q['pass'] else 'FAIL'}")
            out.append(format_table(["criterion", "value", "limit", "verdict"], quality_table_rows(q)))
    return out


def insulator_lines(runs: list[tuple[str, dict]]) -> list[str]:
    """The table of the contact force at each section insulator on a contact wire (`stats.insulator_statistics`),
    one row per run ((label, its statistics)) and insulator."""
    rows = []
    for label, stats in runs:
        for name, d in stats.get("insulators", {}).items():
            a, b = d["x_range"]
            if not d["n_samples"]:
                rows.append([label, name, f"{a:g} .. {b:g}", "0", *["-"] * 6])
                continue
            part = "" if d.get("whole", True) else " (part: the run starts or ends on it)"
            rows.append([label, name + part, f"{a:g} .. {b:g}", str(d["n_samples"]), f"{d['Fm']:.2f}",
                         f"{d['max']:.2f}", f"{d['min']:.2f}", f"{d['raw_max']:.2f} / {d['raw_min']:.2f}",
                         f"{d['loss_pct']:.1f}", str(d["n_losses"])])
    return ["insulators: the contact force while the head is on each one (filtered at 20 Hz; raw: unfiltered):",
            format_table(["run", "insulator", "x (m)", "samples", "Fm (N)", "max (N)", "min (N)",
                                              "raw max / min (N)", "loss (%)", "losses"], rows)]


def write_run_files(runs: list[CatenaryRun], out: Path) -> list[Path]:
    """Write each run's contact-force record (`contact_force_<pantograph>_<droppers>_<speed>kmh.csv`, SI units in
    the header) and the force/uplift figure of all of them (`force_uplift_<pantograph>_<speed>kmh.png`); return the
    paths."""
    from ...plotting import save

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    files = []
    for r in runs:
        tag = f"{r.pantograph}_{r.dropper_law}_{r.speed_kmh:g}kmh"
        res = r.result
        per_wire = [col for name, w in (res.wires or {}).items()
                    for col in ((f"force_{name}", "N", w["force"]), (f"wire_height_{name}", "m", w["wire"]))]
        files.append(write_csv(out / f"contact_force_{tag}.csv", [
            ("t", "s", res.t), ("x", "m", res.x), ("force", "N", res.force), ("force_filtered_20Hz", "N", r.filtered),
            ("head_height", "m", res.head), ("wire_height", "m", res.wire), *per_wire]))
    files.append(save(force_uplift_figure(runs),
                      out / f"force_uplift_{runs[0].pantograph}_{runs[0].speed_kmh:g}kmh.png"))
    return files


# --- trains ---------------------------------------------------------------------------------------------------------
STAT_KEYS = ("Fm", "sigma", "stat_max", "stat_min", "max", "min", "uplift_mm", "loss_pct")


def _label(run: TrainRun, k: int) -> str:
    role = "leading" if k == 0 else ("trailing" if len(run.names) == 2 else f"#{k + 1}")
    path = "" if run.engines[k] == "reference" or run.names[k] == "reference2mass" else f", {run.engines[k]}"
    return f"{role} {run.names[k]}{path} (s = {run.offsets[k]:g} m)"


def train_assessments(run: TrainRun, criteria: QualityCriteria) -> list[dict]:
    """The current-collection quality assessment of every pantograph of a train passage (`quality.assess`)."""
    return [assess(s, run.speed_kmh, criteria, float(s["n_samples_window"]) * run.dt) for s in run.stats]


def train_report(run: TrainRun, quality: QualityCriteria | None = None, scene_dict: dict | None = None) -> Report:
    """Table (one column per pantograph), JSON data and writer (per-pantograph CSV, force/uplift plot, quality plot)
    of a train passage; `quality` (QualityCriteria) adds the quality report of every pantograph."""
    from ...plotting import save

    labels = [_label(run, k) for k in range(len(run.names))]
    rows = [[STAT_NAMES[key]] + [f"{s[key]:.2f}" for s in run.stats] for key in STAT_KEYS]
    lines = [f"train of {len(run.names)} pantographs on the {line_label(run.params)}, {run.speed_kmh:g} km/h "
             f"(element {run.params.element_length:g} m, "
             f"dt {run.dt:g} s, {run.timing['steps']} steps, {run.timing['cpu_s']:.2f} s CPU); window "
             f"[{run.params.window_start:g}, {run.params.window_end:g}] m on each pantograph's own position",
             format_table(["statistic", *labels], rows)]
    for k, s in enumerate(run.stats):
        c = s["loss_counts"]
        lines.append(f"{labels[k]}: static contact force {run.static_forces[k]:.2f} N; contact losses in window "
                     f"{len(s['loss_events'])} (<5 ms: {c['short_lt_5ms']}, 5-20 ms: {c['damaging_5_20ms']}, "
                     f">20 ms: {c['power_loss_gt_20ms']})")
        if run.aerodynamics is not None:
            lines.append(f"{labels[k]}: {run.aerodynamics[k].describe()}")
    if any("insulators" in s for s in run.stats):  # the contact force at the line's section insulators
        lines += insulator_lines(list(zip(labels, run.stats, strict=True)))
    for w in run.warnings:
        lines.append(f"WARNING: {w}")
    data = {"speed_kmh": run.speed_kmh, "element_length": run.params.element_length, "timestep": run.dt,
            **rerun_record(run.params, scene_dict),
            "timing": run.timing,
            "pantographs": [{"name": run.names[k], "engine": run.engines[k], "offset_m": run.offsets[k],
                             "static_contact_force": run.static_forces[k],
                             "statistics": {key: run.stats[k][key] for key in STAT_KEYS},
                             "uplift_at_supports_mm": run.stats[k]["uplift_at_supports_mm"],
                             "loss_events": run.stats[k]["loss_events"],
                             "aerodynamics": None if run.aerodynamics is None else run.aerodynamics[k].as_dict(),
                             **({"insulators": run.stats[k]["insulators"]} if "insulators" in run.stats[k] else {})}
                            for k in range(len(run.names))],
            "warnings": run.warnings}
    qs = []
    if quality is not None:
        qs = train_assessments(run, quality)
        for k, q in enumerate(qs):
            data["pantographs"][k]["quality"] = q
            lines.append(f"current-collection quality, {labels[k]}, {quality.system} criteria: "
                         f"{'PASS' if q['pass'] else 'FAIL'}")
            lines.append(format_table(["criterion", "value", "limit", "verdict"], quality_table_rows(q)))
        data["quality_pass"] = all(q["pass"] for q in qs)
    if "windows" in run.stats[0]:  # further windows (a route: its sections alone and its overlaps), per pantograph
        data["overlaps"] = overlaps(run.params)
        for k in range(len(run.names)):
            one = SimpleNamespace(stats=run.stats[k], params=run.params, speed_kmh=run.speed_kmh, dt=run.dt)
            lines.append(f"{labels[k]}:")
            lines += window_lines(one, quality)
            data["pantographs"][k]["windows"] = window_data(one, quality)

    def write(out: Path) -> list[Path]:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        files = []
        for k, res in enumerate(run.results):
            tag = f"p{k + 1}_{run.names[k]}_{run.speed_kmh:g}kmh"
            per_wire = [col for name, w in (res.wires or {}).items()
                        for col in ((f"force_{name}", "N", w["force"]), (f"wire_height_{name}", "m", w["wire"]))]
            files.append(write_csv(out / f"contact_force_{tag}.csv", [
                ("t", "s", res.t), ("x", "m", res.x), ("force", "N", res.force),
                ("force_filtered_20Hz", "N", run.filtered[k]), ("head_height", "m", res.head),
                ("wire_height", "m", res.wire), *per_wire]))
        files.append(save(train_figure(run, labels), out / f"train_force_{run.speed_kmh:g}kmh.png"))
        if qs:
            files.append(quality_plot(list(zip(labels, qs, strict=True)),
                                      out / f"quality_train_{run.speed_kmh:g}kmh.png", line_label(run.params)))
        return files

    return Report(data=data, table="\n".join(lines), write=write)


def train_to_simresult(run: TrainRun, scene) -> SimResult:
    """A train passage as a SimResult: the leading pantograph's channels under the usual names (on its own record),
    `contact_force_p<k>` / `position_p<k>` for every pantograph k = 1, 2, ... (each on its own record; all records
    have the same length, one passage from x_start to x_end, on the time since the pantograph's entry), and per
    pantograph the eight statistics and quality verdicts in `statistics` (`p<k>_Fm`, ..., `p<k>_quality_pass`)."""
    lead = run.results[0]
    signals = {"contact_force": lead.force, "contact_force_filtered": run.filtered[0], "position": lead.x,
               "head_height": lead.head, "wire_height": lead.wire, "slack_droppers": lead.n_slack.astype(float)}
    qs = train_assessments(run, criteria_from(scene.sections.get("quality")))
    stats = {"steps": run.timing["steps"], "cpu_s": run.timing["cpu_s"], "total_s": run.timing["total_s"]}
    if any("insulators" in s for s in run.stats):  # per pantograph (p<k>) the contact force at the insulators
        stats["insulators"] = {f"p{k + 1}": s.get("insulators", {}) for k, s in enumerate(run.stats)}
    statistics: dict[str, Any] = {}
    for k, s in enumerate(run.stats):
        statistics.update({f"p{k + 1}_{key}": s[key] for key in STAT_KEYS})
        statistics[f"p{k + 1}_static_contact_force"] = run.static_forces[k]
        statistics[f"p{k + 1}_quality_pass"] = qs[k]["pass"]
    if "windows" in run.stats[0]:  # each pantograph's further windows (`accuracy.values`)
        stats["windows"] = {f"p{k + 1}": {n: {"statistics": {key: w[key] for key in STAT_NAMES}}
                                          for n, w in s["windows"].items()} for k, s in enumerate(run.stats)}
    events = [{**e, "pantograph": k + 1} for k, s in enumerate(run.stats) for e in s["loss_events"]]
    res = assemble_result(scene, lead.t, signals, engine=run.engines[-1], events=events, stats=stats,
                          statistics=statistics, health=health_of_regime(run.speed_kmh / 3.6, run.params, run.dt))
    for k, r in enumerate(run.results):
        res.signals[f"contact_force_p{k + 1}"] = r.force
        res.units[f"contact_force_p{k + 1}"] = "N"
        res.signals[f"position_p{k + 1}"] = r.x
        res.units[f"position_p{k + 1}"] = "m"
    return res
