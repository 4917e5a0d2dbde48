"""Current-collection quality of a pantograph passage, in the shape of EN 50367 / the TSI Energy assessment.

One function, `assess(stats, speed_kmh, criteria)`, used by every pantograph-under-the-wire run (single and
several pantographs, `mbsuite catenary SCENE --quality`), judges one pantograph's window statistics against:

1. the mean contact force Fm against the target curve Fm(v) = a v^2 + b (v in km/h): inside [lower, upper] with the
   upper curve a v^2 + b and the lower curve a v^2 + b_lower;
2. the standard deviation sigma <= sigma_ratio_max * Fm (0.3: EN 50367 / TSI);
3. the statistical minimum Fm - 3 sigma > stat_min_floor (0 N: the pantograph must not statistically leave the wire);
4. the percentage of contact loss (unfiltered force <= 0 in the window) <= loss_max_pct;
5. the arcing measure NQ = (sum of the durations of the losses that last at least arc_min_duration) / (time in the
   window) x 100 % <= nq_max_pct;
6. the largest uplift at the steady arms in the window <= uplift_max.

Defaults and their sources. The target curves are those of Commission Regulation (EU) No 1301/2014 (TSI Energy),
4.2.11, and EN 50367:2012 (Railway applications - Current collection systems - Technical criteria for the
interaction between pantograph and overhead line): AC Fm = 0.00047 v^2 + 90 N (upper) with the lower curve
0.00047 v^2 + 60 N; DC 3 kV 0.00097 v^2 + 110 N; DC 1.5 kV 0.00228 v^2 + 90 N (the DC lower curves are 30 N below
the upper ones here, like the AC band). The DC coefficients differ between editions and sources, which is why every
coefficient is an input. sigma <= 0.3 Fm, Fm - 3 sigma > 0 and NQ <= 0.2 % (AC) / 0.1 % (DC) are the TSI Energy's
and EN 50367's figures. In a simulation an arc is a contact loss; arc_min_duration = 0 counts every loss (a stated
choice: measured NQ counts the arcs a detector sees). The uplift limit is a line design input (the free space at the
steady arm; the TSI asks for 2 S0 of the design uplift S0): default 0.12 m, i.e. room for S0 = 60 mm.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ...errors import ParameterError, SceneError
from ...limits import check_fields, param
from ...schema import Section

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

#: target curve coefficients per system: (a N/(km/h)^2, upper b N, lower b N), NQ limit (%)
SYSTEMS: dict[str, dict[str, float]] = {
    "AC": {"fm_a": 0.00047, "fm_b": 90.0, "fm_b_lower": 60.0, "nq_max_pct": 0.2},
    "DC3kV": {"fm_a": 0.00097, "fm_b": 110.0, "fm_b_lower": 80.0, "nq_max_pct": 0.1},
    "DC1.5kV": {"fm_a": 0.00228, "fm_b": 90.0, "fm_b_lower": 60.0, "nq_max_pct": 0.1},
}

CRITERIA = ("mean_force", "sigma", "stat_min", "contact_loss", "arcing_nq", "uplift")


@dataclass(frozen=True)
class QualityCriteria:
    """Limits of the current-collection quality assessment (module docstring; SI units, speeds in km/h)."""

    system: str = param("AC", kind=str, choices=tuple(SYSTEMS), doc="electrification system (label of the defaults)")
    fm_a: float = param(0.00047, lo=0.0, hi=1.0, unit="N/(km/h)^2", doc="target curve Fm(v) = fm_a v^2 + fm_b")
    fm_b: float = param(90.0, lo=0.0, lo_open=True, hi=1e4, unit="N", doc="upper target curve: constant term")
    fm_b_lower: float = param(60.0, lo=0.0, hi=1e4, unit="N", doc="lower target curve: constant term")
    sigma_ratio_max: float = param(0.3, lo=0.0, lo_open=True, hi=10.0, unit="-", doc="sigma <= ratio * Fm")
    stat_min_floor: float = param(0.0, lo=-1e4, hi=1e4, unit="N", doc="Fm - 3 sigma must exceed this")
    loss_max_pct: float = param(0.2, lo=0.0, hi=100.0, unit="%", doc="largest percentage of contact loss")
    nq_max_pct: float = param(0.2, lo=0.0, hi=100.0, unit="%", doc="largest arcing measure NQ")
    arc_min_duration: float = param(0.0, lo=0.0, hi=10.0, unit="s", doc="shortest loss counted as an arc in NQ")
    uplift_max: float = param(0.12, lo=0.0, lo_open=True, hi=10.0, unit="m", doc="uplift limit at the steady arms")

    def __post_init__(self) -> None:
        check_fields(self, "quality criterion")
        if not self.fm_b_lower < self.fm_b:
            raise ParameterError(f"quality criterion fm_b_lower = {self.fm_b_lower!r} N must lie below fm_b = "
                                 f"{self.fm_b!r} N (the lower target curve under the upper one)")

    @classmethod
    def for_system(cls, system: str = "AC", **overrides: Any) -> QualityCriteria:
        """The defaults of `system` (SYSTEMS) with `overrides`."""
        if system not in SYSTEMS:
            raise ParameterError(f"quality criterion system = {system!r}; valid: {list(SYSTEMS)}")
        return cls(system=system, **{**SYSTEMS[system], **overrides})

    def target(self, speed_kmh: float) -> tuple[float, float]:
        """(lower, upper) target mean contact force at `speed_kmh` (N); a curve that is not positive is an error."""
        v2 = float(speed_kmh) ** 2
        lo, hi = self.fm_a * v2 + self.fm_b_lower, self.fm_a * v2 + self.fm_b
        if not (math.isfinite(hi) and hi > 0 and lo >= 0):
            raise ParameterError(f"target curve Fm({speed_kmh:g} km/h) = [{lo:g}, {hi:g}] N: the target contact "
                                 "force must be positive (fm_a, fm_b, fm_b_lower)")
        return lo, hi


#: the declaration of a scene's `[quality]` section: `system` plus any field of `QualityCriteria` (absent: the
#: system's value, `SYSTEMS`)
SECTION = Section("[quality]", {f.name: f.metadata["limit"].optional() for f in dataclasses.fields(QualityCriteria)},
                  doc="EN 50367 / TSI Energy criteria; a key left out takes the value of the system (default AC)",
                  example={"system": "DC3kV", "fm_a": 0.00097, "fm_b": 110.0, "fm_b_lower": 80.0,
                           "sigma_ratio_max": 0.3, "stat_min_floor": 0.0, "loss_max_pct": 0.2, "nq_max_pct": 0.1,
                           "arc_min_duration": 0.0, "uplift_max": 0.12})


def validate_section(value: Any) -> dict[str, Any]:
    """Validator of a scene's `[quality]` section (`SECTION`; the system's defaults fill the rest)."""
    out = SECTION.check(value, "[quality]")
    try:
        criteria_from(out)
    except ParameterError as exc:
        raise SceneError(f"[quality]: {exc}") from None
    return out


validate_section.schema = SECTION


def band_target(system: str, scene: Any) -> tuple[float, float]:
    """The EN 50367 target band of the mean contact force (N) of supply system `system` at the scene's train speed:
    the catenary's `Band` for the design studies (`SPEC.studies`)."""
    return QualityCriteria.for_system(system).target(float(scene.input["speed"]))


