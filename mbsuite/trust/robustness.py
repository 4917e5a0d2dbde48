"""Stability under perturbation: copies of a run with every parameter and the initial state changed by a relative
1e-12 or 1e-9 (`mbsuite.trust.perturbation`), and what must (and may not) change.

`check_scene(scene)` runs the unperturbed scene and the copies and holds them to two rules:
(a) **invariants**: every health figure of every copy (energy balance, closure residual, stability margins, ...)
    stays within its bound - `mbsuite.run` raises `AccuracyError` otherwise;
(b) **sensitivity**: each headline output y (the numbers of `SimResult.statistics` and `.stats`, and each signal's
    final, min and max)
    moves by at most `KAPPA_MAX` x eps x scale (scale: `headline`): the measured
    condition estimate kappa = |dy| / (eps scale) is reported per output. An output whose kappa exceeds the bound must
    be declared by the model (`PERTURBATION_JUMPS` in its suite module: output pattern -> why), as a true
    discontinuity of the physics (a discrete event that the perturbation moves across a decision instant); an
    undeclared jump fails the check.
`check_case(case)` runs a hard case inside the context: every assertion of the case must hold in every copy.
"""
from __future__ import annotations

import dataclasses
import fnmatch
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..hardcases import run_case
from ..registry import get_model
from ..results import Report, format_table
from ..simulate import run
from . import perturbation
from .perturbation import perturbed

#: relative perturbations of the check (the default suite runs the first, the slow suite both)
EPSILONS = (1e-12, 1e-9)
#: largest condition estimate kappa = |dy| / (eps * scale) accepted for an output not declared a jump
KAPPA_MAX = 1e6


def shortened(scene: Any, duration: float | None) -> Any:
    """`scene` with a run longer than `duration` (s) cut to it (its settling time to at most half of it); None or a
    shorter run: the scene itself."""
    if duration is None or not getattr(scene.solver, "duration", None) or scene.solver.duration <= duration:
        return scene
    upd: dict[str, float] = {"duration": duration}
    if getattr(scene.solver, "t_settle", None):
        upd["t_settle"] = min(scene.solver.t_settle, 0.5 * duration)
    return scene.replace(solver=upd)


@dataclass
class OutputSensitivity:
    """One headline output across the copies: its value, the largest change, kappa, and whether it jumped."""
    name: str
    value: float
    max_change: float
    kappa: float
    jump: str = ""  # the declared reason when kappa exceeds KAPPA_MAX (an undeclared jump fails)

    @property
    def ok(self) -> bool:
        """Within the bound, or a declared discontinuity."""
        return self.kappa <= KAPPA_MAX or bool(self.jump)


@dataclass
class PerturbationReport:
    """The check of one scene (or hard case) at one eps: invariants, sensitivities, errors."""
    target: str
    eps: float
    draws: int
    invariants: dict[str, tuple[float, float, float]] = field(default_factory=dict)  # name -> (base, worst, bound)
    outputs: list[OutputSensitivity] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    base: Any = field(default=None, repr=False, compare=False)  # unperturbed run: SimResult or Outcome

    @property
    def ok(self) -> bool:
        """No error, every invariant within its bound in every copy, every output within KAPPA_MAX or declared."""
        return (not self.errors and all(w <= b for _, w, b in self.invariants.values())
                and all(o.ok for o in self.outputs))

    @property
    def max_kappa(self) -> float:
        """The largest condition estimate among the outputs that did not jump (0 if none)."""
        ks = [o.kappa for o in self.outputs if not o.jump]
        return max(ks) if ks else 0.0

    def jumps(self) -> list[OutputSensitivity]:
        """The outputs past KAPPA_MAX (declared or not)."""
        return [o for o in self.outputs if o.kappa > KAPPA_MAX]

    def row(self) -> list[Any]:
        """Table row: target, eps, draws, worst invariant / bound, max kappa, jumps, verdict."""
        inv = max((w / b for _, w, b in self.invariants.values() if b > 0), default=0.0)
        jumps = ", ".join(o.name for o in self.jumps()) or "-"
        return [self.target, f"{self.eps:.0e}", self.draws, f"{inv:.2g}", f"{self.max_kappa:.2g}", jumps,
                "ok" if self.ok else "FAIL: " + "; ".join(self.errors or [o.name for o in self.outputs if not o.ok])]

    def to_dict(self) -> dict[str, Any]:
        """JSON-able form."""
        return {"target": self.target, "eps": self.eps, "draws": self.draws, "ok": self.ok,
                "max_kappa": self.max_kappa,
                "invariants": {k: {"base": b, "worst": w, "bound": bd} for k, (b, w, bd) in self.invariants.items()},
                "jumps": [{"output": o.name, "kappa": o.kappa, "why": o.jump} for o in self.jumps()],
                "outputs": [dataclasses.asdict(o) for o in self.outputs], "errors": self.errors}


