"""Work-precision studies: what accuracy costs in wall time, for every engine and method of a scene.

`workprecision(scene)` (CLI: `mbsuite workprecision SCENE [--out DIR] [--json]`) runs the study the scene's model
declares (`workprecision_study(scene, quick)` in the module named by its `ModelSpec.cases`); this module names no model.
Each study (a `Study`: its settings, its reference from a different method, a state error and a physics metric) is
described where it is declared: the model's `cases` module, and in `docs/accuracy.md`.

Wall time: median of `repeats` (>= 5 by default) runs in this process, one after another, min-max shown.
The result lists, per engine/method, the cheapest setting reaching 1e-2, 1e-4 and 1e-6 relative physics error.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MbsuiteError
from ..progress import planned
from ..results import Report, format_table, write_csv
from ..scenes import Scene

TOLS = (1e-2, 1e-4, 1e-6)


@dataclass
class Row:
    """One measured setting of a work-precision study: engine, method, setting, wall times (median, min, max) and
    the two errors."""
    engine: str
    method: str
    setting: Any
    time_s: float = math.nan
    time_min: float = math.nan
    time_max: float = math.nan
    state_error: float = math.nan
    physics_error: float = math.nan
    details: dict = field(default_factory=dict)
    error: str | None = None

    def as_dict(self) -> dict:
        """The row as a JSON-able dictionary."""
        return {"engine": self.engine, "method": self.method, "setting": self.setting, "time_s": self.time_s,
                "time_min": self.time_min, "time_max": self.time_max, "state_error": self.state_error,
                "physics_error": self.physics_error, "details": self.details, "error": self.error}


def timed(fn: Callable[[], Any], repeats: int) -> tuple[Any, float, float, float]:
    """Run `fn` `repeats` times; return its last result and the median, min and max wall time (s)."""
    times, res = [], None
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        res = fn()
        times.append(time.perf_counter() - t0)
    return res, float(np.median(times)), float(min(times)), float(max(times))


def _rel(a: float, b: float, floor: float = 1e-300) -> float:
    return abs(a - b) / max(abs(b), floor)


@dataclass
class Setting:
    """One setting of a study: which engine and method, the setting value (step, rtol...), and how to run it."""
    engine: str
    method: str
    setting: Any
    run: Callable[[], Any]


class Study:
    """One scene family's study: settings, the reference, and the two error measures."""

    state_doc = ""
    physics_doc = ""

    def __init__(self, scene: Scene, quick: bool = False):
        self.scene = scene
        self.quick = quick

    def settings(self) -> list[Setting]:
        """Every setting the study measures."""
        raise NotImplementedError

    def reference(self) -> tuple[Any, dict]:
        """The converged reference solution the errors are measured against."""
        raise NotImplementedError

    def state_error(self, res: Any, ref: Any) -> float:
        """Relative error of a run's state trajectory against the reference."""
        raise NotImplementedError

    def physics_error(self, res: Any, ref: Any) -> tuple[float, dict]:
        """Relative error of a run's physics figure (the quantity an engineer reads) against the reference."""
        raise NotImplementedError


class LadderStudy(Study):
    """A study of a model with an event-exact hand path (`reference`, one integrator: its tolerance ladder
    `HAND_RTOLS`, atol = rtol / 100) and a MuJoCo path (`MJ_INTEGRATORS` x `MJ_STEPS`); the reference is the hand
    path at rtol 1e-12 (checked against rtol 1e-11). A subclass sets `base` (the scene the settings change) and
    `signals` (the outputs the state error compares: max_t |y - y_ref| / max_t |y_ref| over them, on the output
    grid), and writes `physics_error`."""

    HAND_RTOLS: tuple[float, ...] = (1e-4, 1e-6, 1e-8, 1e-10)
    HAND_METHOD = "event-exact DOP853"
    MJ_INTEGRATORS: tuple[str, ...] = ("rk4", "euler")
    MJ_STEPS: tuple[float, ...] = (1e-4, 5e-5, 2e-5)
    base: Scene
    signals: list[str]

    def settings(self) -> list[Setting]:
        """The settings of the study: hand-path tolerances and MuJoCo integrators x timesteps (quick: one each)."""
        from ..simulate import run

        out = []
        for r in ((1e-6,) if self.quick else self.HAND_RTOLS):
            sc = self.base.replace(solver={"engine": "reference", "rtol": r, "atol": r * 1e-2})
            out.append(Setting("reference", self.HAND_METHOD, r, lambda sc=sc: run(sc)))
        for i in ("rk4",) if self.quick else self.MJ_INTEGRATORS:
            for h in ((1e-4,) if self.quick else self.MJ_STEPS):
                sc = self.base.replace(solver={"engine": "mujoco", "integrator": i, "timestep": h})
                out.append(Setting("mujoco", i, h, lambda sc=sc: run(sc)))
        return out

    def reference(self) -> tuple[Any, dict]:
        """The reference run (hand path, rtol 1e-12) and its own accuracy (against rtol 1e-11)."""
        from ..simulate import run

        ref = run(self.base.replace(solver={"engine": "reference", "rtol": 1e-12, "atol": 1e-14}))
        chk = run(self.base.replace(solver={"engine": "reference", "rtol": 1e-11, "atol": 1e-13}))
        err, _ = self.physics_error(chk, ref)
        return ref, {"reference": f"hand path ({self.HAND_METHOD}) rtol 1e-12, atol 1e-14",
                     "check": "hand path rtol 1e-11", "check_state_error": self.state_error(chk, ref),
                     "check_physics_error": err}

    def state_error(self, res: Any, ref: Any) -> float:
        """Largest difference of the compared signals from the reference, relative to their largest value."""
        scale = max(float(np.max(np.abs(ref[s]))) for s in self.signals) or 1.0
        return max(float(np.max(np.abs(np.interp(ref.t, res.t, res[s]) - ref[s]))) for s in self.signals) / scale