def criteria_from(section: dict[str, Any] | None) -> QualityCriteria:
    """QualityCriteria of a `[quality]` section (or the AC defaults)."""
    sec = dict(section or {})
    system = sec.pop("system", "AC")
    return QualityCriteria.for_system(system, **sec)


def nq(events: list[dict], window_time: float, min_duration: float) -> float:
    """Arcing measure NQ (%): summed durations of the losses lasting at least `min_duration` over `window_time`."""
    if not window_time > 0:
        raise ParameterError(f"the statistics window lasts {window_time!r} s; NQ needs a positive time")
    return 100.0 * sum(e["duration"] for e in events if e["duration"] >= min_duration) / window_time


def assess(stats: dict, speed_kmh: float, criteria: QualityCriteria, window_time: float) -> dict[str, Any]:
    """Each criterion with its value, limit and verdict for one pantograph's window statistics `stats` (the keys of
    `stats.en50318_statistics`) at `speed_kmh`; `window_time` is the time the pantograph spent in the window (s)."""
    lo, hi = criteria.target(speed_kmh)
    fm, sd = float(stats["Fm"]), float(stats["sigma"])
    nqv = nq(stats["loss_events"], window_time, criteria.arc_min_duration)
    up = float(stats["uplift_mm"]) / 1000.0
    rows = {
        "mean_force": {"label": "mean contact force Fm (N)", "value": fm, "limit": f"{lo:.1f} .. {hi:.1f}",
                       "low": lo, "high": hi, "pass": bool(lo <= fm <= hi)},
        "sigma": {"label": "standard deviation sigma (N)", "value": sd,
                  "limit": f"<= {criteria.sigma_ratio_max:g} Fm = {criteria.sigma_ratio_max * fm:.2f}",
                  "high": criteria.sigma_ratio_max * fm, "pass": bool(sd <= criteria.sigma_ratio_max * fm)},
        "stat_min": {"label": "statistical minimum Fm-3sigma (N)", "value": fm - 3 * sd,
                     "limit": f"> {criteria.stat_min_floor:g}", "low": criteria.stat_min_floor,
                     "pass": bool(fm - 3 * sd > criteria.stat_min_floor)},
        "contact_loss": {"label": "contact loss (%)", "value": float(stats["loss_pct"]),
                         "limit": f"<= {criteria.loss_max_pct:g}", "high": criteria.loss_max_pct,
                         "pass": bool(stats["loss_pct"] <= criteria.loss_max_pct)},
        "arcing_nq": {"label": f"arcing NQ (%, losses >= {1000 * criteria.arc_min_duration:g} ms)", "value": nqv,
                      "limit": f"<= {criteria.nq_max_pct:g}", "high": criteria.nq_max_pct,
                      "pass": bool(nqv <= criteria.nq_max_pct)},
        "uplift": {"label": "max uplift at steady arms (mm)", "value": 1000 * up,
                   "limit": f"<= {1000 * criteria.uplift_max:g}", "high": 1000 * criteria.uplift_max,
                   "pass": bool(up <= criteria.uplift_max)},
    }
    return {"speed_kmh": float(speed_kmh), "system": criteria.system, "criteria": dataclasses.asdict(criteria),
            "window_time_s": float(window_time), "rows": rows, "pass": all(r["pass"] for r in rows.values())}


