"""The design that minimises one headline output of a scene (e.g. the catenary's sigma) over declared parameter
ranges, subject to bounds on other outputs (e.g. Fm inside the EN 50367 band), at one operating point or robustly
over several; and the trade-off between two outputs (a Pareto front).

    from mbsuite.analysis import optimise
    res = optimise.run(scene, ["params.k1=3000:6000", "params.c2=50:150"], objective="sigma",
                       constraints=[optimise.band("AC")], maxiter=10, seed=1)
    res.best, res.value                # the optimum and its objective; res.evaluations: every point run

Method: scipy's `differential_evolution` (bounded, derivative-free, seeded; Storn and Price 1997) with deferred
updating, so that each generation is one batch evaluated on the sweep machinery (`workers` map: local processes or
threads, Dask, the resumable store: a rerun with the same store resumes). No gradient polish (the outputs of a
passage are not smooth in the parameters to finite-difference precision). Constraints enter as an exact penalty:
J = objective + `penalty` x (sum of the distances of the bounded outputs outside their bounds), so a design outside
its bounds ranks below any inside them whose objective is less than `penalty` x the distance larger; the optimum is
reported feasible or not.

Robust variant: `over={"input.speed": [250, 300]}` evaluates every design at each value (every combination of
several keys) and minimises the worst (`aggregate="worst"`) or the mean; the constraints hold at each.

Pareto front (`pareto`): the epsilon-constraint method with scipy — minimise the objective subject to the second
output >= each level of a list (Haimes, Lasdon and Wismer 1971), every level a `run`; the front is the non-dominated
set of all evaluations of all levels (over several operating points, of all designs, each with its aggregated
objective and its least second output: `candidates`). A multi-objective library (pymoo) is not used: it would add
ten packages to the install for a front that a few bounded runs on the same machinery give, with the same executors
and store.

The module is kept whole (about 600 lines): the bounds, the penalised problem, `run`, `pareto` and their results
with their reports are one method, read together."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..engines.core import n_workers
from ..errors import MbsuiteError
from ..limits import Limit, real
from ..progress import planned
from .designspace import Factor, evaluate, factors_for, headline_units, key_unit, point_scene, scene_evaluator

if TYPE_CHECKING:
    from ..results import Report
    from ..scenes import Scene
    from .sweep import SweepOptions

AGGREGATES = ("worst", "mean")
#: the numbers `run` and `pareto` take, declared once (`Limit.check`: numpy scalars too; bools, NaN, inf refused)
BOUND = Limit(doc="a bound on a headline output (its unit)")
LIMITS = {"penalty": Limit(lo=0.0, lo_open=True, doc="objective units per unit of constraint violation"),
          "tol": Limit(lo=0.0, lo_open=True, doc="scipy's relative convergence tolerance"),
          "maxiter": Limit(lo=1, hi=10_000, kind=int, doc="generations of differential evolution"),
          "popsize": Limit(lo=2, hi=1000, kind=int, doc="members per factor"),
          "seed": Limit(lo=0, hi=2**32 - 1, kind=int, doc="seed of the optimiser"),
          "level": Limit(doc="a level of the traded output (its unit)")}


@dataclass(frozen=True)
class Bound:
    """`lo <= output <= hi` (either side may be None). `band`: a system of the band the scene's model declares
    (`SPEC.studies.band`, e.g. the catenary's EN 50367 band of Fm per supply system; "" = its first system), read at
    each evaluation's operating point."""

    output: str
    lo: float | None = None
    hi: float | None = None
    band: str | None = None
    band_name: str = "band"  # what the band is, for tables (the model's `Band.name`, set by `for_scene`)

    def __post_init__(self) -> None:
        for name in ("lo", "hi"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, BOUND.check(f"constraint on {self.output}: {name}",
                                                           getattr(self, name), MbsuiteError))
        if self.band is None and self.lo is None and self.hi is None:
            raise MbsuiteError(f"constraint on {self.output}: give a lower bound, an upper bound or both")
        if self.lo is not None and self.hi is not None and self.lo > self.hi:
            raise MbsuiteError(f"constraint on {self.output}: lower bound {self.lo:g} above upper bound {self.hi:g}")

    def for_scene(self, scene: Scene | None) -> Bound:
        """This bound with its band's system named, checked against the band the scene's model declares."""
        if self.band is None:
            return self
        if scene is None or scene.spec.studies.band is None:
            owner = "a function" if scene is None else f"model '{scene.model}'"
            raise MbsuiteError(f"constraint {self.output or 'OUTPUT'}=band: {owner} declares no band "
                               "(SPEC.studies.band)")
        declared = scene.spec.studies.band
        system = declared.check(self.band, self.output or declared.output, scene.model)
        return Bound(declared.output, band=system, band_name=declared.name)

    def at(self, scene: Scene | None) -> tuple[float, float]:
        """(lo, hi) at the scene's operating point (-inf/inf for an open side)."""
        if self.band is not None:
            b = self.for_scene(scene)
            return scene.spec.studies.band.target(b.band, scene)
        return (-math.inf if self.lo is None else float(self.lo), math.inf if self.hi is None else float(self.hi))

    def text(self) -> str:
        """How the constraint reads in tables."""
        if self.band is not None:
            return f"{self.output} in the {self.band_name} ({self.band})"
        lo = "" if self.lo is None else f"{self.lo:g} <= "
        hi = "" if self.hi is None else f" <= {self.hi:g}"
        return f"{lo}{self.output}{hi}"


def band(system: str = "") -> Bound:
    """The band the scene's model declares on its output, of `system` ("" = its first), at each evaluation's
    operating point (the catenary: Fm in the EN 50367 band of a supply system)."""
    return Bound("", band=system)


def parse_bound(text: str) -> Bound:
    """`OUTPUT=LO:HI` (either side may be empty: `Fm=100:`), or `OUTPUT=band` / `OUTPUT=band:SYSTEM` for the band the
    scene's model declares (the catenary: `Fm=band:DC3kV`, the EN 50367 band)."""
    name, sep, value = text.partition("=")
    name = name.strip()
    if not sep or not name:
        raise MbsuiteError(f"--constraint {text!r}: expected OUTPUT=LO:HI (e.g. Fm=100:130) or Fm=band[:SYSTEM]")
    head, _, tail = value.partition(":")
    if head.strip() == "band":
        return Bound(name, band=tail.strip())
    if value.count(":") != 1:
        raise MbsuiteError(f"--constraint {text!r}: expected OUTPUT=LO:HI with one colon (an empty side is open)")
    sides = []
    for part in value.split(":"):
        try:
            sides.append(float(part) if part.strip() else None)
        except ValueError:
            raise MbsuiteError(f"--constraint {text!r}: {part!r} is not a number") from None
    try:
        return Bound(name, sides[0], sides[1])
    except MbsuiteError as exc:
        raise MbsuiteError(f"--constraint {text!r}: {exc}") from None


@dataclass
class OptimiseResult:
    """A finished optimisation: the optimum `best` ({factor: value}), its aggregated objective `value`, its outputs
    at every operating point (`best_outputs`), whether it meets the constraints, every evaluation (`evaluations`:
    design, operating point, outputs, objective term, violation) and scipy's report."""

    objective: str
    aggregate: str
    factors: list[Factor]
    constraints: list[Bound]
    contexts: list[dict[str, Any]]
    best: dict[str, float]
    value: float
    feasible: bool
    best_outputs: list[dict[str, float]]
    evaluations: list[dict[str, Any]]
    seed: int
    settings: dict[str, Any]
    message: str = ""
    units: dict[str, str] = field(default_factory=dict)
    target: str = ""
    start: dict[str, Any] | None = None
    rerun: dict[str, Any] | None = None
    #: factor or operating-point key ("section.key") -> the SI unit it declares (`designspace.key_unit`)
    key_units: dict[str, str] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """Inputs, seed, settings, the optimum and every evaluation as JSON-able data."""
        from ..results import to_jsonable

        return to_jsonable({
            "target": self.target, "objective": self.objective, "aggregate": self.aggregate, "seed": self.seed,
            "factors": [{"name": f.label, "lo": f.lo, "hi": f.hi, "unit": self.key_units.get(f.label, "")}
                        for f in self.factors],
            "constraints": [c.text() for c in self.constraints], "operating_points": self.contexts,
            "settings": self.settings, "best": self.best, "value": self.value, "feasible": self.feasible,
            "best_outputs": self.best_outputs, "start": self.start, "message": self.message,
            "rerun": None if self.rerun is None else {"points": [{k: v for k, v in p.items() if not k.startswith("_")}
                                                                 for p in self.rerun["points"]]},
            "units": self.units, "evaluations_count": len(self.evaluations), "evaluations": self.evaluations})

    def table(self) -> str:
        """The optimum, its outputs at each operating point against the start design, and the constraints."""
        from ..results import format_table

        unit = self.units.get(self.objective, "")
        u = f" {unit}" if unit else ""
        agg = f"the {self.aggregate} over {len(self.contexts)} operating points of " if len(self.contexts) > 1 else ""
        lines = [f"minimise {agg}{self.objective} of {self.target or 'the target'} over {len(self.factors)} factors; "
                 + (f"subject to {'; '.join(c.text() for c in self.constraints)}; " if self.constraints else "")
                 + f"{len(self.evaluations)} evaluations, seed {self.seed}",
                 format_table(["factor", "unit", "lo", "hi", "optimum"] + (["start"] if self.start else []),
                              [[f.label, self.key_units.get(f.label, "") or "-", f.lo, f.hi, self.best[f.label]]
                               + ([self.start["design"].get(f.label, "")] if self.start else [])
                               for f in self.factors], ".5g"),
                 f"objective {self.value:.5g}{u} ({'meets' if self.feasible else 'VIOLATES'} the constraints)"]
        heads = sorted({k for o in self.best_outputs for k in o})
        rows = []
        for i, ctx in enumerate(self.contexts):
            where = ", ".join(f"{k} = {v:g}" for k, v in ctx.items()) or "-"
            rows.append([where, "optimum", *[self.best_outputs[i].get(h, float("nan")) for h in heads]])
            if self.start:
                rows.append([where, "start", *[self.start["outputs"][i].get(h, float("nan")) for h in heads]])
        lines.append(format_table(["operating point", "design",
                                   *(f"{h} [{self.units[h]}]" if self.units.get(h) else h for h in heads)], rows,
                                  ".5g"))
        if self.rerun:
            lines.append(self.rerun.get("table", ""))
        return "\n\n".join(x for x in lines if x)

    def report(self) -> Report:
        """The CLI report: table, data, and the writer of `evaluations.csv`, `optimise.png`."""
        from ..results import Report

        return Report(self.to_dict(), self.table(), self.write)

    def write(self, out: str | Path) -> list[Path]:
        """`evaluations.csv` (every design and operating point, its outputs, objective term and violation) and
        `optimise.png` (the objective of every evaluation in order, the optimum marked) under `out`."""
        from ..plotting import figure, save
        from ..results import write_csv

        out = Path(out)
        ev = self.evaluations
        keys = sorted({k for e in ev for k in e["outputs"]})
        ctx_keys = sorted({k for e in ev for k in e["context"]})
        cols = [("evaluation", "", list(range(len(ev))))]
        cols += [(f.label, self.key_units.get(f.label, ""), [e["design"][f.label] for e in ev]) for f in self.factors]
        cols += [(k, self.key_units.get(k, ""), [e["context"].get(k, "") for e in ev]) for k in ctx_keys]
        cols += [(k, self.units.get(k, ""), [e["outputs"].get(k, float("nan")) for e in ev]) for k in keys]
        cols += [("violation", "", [e["violation"] for e in ev]), ("penalised", "", [e["penalised"] for e in ev])]
        fig, axs = figure(1, 1, size=(7.0, 3.2), squeeze=False)
        ax = axs[0, 0]
        y = np.array([e["outputs"].get(self.objective, np.nan) for e in ev])
        ok = np.array([e["violation"] == 0.0 for e in ev])
        idx = np.arange(len(ev))
        ax.plot(idx[ok], y[ok], ".", ms=3, color="C0", label="meets the constraints")
        ax.plot(idx[~ok], y[~ok], "x", ms=3, color="C3", label="violates them")
        ax.axhline(self.value, color="k", lw=0.8, ls="--", label=f"optimum {self.value:.4g}")
        unit = self.units.get(self.objective, "")
        ax.set_xlabel("evaluation")
        ax.set_ylabel(f"{self.objective} [{unit}]" if unit else self.objective)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
        return [write_csv(out / "evaluations.csv", cols), save(fig, out / "optimise.png")]


def contexts_of(over: Mapping[str, Sequence[Any]] | None) -> list[dict[str, Any]]:
    """Every combination of the operating-point values (`{"input.speed": [250, 300]}`); [{}] without any."""
    if not over:
        return [{}]
    keys = list(over)
    for k in keys:
        if not isinstance(over[k], Sequence) or isinstance(over[k], str) or not over[k]:
            raise MbsuiteError(f"operating point {k}: give a non-empty list of values, got {over[k]!r}")
    return [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*(over[k] for k in keys))]


