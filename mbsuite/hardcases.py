"""The hard-case harness: situations that break naive multibody codes, each with the scene that provokes it and what
must hold (no NaN/inf, bounded work in steps or RHS calls, bounded closure residual, bounded energy drift, correct
detection and reporting).

Each model declares its own cases (`HARD_CASES` in the module named by its `ModelSpec.cases`); this module names no
model: it holds the `HardCase`/`Checker` machinery, collects the registry from the models and runs cases.
`mbsuite hardcases` lists the registry; `mbsuite hardcases --run` runs it and prints what was measured against each
bound; `tests/suite/test_hardcases.py` runs every entry (entries marked slow only under `pytest -m slow`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import MbsuiteError, ParameterError, SceneError


@dataclass
class Check:
    what: str
    ok: bool
    value: Any = None
    bound: Any = None

    def line(self) -> str:
        v = "" if self.value is None else f" = {_fmt(self.value)}"
        b = "" if self.bound is None else f" (bound {_fmt(self.bound)})"
        return f"[{'ok' if self.ok else 'FAIL'}] {self.what}{v}{b}"


def _fmt(x: Any) -> str:
    if isinstance(x, float | np.floating):
        return f"{float(x):.4g}"
    return str(x)


class Checker:
    """Collects the assertions of one hard case (all are evaluated; the case fails if any fails)."""

    def __init__(self) -> None:
        self.checks: list[Check] = []
        self.measured: dict[str, Any] = {}

    def le(self, what: str, value: float, bound: float) -> None:
        value = float(value)
        self.checks.append(Check(what, bool(math.isfinite(value) and value <= bound), value, f"<= {bound:g}"))

    def ge(self, what: str, value: float, bound: float) -> None:
        value = float(value)
        self.checks.append(Check(what, bool(math.isfinite(value) and value >= bound), value, f">= {bound:g}"))

    def true(self, what: str, cond: bool, value: Any = None) -> None:
        self.checks.append(Check(what, bool(cond), value))

    def finite(self, what: str, *arrays: Any) -> None:
        ok = all(np.all(np.isfinite(np.asarray(a, float))) for a in arrays)
        self.checks.append(Check(f"{what}: no NaN/inf", ok))

    def raises(self, what: str, fn: Callable[[], Any], exc: type[BaseException] | tuple, match: str) -> None:
        try:
            fn()
        except exc as e:  # noqa: B030 - exc is a class or tuple of classes
            self.checks.append(Check(what, match.lower() in str(e).lower(), f"{type(e).__name__}: {str(e)[:90]}"))
            return
        except Exception as e:  # noqa: BLE001 - a different error is a failed check, reported
            self.checks.append(Check(what, False, f"unexpected {type(e).__name__}: {str(e)[:90]}"))
            return
        self.checks.append(Check(what, False, "no error raised"))


@dataclass(frozen=True)
class HardCase:
    name: str
    model: str
    hard: str  # what makes it hard
    scene: str  # the scene (or machinery) that provokes it
    asserts: str  # what is asserted, in words
    check: Callable[[Checker], None] = field(repr=False, compare=False)
    slow: bool = False
    known: str = ""  # a limitation found by this case and left to the model's owner
    expected_failure: str = ""  # non-empty: the case fails today for this reason (tests: strict xfail)


@dataclass
class Outcome:
    case: HardCase
    checks: list[Check]
    measured: dict[str, Any]
    error: str | None = None

    @property
    def passed(self) -> bool:
        return self.error is None and bool(self.checks) and all(c.ok for c in self.checks)

    def text(self) -> str:
        lines = [f"{self.case.name}: {'PASS' if self.passed else 'FAIL'}"]
        if self.error:
            lines.append(f"  error: {self.error}")
        lines += ["  " + c.line() for c in self.checks]
        return "\n".join(lines)


def run_case(case: HardCase) -> Outcome:
    ck = Checker()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            case.check(ck)
    except Exception as e:  # noqa: BLE001 - an unexpected error is a failed hard case, reported with its message
        return Outcome(case, ck.checks, ck.measured, f"{type(e).__name__}: {e}")
    return Outcome(case, ck.checks, ck.measured)


def registry() -> tuple[HardCase, ...]:
    """Every model's hard cases (`HARD_CASES` of the module named by its `ModelSpec.cases`), in model order."""
    from .registry import models

    out: list[HardCase] = []
    for name, spec in sorted(models().items()):
        suite = spec.suite()
        for c in getattr(suite, "HARD_CASES", ()):
            if c.model != name:
                raise MbsuiteError(f"hard case {c.name!r} is declared by model {name!r} but names model {c.model!r}")
            out.append(c)
    names = [c.name for c in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise MbsuiteError(f"hard case names must be unique; repeated: {dup}")
    return tuple(out)


def cases(model: str | None = None, include_slow: bool = True) -> list[HardCase]:
    out = [c for c in registry() if (model is None or c.model == model) and (include_slow or not c.slow)]
    if model is not None and not out:
        raise MbsuiteError(f"no hard cases for model {model!r}; models: {sorted({c.model for c in registry()})}")
    return out


def get(name: str) -> HardCase:
    for c in registry():
        if c.name == name:
            return c
    raise MbsuiteError(f"unknown hard case {name!r}; valid: {[c.name for c in registry()]}")


# ---- TRANSITIONAL: the coupler, drives and catenary cases below move to their models' cases modules ----
# ================================================================================================ drives
def _drives_coupled_clutches(ck: Checker) -> None:
    from .models.drives import coupled_clutches as cc
    from .models.drives.friction import simulate_reference
    from .models.drives.mujoco_path import MujocoRotorSim
    from .paths import mjcf_path

    rev = cc.reference_events(cc.load_reference())
    hand = simulate_reference(cc.build_system(), cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)
    mj = MujocoRotorSim(cc.build_system(), mjcf_path("coupled_clutches"), timestep=1e-4).run(
        cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)
    for name, res, tol in (("hand path", hand, 1e-5), ("MuJoCo", mj, 2e-4)):
        rows = cc.match_events(cc.events_as_codes(res.events), rev)
        same = all(r["t"] is not None and r["t_ref"] is not None for r in rows)
        ck.true(f"{name}: same clutch mode sequence as Dymola (lock/unlock x {len(rows)})", same)
        dts = [abs(r["t"] - r["t_ref"]) for r in rows if r["t"] is not None and r["t_ref"] is not None]
        ck.le(f"{name}: max |event time - Dymola| (s)", max(dts) if dts else math.inf, tol)
        ck.finite(f"{name} speeds", res.w)
    ck.le("hand path RHS calls", hand.stats.get("nfev", 0), 50_000)


def _rotors(frictions, J, springs=(), sources=(), breaks=()):
    from .models.drives.friction import RotorSystem

    return RotorSystem(names=["motor", "spring", "load"], J=np.asarray(J, float), B=np.zeros(3),
                       frictions=list(frictions), springs=list(springs), sources=list(sources), breaks=list(breaks))


def _drives_load_reversal(ck: Checker) -> None:
    from .models.drives.friction import Friction, Part, Spring, simulate_reference
    from .models.drives.mujoco_path import MujocoRotorSim
    from .paths import mjcf_path

    sys_ = _rotors([Friction("load_ground", 2, -1, [Part("load", 0.05, output=True)])], [1.0, 1.0, 1e-3],
                   springs=[Spring("k", 2, -1, 1.0)])
    res = simulate_reference(sys_, [0, 0, 1.0], [0, 0, 0], 2.0, sample_dt=1e-3)
    kinds = [(e["from"], e["to"]) for e in res.events]
    n_rev = sum(1 for k in kinds if "stuck" not in k)
    ck.true("hand path: ends stuck", bool(kinds) and kinds[-1][1] == "stuck")
    ck.true("hand path: 9 reversals (amplitude 1.0 -> C/K in steps of 2C/K), no chatter", n_rev == 9, n_rev)
    ck.le("hand path RHS calls", res.stats["nfev"], 20_000)
    mj = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=1e-4).run([0, 0, 1.0], [0, 0, 0], 2.0,
                                                                                  sample_dt=1e-3)
    n_mj = sum(1 for e in mj.events if "stuck" not in (e["from"], e["to"]))
    ck.le("MuJoCo reversals vs hand path", abs(n_mj - n_rev), 1)
    ck.le("MuJoCo final |theta| within the stiction band C/K (+1e-3)", abs(mj.q[2, -1]), 0.05 + 1e-3)
    ck.true("MuJoCo warnings", mj.stats.get("warnings", {}) == {}, mj.stats.get("warnings"))


