"""Declared accuracy and error estimates: what a scene promises about its headline outputs, and how a run checks it.

A model declares (`ModelSpec.accuracy`, an `AccuracySpec`):
- `headlines(scene)`: its headline outputs (`Headline`: name, unit, the tolerance its defaults meet: `tol`, plus
  `rtol` times the value where the error scales with the value);
- `values(scene, result)`: the headline values of one run's result;
- `refinement(scene)`: how the scene's path is refined (`Refinement`: the setting, the factor per level, the
  method's nominal order, and `refine(scene, level)` giving the refined scene; `companions`: "coarse" where
  `refine(scene, -k)` gives the scene coarsened and the error estimate tries those first, below).
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

Coarse companions (`Refinement.companions = "coarse"`): a model whose setting can also be coarsened (`refine(scene,
-k)`: the scene coarsened k times) estimates the error of the run from the same scene coarsened once and twice, at
1/r^d + 1/r^2d of the run's cost (d: how many settings scale; the catenary's mesh and step, 1/4 + 1/16) instead of
r^d + r^2d. With the run's value v0 and the coarse values v1 (r x coarser), v2 (r^2 x coarser):

    d0 = v1 - v0,  d1 = v2 - v1,  p_obs = ln(|d1| / |d0|) / ln r
    p_obs in [0.75 p, 1.25 p]  (asymptotic):  error(v0) = 1.25 |d0| / (r^p' - 1),  p' = min(p_obs, p)
    p_obs in (1.25 p, 2 p]     (faster):      error(v0) = 3 |d0| / (r^p - 1)

The first is Richardson's estimate of |v_exact - v0| at the smaller of the observed and the nominal order (never
extrapolated at an order the method does not have) with the grid-convergence index's safety factor 1.25 of a
three-level study; the second is Roy's rule for an observed order away from the formal one (C. J. Roy, "Review of
code and solution verification procedures for computational simulation", J. Comput. Phys. 205, 2005: safety factor
3 at the formal order). Both need the companions in the asymptotic range (`check_coarse`): d0 and d1 of one sign,
|d1| > |d0|, and p_obs in [0.75 p, 2 p] (`ORDER_BAND`). The companions are coarser than the run, so they are the first
to leave the asymptotic range, and an order away from the method's says their error balance is not the run's. Below
0.75 p the coarse values converge slower than the method (a lower-order error or a resolution limit dominates them;
Richardson at that order is as uncertain as the error itself). Above 1.25 p they converge faster than the method,
which a mesh of higher order than the step does at coarse levels (the catenary's cubic elements against its
second-order step) while the run's own error may already fall at the method's order or slower: on the catenary
(2-span line, 150 km/h, run at 0.25 m / 1e-4 s) sigma and Fm +- 3 sigma show p_obs 3.2-3.5 between 1, 0.5 and 0.25 m
while their difference to 0.125 m falls at order 1.1-1.3; Richardson at the nominal order with 1.25 gave 0.76-1.0 of
the true error there, the factor 3 gives 1.8-2.4 of it. Above 2 p the coarsest value is off by far more than any order
predicts (it does not resolve what the run resolves) and d0 may be a crossing, not a trend. Inside [0.75 p, 1.25 p]
the estimate brackets a sequence c + a h^p (1 + x h) whose second term moves the observed order to either edge
(1.6-1.8x the true error at p = 2).

Values equal to round-off at the three levels pass (a converged quantity: contact loss 0 %). A headline outside the
asymptotic range still passes when its three values agree so closely that the two-level estimate,
3 max(|d0|, |v2 - v0|), is at most `SMALL` (a quarter) of its tolerance: its values at the run's resolution and at two
and four times coarser then differ by less than a twelfth of the tolerance, and the run is within its tolerance with a
factor 4 of margin unless its error were a plateau that the coarse levels share (an error that no refinement removes
is not a discretisation error, and the refined companions would not see it either). Any other headline failing the
check makes the estimate fall back to the refined companions (the method above), and the estimate says which
headlines failed and why (`ErrorEstimate.fallback`, `ErrorEstimate.coarse`).
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
#: the observed orders accepted on coarse companions, as multiples of the nominal order: [lo, asymptotic] with the
#: safety factor 1.25, (asymptotic, hi] with 3 at the nominal order (module docstring)
ORDER_BAND = (0.75, 1.25, 2.0)
#: a headline outside the asymptotic range passes the coarse check when 3 x its spread is at most this fraction of
#: its tolerance (module docstring)
SMALL = 0.25
#: the two kinds of companions (`Refinement.companions`)
COMPANIONS = ("fine", "coarse")


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

    `refine(scene, level)` returns the scene refined `level` times (level 0: the scene itself).

    `companions`: which companions an error estimate runs by default. "fine" (every model's default): the scene
    refined once and twice. "coarse": the scene coarsened once and twice (`refine(scene, -1)`, `refine(scene, -2)`,
    which raise a `SceneError` saying why where a coarser scene does not exist, e.g. a mesh that does not fit), with
    the refined ones as the fallback where the coarse ones are not in the asymptotic range (module docstring)."""

    setting: str
    factor: float
    order: float
    refine: Callable[[Any, int], Any]
    doc: str = ""
    companions: str = "fine"

    def __post_init__(self) -> None:
        if self.companions not in COMPANIONS:
            raise ValueError(f"Refinement.companions must be one of {COMPANIONS}, got {self.companions!r}")


