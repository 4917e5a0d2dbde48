"""Global sensitivity of a scene's headline outputs to declared parameter ranges: Morris screening (elementary
effects) and Sobol indices, sampled and analysed by SALib, every point evaluated on the sweep machinery.

    from mbsuite.analysis import sensitivity
    res = sensitivity.run(scene, ["params.m1=5:10", "params.F0=100:140"], method="sobol", n=64, seed=1)
    res.ranking("sigma")          # the factors by their total index on sigma, with confidence intervals
    res.report().save("out/sens") # sensitivity.csv, evaluations.csv, sensitivity.png, summary.json

Methods (SALib's implementations, named after their sources):
- `morris`: `n` trajectories of k + 1 points on a `levels`-level grid (Morris 1991; mu* of Campolongo, Cariboni and
  Saltelli 2007); per output mu* (mean absolute elementary effect, in the output's unit per range), sigma, and the
  bootstrap confidence interval of mu*. n (k + 1) evaluations.
- `sobol`: Saltelli's scheme with Sobol' sequences (Saltelli 2002; Saltelli et al. 2010), `n` a power of two; per
  output first-order S1 and total ST with bootstrap confidence intervals. n (k + 2) evaluations.

The target is a scene (its declared headline outputs, `designspace.scene_outputs`) or any module-level function
`point -> {output: number}` (`ishigami` below: the test function with closed-form indices)."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..engines.core import n_workers
from ..errors import MbsuiteError
from ..limits import Limit
from ..progress import planned
from .designspace import (
    Factor,
    evaluate,
    factor_unit,
    factors_for,
    headline_units,
    output_names,
    scene_evaluator,
)

if TYPE_CHECKING:
    from ..results import Report
    from ..scenes import Scene
    from .sweep import SweepOptions

METHODS = ("morris", "sobol")
MAX_N = 2**16
#: the numbers `run` takes, declared once (`Limit.check`: numpy scalars too; bools, NaN, inf refused)
LIMITS = {"n": Limit(lo=2, hi=MAX_N, kind=int, doc="morris trajectories or sobol base sample"),
          "seed": Limit(lo=0, hi=2**32 - 1, kind=int, doc="seed of the sample and the bootstrap"),
          "levels": Limit(lo=2, hi=MAX_N, kind=int, doc="morris grid levels"),
          "conf_level": Limit(lo=0.0, hi=1.0, lo_open=True, hi_open=True, doc="confidence level of the intervals")}


def ishigami(point: Mapping[str, float], a: float = 7.0, b: float = 0.1) -> dict[str, float]:
    """The Ishigami function of `x.x1`, `x.x2`, `x.x3` on [-pi, pi]^3 (Ishigami and Homma 1990): f = sin x1 +
    a sin^2 x2 + b x3^4 sin x1. Its Sobol indices in closed form: `ishigami_indices`."""
    x1, x2, x3 = (float(point[f"x.x{i}"]) for i in (1, 2, 3))
    return {"f": math.sin(x1) + a * math.sin(x2) ** 2 + b * x3**4 * math.sin(x1)}


def ishigami_indices(a: float = 7.0, b: float = 0.1) -> dict[str, list[float]]:
    """The closed-form first-order and total Sobol indices of `ishigami` (variance decomposition of the function on
    uniform inputs): V1 = (1 + b pi^4 / 5)^2 / 2, V2 = a^2 / 8, V13 = b^2 pi^8 (1/18 - 1/50), V = V1 + V2 + V13."""
    pi4 = math.pi**4
    v1 = 0.5 * (1 + b * pi4 / 5) ** 2
    v2 = a**2 / 8
    v13 = b**2 * pi4**2 * (1 / 18 - 1 / 50)
    v = v1 + v2 + v13
    return {"S1": [v1 / v, v2 / v, 0.0], "ST": [(v1 + v13) / v, v2 / v, v13 / v]}


ISHIGAMI_FACTORS = tuple(Factor("x", f"x{i}", -math.pi, math.pi) for i in (1, 2, 3))


@dataclass
class SensitivityResult:
    """A finished study: the factors, the sample and every evaluation, and per output the indices SALib computed
    (`indices[output][name]`: for morris `mu`, `mu_star`, `sigma`, `mu_star_conf`; for sobol `S1`, `S1_conf`, `ST`,
    `ST_conf`; one value per factor)."""

    method: str
    factors: list[Factor]
    n: int
    seed: int
    levels: int
    conf_level: float
    outputs: list[str]
    samples: np.ndarray
    evaluations: list[dict[str, float]]
    indices: dict[str, dict[str, list[float]]]
    units: dict[str, str] = field(default_factory=dict)
    target: str = ""
    #: factor label -> the SI unit its key declares (`designspace.factor_unit`; absent: none declared)
    factor_units: dict[str, str] = field(default_factory=dict)

    @property
    def key(self) -> str:
        """The index the ranking sorts by: `mu_star` (morris) or `ST` (sobol)."""
        return "mu_star" if self.method == "morris" else "ST"

    def ranking(self, output: str) -> list[dict[str, Any]]:
        """The factors of `output` from most to least influential (by `key`), each with its indices."""
        if output not in self.indices:
            raise MbsuiteError(f"output {output!r} not in the study; valid: {', '.join(self.indices)}")
        ind = self.indices[output]
        rows = [{"factor": f.label, **{k: v[i] for k, v in ind.items()}} for i, f in enumerate(self.factors)]
        return sorted(rows, key=lambda r: -abs(r[self.key]) if math.isfinite(r[self.key]) else 0.0)

    def to_dict(self) -> dict[str, Any]:
        """Inputs, seed, indices, rankings and every evaluation as JSON-able data."""
        return {"method": self.method, "target": self.target, "n": self.n, "seed": self.seed, "levels": self.levels,
                "conf_level": self.conf_level, "evaluations_count": len(self.evaluations),
                "factors": [{"name": f.label, "lo": f.lo, "hi": f.hi, "unit": self.factor_units.get(f.label, "")}
                            for f in self.factors],
                "outputs": self.outputs, "units": self.units, "indices": self.indices,
                "ranking": {o: self.ranking(o) for o in self.outputs},
                "evaluations": [{"point": dict(zip([f.label for f in self.factors], map(float, x), strict=True)),
                                 "outputs": y} for x, y in zip(self.samples, self.evaluations, strict=True)]}

    def table(self) -> str:
        """The ranked table of every output with the indices and their confidence intervals."""
        from ..results import format_table

        pct = f"{100 * self.conf_level:g} %"
        blocks = [f"{self.method} sensitivity of {self.target or 'the target'}: {len(self.factors)} factors, "
                  f"n = {self.n}, {len(self.evaluations)} evaluations, seed {self.seed}; +- = {pct} confidence "
                  "half-width (bootstrap)"]
        for o in self.outputs:
            unit = self.units.get(o, "")
            if self.method == "morris":
                head = ["rank", "factor", *(f"{h} [{unit}]" if unit else h for h in ("mu*", "+-", "mu", "sigma"))]
                rows = [[i + 1, r["factor"], r["mu_star"], r["mu_star_conf"], r["mu"], r["sigma"]]
                        for i, r in enumerate(self.ranking(o))]
            else:
                head = ["rank", "factor", "ST", "+-", "S1", "+-"]
                rows = [[i + 1, r["factor"], r["ST"], r["ST_conf"], r["S1"], r["S1_conf"]]
                        for i, r in enumerate(self.ranking(o))]
            blocks.append(f"{o}" + (f" [{unit}]" if unit else "") + "\n" + format_table(head, rows, ".4g"))
        return "\n\n".join(blocks)

    def report(self) -> Report:
        """The CLI report: the table, the data, and the writer of `sensitivity.csv`, `evaluations.csv`,
        `sensitivity.png`."""
        from ..results import Report

        return Report(self.to_dict(), self.table(), self.write)

    def write(self, out: str | Path) -> list[Path]:
        """`sensitivity.csv` (one row per output and factor, ranked; its `unit` the unit of the row's morris indices,
        the output's, "-" for sobol's fractions of variance), `evaluations.csv` (every point and its outputs, the
        header `name [unit]`) and `sensitivity.png` under `out`."""
        from ..plotting import save
        from ..results import write_csv

        out = Path(out)
        rows = [(o, i + 1, r) for o in self.outputs for i, r in enumerate(self.ranking(o))]
        names = list(self.indices[self.outputs[0]]) if self.outputs else []
        cols = [("output", "", [o for o, _, _ in rows]),
                ("unit", "", [self.units.get(o, "") if self.method == "morris" else "-" for o, _, _ in rows]),
                ("rank", "", [k for _, k, _ in rows]),
                ("factor", "", [r["factor"] for _, _, r in rows])]
        cols += [(n, "", [r[n] for _, _, r in rows]) for n in names]
        ev = [(f.label, self.factor_units.get(f.label, ""), self.samples[:, j]) for j, f in enumerate(self.factors)]
        ev += [(o, self.units.get(o, ""), [e.get(o, float("nan")) for e in self.evaluations])
               for o in sorted({k for e in self.evaluations for k in e})]
        return [write_csv(out / "sensitivity.csv", cols), write_csv(out / "evaluations.csv", ev),
                save(self.figure(), out / "sensitivity.png")]

    def figure(self) -> Any:
        """One panel per output (at most 8): the factors' indices as horizontal bars with their confidence
        intervals (morris: mu* against sigma is in the table; sobol: S1 and ST side by side)."""
        from ..plotting import figure

        shown = self.outputs[:8]
        ncol = 2 if len(shown) > 1 else 1
        nrow = math.ceil(len(shown) / ncol)
        fig, axs = figure(nrow, ncol, size=(5.0 * ncol, 0.6 + (0.45 * len(self.factors) + 0.9) * nrow),
                          squeeze=False)
        for ax in axs.ravel()[len(shown):]:
            ax.set_visible(False)
        for ax, o in zip(axs.ravel(), shown, strict=False):
            rank = self.ranking(o)[::-1]
            y = np.arange(len(rank))
            if self.method == "morris":
                ax.barh(y, [r["mu_star"] for r in rank], xerr=[r["mu_star_conf"] for r in rank], color="C0",
                        capsize=2, label="mu*")
                unit = self.units.get(o, "")
                ax.set_xlabel(f"mu* [{unit}], change over the range" if unit else "mu*, change over the range")
            else:
                ax.barh(y + 0.2, [r["ST"] for r in rank], height=0.4, xerr=[r["ST_conf"] for r in rank],
                        color="C0", capsize=2, label="ST")
                ax.barh(y - 0.2, [r["S1"] for r in rank], height=0.4, xerr=[r["S1_conf"] for r in rank],
                        color="C1", capsize=2, label="S1")
                ax.set_xlabel("Sobol index")
            ax.set_yticks(y, [r["factor"] for r in rank], fontsize=7)
            ax.set_title(o, fontsize=9)
            ax.grid(True, axis="x", alpha=0.3)
            ax.legend(fontsize=7)
        fig.suptitle(f"{self.method} sensitivity ({100 * self.conf_level:g} % confidence intervals), "
                     f"{len(self.evaluations)} evaluations", fontsize=9)
        return fig


def _check(method: str, n: Any, seed: Any, levels: Any, conf_level: Any) -> tuple[int, int, int, float]:
    if method not in METHODS:
        raise MbsuiteError(f"sensitivity method {method!r} is unknown; valid: {', '.join(METHODS)}")
    given = {"n": n, "seed": seed, "levels": levels, "conf_level": conf_level}
    n, seed, levels, conf_level = (LIMITS[k].check(f"sensitivity {k}", v, MbsuiteError) for k, v in given.items())
    if method == "sobol" and int(n) & (int(n) - 1):
        raise MbsuiteError(f"sensitivity n = {n} is invalid for sobol; valid: a power of two (Sobol' sequence)")
    if method == "morris" and int(levels) % 2:
        raise MbsuiteError(f"sensitivity levels = {levels} is invalid for morris; valid: an even number")
    return n, seed, levels, conf_level


def sample(method: str, factors: Sequence[Factor], n: int, seed: int, levels: int = 4) -> np.ndarray:
    """SALib's sample of the method over the factors' ranges (one row per evaluation, one column per factor)."""
    problem = _problem(factors)
    if method == "morris":
        from SALib.sample import morris

        return morris.sample(problem, n, num_levels=levels, seed=seed)
    from SALib.sample import sobol

    return sobol.sample(problem, n, calc_second_order=False, scramble=True, seed=seed)


def _problem(factors: Sequence[Factor]) -> dict[str, Any]:
    return {"num_vars": len(factors), "names": [f.label for f in factors], "bounds": [[f.lo, f.hi] for f in factors]}


def analyse(method: str, factors: Sequence[Factor], x: np.ndarray, y: np.ndarray, *, seed: int, levels: int = 4,
            conf_level: float = 0.95, num_resamples: int = 1000) -> dict[str, list[float]]:
    """SALib's indices of one output `y` over the sample `x` (bootstrap confidence intervals, seeded)."""
    import warnings

    problem = _problem(factors)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a constant output: SALib divides 0 by 0 (nan indices)
        if method == "morris":
            from SALib.analyze import morris

            res = morris.analyze(problem, x, y, num_resamples=num_resamples, conf_level=conf_level,
                                 num_levels=levels, seed=seed)
            names = ("mu", "mu_star", "sigma", "mu_star_conf")
        else:
            from SALib.analyze import sobol

            res = sobol.analyze(problem, y, calc_second_order=False, num_resamples=num_resamples,
                                conf_level=conf_level, seed=seed)
            names = ("S1", "S1_conf", "ST", "ST_conf")
    return {k: [float(v) for v in np.asarray(res[k], dtype=float)] for k in names}


