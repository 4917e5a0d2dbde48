"""Declared accuracy and error estimates: what a scene promises about its headline outputs, and how a run checks it.

A model declares (`ModelSpec.accuracy`, an `AccuracySpec`):
- `headlines(scene)`: its headline outputs (`Headline`: name, unit, the tolerance its defaults meet: `tol`, plus
  `rtol` times the value where the error scales with the value);
- `values(scene, result)`: the headline values of one run's result;
- `refinement(scene)`: how the scene's path is refined (`Refinement`: the setting, the factor per level, the
  method's nominal order, and `refine(scene, level)` giving the refined scene).
A scene may tighten or loosen a tolerance in its `[accuracy]` section (`name = tolerance`: absolute, in the headline's
unit, replacing the declared tolerance);
a name that is not a headline of the scene is an error.

The error estimate (`estimate`) follows the grid-convergence index of Roache ("Verification and Validation in
Computational Science and Engineering", 1998; ASME V&V 20-2009, section 2.4). With the run's value q0 and the values
q1, q2 of the scene refined once and twice by the factor r:

    e01 = q1 - q0,  e12 = q2 - q1,  p_obs = ln(|e01| / |e12|) / ln r          (observed order)
    monotone (e01, e12 of one sign) and p_obs >= p/2:   error(q0) = 1.25 |e01| r^p' / (r^p' - 1),  p' = min(p_obs, p)
    otherwise (oscillating, or not yet in the asymptotic range):   error(q0) = 3 max(|e01|, |q2 - q0|)

where p is the method's nominal order. The first is Richardson's estimate of |q_exact - q0| with the safety factor
1.25 of a three-level study, at the smaller (more cautious) of the observed and the nominal order; the second is the
two-level factor 3 applied to the larger difference. Values that agree to round-off give an error at round-off and no
observed order; if only the two refined values agree, the error of q0 is |e01| (the refined value is converged).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..errors import SceneError
from ..limits import Limit
from ..settings import SOLVER_LIMITS
from .health import Figure

#: safety factors of the grid-convergence index (Roache 1998): three levels in the asymptotic range, else two levels
SAFETY_ASYMPTOTIC, SAFETY_OTHER = 1.25, 3.0
#: relative round-off level below which two values count as equal
ROUND_OFF = 1e-12


@dataclass(frozen=True)
class Headline:
    """One headline output of a scene: its default settings meet the tolerance `tol + rtol |value|` (in `unit`;
    `rtol` for an output whose error scales with its size, e.g. a fraction of time lost, 0 for most)."""

    name: str
    unit: str
    tol: float
    doc: str = ""
    rtol: float = 0.0

    def bound(self, value: float) -> float | None:
        """The tolerance at `value`: tol + rtol |value| (None where no tolerance is declared)."""
        if self.tol is None or not math.isfinite(value):
            return self.tol
        return self.tol + self.rtol * abs(value)


@dataclass(frozen=True)
class Refinement:
    """How a run is refined: each level divides `setting` by `factor`, which divides the error by factor**order.

    `refine(scene, level)` returns the scene refined `level` times (level 0: the scene itself)."""

    setting: str
    factor: float
    order: float
    refine: Callable[[Any, int], Any]
    doc: str = ""


@dataclass(frozen=True)
class AccuracySpec:
    """A model's accuracy declaration (module docstring)."""

    headlines: Callable[[Any], tuple[Headline, ...]]
    values: Callable[[Any, Any], Mapping[str, float]]
    refinement: Callable[[Any], Refinement]


@dataclass(frozen=True)
class Estimate:
    """The estimated error of one headline value. `refined` holds the values of the two refined runs; `order` is the
    observed order (None where it cannot be observed); `asymptotic` says which formula gave `error`."""

    name: str
    unit: str
    value: float
    refined: tuple[float, float]
    error: float
    order: float | None
    asymptotic: bool
    tol: float | None = None

    @property
    def ok(self) -> bool:
        """True when the estimate is finite and within the declared tolerance (or none is declared)."""
        return math.isfinite(self.error) and (self.tol is None or self.error <= self.tol)

    def to_dict(self) -> dict[str, Any]:
        """The row as JSON-able values."""
        return {"name": self.name, "unit": self.unit, "value": self.value, "refined": list(self.refined),
                "error": self.error, "order": self.order, "asymptotic": self.asymptotic, "tol": self.tol,
                "ok": self.ok}