#: solver work counters and timings: not outputs (an adaptive solver may take another step for a last-bit change;
#: `stats.events` counts the hand path's located event instants, re-trials included - the mode changes themselves
#: are the output `events.count`)
WORK_COUNTERS = ("stats.nfev", "stats.njev", "stats.nlu", "stats.steps", "stats.restarts", "stats.n_steps",
                 "stats.*.nfev", "stats.*.steps", "stats.*_s", "stats.us_per_step", "stats.events")


def headline(res: Any) -> dict[str, tuple[float, float]]:
    """The headline outputs of a `SimResult`: name -> (value, scale). Every finite number of its declared
    `statistics` and of its `stats` (nested keys
    joined by '.', lists by their length; solver work counters left out), scaled by the largest magnitude in its
    top-level group (an energy residual by the energies of its balance), and per signal its final, min and max,
    scaled by the largest magnitude among the signals of its unit."""
    out: dict[str, tuple[float, float]] = {}

    def walk(prefix: str, v: Any) -> None:
        if isinstance(v, bool) or any(fnmatch.fnmatchcase(prefix, p) for p in WORK_COUNTERS):
            return
        if isinstance(v, int | float | np.integer | np.floating):
            if math.isfinite(float(v)):
                out[prefix] = (float(v), abs(float(v)))
        elif isinstance(v, Mapping):
            for k, w in v.items():
                walk(f"{prefix}.{k}", w)
        elif isinstance(v, list | tuple):
            out[f"{prefix}.count"] = (float(len(v)), float(len(v)))

    walk("statistics", res.statistics)
    walk("stats", res.stats)
    groups: dict[str, float] = {}  # "statistics.<key>" / "stats.<key>" -> the largest magnitude under it
    for k, (x, _) in out.items():
        g = ".".join(k.split(".")[:2])
        groups[g] = max(groups.get(g, 0.0), abs(x))
    out = {k: (x, groups[".".join(k.split(".")[:2])]) for k, (x, _) in out.items()}
    out["events.count"] = (float(len(res.events)), float(len(res.events)))
    sig = {k: np.asarray(v, float) for k, v in res.signals.items()}
    sig = {k: a for k, a in sig.items() if a.size and np.all(np.isfinite(a))}
    unit_scale: dict[str, float] = {}  # a signal is measured against the run's signals of its unit (a held brake's
    for k, a in sig.items():           # speed of 1e-15 rad/s against the speeds of the run)
        u = res.units.get(k, "")
        unit_scale[u] = max(unit_scale.get(u, 0.0), float(np.max(np.abs(a))))
    for k, a in sig.items():
        scale = unit_scale[res.units.get(k, "")]
        for what, x in (("final", a[-1]), ("min", np.min(a)), ("max", np.max(a))):
            out[f"{k}.{what}"] = (float(x), max(abs(float(x)), scale))
    return out


def _declared(jumps: Mapping[str, str], name: str) -> str:
    for pat, why in jumps.items():
        if fnmatch.fnmatchcase(name, pat):
            return why
    return ""


def check_scene(scene: Any, *, eps: float = EPSILONS[0], draws: int = 3, seed: int = 0,
                jumps: Mapping[str, str] | None = None, base: Any = None) -> PerturbationReport:
    """Run `scene` and `draws` perturbed copies (seeds seed, seed+1, ...) and compare (rules (a) and (b) of the module
    docstring). `jumps`: the model's declared discontinuities (default: its suite module's `PERTURBATION_JUMPS`);
    `base`: the unperturbed `SimResult` if already computed."""

    if jumps is None:
        suite = get_model(scene.model).suite()
        jumps = getattr(suite, "PERTURBATION_JUMPS", {}) if suite is not None else {}
    rep = PerturbationReport(f"{scene.model}/{scene.name}", eps, draws)
    base = base if base is not None else run(scene)
    y0 = headline(base)
    inv = {f.name: (float(f.value), float(f.value), float(f.bound)) for f in base.health}
    worst: dict[str, float] = {k: 0.0 for k in y0}
    for i in range(draws):
        try:
            with perturbed(eps, seed + i):
                res = run(scene.replace())
        except Exception as e:  # noqa: BLE001 - a copy that fails is the finding, reported by name
            rep.errors.append(f"draw {seed + i}: {type(e).__name__}: {e}"[:300])
            continue
        for f in res.health:
            b, w, bd = inv.get(f.name, (math.nan, 0.0, float(f.bound)))
            inv[f.name] = (b, max(w, float(f.value)) if math.isfinite(f.value) else math.inf, bd)
        y = headline(res)
        for k, (v, _) in y0.items():
            if k not in y:
                rep.errors.append(f"draw {seed + i}: output {k} missing")
                continue
            worst[k] = max(worst[k], abs(y[k][0] - v))
    rep.invariants = inv
    rep.base = base
    for k, (v, scale) in y0.items():
        kappa = worst[k] / (eps * max(scale, 1e-300))
        rep.outputs.append(OutputSensitivity(k, v, worst[k], kappa,
                                             _declared(jumps, k) if kappa > KAPPA_MAX else ""))
    return rep