def run(target: Scene | Callable[[dict[str, Any]], Mapping[str, Any]], factors: Sequence[Factor | str], *,
        method: str = "morris", n: int = 8, seed: int = 0, outputs: Sequence[str] | None = None, levels: int = 4,
        conf_level: float = 0.95, workers: int = 0, options: SweepOptions | None = None,
        progress: bool | None = None) -> SensitivityResult:
    """Sample the factors' ranges (SALib), evaluate `target` at every sample on the sweep machinery and analyse each
    output (SALib). `target`: a scene (its headline outputs) or a module-level function `point -> {output: value}`
    (a point is `{factor label: value}`). `n`: morris trajectories, or sobol's base sample (a power of two).
    `outputs`: the outputs to analyse (default all). `seed` fixes the sample and the bootstrap."""
    from ..scenes import Scene

    n, seed, levels, conf_level = _check(method, n, seed, levels, conf_level)
    scene = target if isinstance(target, Scene) else None
    facs = factors_for(scene, factors)
    units = headline_units(scene)
    if scene is not None and outputs:
        output_names([dict.fromkeys(units, 0.0)], outputs, "sensitivity")  # before anything runs
    fn = scene_evaluator(scene) if scene is not None else target
    if not callable(fn):
        raise MbsuiteError(f"sensitivity target {target!r} is neither a scene nor a function")
    x = sample(method, facs, n, seed, levels)
    points = [dict(zip([f.label for f in facs], map(float, row), strict=True)) for row in x]
    per = len(facs) + (1 if method == "morris" else 2)  # runs per trajectory / base sample

    def fit(runs: int) -> str | None:
        k = runs // per
        if method == "sobol":
            k = 2 ** int(math.log2(k)) if k >= 1 else 0
        return f"--n {k}" if 1 <= k < n else None

    with planned(f"{method} sensitivity", len(points), min(n_workers(workers), len(points)),
                 detail=f"n = {n} x {per}", cheaper=fit):
        results = evaluate(fn, points, scene=scene, workers=workers, options=options, progress=progress,
                           desc=f"{method} sensitivity")
    names = output_names(results, outputs, "sensitivity")
    indices = {}
    for o in names:
        y = np.array([r.get(o, float("nan")) for r in results], dtype=float)
        if not np.all(np.isfinite(y)):
            raise MbsuiteError(f"sensitivity: output {o!r} is not finite at {int(np.sum(~np.isfinite(y)))} of "
                               f"{len(y)} points; narrow the ranges or leave the output out")
        indices[o] = analyse(method, facs, x, y, seed=seed, levels=levels, conf_level=conf_level)
    what = scene.name if scene is not None else getattr(fn, "__name__", None) or getattr(
        getattr(fn, "func", None), "__name__", "function")
    return SensitivityResult(method, facs, n, seed, levels, conf_level, names, x, results, indices, units, what,
                             {f.label: u for f in facs if (u := factor_unit(scene, f))})


__all__ = ["ISHIGAMI_FACTORS", "METHODS", "SensitivityResult", "analyse", "ishigami", "ishigami_indices", "run",
           "sample"]