@dataclass
class ErrorEstimate:
    """Error estimates of every headline of one run: the refinement used and one `Estimate` per headline."""

    setting: str
    factor: float
    nominal_order: float
    rows: list[Estimate] = field(default_factory=list)
    settings: list[str] = field(default_factory=list)  # what each level ran (level 0, 1, 2), in words

    def __getitem__(self, name: str) -> Estimate:
        for r in self.rows:
            if r.name == name:
                return r
        raise KeyError(f"no headline {name!r}; headlines: {[r.name for r in self.rows]}")

    def figures(self) -> list[Figure]:
        """One health figure per headline with a declared tolerance: the estimate against the tolerance."""
        out = []
        for r in self.rows:
            if r.tol is None:
                continue
            need = _levels_needed(r.error, r.tol, self.factor, self.nominal_order)
            out.append(Figure(f"error_estimate[{r.name}]", r.error, r.tol, r.unit,
                              f"estimated error of {r.name} against its declared tolerance",
                              f"refine {self.setting} by a factor {self.factor ** need:g} (or set accuracy.{r.name} "
                              "in the scene if a looser tolerance will do)"))
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON-able: the refinement and every row."""
        return {"setting": self.setting, "factor": self.factor, "nominal_order": self.nominal_order,
                "levels": list(self.settings), "rows": [r.to_dict() for r in self.rows]}

    def table(self) -> str:
        """The estimates as a text table."""
        from ..results import format_table

        rows = [[r.name, r.unit, r.value, r.error, "-" if r.tol is None else r.tol,
                 "-" if r.order is None else f"{r.order:.2f}", "yes" if r.asymptotic else "no",
                 "ok" if r.ok else "EXCEEDED"] for r in self.rows]
        head = (f"error estimate: {self.setting} refined by {self.factor:g} twice (nominal order "
                f"{self.nominal_order:g}; levels: {'; '.join(self.settings)})")
        return head + "\n" + format_table(["headline", "unit", "value", "est. error", "tol", "observed order",
                                           "asymptotic", ""], rows, ".4g")


def _levels_needed(error: float, tol: float, factor: float, order: float) -> int:
    """How many refinement levels bring `error` below `tol` at the nominal order (at least 1)."""
    if not (math.isfinite(error) and error > tol > 0):
        return 1
    return max(1, math.ceil(math.log(error / tol) / (order * math.log(factor))))


def estimate_one(q0: float, q1: float, q2: float, factor: float, order: float) -> tuple[float, float | None, bool]:
    """(error of q0, observed order or None, asymptotic) from three levels (module docstring)."""
    vals = (q0, q1, q2)
    if not all(math.isfinite(v) for v in vals):
        return math.inf, None, False
    floor = ROUND_OFF * max(abs(v) for v in vals) + 1e-300
    e01, e12 = q1 - q0, q2 - q1
    if abs(e01) <= floor and abs(e12) <= floor:
        return max(abs(e01), abs(q2 - q0)), None, True
    if abs(e12) <= floor:
        return abs(e01), None, True
    if abs(e01) <= floor:
        return SAFETY_OTHER * max(abs(e01), abs(q2 - q0)), None, False
    p_obs = math.log(abs(e01) / abs(e12)) / math.log(factor)
    if e01 * e12 > 0 and p_obs >= order / 2:
        p = min(p_obs, order)
        rp = factor**p
        return SAFETY_ASYMPTOTIC * abs(e01) * rp / (rp - 1.0), p_obs, True
    return SAFETY_OTHER * max(abs(e01), abs(q2 - q0)), p_obs, False


def estimate(levels: list[Mapping[str, float]], headlines: tuple[Headline, ...], refinement: Refinement,
             settings: list[str] | None = None) -> ErrorEstimate:
    """The error estimate of every headline from its values at levels 0, 1, 2 (the run, refined once and twice)."""
    if len(levels) != 3:
        raise ValueError(f"an error estimate needs the values of 3 levels, got {len(levels)}")
    out = ErrorEstimate(refinement.setting, refinement.factor, refinement.order, settings=list(settings or []))
    for h in headlines:
        missing = [k for k, lv in enumerate(levels) if h.name not in lv]
        if missing:
            raise KeyError(f"headline {h.name!r} missing from the values of level(s) {missing}")
        q = [float(lv[h.name]) for lv in levels]
        err, p_obs, asym = estimate_one(q[0], q[1], q[2], refinement.factor, refinement.order)
        out.rows.append(Estimate(h.name, h.unit, q[0], (q[1], q[2]), err, p_obs, asym, h.bound(q[0])))
    return out


#: a tolerance of the scene's `[accuracy]` section (headline name = tolerance, in the headline's unit)
TOLERANCE = Limit(lo=0.0, lo_open=True, unit="in the headline's unit", doc="tolerance of a headline output")


def check_tolerances(section: Any, where: str = "") -> dict[str, float]:
    """The scene's `[accuracy]` section: headline name -> positive finite tolerance (names are checked against the
    model's headlines by `declared`)."""
    if not isinstance(section, Mapping):
        raise SceneError(f"[accuracy]{where} must be a table of headline = tolerance")
    return {str(k): TOLERANCE.check(f"accuracy.{k}", v, SceneError, where) for k, v in section.items()}


