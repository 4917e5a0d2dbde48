"""The rotational model's suite declarations: its hard cases, its work-precision study and the random admissible inputs
of the random-input test (collected by `mbsuite.hardcases`, `mbsuite.analysis.workprecision` and the suite's tests
through `SPEC.cases`). Bounds are stated with the numbers measured when they were set."""

from __future__ import annotations

import math

import numpy as np

from ...analysis.workprecision import LadderStudy, Study
from ...components.rotational.event_exact import simulate_reference
from ...components.rotational.locks import lock_time_error, lock_ups
from ...components.rotational.mujoco_sim import MujocoRotorSim
from ...hardcases import Checker, HardCase
from ...paths import mjcf_path
from ...scenes import Scene
from . import coupled_clutches as cc
from . import examples


# ================================================================================================ hard cases
# Each case is the one source of truth for its situation (the model tests do not re-test it). Bounds carry the value
# measured when they were set (hand path DOP853 at the default rtol, MuJoCo RK4) and the factor above it.
def _coupled_clutches(ck: Checker) -> None:
    ref = cc.load_reference()
    rev = cc.reference_events(ref)
    hand = simulate_reference(cc.build_system(), cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)
    mj = MujocoRotorSim(cc.build_system(), mjcf_path("coupled_clutches"), timestep=1e-4).run(
        cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)
    # vs Dymola: hand 1e-5 s (measured 4.1e-6; the reference's own event accuracy at DASSL tol 1e-6 is a few us);
    # MuJoCo within one timestep, 1e-4 s (measured 4.7e-5; the path resolves an event only to its step)
    for name, res, tol in (("hand path", hand, 1e-5), ("MuJoCo", mj, 1e-4)):
        rows = cc.match_events(cc.events_as_codes(res.events), rev)
        same = all(r["t"] is not None and r["t_ref"] is not None for r in rows)
        ck.true(f"{name}: same clutch mode sequence as Dymola (lock/unlock x {len(rows)})", same and len(rows) == 9)
        dts = [abs(r["t"] - r["t_ref"]) for r in rows if r["t"] is not None and r["t_ref"] is not None]
        ck.le(f"{name}: max |event time - Dymola| (s)", max(dts) if dts else math.inf, tol)
        ck.finite(f"{name} speeds", res.w)
    # MuJoCo vs the event-exact hand path: interpolated event time within one step (measured 4.7e-5 s), the step at
    # which the change is applied within two (measured 1.5e-4 s)
    same = [(a["element"], a["from"], a["to"]) for a in mj.events] == [(b["element"], b["from"], b["to"])
                                                                       for b in hand.events]
    ck.true("MuJoCo: same events as the hand path", same)
    if same:
        ck.le("MuJoCo vs hand: max |t_event| (s)", max(abs(a["t"] - b["t"]) for a, b in zip(mj.events, hand.events,
                                                                                             strict=True)), 1e-4)
        ck.le("MuJoCo vs hand: max |t_applied - t_event| (s)",
              max(abs(a["t_step"] - b["t"]) for a, b in zip(mj.events, hand.events, strict=True)), 2e-4)
    # speeds every 0.1 s: hand vs Dymola 1e-4 rad/s (measured 6.0e-5, the reference's accuracy); MuJoCo vs hand
    # 2e-4 rad/s (measured 4.6e-5, 4x)
    grid = np.round(np.arange(0, cc.T_END + 1e-9, 0.1), 10)
    j = [int(np.nonzero(np.isclose(ref["t"], tt))[0][-1]) for tt in grid]
    i = [int(np.argmin(np.abs(hand.t - tt))) for tt in grid]
    ck.le("hand vs Dymola: max |w| on the 0.1 s grid (rad/s)", np.max(np.abs(hand.w[:, i] - ref["w"][:, j])), 1e-4)
    ck.le("MuJoCo vs hand: max |w| on the 0.1 s grid (rad/s)", np.max(np.abs(mj.w[:, i] - hand.w[:, i])), 2e-4)
    ck.true("MuJoCo warnings", not mj.stats["warnings"], mj.stats["warnings"])
    ck.le("hand path RHS calls (measured 2664)", hand.stats.get("nfev", 0), 10_000)