def _drives_both_locked(ck: Checker) -> None:
    from .models.drives.friction import Friction, Part, simulate_reference
    from .models.drives.mujoco_path import MujocoRotorSim
    from .paths import mjcf_path

    def brake(t: float) -> float:
        return 1.0 if t >= 0.3 else 0.0

    sys_ = _rotors([Friction("clutch_a", 0, 1, [Part("ca", 0.5)]), Friction("clutch_b", 1, 2, [Part("cb", 0.5)]),
                    Friction("spring_ground", 1, -1, [Part("brake", 0.3, schedule=brake)])], [1e-3, 2e-3, 3e-3],
                   breaks=[0.3])
    w0 = [30.0, 10.0, 0.0]
    res = simulate_reference(sys_, [0, 0, 0], w0, 1.0, sample_dt=1e-3)
    mj = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=1e-4).run([0, 0, 0], w0, 1.0,
                                                                                  sample_dt=1e-3)
    stuck = [e["t"] for e in res.events if e["to"] == "stuck" and e["element"] in ("clutch_a", "clutch_b")]
    ck.ge("both clutches lock (hand path)", len(stuck), 2)
    ck.true("hand path: all three rotors held at the end", res.modes[:, -1].tolist() == [0, 0, 0])
    ck.true("MuJoCo: all three rotors held at the end", mj.modes[:, -1].tolist() == [0, 0, 0])
    ck.le("MuJoCo final speeds (rad/s)", np.max(np.abs(mj.w[:, -1])), 1e-6)
    dt = []
    for el in ("clutch_a", "clutch_b", "spring_ground"):
        tr = [e["t"] for e in res.events if e["element"] == el]
        tm = [e["t"] for e in mj.events if e["element"] == el]
        ck.true(f"{el}: same number of events in both paths", len(tr) == len(tm), (len(tr), len(tm)))
        if len(tr) == len(tm):
            dt += [abs(a - b) for a, b in zip(tr, tm, strict=True)]
    ck.le("max |event time MuJoCo - hand| (s)", max(dt) if dt else math.inf, 1e-4)