def declared(scene: Any) -> tuple[Headline, ...]:
    """The scene's headlines with its tolerances: the model's declaration, then the scene's `[accuracy]` overrides."""
    spec = scene.spec.accuracy
    if spec is None:
        raise SceneError(f"model '{scene.model}' declares no headline outputs (no accuracy declaration)")
    heads = tuple(spec.headlines(scene))
    over = dict(getattr(scene, "accuracy", {}) or {})
    names = [h.name for h in heads]
    bad = sorted(set(over) - set(names))
    if bad:
        raise SceneError(f"unknown headline(s) {bad} in [accuracy]; headlines of this scene: {names}")
    return tuple(Headline(h.name, h.unit, over[h.name], h.doc) if h.name in over else h for h in heads)


def halving(setting: str, order: float, refine: Callable[[Any, int], Any], doc: str = "") -> Refinement:
    """A refinement that halves `setting` per level (a step size, an element length)."""
    return Refinement(setting, 2.0, order, refine, doc)


def refine_timestep(scene: Any, level: int) -> Any:
    """The scene with `solver.timestep` halved `level` times (`solver.sample_dt` left as it is); the size guard
    `solver.max_steps` grows with it (the user asked for the finer run)."""
    if level == 0:
        return scene
    s = scene.solver
    return scene.replace(solver={"timestep": s.timestep / 2**level, "max_steps": s.max_steps * 2**level})


def refine_timestep_and_samples(scene: Any, level: int) -> Any:
    """`refine_timestep`, and a nonzero `solver.sample_dt` halved with it: for headlines read off the samples
    (maxima, means), whose grid is then refined too."""
    out = refine_timestep(scene, level)
    if level and scene.solver.sample_dt > 0:
        out = out.replace(solver={"sample_dt": scene.solver.sample_dt / 2**level})
    return out


def refine_rtol(scene: Any, level: int) -> Any:
    """The scene with `solver.rtol` and `solver.atol` divided by 10 per level (an adaptive method's tolerances);
    a SceneError if that passes the smallest tolerance the solver settings allow."""
    if level == 0:
        return scene
    s = scene.solver
    lo = SOLVER_LIMITS["rtol"].lo
    if s.rtol / 10**level < lo:
        raise SceneError(f"solver.rtol = {s.rtol:g} cannot be refined {level} time(s) by 10 (smallest rtol {lo:g}): "
                         "estimate the error of a run at a looser rtol")
    return scene.replace(solver={"rtol": s.rtol / 10**level, "atol": s.atol / 10**level})


def timestep_refinement(order: float, samples: bool = False) -> Refinement:
    """Fixed-step integration of nominal `order`: halve `solver.timestep` (with `samples`, a nonzero
    `solver.sample_dt` too)."""
    if samples:
        return halving("solver.timestep + solver.sample_dt", order, refine_timestep_and_samples)
    return halving("solver.timestep", order, refine_timestep)


def rtol_refinement(order: float = 1.0) -> Refinement:
    """Adaptive integration: divide `solver.rtol` and `solver.atol` by 10 per level (the global error of an
    error-per-step controller scales about like the tolerance: nominal order 1 in the tolerance)."""
    return Refinement("solver.rtol", 10.0, order, refine_rtol)