def _freewheel_grazing(ck: Checker) -> None:
    """The OneWayClutch released at t_r = 7/6 + asin(3e-5)/(6 pi) (holding torque 5 sin(6 pi (t - 7/6)) reaching
    tau0_max_low = 1.5e-4) closes again tangentially at 8/3 - t_r and is released at 1.5 + asin(3e-5)/(6 pi)."""
    s = math.asin(3e-5) / (6 * math.pi)
    closed = {"release": 7 / 6 + s, "lock": 1.5 - s, "release2": 1.5 + s}
    ex = examples.example("msl_one_way_clutch")
    hand = simulate_reference(ex.system, ex.q0, ex.w0, ex.t_end, sample_dt=1e-3)
    mj = MujocoRotorSim(ex.system, mjcf_path("drive_msl_one_way_clutch"), timestep=1e-4).run(
        ex.q0, ex.w0, ex.t_end, sample_dt=1e-3)
    # hand path 1e-9 s (measured 1.1e-10 at the default rtol, 2e-12 at rtol 1e-10); MuJoCo 2 steps, 2e-4 s
    # (measured 1.24e-4: the release is applied up to 1.5 steps late and t_lock = 8/3 - t_release carries it over)
    for name, res, tol in (("hand path", hand, 1e-9), ("MuJoCo", mj, 2e-4)):
        got = {"release": [e["t"] for e in res.events if e["to"] == "forward" and abs(e["t"] - 7 / 6) < 1e-3],
               "lock": [e["t"] for e in res.events if e["to"] == "stuck" and abs(e["t"] - 1.5) < 1e-3],
               "release2": [e["t"] for e in res.events if e["to"] == "forward" and abs(e["t"] - 1.5) < 1e-3]}
        ck.true(f"{name}: one release near 7/6 s, one lock and one release at the tangency near 1.5 s",
                all(len(v) == 1 for v in got.values()), got)
        ck.le(f"{name}: max |t - closed form| of those three (s)",
              max((abs(v[0] - closed[k]) for k, v in got.items() if v), default=math.inf), tol)
        ck.true(f"{name}: 9 mode changes (as the reference)", len(res.events) == 9, len(res.events))
        ck.finite(f"{name} speeds", res.w)


def _planetary_handover(ck: Checker) -> None:
    ex = examples.example("msl_simple_gear_shift")
    hand = simulate_reference(ex.system, ex.q0, ex.w0, ex.t_end, sample_dt=1e-3)
    mj = MujocoRotorSim(ex.system, mjcf_path("drive_msl_simple_gear_shift"), timestep=1e-4).run(
        ex.q0, ex.w0, ex.t_end, sample_dt=1e-3)
    for name, res in (("hand path", hand), ("MuJoCo", mj)):
        seq = [(e["element"], e["to"]) for e in res.events]
        ck.true(f"{name}: clutch engages, brake slips, brake free, clutch locks", seq == [
            ("clutch", "backward"), ("brake", "forward"), ("brake", "free"), ("clutch", "stuck")], seq)
        # rigid 1:1 after the clutch lock: measured 8.8e-16 (hand), 7.2e-13 (MuJoCo, the soft lock's residual)
        ck.le(f"{name}: final |w_engine - w_load| / w_load (rigid 1:1 after the shift)",
              abs(res.w[0, -1] - res.w[1, -1]) / abs(res.w[1, -1]), 1e-10)
    same = len(hand.events) == len(mj.events)
    ck.le("MuJoCo vs hand: max event time difference (s)",
          max(abs(a["t"] - b["t"]) for a, b in zip(hand.events, mj.events, strict=True)) if same else math.inf,
          1e-4 + 1e-12)