def available() -> list[str]:
    """Models that declare a work-precision study (`workprecision_study` in their `ModelSpec.cases` module)."""
    from ..registry import models

    return sorted(n for n, s in models().items() if hasattr(s.suite(), "workprecision_study"))


def study_for(scene: Scene, quick: bool = False) -> Study:
    """The study the scene's model declares (its `ModelSpec.cases` module's `workprecision_study`)."""
    make = getattr(scene.spec.suite(), "workprecision_study", None)
    if make is None:
        raise MbsuiteError(f"no work-precision study for model '{scene.model}'; available: {available()}")
    return make(scene, quick=quick)


def find_row(report: Report, engine: str, method: str, setting: Any) -> dict:
    """The one row of a study's report with this engine, method and setting (KeyError if there is not exactly one)."""
    rows = [r for r in report.data["rows"] if (r["engine"], r["method"], r["setting"]) == (engine, method, setting)]
    if len(rows) != 1:
        raise KeyError(f"{len(rows)} rows for {engine} {method} {setting!r}")
    return rows[0]


def cheapest(rows: list[Row], tols=TOLS) -> list[dict]:
    """Per engine/method and overall: the cheapest (median wall time) setting reaching each physics tolerance."""
    ok = [r for r in rows if r.error is None and math.isfinite(r.physics_error)]
    out = []
    for tol in tols:
        keys = sorted({(r.engine, r.method) for r in ok}) + [("any", "any")]
        for key in keys:
            cand = [r for r in ok if (key == ("any", "any") or (r.engine, r.method) == key) and r.physics_error <= tol]
            best = min(cand, key=lambda r: r.time_s) if cand else None
            out.append({"tol": tol, "engine": key[0], "method": key[1], "setting": best.setting if best else None,
                        "time_s": best.time_s if best else None,
                        "physics_error": best.physics_error if best else None,
                        "best_engine": f"{best.engine} {best.method}" if best else None})
    return out


def workprecision(scene: Scene, repeats: int = 5, quick: bool = False, progress: Callable[[str], None] | None = None
                  ) -> Report:
    """Run the scene's study (module docstring) and return a Report (table, data, CSV/JSON/PNG writer)."""
    study = study_for(scene, quick)
    settings = study.settings()
    rows: list[Row] = []
    ref, ref_info = study.reference()
    with planned("work-precision", len(settings) * repeats, 1,
                 detail=f"{len(settings)} settings x {repeats} timed repeats, after the reference run") as plan:
        for s in settings:
            row = Row(s.engine, s.method, s.setting)
            try:
                res, row.time_s, row.time_min, row.time_max = timed(s.run, repeats)
                row.state_error = study.state_error(res, ref)
                row.physics_error, row.details = study.physics_error(res, ref)
            except MbsuiteError as exc:  # a diverging setting is a data point, not a crash
                row.error = str(exc)
            rows.append(row)
            if plan is not None:
                plan.update(repeats)
            if progress:
                progress(f"{row.engine} {row.method} {row.setting}: {row.time_s:.3g} s, physics "
                         f"{row.physics_error:.2e}")
    best = cheapest(rows)
    data = {"scene": scene.name or scene.model, "model": scene.model, "repeats": repeats, "quick": quick,
            "state_error": study.state_doc, "physics_error": study.physics_doc, **ref_info,
            "rows": [r.as_dict() for r in rows], "cheapest": best}
    return Report(data, _table(rows, best, study, ref_info), lambda out: _write(out, rows, best, scene, study))


