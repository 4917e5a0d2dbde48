"""The drives' suite declarations: their hard cases, their work-precision study and the random admissible inputs of the
random-input test (collected by `mbsuite.hardcases`, `mbsuite.analysis.workprecision` and the suite's tests through
`SPEC.cases`). Bounds are stated with the numbers measured when they were set."""

from __future__ import annotations

import math

import numpy as np

from ... import load_scene, run
from ...analysis.workprecision import Setting, Study, _rel
from ...engines.signals import Step
from ...errors import SceneError
from ...hardcases import Checker, HardCase
from ...paths import mjcf_path
from ...scenes import Scene
from . import coupled_clutches as cc
from .friction import Friction, Part, RotorSystem, Source, Spring, simulate_reference
from .mujoco_path import MujocoRotorSim


# ================================================================================================ hard cases
def _drives_coupled_clutches(ck: Checker) -> None:
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
    return RotorSystem(names=["motor", "spring", "load"], J=np.asarray(J, float), B=np.zeros(3),
                       frictions=list(frictions), springs=list(springs), sources=list(sources), breaks=list(breaks))


def _drives_load_reversal(ck: Checker) -> None:
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
    brake = Step(height=1.0, t0=0.3)  # the brake engages at 0.3 s (a signal: the MuJoCo path evaluates it in C)
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
    sc = load_scene("drives/step_up_pwm").replace(solver={"engine": "mujoco", "duration": 0.2, "t_settle": 0.0})
    ck.raises("a timestep that does not divide the controller period", lambda: run(sc.replace(
        solver={"timestep": 3e-4})), SceneError, "must divide")
    res = run(sc.replace(solver={"timestep": 2e-3}))
    ck.finite("h = controller period (2 ms)", *res.signals.values())
    ck.le("h = 2 ms: energy balance residual / input", abs(res.stats["energy_balance"]["relative"]), 1e-3)


def _drives_energy_balance(ck: Checker) -> None:
    for scene in ("step_up_pwm", "susd_500w_open"):
        for eng in ("reference", "mujoco"):
            res = run(load_scene(f"drives/{scene}").replace(solver={"engine": eng, "duration": 0.5, "t_settle": 0.0}))
            ck.finite(f"{scene} {eng}", *res.signals.values())
            # README: <= 4e-5 of the input (hand path), <= 2e-7 (MuJoCo) over the shipped scenes
            ck.le(f"{scene} {eng}: |input - output - losses - stored| / input", abs(
                res.stats["energy_balance"]["relative"]), 1e-4)


def _drives_freewheel_grazing(ck: Checker) -> None:
    from . import msl

    ex = msl.example("msl_one_way_clutch")
    t_graze = 1.5 - math.asin(3e-5) / (6 * math.pi)  # closed form: 8/3 - t_release (tests/drives/test_msl.py)
    hand = simulate_reference(ex.system, ex.q0, ex.w0, ex.t_end, sample_dt=1e-3)
    mj = MujocoRotorSim(ex.system, mjcf_path("drive_msl_one_way_clutch"), timestep=1e-4).run(
        ex.q0, ex.w0, ex.t_end, sample_dt=1e-3)
    for name, res, tol in (("hand path", hand, 1e-8), ("MuJoCo", mj, 2e-4)):
        locks = [e["t"] for e in res.events if e["to"] == "stuck" and abs(e["t"] - 1.5) < 1e-3]
        ck.true(f"{name}: one lock at the tangency near 1.5 s", len(locks) == 1, locks)
        ck.le(f"{name}: |t_lock - closed form| (s)", abs(locks[0] - t_graze) if locks else math.inf, tol)
        ck.true(f"{name}: 9 mode changes (as the reference)", len(res.events) == 9, len(res.events))
        ck.finite(f"{name} speeds", res.w)