@dataclass(frozen=True)
class AccuracySpec:
    """A model's accuracy declaration (module docstring)."""

    headlines: Callable[[Any], tuple[Headline, ...]]
    values: Callable[[Any, Any], Mapping[str, float]]
    refinement: Callable[[Any], Refinement]


@dataclass(frozen=True)
class Estimate:
    """The estimated error of one headline value. `refined` holds the values of the two companions (refined once and
    twice; with `companions` "coarse", coarsened once and twice); `order` is the observed order (None where it
    cannot be observed); `asymptotic` says which formula gave `error`. `check`: coarse companions' only, how the
    asymptotic check went ("asymptotic", "converged", "small: <why not asymptotic>", or why it failed); `passed`
    whether it did."""

    name: str
    unit: str
    value: float
    refined: tuple[float, float]
    error: float
    order: float | None
    asymptotic: bool
    tol: float | None = None
    companions: str = "fine"
    check: str = ""
    passed: bool = True

    @property
    def ok(self) -> bool:
        """True when the estimate is finite and within the declared tolerance (or none is declared)."""
        return math.isfinite(self.error) and (self.tol is None or self.error <= self.tol)

    @property
    def differences(self) -> tuple[float, float]:
        """(d0, d1): the first companion minus the run, the second minus the first."""
        return self.refined[0] - self.value, self.refined[1] - self.refined[0]

    def to_dict(self) -> dict[str, Any]:
        """The row as JSON-able values (the companions' values under "refined" or "coarse")."""
        out = {"name": self.name, "unit": self.unit, "value": self.value,
               ("coarse" if self.companions == "coarse" else "refined"): list(self.refined),
               "differences": list(self.differences), "error": self.error, "order": self.order,
               "asymptotic": self.asymptotic, "tol": self.tol, "ok": self.ok}
        if self.companions == "coarse":
            out.update(check=self.check, passed=self.passed)
        return out