def table_rows(q: dict[str, Any]) -> list[list[str]]:
    """Rows (criterion, value, limit, verdict) of an assessment for `results.format_table`."""
    return [[r["label"], f"{r['value']:.2f}", r["limit"], "pass" if r["pass"] else "FAIL"] for r in q["rows"].values()]


def plot(assessments: list[tuple[str, dict[str, Any]]], path: Path, line: str | None = None) -> Path:
    """Write `figure(assessments, line)` to `path` (PNG) and return it."""
    from ...plotting import save

    return save(figure(assessments, line), path)


#: each criterion's panel title and unit (the table's labels are longer)
_PANELS = {"mean_force": ("mean force Fm", "N"), "sigma": ("standard deviation σ", "N"),
           "stat_min": ("statistical minimum Fm − 3σ", "N"), "contact_loss": ("contact loss", "%"),
           "arcing_nq": ("arcing NQ", "%"), "uplift": ("uplift at the steady arms", "mm")}


def figure(assessments: list[tuple[str, dict[str, Any]]], line: str | None = None) -> MplFigure:
    """The target band Fm(v) with each pantograph's Fm ± σ at its speed (left), and one panel per criterion in its
    own unit (right): each pantograph's value as a marker (green: pass, red: fail; a zero is drawn like any other
    value) against the criterion's limit drawn as a line (σ ≤ r Fm: each pantograph's own limit as a short line at
    its marker; Fm: the band between the two target curves; Fm − 3σ: the floor, passing above it); `line` (the
    line's name, `marks.line_label`) is named in the title."""
    import numpy as np

    from ...plotting import figure as new_figure

    fig, _ = new_figure(1, 1, size=(14, 5.2))
    fig.clear()
    grid = fig.add_gridspec(2, 4, width_ratios=(2.2, 1, 1, 1))
    ax = fig.add_subplot(grid[:, 0])
    panels = {k: fig.add_subplot(grid[i // 3, 1 + i % 3]) for i, k in enumerate(CRITERIA)}
    c = QualityCriteria(**assessments[0][1]["criteria"])
    v = np.linspace(0.0, max(400.0, max(q["speed_kmh"] for _, q in assessments)), 200)
    ax.fill_between(v, c.fm_a * v**2 + c.fm_b_lower, c.fm_a * v**2 + c.fm_b, color="0.85",
                    label=f"target band ({c.system}): Fm = {c.fm_a:g} v² + [{c.fm_b_lower:g}, {c.fm_b:g}] N, "
                          "v in km/h")
    x = np.arange(len(assessments))
    for i, (name, q) in enumerate(assessments):
        r = q["rows"]
        ax.errorbar([q["speed_kmh"] + 4 * (i - (len(assessments) - 1) / 2)], [r["mean_force"]["value"]],
                    yerr=[r["sigma"]["value"]], fmt="o", capsize=4,
                    label=f"{name}: Fm ± σ ({'pass' if q['pass'] else 'FAIL'})")
    for k, px in panels.items():
        title, unit = _PANELS[k]
        rows = [q["rows"][k] for _, q in assessments]
        vals = [row["value"] for row in rows]
        if k == "mean_force":
            px.axhspan(rows[0]["low"], rows[0]["high"], color="0.85", label="target band")
        elif k == "stat_min":
            px.axhline(rows[0]["low"], color="k", lw=1.2, label=f"floor {rows[0]['low']:g} {unit}")
        elif k == "sigma":
            for xi, row in zip(x, rows, strict=True):
                px.hlines(row["high"], xi - 0.35, xi + 0.35, color="k", lw=1.2,
                          label=f"limit {c.sigma_ratio_max:g} Fm" if xi == 0 else None)
        else:
            px.axhline(rows[0]["high"], color="k", lw=1.2, label=f"limit {rows[0]['high']:g} {unit}")
        px.scatter(x, vals, s=40, zorder=3, c=["tab:green" if row["pass"] else "tab:red" for row in rows],
                   edgecolors="k")
        px.set_xticks(x, [name for name, _ in assessments], fontsize=7, rotation=20)
        px.set_xlim(-0.6, len(assessments) - 0.4)
        px.set_title(f"{title} [{unit}]", fontsize=9)
        px.legend(fontsize=6, loc="best")
        px.grid(True, lw=0.3, axis="y")
        lo = min(0.0, *vals, *(row.get("low", 0.0) for row in rows))
        hi = max(*vals, *(row.get("high", row.get("low", 0.0)) for row in rows))
        pad = 0.12 * (hi - lo) if hi > lo else 1.0
        px.set_ylim(lo - pad, hi + pad)
    ax.set_xlabel("train speed v [km/h]")
    ax.set_ylabel("mean contact force Fm [N]")
    ax.set_title("mean contact force Fm ± standard deviation σ vs the target band", fontsize=10)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7, loc="upper left")
    on = "" if line is None else f" on the {line}"
    fig.suptitle(f"current-collection criteria ({c.system}) at {assessments[0][1]['speed_kmh']:g} km/h{on} "
                 "(green: pass, red: fail)", fontsize=10)
    return fig