HARD_CASES: tuple[HardCase, ...] = (
    HardCase("rotational_freewheel_grazing_lock", "rotational",
             "a freewheel whose slip touches zero tangentially (the input torque reverses as the speeds meet)",
             "rotational/msl_one_way_clutch at 1.5 s, both paths",
             "the release near 7/6 s and the lock and release at the tangency at their closed-form "
             "times within 1e-9 s (hand) / 2e-4 s (MuJoCo); 9 mode changes",
             _freewheel_grazing),
    HardCase("rotational_planetary_handover", "rotational",
             "clutch/brake hand-over across an ideal planetary with a massless ring (general elements, tendon locks)",
             "rotational/msl_simple_gear_shift, 5 s, both paths",
             "the MSL sequence (clutch bwd, brake fwd, brake free, clutch stuck); 1:1 after the shift within "
             "1e-10; paths within one MuJoCo step (1e-4 s; the engagement at 2.0+ s lands on the next step: measured "
             "exactly one)",
             _planetary_handover),
    HardCase("rotational_clutch_lock_unlock", "rotational",
             "clutch stick/slip with nested mode changes (Modelica CoupledClutches)",
             "rotational/coupled_clutches machinery, both paths vs the Dymola result",
             "same mode sequence; event times vs Dymola within 1e-5 s (hand) / 1e-4 s (MuJoCo), MuJoCo vs hand 1e-4 s; "
             "speeds every 0.1 s within 1e-4 (hand vs Dymola) / 2e-4 rad/s (MuJoCo vs hand); hand RHS calls <= 1e4",
             _coupled_clutches),
)


# ================================================================================================ work-precision
class RotationalStudy(LadderStudy):
    """The hand path (event-exact DOP853) x rtol and MuJoCo (rk4, euler) x timestep; reference: the hand path at rtol
    1e-12 (checked against rtol 1e-11; the hand path has one integrator, so the MuJoCo rows are the different-method
    comparison). State error: max |w - w_ref| / max |w_ref| over the rotors. Physics metric: the lock-up time error
    (max over matched stick events) over 0.1 s (the examples run no controller: no energy cycle sets a period)."""

    state_doc = "max_t |w_i - w_i,ref| / max_t,i |w_ref| over the rotor speeds, on the output grid"
    physics_doc = "max lock-up time error / 0.1 s"
    PERIOD = 0.1

    def __init__(self, scene: Scene, quick: bool = False, duration: float | None = None):
        super().__init__(scene, quick)
        name = scene.effects["example"]
        T = min(scene.solver.duration, duration or (1.0 if quick else 2.0))
        if name in examples.EXAMPLES:
            ex = examples.example(name)
            self.signals = [k for k in ex.signals if ex.units[k] == "rad/s"]
        else:
            self.signals = ["w1", "w2", "w3", "w4"]
        # the study measures the error of loose settings: a health figure past its bound is kept, not refused
        self.base = scene.replace(solver={"duration": T, "t_settle": 0.0, "allow_inaccurate": True},
                                  outputs=[*self.signals, "E_in", "E_out"])

    def physics_error(self, res, ref):
        """The study's physics error: lock-up times over 0.1 s; returns (error, details)."""
        det = {}
        lr, lf = lock_ups(res.events), lock_ups(ref.events)
        if lf:  # a missing or extra lock-up counts as a whole period
            det["lock_time_rel"] = lock_time_error(lr, lf, self.PERIOD)
        det["n_locks_ref"] = len(lf)
        vals = [v for k, v in det.items() if k != "n_locks_ref"]
        # nothing to compare (no lock-up in the run) is no accuracy: NaN, not 0
        return (max(vals) if vals else math.nan), det


def workprecision_study(scene: Scene, quick: bool = False) -> Study:
    """The rotational examples' work-precision study (`mbsuite workprecision`)."""
    return RotationalStudy(scene, quick=quick)


# ================================================================================================ random inputs
def random_input(scene: Scene, rng: np.random.Generator) -> dict:
    """Admissible random changes of a rotational scene's input: none (each example carries its own sources and
    schedules, the MSL's; a scene's input is `type = "none"`): the input as it is."""
    return {"input": dict(scene.input)}