def _fmt_setting(s: Any) -> str:
    return f"{s:g}" if isinstance(s, float) else str(s)


def _table(rows: list[Row], best: list[dict], study: Study, ref_info: dict) -> str:
    body = [[r.engine, r.method, _fmt_setting(r.setting), r.time_s, r.time_min, r.time_max, r.state_error,
             r.physics_error] if r.error is None else
            [r.engine, r.method, _fmt_setting(r.setting), "diverged", "", "", "", ""] for r in rows]
    lines = [f"reference: {ref_info.get('reference')}"]
    if "check_physics_error" in ref_info:
        lines.append(f"  its accuracy ({ref_info['check']}): state {ref_info['check_state_error']:.2e}, "
                     f"physics {ref_info['check_physics_error']:.2e}")
    lines += [f"state error: {study.state_doc}", f"physics error: {study.physics_doc}", ""]
    lines.append(format_table(["engine", "method", "h / rtol / setting", "median s", "min s", "max s", "state err",
                               "physics err"], body, ".3g"))
    lines += ["", "cheapest setting reaching a relative physics error:"]
    lines.append(format_table(["tol", "engine", "method", "setting", "median s", "physics err"],
                              [[f"{b['tol']:g}", b["engine"], b["method"],
                                _fmt_setting(b["setting"]) if b["setting"] is not None else "-",
                                b["time_s"] if b["time_s"] is not None else "-",
                                b["physics_error"] if b["physics_error"] is not None else "-"] for b in best], ".3g"))
    return "\n".join(lines)


def plot(rows: list[Row], study: Study, title: str = "", axes: Any = None) -> Any:
    """Error against wall time for every (engine, method): state error (left) and physics error (right); each point
    is labelled with its setting (step size, or rtol for the scipy paths). Draws on `axes` (two Axes) if given,
    else returns a new Figure."""
    from ..plotting import figure

    fig = None
    if axes is None:
        fig, axes = figure(1, 2, size=(13, 5.5))
    ok = [r for r in rows if r.error is None]
    for key in sorted({(r.engine, r.method) for r in ok}):
        rr = sorted([r for r in ok if (r.engine, r.method) == key], key=lambda r: r.time_s)
        for ax, attr in zip(axes, ("state_error", "physics_error"), strict=True):
            y = np.array([max(getattr(r, attr), 1e-17) for r in rr])
            ax.errorbar([r.time_s for r in rr], y,
                        xerr=[[r.time_s - r.time_min for r in rr], [r.time_max - r.time_s for r in rr]],
                        marker="o" if key[0] == "mujoco" else "s", ls="-" if key[0] == "mujoco" else "--",
                        label=f"{key[0]} {key[1]}", ms=4)
            for r, yy in zip(rr, y, strict=True):
                ax.annotate(_fmt_setting(r.setting), (r.time_s, yy), fontsize=5, alpha=0.7,
                            xytext=(3, 3), textcoords="offset points")
    for ax, what in zip(axes, (f"state error: {study.state_doc}", f"physics error: {study.physics_doc}"),
                        strict=True):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time (s): median, bars min-max; labels: step (s) or rtol")
        ax.set_title(what, fontsize=7, wrap=True)
        ax.grid(True, which="both", alpha=0.3)
        for tol in TOLS:
            ax.axhline(tol, color="grey", lw=0.6, ls=":")
    axes[0].set_ylabel("relative error (dotted: 1e-2, 1e-4, 1e-6)")
    axes[1].legend(fontsize=7, ncol=2)
    if fig is not None and title:
        fig.suptitle(title)
    return fig if fig is not None else axes


def _write(out: Path, rows: list[Row], best: list[dict], scene: Scene, study: Study) -> list[Path]:
    from ..plotting import save

    out = Path(out)
    ok = [r for r in rows if r.error is None]
    files = [write_csv(out / "workprecision.csv", [
        ("engine", "", [r.engine for r in ok]), ("method", "", [r.method for r in ok]),
        ("setting", "s, rtol or tol/steps", [_fmt_setting(r.setting) for r in ok]),
        ("time_median", "s", [r.time_s for r in ok]), ("time_min", "s", [r.time_min for r in ok]),
        ("time_max", "s", [r.time_max for r in ok]), ("state_error", "-", [r.state_error for r in ok]),
        ("physics_error", "-", [r.physics_error for r in ok])])]
    fig = plot(rows, study, title=f"work-precision: {scene.model}/{scene.name}")
    files.append(save(fig, out / "workprecision.png"))
    return files