class _Problem:
    """Evaluation in batches: a generation of designs x every operating point on the sweep machinery, the penalised
    aggregate per design, every evaluation logged."""

    def __init__(self, fn: Callable, scene: Scene | None, factors: list[Factor], objective: str,
                 constraints: list[Bound], contexts: list[dict[str, Any]], aggregate: str, penalty: float,
                 workers: int, options: SweepOptions | None, progress: bool | None):
        self.fn, self.scene, self.factors, self.objective = fn, scene, factors, objective
        self.contexts, self.aggregate, self.penalty = contexts, aggregate, penalty
        self.workers, self.options, self.progress = workers, options, progress
        self.bounds = [[c.at(point_scene(scene, ctx) if scene is not None else None) for c in constraints]
                       for ctx in contexts]
        self.constraints = constraints
        self.log: list[dict[str, Any]] = []
        self.cache: dict[tuple, dict[str, float]] = {}

    def design(self, x: Sequence[float]) -> dict[str, float]:
        """The design {factor: value} of a parameter vector."""
        return {f.label: float(v) for f, v in zip(self.factors, x, strict=True)}

    def evaluate(self, xs: Sequence[Sequence[float]]) -> list[tuple[float, float, list[dict[str, float]]]]:
        """(aggregate objective, total violation, outputs per operating point) of each design."""
        designs = [self.design(x) for x in xs]
        m = len(self.contexts)
        keys = [(tuple(d.values()), j) for d in designs for j in range(m)]
        todo = list(dict.fromkeys(k for k in keys if k not in self.cache))  # a design seen before is not rerun
        if todo:
            points = [{**dict(zip(designs[0], k[0], strict=True)), **self.contexts[k[1]]} for k in todo]
            res = evaluate(self.fn, points, scene=self.scene, workers=self.workers, options=self.options,
                           progress=self.progress, desc="optimise")
            self.cache.update(zip(todo, res, strict=True))
        fresh = set(todo)  # each run is logged once
        out = []
        for i, d in enumerate(designs):
            terms, viols, outs = [], [], []
            for j, ctx in enumerate(self.contexts):
                y = self.cache[keys[i * m + j]]
                if self.objective not in y:
                    raise MbsuiteError(f"optimise: objective {self.objective!r} not among the outputs; valid: "
                                       f"{', '.join(y)}")
                each = []
                for c, (lo, hi) in zip(self.constraints, self.bounds[j], strict=True):
                    if c.output not in y:
                        raise MbsuiteError(f"optimise: constrained output {c.output!r} not among the outputs; "
                                           f"valid: {', '.join(y)}")
                    each.append(max(lo - y[c.output], 0.0, y[c.output] - hi))
                v = float(sum(each))
                term = y[self.objective]
                terms.append(term)
                viols.append(v)
                outs.append(y)
                if keys[i * m + j] in fresh:
                    fresh.discard(keys[i * m + j])
                    self.log.append({"design": d, "context": ctx, "outputs": y, "violation": v,
                                     "violations": each, "penalised": term + self.penalty * v})
            agg = max(terms) if self.aggregate == "worst" else float(np.mean(terms))
            if not all(math.isfinite(t) for t in terms):
                agg = math.inf
            out.append((agg, float(sum(viols)), outs))
        return out

    def penalised(self, xs: Sequence[Sequence[float]]) -> list[float]:
        """The penalised aggregate objective of each design (what the optimiser minimises)."""
        return [a + self.penalty * v for a, v, _ in self.evaluate(xs)]