def _drives_planetary_handover(ck: Checker) -> None:
    from . import msl

    ex = msl.example("msl_simple_gear_shift")
    hand = simulate_reference(ex.system, ex.q0, ex.w0, ex.t_end, sample_dt=1e-3)
    mj = MujocoRotorSim(ex.system, mjcf_path("drive_msl_simple_gear_shift"), timestep=1e-4).run(
        ex.q0, ex.w0, ex.t_end, sample_dt=1e-3)
    for name, res in (("hand path", hand), ("MuJoCo", mj)):
        seq = [(e["element"], e["to"]) for e in res.events]
        ck.true(f"{name}: clutch engages, brake slips, brake free, clutch locks", seq == [
            ("clutch", "backward"), ("brake", "forward"), ("brake", "free"), ("clutch", "stuck")], seq)
        ck.le(f"{name}: final |w_engine - w_load| / w_load (rigid 1:1 after the shift)",
              abs(res.w[0, -1] - res.w[1, -1]) / abs(res.w[1, -1]), 1e-6)
    ck.le("MuJoCo vs hand: max event time difference (s)",
          max(abs(a["t"] - b["t"]) for a, b in zip(hand.events, mj.events, strict=True)), 1e-4 + 1e-12)


HARD_CASES: tuple[HardCase, ...] = (
    HardCase("drives_freewheel_grazing_lock", "drives",
             "a freewheel whose slip touches zero tangentially (the input torque reverses as the speeds meet)",
             "drives/msl_one_way_clutch at 1.5 s, both paths",
             "one lock, at the closed-form time within 1e-8 s (hand) / 2e-4 s (MuJoCo); 9 mode changes",
             _drives_freewheel_grazing),
    HardCase("drives_planetary_handover", "drives",
             "clutch/brake hand-over across an ideal planetary with a massless ring (general elements, tendon locks)",
             "drives/msl_simple_gear_shift, 5 s, both paths",
             "the MSL sequence (clutch bwd, brake fwd, brake free, clutch stuck); 1:1 after the shift; paths "
             "within one MuJoCo step (1e-4 s; the engagement at 2.0+ s lands on the next step: measured exactly one)",
             _drives_planetary_handover),
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
)