def _drives_mismatch(ck: Checker) -> None:
    from .models.drives.friction import Friction, Part, Source, simulate_reference
    from .models.drives.mujoco_path import MujocoRotorSim
    from .paths import mjcf_path

    J1, J2, dw = 2e-3, 5e-4, 50.0
    sys_ = _rotors([Friction("clutch_a", 0, 1, [Part("ca", 0.5)])], [J1, J2, 1.0], sources=[Source("motor", 0, 0.0)])
    expected = 0.5 * J1 * J2 / (J1 + J2) * dw**2
    for name, res in (("hand path", simulate_reference(sys_, [0, 0, 0], [dw, 0, 0], 0.2, sample_dt=1e-3)),
                      ("MuJoCo", MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=1e-5).run(
                          [0, 0, 0], [dw, 0, 0], 0.2, sample_dt=1e-3))):
        lost = res.energy["ca"][-1] + res.stats["reset_energy"]
        ck.le(f"{name}: slip loss vs 1/2 J1 J2/(J1+J2) dw^2, relative", abs(lost / expected - 1), 0.01)
        ck.le(f"{name}: common speed vs momentum, relative",
              float(np.max(np.abs(res.w[:2, -1] / (J1 * dw / (J1 + J2)) - 1))), 1e-4)
        ck.true(f"{name}: one lock event", [e["to"] for e in res.events] == ["stuck"])


def _drives_big_step(ck: Checker) -> None:
    from . import load_scene, run

    sc = load_scene("drives/step_up_pwm").replace(solver={"engine": "mujoco", "duration": 0.2, "t_settle": 0.0})
    ck.raises("a timestep that does not divide the controller period", lambda: run(sc.replace(
        solver={"timestep": 3e-4})), SceneError, "must divide")
    res = run(sc.replace(solver={"timestep": 2e-3}))
    ck.finite("h = controller period (2 ms)", *res.signals.values())
    ck.le("h = 2 ms: energy balance residual / input", abs(res.stats["energy_balance"]["relative"]), 1e-3)