def _check(objective: Any, aggregate: str, **numbers: Any) -> dict[str, Any]:
    """`numbers` (penalty, tol, maxiter, popsize, seed) checked against `LIMITS`, as Python floats and ints."""
    if not isinstance(objective, str) or not objective:
        raise MbsuiteError(f"optimise objective {objective!r} is invalid; valid: an output name (e.g. sigma)")
    if aggregate not in AGGREGATES:
        raise MbsuiteError(f"optimise aggregate {aggregate!r} is unknown; valid: {', '.join(AGGREGATES)}")
    return {k: LIMITS[k].check(f"optimise {k}", v, MbsuiteError) for k, v in numbers.items()}


def run(target: Scene | Callable[[dict[str, Any]], Mapping[str, Any]], factors: Sequence[Factor | str], *,
        objective: str | None = None, constraints: Sequence[Bound | str] = (),
        over: Mapping[str, Sequence] | None = None, aggregate: str = "worst", penalty: float = 10.0,
        maxiter: int = 20, popsize: int = 5, seed: int = 0, tol: float = 1e-3,
        start: Mapping[str, float] | None = None, workers: int = 0, options: SweepOptions | None = None,
        progress: bool | None = None) -> OptimiseResult:
    """Minimise `objective` over the factors' ranges (scipy `differential_evolution`, generations evaluated on the
    sweep machinery), subject to `constraints` (`Bound`s or `OUTPUT=LO:HI` texts) at every operating point of
    `over`, aggregated by `aggregate`. `popsize`: members per factor (scipy's meaning, at least 5 in all);
    `maxiter`: generations. `objective` None: the model's declared one (`SPEC.studies.objective`).
    `start`: a design evaluated first and reported beside the optimum (default: the scene's own values of the
    factors, when they lie in the ranges)."""
    from ..scenes import Scene

    scene = target if isinstance(target, Scene) else None
    objective = _default(scene, "objective", objective)
    checked = _check(objective, aggregate, penalty=penalty, tol=tol, maxiter=maxiter, popsize=popsize, seed=seed)
    penalty, tol, maxiter, popsize, seed = (checked[k] for k in ("penalty", "tol", "maxiter", "popsize", "seed"))
    facs = factors_for(scene, factors)
    cons = [(parse_bound(c) if isinstance(c, str) else c).for_scene(scene) for c in constraints]
    units = headline_units(scene)
    if scene is not None:
        for name in (objective, *(c.output for c in cons)):
            if name not in units:
                raise MbsuiteError(f"optimise: {name!r} is not a headline output of {scene.name}; valid: "
                                   f"{', '.join(units)}")
    fn = scene_evaluator(scene) if scene is not None else target
    if not callable(fn):
        raise MbsuiteError(f"optimise target {target!r} is neither a scene nor a function")
    ctxs = contexts_of(over)
    if scene is not None:
        for ctx in ctxs:
            point_scene(scene, ctx, origin="at an operating point of the study")
    prob = _Problem(fn, scene, facs, objective, cons, ctxs, aggregate, float(penalty), workers, options, progress)
    x0 = _start(scene, facs, start)
    with planned(*plan(len(facs), len(ctxs), maxiter, popsize, x0 is not None, workers), upto=True,
                 cheaper=cheaper(len(facs), len(ctxs), popsize, x0 is not None)):
        return _minimise(prob, facs, cons, ctxs, objective, aggregate, maxiter, popsize, seed, tol, penalty, x0,
                         scene, fn, units)