@dataclass
class ErrorEstimate:
    """Error estimates of every headline of one run: the refinement used and one `Estimate` per headline.

    `companions`: whose values the rows' estimates come from, "fine" (refined once and twice) or "coarse"
    (coarsened once and twice); `settings`: what each level ran (the run, then its companions), in words. With fine
    companions where the model declares coarse ones, `fallback` says why (which headlines failed the asymptotic
    check and how, or why the coarse companions could not run) and `coarse` holds the coarse estimate that failed
    (None if they did not run)."""

    setting: str
    factor: float
    nominal_order: float
    rows: list[Estimate] = field(default_factory=list)
    settings: list[str] = field(default_factory=list)  # what each level ran (level 0, 1, 2), in words
    companions: str = "fine"
    fallback: str = ""
    coarse: ErrorEstimate | None = None

    def __getitem__(self, name: str) -> Estimate:
        for r in self.rows:
            if r.name == name:
                return r
        raise KeyError(f"no headline {name!r}; headlines: {[r.name for r in self.rows]}")

    @property
    def passed(self) -> bool:
        """True unless a row failed the coarse companions' asymptotic check (always True with fine companions)."""
        return all(r.passed for r in self.rows)

    def failed(self) -> list[Estimate]:
        """The rows that failed the coarse companions' asymptotic check."""
        return [r for r in self.rows if not r.passed]

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
        """JSON-able: the refinement, the companions and their settings, every row; with a fallback its reason and the
        coarse estimate that failed."""
        out = {"setting": self.setting, "factor": self.factor, "nominal_order": self.nominal_order,
               "companions": self.companions, "levels": list(self.settings), "rows": [r.to_dict() for r in self.rows]}
        if self.companions == "coarse":
            out["order_band"] = [b * self.nominal_order for b in ORDER_BAND]
        if self.fallback:
            out["fallback"] = self.fallback
            out["coarse"] = self.coarse.to_dict() if self.coarse is not None else None
        return out

    def describe(self) -> str:
        """The companions in words: how the setting was changed and the levels that ran."""
        if self.companions == "coarse":
            lo, mid, hi = (b * self.nominal_order for b in ORDER_BAND)
            return (f"{self.setting} coarsened by {self.factor:g} and {self.factor ** 2:g} (coarse companions; nominal "
                    f"order {self.nominal_order:g}, observed orders accepted in [{lo:g}, {hi:g}], safety factor "
                    f"{SAFETY_ASYMPTOTIC:g} up to {mid:g}, {SAFETY_OTHER:g} above; levels: {'; '.join(self.settings)})")
        return (f"{self.setting} refined by {self.factor:g} twice (nominal order {self.nominal_order:g}; levels: "
                f"{'; '.join(self.settings)})")

    def table(self) -> str:
        """The estimates as a text table (with coarse companions also their differences and checks); after a
        fallback, why it fell back and the coarse companions' table."""
        from ..results import format_table

        head = f"error estimate: {self.describe()}"
        if self.companions == "coarse":
            rows = [[r.name, r.unit, r.value, r.error, "-" if r.tol is None else r.tol, *r.differences,
                     "-" if r.order is None else f"{r.order:.2f}", r.check.partition(":")[0] if r.passed else "FAILED",
                     ("ok" if r.ok else "EXCEEDED") if r.passed else "-"] for r in self.rows]
            text = head + "\n" + format_table(["headline", "unit", "value", "est. error", "tol", "d0 (coarse 1 - run)",
                                               "d1 (coarse 2 - coarse 1)", "observed order", "check", "verdict"], rows,
                                              ".4g")
            failed = [f"  {r.name}: {r.check}" for r in self.rows if r.check not in ("asymptotic", "converged")]
            return text + ("\n" + "\n".join(failed) if failed else "")
        rows = [[r.name, r.unit, r.value, r.error, "-" if r.tol is None else r.tol,
                 "-" if r.order is None else f"{r.order:.2f}", "yes" if r.asymptotic else "no",
                 "ok" if r.ok else "EXCEEDED"] for r in self.rows]
        text = head + "\n" + format_table(["headline", "unit", "value", "est. error", "tol", "observed order",
                                           "asymptotic", "verdict"], rows, ".4g")
        if any(not r.asymptotic for r in self.rows):
            text += ("\nasymptotic no: the differences oscillate or the observed order is below half the nominal "
                     "one, so the estimate is the cautious 3 x the larger difference (not Richardson's); verdict ok: "
                     "that estimate is within the tolerance")
        if self.fallback:
            text += "\n" + self.fallback
            if self.coarse is not None:
                text += "\n" + self.coarse.table()
        return text

    def failure_text(self) -> str:
        """The rows that failed the coarse check and why, in words."""
        return "; ".join(f"{r.name} ({r.check})" for r in self.failed())


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