def _drives_energy_balance(ck: Checker) -> None:
    from . import load_scene, run

    for scene in ("step_up_pwm", "susd_500w_open"):
        for eng in ("reference", "mujoco"):
            res = run(load_scene(f"drives/{scene}").replace(solver={"engine": eng, "duration": 0.5, "t_settle": 0.0}))
            ck.finite(f"{scene} {eng}", *res.signals.values())
            # README: <= 4e-5 of the input (hand path), <= 2e-7 (MuJoCo) over the shipped scenes
            ck.le(f"{scene} {eng}: |input - output - losses - stored| / input", abs(
                res.stats["energy_balance"]["relative"]), 1e-4)


# ================================================================================================ catenary
def _catenary_critical_speed(ck: Checker) -> None:
    from .models.catenary.analysis import CriticalSpeedWarning, speed_regime
    from .models.catenary.params import CatenaryParams

    p = CatenaryParams()
    c = p.cw_wave_speed
    ck.raises("speed at the wave speed sqrt(T/rho)", lambda: speed_regime(p, c), ParameterError, "wave speed")
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        info = speed_regime(p, 0.95 * c)
    ck.true("95 % of c: CriticalSpeedWarning, regime near-critical",
            any(issubclass(x.category, CriticalSpeedWarning) for x in w) and info["regime"] == "near-critical")
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        info = speed_regime(p, 0.5 * c)
    ck.true("50 % of c: no warning, subcritical", not w and info["regime"] == "subcritical")



_TRANSITIONAL_ENTRIES = (
    HardCase("drives_clutch_lock_unlock", "drives",
             "clutch stick/slip with nested mode changes (Modelica CoupledClutches)",
             "drives/coupled_clutches machinery, both paths vs the Dymola result",
             "same mode sequence; event times within 1e-5 s (hand) / 2e-4 s (MuJoCo); hand RHS calls <= 5e4",
             _drives_coupled_clutches),
    HardCase("drives_load_reversal", "drives",
             "Coulomb load on a spring reversing direction: chatter or stall at every reversal",
             "rotor system: load with 0.05 N m Coulomb friction on a 1 N m/rad spring, 2 s",
             "9 reversals then stuck; hand RHS calls <= 2e4; MuJoCo reversals within 1, ends inside the stiction band",
             _drives_load_reversal),
    HardCase("drives_both_clutches_locked", "drives",
             "both clutches locked (one rigid group) then a brake holds the group: nested locks",
             "three rotors, clutches a/b, brake at 0.3 s, both paths",
             "all rotors held; same events in both paths within 1e-4 s; MuJoCo speeds <= 1e-6 rad/s",
             _drives_both_locked),
    HardCase("drives_engagement_mismatch", "drives",
             "engagement with a 50 rad/s speed mismatch: plastic lock, energy bookkeeping",
             "two free inertias and a clutch, both paths",
             "slip loss = 1/2 J1 J2/(J1+J2) dw^2 within 1 %; common speed within 1e-4; one lock event",
             _drives_mismatch),
    HardCase("drives_over_large_timestep", "drives",
             "MuJoCo step not aligned with the controller, or as long as the controller period",
             "drives/step_up_pwm on MuJoCo at 0.3 ms and 2 ms",
             "SceneError 'must divide' for 0.3 ms; 2 ms finite with energy balance <= 1e-3", _drives_big_step),
    HardCase("drives_energy_balance", "drives",
             "energy bookkeeping through locks, slips and controller switching",
             "drives/step_up_pwm and drives/susd_500w_open, 0.5 s, both paths",
             "|input - output - losses - stored| <= 1e-4 of the input; no NaN", _drives_energy_balance),
    HardCase("catenary_critical_speed", "catenary",
             "train speed approaching the contact wire's wave speed: no steady solution",
             "catenary speed regime at 50 %, 95 %, 100 % of sqrt(T/rho)",
             "ParameterError at c; CriticalSpeedWarning near c; nothing at 50 %", _catenary_critical_speed),

)