def plan(n_factors: int, n_contexts: int, maxiter: int, popsize: int, start: bool, workers: int, levels: int = 1
         ) -> tuple[str, int, int]:
    """(what, runs at most, in parallel) of an optimisation (`levels` of them: a Pareto front), for
    `mbsuite.progress.planned`: scipy's population max(5, popsize x factors), maxiter + 1 generations, each design
    at every operating point. The start design (`start`) adds none: it is a member of the first generation (scipy's
    `x0`), run once, so the plan's count is the evaluations' count when no generation stops early."""
    npop = max(5, popsize * n_factors)
    runs = levels * (maxiter + 1) * npop * n_contexts
    return ("optimise" if levels == 1 else f"pareto front ({levels} optimisations)"), runs, min(
        n_workers(workers), npop * n_contexts)


def cheaper(n_factors: int, n_contexts: int, popsize: int, start: bool, levels: int = 1) -> Callable[[int], str | None]:
    """The setting of an optimisation that fits in a number of runs (`plan`'s count; the budget's check computes
    that number from the first run's measured time): a smaller `--maxiter` of the same population; where not even
    `--maxiter 1` (two generations) fits, the largest `--popsize` (at least 2) whose two generations fit, with
    `--maxiter 1`; None if not even that fits (`start` is in the first generation: no run of its own)."""
    def fit(runs: int) -> str | None:
        npop = max(5, popsize * n_factors)
        k = runs // (levels * n_contexts)  # designs that fit
        if k // npop - 1 >= 1:
            return f"--maxiter {k // npop - 1}"
        smaller = (k // 2) // n_factors
        if smaller >= 2 and max(5, smaller * n_factors) * 2 <= k:
            return f"--popsize {smaller} --maxiter 1"
        return None

    return fit


def _minimise(prob: _Problem, facs: list[Factor], cons: list[Bound], ctxs: list[dict[str, Any]], objective: str,
              aggregate: str, maxiter: int, popsize: int, seed: int, tol: float, penalty: float,
              x0: np.ndarray | None, scene: Scene | None, fn: Callable, units: dict[str, str]) -> OptimiseResult:
    """Differential evolution on `prob` (`run`)."""
    from scipy.optimize import differential_evolution

    start_rec = None
    if x0 is not None:
        agg, viol, outs = prob.evaluate([x0])[0]
        start_rec = {"design": prob.design(x0), "value": agg, "violation": viol, "outputs": outs}

    def batch_map(_func: Callable, xs: Any) -> list[float]:
        return prob.penalised([np.asarray(x, dtype=float) for x in xs])

    res = differential_evolution(lambda x: prob.penalised([x])[0], [(f.lo, f.hi) for f in facs], maxiter=maxiter,
                                 popsize=popsize, tol=tol, rng=np.random.default_rng(seed), polish=False,
                                 updating="deferred", workers=batch_map, x0=x0, init="latinhypercube")
    best_x = np.asarray(res.x, dtype=float)
    value, viol, outs = prob.evaluate([best_x])[0]  # from the cache: the optimum was evaluated
    return OptimiseResult(objective, aggregate, facs, cons, ctxs, prob.design(best_x), float(value), viol == 0.0,
                          outs, prob.log, int(seed),
                          {"method": "scipy.optimize.differential_evolution", "maxiter": maxiter,
                           "popsize": popsize, "tol": tol, "penalty": penalty, "generations": int(res.nit),
                           "polish": False, "updating": "deferred"},
                          str(res.message), units, scene.name if scene is not None else _name(fn), start_rec,
                          key_units={k: u for k in [*(f.label for f in facs), *{k for c in ctxs for k in c}]
                                     if (u := key_unit(scene, k))})


def _default(scene: Scene | None, what: str, value: str | None) -> str:
    """`value`, or the model's declared default study output `what` (`SPEC.studies.objective` / `.against`)."""
    if value is not None:
        return value
    declared = getattr(scene.spec.studies, what) if scene is not None else None
    if declared is None:
        owner = "a function" if scene is None else f"model '{scene.model}'"
        raise MbsuiteError(f"optimise: give the {what} (an output name): {owner} declares no default "
                           f"(SPEC.studies.{what})")
    return declared


def _name(fn: Any) -> str:
    return getattr(fn, "__name__", None) or getattr(getattr(fn, "func", None), "__name__", "function")


def _start(scene: Scene | None, facs: list[Factor], start: Mapping[str, float] | None) -> np.ndarray | None:
    """The start design: `start` (each factor's value, inside its range), else the scene's own values when every
    factor has one inside its range, else None."""
    if start is not None:
        missing = [f.label for f in facs if f.label not in start]
        extra = [k for k in start if k not in {f.label for f in facs}]
        if missing or extra:
            raise MbsuiteError("optimise start design: " + "; ".join(
                ([f"no value for {', '.join(missing)}"] if missing else [])
                + ([f"{', '.join(extra)} is not a factor (--vary)"] if extra else [])))
        x = np.array([float(start[f.label]) for f in facs])
    elif scene is not None:
        d = scene.to_dict()
        vals = []
        for f in facs:
            node: Any = d.get(f.section) or {}
            for k in f.key.split("."):
                node = node.get(k) if isinstance(node, Mapping) else None
            if node is None:
                node = _declared_default(scene, f)
            if real(node) is None:
                return None
            vals.append(float(real(node)))
        x = np.array(vals)
    else:
        return None
    inside = all(f.lo <= v <= f.hi for f, v in zip(facs, x, strict=True))
    if not inside and start is not None:
        raise MbsuiteError("optimise start design: " + ", ".join(f"{f.label} = {v:g} outside [{f.lo:g}, {f.hi:g}]"
                                                                 for f, v in zip(facs, x, strict=True)
                                                                 if not f.lo <= v <= f.hi))
    return x if inside else None


def _declared_default(scene: Scene, f: Factor) -> Any:
    """The declared default of a parameter the scene file omits (`params.KEY` of the model's parameter class)."""
    if f.section != "params" or "." in f.key:
        return None
    import dataclasses

    cls = scene.spec.params_cls
    fields = {x.name: x for x in dataclasses.fields(cls)} if cls is not None else {}
    fld = fields.get(f.key)
    return fld.default if fld is not None and fld.default is not dataclasses.MISSING else None


def rerun(result: OptimiseResult, scene: Scene, workers: int = 0) -> dict[str, Any]:
    """Run the optimum again at every operating point with its error estimate (the scene refined once and twice,
    `mbsuite.analysis.errorestimate`); stores and returns per point the headline values, the estimate and a table.
    Judging the estimates against their tolerances is left to `judge_rerun`, so that the result is reported
    first."""
    from ..pathrun import run_judged
    from .errorestimate import error_estimate

    points = []
    tables = []
    for ctx in result.contexts:
        sc = point_scene(scene, {**result.best, **ctx}, origin="at the optimum")
        res = run_judged(sc)
        est = error_estimate(sc, base=sc.spec.accuracy.values(sc, res), workers=workers)
        where = ", ".join(f"{k} = {v:g}" for k, v in ctx.items())
        points.append({"context": ctx, "values": {r.name: r.value for r in est.rows},
                       "error_estimate": est.to_dict(), "within_tolerance": all(r.ok for r in est.rows),
                       "_figures": est.figures()})
        tables.append(f"optimum re-run{' at ' + where if where else ''} with its error estimate\n{est.table()}")
    result.rerun = {"points": points, "table": "\n\n".join(tables)}
    return result.rerun


def judge_rerun(result: OptimiseResult, scene: Scene) -> list[str]:
    """The re-run's error estimates against their tolerances (`trust.health.judge_estimate`): the `INACCURATE:`
    lines of those past it (emitted as warnings with solver.allow_inaccurate / --allow-inaccurate). The result is
    kept either way: the command line flags its report with them unless allowed (exit status 3)."""
    from ..trust.health import judge_estimate

    out = []
    for p in (result.rerun or {}).get("points", []):
        where = ", ".join(f"{k} = {v:g}" for k, v in p["context"].items())
        out += judge_estimate(p["_figures"], allow_inaccurate=scene.solver.allow_inaccurate,
                              what=f"the optimum of {scene.name}{' at ' + where if where else ''}")
    return out


@dataclass
class ParetoResult:
    """The epsilon-constraint front: per level the optimum (`runs`), and the non-dominated set of every evaluation
    (`front`: minimise `objective`, maximise `against`; over several operating points, of every design with its
    aggregate, `candidates`)."""

    objective: str
    against: str
    levels: list[float]
    runs: list[OptimiseResult]
    front: list[dict[str, Any]]
    units: dict[str, str]
    target: str

    def to_dict(self) -> dict[str, Any]:
        """Inputs, each level's optimum and the front as JSON-able data."""
        from ..results import to_jsonable

        return to_jsonable({"target": self.target, "objective": self.objective, "against": self.against,
                            "levels": self.levels, "front": self.front,
                            "runs": [{k: v for k, v in r.to_dict().items() if k != "evaluations"} for r in self.runs],
                            "evaluations": self.evaluations()})

    def evaluations(self) -> list[dict[str, Any]]:
        """Every evaluation of every level, its `violation` that of the run's own constraints (the level's is the
        last of its `violations`): what `evaluations.csv` and summary.json report, so that both give one number."""
        return _evaluations(self.runs)

    def table(self) -> str:
        """Each level's optimum and the front."""
        from ..results import format_table

        # the traded output of each level's optimum: the least over the operating points (the level holds at each)
        rows = [[lv, r.value, min(o.get(self.against, float("nan")) for o in r.best_outputs),
                 "yes" if r.feasible else "NO", *[r.best[f.label] for f in r.factors]]
                for lv, r in zip(self.levels, self.runs, strict=True)]
        head = [f"{self.against} >=", self.objective, self.against, "feasible",
                *[f.label for f in self.runs[0].factors]]
        text = (f"epsilon-constraint front of {self.target}: minimise {self.objective}, {self.against} >= each level "
                f"(and the run's constraints)\n" + format_table(head, rows, ".5g"))
        front = [[p["outputs"][self.against], p["outputs"][self.objective], *p["design"].values()] for p in self.front]
        return text + "\n\nnon-dominated evaluations (all levels)\n" + format_table(
            [self.against, self.objective, *[f.label for f in self.runs[0].factors]], front, ".5g")

    def report(self) -> Report:
        """The CLI report: table, data, `pareto.csv` and `pareto.png`."""
        from ..results import Report

        return Report(self.to_dict(), self.table(), self.write)

    def write(self, out: str | Path) -> list[Path]:
        """`pareto.csv` (the front), `evaluations.csv` (every evaluation, its operating point, the violation of the
        run's own constraints) and `pareto.png` (the candidates of the front, `candidates`) under `out`."""
        from ..plotting import figure, save
        from ..results import write_csv

        out = Path(out)
        labels = [f.label for f in self.runs[0].factors]
        cols = [(self.against, self.units.get(self.against, ""), [p["outputs"][self.against] for p in self.front]),
                (self.objective, self.units.get(self.objective, ""),
                 [p["outputs"][self.objective] for p in self.front])]
        ku = self.runs[0].key_units
        cols += [(k, ku.get(k, ""), [p["design"][k] for p in self.front]) for k in labels]
        ev = self.evaluations()
        ecols = [(k, ku.get(k, ""), [e["design"][k] for e in ev]) for k in labels]
        ecols += [(k, ku.get(k, ""), [e["context"].get(k, "") for e in ev])
                  for k in sorted({k for e in ev for k in e["context"]})]
        ecols += [(k, self.units.get(k, ""), [e["outputs"].get(k, float("nan")) for e in ev])
                  for k in sorted({k for e in ev for k in e["outputs"]})]
        ecols += [("violation", "", [e["violation"] for e in ev])]
        fig, axs = figure(1, 1, size=(6.5, 4.2), squeeze=False)
        ax = axs[0, 0]
        cand = candidates(ev, self.runs[0].contexts, self.objective, self.against, self.runs[0].aggregate)
        ok = [e for e in cand if e["violation"] == 0.0]
        bad = [e for e in cand if e["violation"] > 0.0]
        ax.plot([e["outputs"][self.against] for e in bad], [e["outputs"][self.objective] for e in bad], "x",
                color="0.7", ms=3, label="evaluations violating the run's constraints")
        ax.plot([e["outputs"][self.against] for e in ok], [e["outputs"][self.objective] for e in ok], ".",
                color="C0", ms=3, label="evaluations meeting them")
        fx = [p["outputs"][self.against] for p in self.front]
        fy = [p["outputs"][self.objective] for p in self.front]
        ax.plot(fx, fy, "-o", color="C3", ms=4, label="non-dominated (front)")
        for lv in self.levels:
            ax.axvline(lv, color="0.85", lw=0.6)
        ua, uo = self.units.get(self.against, ""), self.units.get(self.objective, "")
        ax.set_xlabel(f"{self.against} [{ua}]" if ua else self.against)
        ax.set_ylabel(f"{self.objective} [{uo}]" if uo else self.objective)
        ax.set_title(f"{self.target}: {self.objective} against {self.against} (epsilon-constraint levels: grey)",
                     fontsize=9)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
        return [write_csv(out / "pareto.csv", cols), write_csv(out / "evaluations.csv", ecols),
                save(fig, out / "pareto.png")]


def non_dominated(evals: Sequence[Mapping[str, Any]], objective: str, against: str) -> list[dict[str, Any]]:
    """The evaluations meeting their constraints that no other one beats in both `objective` (lower) and `against`
    (higher), sorted by `against`."""
    pts = [e for e in evals if e["violation"] == 0.0]
    front = []
    for e in pts:
        a, o = e["outputs"][against], e["outputs"][objective]
        if not any(p["outputs"][against] >= a and p["outputs"][objective] <= o
                   and (p["outputs"][against] > a or p["outputs"][objective] < o) for p in pts):
            front.append(dict(e))
    uniq = {(p["outputs"][against], p["outputs"][objective]): p for p in front}
    return sorted(uniq.values(), key=lambda p: p["outputs"][against])


def _evaluations(runs: Sequence[OptimiseResult]) -> list[dict[str, Any]]:
    """Every evaluation of every level's run, its `violation` that of the run's own constraints only (each run's last
    constraint is its level, which does not count against a design on the front)."""
    n_base = len(runs[0].constraints) - 1
    return [{**e, "violation": float(sum(e["violations"][:n_base]))} for r in runs for e in r.evaluations]


def candidates(evals: Sequence[Mapping[str, Any]], contexts: Sequence[Mapping[str, Any]], objective: str,
               against: str, aggregate: str) -> list[dict[str, Any]]:
    """What the front is chosen from. At one operating point: the evaluations. Over several: the designs, each with
    the figures its runs constrain and minimise -- the objective aggregated over the points as the runs minimise it
    (`worst`: the max, `mean`: the mean), `against` the least over the points (the level it meets at every one), the
    violation summed over the points, its evaluations in `points`; a design is not compared by one operating point's
    evaluation."""
    if len(contexts) <= 1:
        return [dict(e) for e in evals]
    by_design: dict[tuple, dict[tuple, Mapping[str, Any]]] = {}
    for e in evals:  # a design met again (the start design in every run) has the same outputs
        by_design.setdefault(tuple(e["design"].items()), {})[tuple(e["context"].items())] = e
    out = []
    for key, per in by_design.items():
        pts = [per.get(tuple(c.items())) for c in contexts]
        if any(p is None for p in pts):
            continue
        terms = [float(p["outputs"][objective]) for p in pts]
        out.append({"design": dict(key), "context": {},
                    "outputs": {objective: max(terms) if aggregate == "worst" else float(np.mean(terms)),
                                against: min(float(p["outputs"][against]) for p in pts)},
                    "violation": float(sum(p["violation"] for p in pts)), "points": [dict(p) for p in pts]})
    return out


def pareto(target: Scene | Callable[[dict[str, Any]], Mapping[str, Any]], factors: Sequence[Factor | str], *,
           objective: str | None = None, against: str | None = None, levels: Sequence[float],
           **kwargs: Any) -> ParetoResult:
    """The trade-off of `objective` (minimised) against `against` (maximised): one `run` per level with the extra
    constraint `against >= level` (epsilon-constraint), the front the non-dominated set of all their evaluations.
    Over several operating points (`over`) the front is of designs (`candidates`): each with its aggregated objective
    (what the runs minimise) and the least `against` over the points (the level it meets at each). Before, it was the
    non-dominated set of single evaluations, so a design entered by its best operating point (e.g. sigma at 250 km/h
    for a worst case set at 300 km/h), below what the runs could reach, and the table gave `against` at the first
    point only. `objective` / `against` None: the model's declared ones (`SPEC.studies`). `kwargs` go to `run`
    (constraints, over, aggregate, maxiter, popsize, seed, workers, options)."""
    from ..scenes import Scene

    lv = [LIMITS["level"].check("pareto level", x, MbsuiteError) for x in levels]
    if not lv:
        raise MbsuiteError(f"pareto levels {levels!r}: give one or more finite numbers")
    scene = target if isinstance(target, Scene) else None
    objective, against = _default(scene, "objective", objective), _default(scene, "against", against)
    base = [parse_bound(c) if isinstance(c, str) else c for c in kwargs.pop("constraints", ())]
    nf, nc = len(factors), len(contexts_of(kwargs.get("over")))
    start = kwargs.get("start") is not None or scene is not None
    popsize, workers = kwargs.get("popsize", 5), kwargs.get("workers", 0)
    with planned(*plan(nf, nc, kwargs.get("maxiter", 20), popsize, start, workers, len(lv)), upto=True,
                 cheaper=cheaper(nf, nc, popsize, start, len(lv))):
        runs = [run(target, factors, objective=objective, constraints=[*base, Bound(against, lo=x)], **kwargs)
                for x in lv]
    # a design is on the front if it meets the run's own constraints; the level it was searched under does not count
    cand = candidates(_evaluations(runs), runs[0].contexts, objective, against, runs[0].aggregate)
    return ParetoResult(objective, against, lv, runs, non_dominated(cand, objective, against), runs[0].units,
                        scene.name if scene is not None else runs[0].target)


__all__ = ["AGGREGATES", "Bound", "OptimiseResult", "ParetoResult", "band", "candidates", "cheaper", "contexts_of",
           "judge_rerun", "non_dominated", "parse_bound", "pareto", "plan", "rerun", "run"]