def check_coarse(v0: float, v1: float, v2: float, factor: float, order: float,
                 tol: float | None = None) -> tuple[float, float | None, bool, str]:
    """(error of v0, observed order or None, passed, how) from the run `v0` and its companions coarsened once (`v1`)
    and twice (`v2`) by `factor`, against the nominal `order` and the headline's tolerance `tol` (module docstring).

    `how` is "converged" (the three values equal to round-off), "asymptotic" (Richardson with 1.25 at the smaller of
    the observed and the nominal order), "faster: ..." (an observed order above 1.25 p: 3 at the nominal order),
    "small: <why not asymptotic>" (outside the asymptotic range, but three times the spread is within `SMALL` of the
    tolerance), or, when the check fails, why; the error is then the two-level estimate 3 max(|d0|, |v2 - v0|),
    reported but not used (the fallback runs the refined companions)."""
    vals = (v0, v1, v2)
    if not all(math.isfinite(v) for v in vals):
        return math.inf, None, False, "a value is not finite"
    floor = ROUND_OFF * max(abs(v) for v in vals) + 1e-300
    d0, d1 = v1 - v0, v2 - v1
    if abs(d0) <= floor and abs(d1) <= floor:
        return max(abs(d0), abs(v2 - v0)), None, True, "converged"
    p_obs = math.log(abs(d1) / abs(d0)) / math.log(factor) if abs(d0) > floor and abs(d1) > floor else None
    lo, mid, hi = (b * order for b in ORDER_BAND)
    if abs(d0) <= floor:
        why = f"the first coarse value equals the run's, the second differs by {d1:.3g}: no order to observe"
    elif abs(d1) <= floor:
        why = f"the coarse values agree, the run differs by {-d0:.3g}: the differences do not shrink towards the run"
    elif d0 * d1 < 0:
        why = f"not monotone: d0 = {d0:.3g}, d1 = {d1:.3g} of opposite signs"
    elif abs(d1) <= abs(d0):
        why = f"the differences do not shrink towards the run: |d1| = {abs(d1):.3g} <= |d0| = {abs(d0):.3g}"
    elif p_obs < lo:
        why = f"observed order {p_obs:.2f} below {lo:g} (d0 = {d0:.3g}, d1 = {d1:.3g})"
    elif p_obs > hi:
        why = f"observed order {p_obs:.2f} above {hi:g} (d0 = {d0:.3g}, d1 = {d1:.3g})"
    elif p_obs <= mid:
        p = min(p_obs, order)
        return SAFETY_ASYMPTOTIC * abs(d0) / (factor**p - 1.0), p_obs, True, "asymptotic"
    else:
        return (SAFETY_OTHER * abs(d0) / (factor**order - 1.0), p_obs, True,
                f"faster: observed order {p_obs:.2f} above {mid:g}, safety factor {SAFETY_OTHER:g} at the nominal "
                f"order")
    err = SAFETY_OTHER * max(abs(d0), abs(v2 - v0))
    if tol is not None and err <= SMALL * tol:
        return err, p_obs, True, f"small: {why}; 3 x the spread = {err:.3g} <= {SMALL:g} x tol"
    return err, p_obs, False, why


def estimate(levels: list[Mapping[str, float]], headlines: tuple[Headline, ...], refinement: Refinement,
             settings: list[str] | None = None, companions: str = "fine") -> ErrorEstimate:
    """The error estimate of every headline from its values at levels 0, 1, 2: the run, refined once and twice
    (`companions` "fine"), or the run, coarsened once and twice ("coarse": `check_coarse`, each row with its
    check)."""
    if len(levels) != 3:
        raise ValueError(f"an error estimate needs the values of 3 levels, got {len(levels)}")
    if companions not in COMPANIONS:
        raise ValueError(f"companions must be one of {COMPANIONS}, got {companions!r}")
    out = ErrorEstimate(refinement.setting, refinement.factor, refinement.order, settings=list(settings or []),
                        companions=companions)
    for h in headlines:
        missing = [k for k, lv in enumerate(levels) if h.name not in lv]
        if missing:
            raise KeyError(f"headline {h.name!r} missing from the values of level(s) {missing}")
        q = [float(lv[h.name]) for lv in levels]
        tol = h.bound(q[0])
        if companions == "coarse":
            err, p_obs, passed, how = check_coarse(q[0], q[1], q[2], refinement.factor, refinement.order, tol)
            out.rows.append(Estimate(h.name, h.unit, q[0], (q[1], q[2]), err, p_obs,
                                     how == "asymptotic" or how.startswith("faster"), tol, "coarse", how, passed))
        else:
            err, p_obs, asym = estimate_one(q[0], q[1], q[2], refinement.factor, refinement.order)
            out.rows.append(Estimate(h.name, h.unit, q[0], (q[1], q[2]), err, p_obs, asym, tol))
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