@dataclass
class Condition:
    """The condition estimate of a quantity derived from a run: its unperturbed value, the largest change over the
    copies and kappa = max |change| / (eps scale). A copy whose quantity changes shape (another count of
    engagements, a crossing that vanished) has kappa = inf: the quantity jumped."""
    value: np.ndarray
    max_change: float
    kappa: float
    eps: float
    draws: int


def condition(measure: Callable[[], Any], *, scale: float, eps: float = EPSILONS[0], draws: int = 2,
              seed: int = 0) -> Condition:
    """kappa of any quantity a test or study derives from runs: `measure()` (which loads, runs and reduces; a
    number or an array) is called unperturbed and inside `perturbed(eps, seed + i)` for i < draws, and its largest
    change is divided by eps x `scale` (scale: the quantity's own size or the resolution it is read to). The rule of
    `check_scene` (b) applied to what a test reads instead of a run's headline outputs."""
    if not (math.isfinite(scale) and scale > 0.0):
        raise ValueError(f"condition: scale must be a positive finite number, got {scale!r}")
    y0 = np.asarray(measure(), dtype=float)
    worst = 0.0
    for i in range(draws):
        with perturbed(eps, seed + i):
            y = np.asarray(measure(), dtype=float)
        if y.shape != y0.shape or not np.array_equal(np.isfinite(y), np.isfinite(y0)):
            worst = math.inf
            break
        fin = np.isfinite(y0)
        if fin.any():
            worst = max(worst, float(np.max(np.abs(y[fin] - y0[fin]))))
    return Condition(y0, worst, worst / (eps * scale), eps, draws)


#: what a perturbation of eps may move an asserted value of a hard case by, in the assertion's own unit: KAPPA_CASE eps
#: (its closed forms are computed from the unperturbed constants, so a copy is judged against bound + KAPPA_CASE eps)
KAPPA_CASE = 1e3


def check_case(case: Any, *, eps: float = EPSILONS[0], draws: int = 2, seed: int = 0,
               base: Any = None) -> PerturbationReport:
    """Run hard case `case` unperturbed and `draws` times inside `perturbed`. In every copy every assertion must hold:
    errors, conditions and `raises` exactly; a bound `value <= b` as `value <= b + KAPPA_CASE eps` (the case's closed
    forms use the unperturbed constants; the unperturbed run, when it is made inside an outer perturbation, as
    `value <= b + KAPPA_CASE perturbation.size()`). The asserted values are reported as invariants: name ->
    (unperturbed, worst copy, bound). `base`: the unperturbed `Outcome` if already computed (kept in the report's
    `base`)."""

    rep = PerturbationReport(case.name, eps, draws)
    allowance = KAPPA_CASE * eps
    outer = KAPPA_CASE * perturbation.size()  # the unperturbed run made inside a perturbation (the perturbed tests)
    for i in range(-1, draws):
        if i < 0:
            out = rep.base = base if base is not None else run_case(case)
        else:
            with perturbed(eps, seed + i):
                out = run_case(case)
        tag = "unperturbed" if i < 0 else f"draw {seed + i}"
        if out.error:
            rep.errors.append(f"{tag}: {out.error}"[:300])
        for c in out.checks:
            bound = float(c.bound[3:]) if isinstance(c.bound, str) and c.bound.startswith("<= ") else None
            numeric = isinstance(c.value, float | int) and not isinstance(c.value, bool) and bound is not None
            slack = allowance if i >= 0 else outer
            held = c.ok or (slack > 0 and numeric and math.isfinite(c.value) and c.value <= bound + slack)
            if not held:
                rep.errors.append(f"{tag}: {c.line()}"[:300])
            if numeric:
                b, w, _ = rep.invariants.get(c.what, (float(c.value), -math.inf, bound))
                rep.invariants[c.what] = (b, w if i < 0 else max(w, float(c.value)), bound + (allowance if i >= 0
                                                                                              else outer))
    return rep


#: columns of the perturbation table
COLUMNS = ["target", "eps", "draws", "invariant/bound", "max kappa", "jumps", "verdict"]


def report(reports: Sequence[PerturbationReport]) -> Any:
    """The reports as a CLI `Report`: one table row per target and eps, the declared jumps with their reasons."""

    rows = [r.row() for r in reports]
    table = format_table(COLUMNS, rows)
    why = {(o.name, o.jump) for r in reports for o in r.jumps() if o.jump}
    if why:
        table += "\njumps declared as discontinuities of the physics:\n" + "\n".join(
            f"- {n}: {w}" for n, w in sorted(why))
    n_ok = sum(r.ok for r in reports)
    table += (f"\n{n_ok}/{len(reports)} stable (invariant/bound: worst health figure or asserted value of any copy "
              f"over its bound; kappa = |change| / (eps x scale), bound {KAPPA_MAX:g})")
    return Report({"reports": [r.to_dict() for r in reports], "kappa_max": KAPPA_MAX,
                   "passed": n_ok, "total": len(reports)}, table)