# ================================================================================================ work-precision
class DrivesStudy(Study):
    """The hand path (event-exact DOP853) x rtol and MuJoCo (rk4, euler) x timestep; reference: the hand path at rtol
    1e-12 (checked against rtol 1e-11; the hand path has one integrator, so the MuJoCo rows are the different-method
    comparison). State error: max |w - w_ref| / max |w_ref| over the rotors. Physics metric: relative errors of the
    cycle-mean load speed and of the efficiency E_out/E_in over [t_settle, T], and the lock-up time error (max over
    matched stick events) over the energy-cycle period (CoupledClutches: over 0.1 s)."""

    HAND_RTOLS = (1e-4, 1e-6, 1e-8, 1e-10)
    MJ_INTEGRATORS = ("rk4", "euler")
    MJ_STEPS = (1e-4, 5e-5, 2e-5)
    state_doc = "max_t |w_i - w_i,ref| / max_t,i |w_ref| over the rotor speeds, on the output grid"
    physics_doc = ("max(rel. error of cycle-mean load speed and of efficiency E_out/E_in over [t_settle, T]; max "
                   "lock-up time error / energy-cycle period (CoupledClutches: / 0.1 s))")

    def __init__(self, scene: Scene, quick: bool = False, duration: float | None = None):
        super().__init__(scene, quick)
        from . import msl

        mech = scene.effects["mechanism"]
        is_cc = mech == "coupled_clutches" or mech in msl.EXAMPLES  # no controller: lock times over 0.1 s
        self.cc = is_cc
        T = min(scene.solver.duration, duration or (1.0 if quick else 2.0))
        ts = 0.0 if is_cc else T / 2
        if mech in msl.EXAMPLES:
            ex = msl.example(mech)
            self.speeds = [k for k in ex.signals if ex.units[k] == "rad/s"]
        else:
            self.speeds = ["w1", "w2", "w3", "w4"] if is_cc else ["w_motor", "w_spring", "w_load"]
        # the study measures the error of loose settings: a health figure past its bound is kept, not refused
        self.base = scene.replace(solver={"duration": T, "t_settle": ts, "allow_inaccurate": True},
                                  outputs=[*self.speeds, "E_in", "E_out"])
        self.ts = ts

    def settings(self) -> list[Setting]:
        out = []
        for r in ((1e-6,) if self.quick else self.HAND_RTOLS):
            sc = self.base.replace(solver={"engine": "reference", "rtol": r, "atol": r * 1e-2})
            out.append(Setting("reference", "event-exact DOP853", r, lambda sc=sc: run(sc)))
        integ = ("rk4",) if self.quick else self.MJ_INTEGRATORS
        for i in integ:
            for h in ((1e-4,) if self.quick else self.MJ_STEPS):
                sc = self.base.replace(solver={"engine": "mujoco", "integrator": i, "timestep": h})
                out.append(Setting("mujoco", i, h, lambda sc=sc: run(sc)))
        return out

    def reference(self):
        ref = run(self.base.replace(solver={"engine": "reference", "rtol": 1e-12, "atol": 1e-14}))
        chk = run(self.base.replace(solver={"engine": "reference", "rtol": 1e-11, "atol": 1e-13}))
        err, _ = self.physics_error(chk, ref)
        return ref, {"reference": "hand path (event-exact DOP853) rtol 1e-12, atol 1e-14",
                     "check": "hand path rtol 1e-11", "check_state_error": self.state_error(chk, ref),
                     "check_physics_error": err}

    def state_error(self, res, ref) -> float:
        scale = max(float(np.max(np.abs(ref[s]))) for s in self.speeds) or 1.0
        return max(float(np.max(np.abs(np.interp(ref.t, res.t, res[s]) - ref[s]))) for s in self.speeds) / scale

    def _locks(self, res) -> list[tuple[str, float]]:
        return [(e.get("element", "?"), float(e["t"])) for e in res.events
                if e.get("to") == "stuck" and e.get("t") is not None and e["t"] >= self.ts]

    def physics_error(self, res, ref):
        det = {}
        period = 0.1
        if not self.cc:
            cr, cf = res.stats.get("cycles", {}), ref.stats.get("cycles", {})
            if abs(cf.get("mean_load_speed", 0.0)) > 0:
                det["load_speed_rel"] = _rel(cr.get("mean_load_speed", math.nan), cf["mean_load_speed"])
            if cf.get("switching_rate"):
                period = 1.0 / cf["switching_rate"]

            def eff(r):
                m = r.t >= self.ts
                ein = r["E_in"][m][-1] - r["E_in"][m][0]
                return (r["E_out"][m][-1] - r["E_out"][m][0]) / ein if ein else math.nan

            det["efficiency_rel"] = _rel(eff(res), eff(ref))
        lr, lf = self._locks(res), self._locks(ref)
        by_el: dict[str, tuple[list, list]] = {}
        for el, t in lf:
            by_el.setdefault(el, ([], []))[1].append(t)
        for el, t in lr:
            by_el.setdefault(el, ([], []))[0].append(t)
        errs = []
        for a, b in by_el.values():
            k = min(len(a), len(b))
            errs += [abs(x - y) for x, y in zip(a[:k], b[:k], strict=True)]
            if len(a) != len(b):
                errs.append(period)  # a missing or extra lock-up counts as a whole period
        if lf:
            det["lock_time_rel"] = (max(errs) if errs else 0.0) / period
        det["n_locks_ref"] = len(lf)
        vals = [v for k, v in det.items() if k != "n_locks_ref"]
        # nothing to compare (no lock-up and no load speed in the window) is no accuracy: NaN, not 0
        return (max(vals) if vals else math.nan), det


def workprecision_study(scene: Scene, quick: bool = False) -> Study:
    return DrivesStudy(scene, quick=quick)


# ================================================================================================ random inputs
def random_input(scene: Scene, rng: np.random.Generator) -> dict:
    """Admissible random changes of a drives scene's input: the speed reference (a constant or every point of a
    profile) scaled by 0.5-1."""
    inp = dict(scene.input)
    if "value" in inp:
        inp["value"] = float(inp["value"]) * rng.uniform(0.5, 1.0)
    if "profile" in inp:
        s = rng.uniform(0.5, 1.0)
        inp["profile"] = [[t, r * s] for t, r in inp["profile"]]
    return {"input": inp}
