"""Drives: scenes, both paths cross-checked, energy balance, controllers, reproduction of the thesis, bad input."""

from __future__ import annotations

import math
import re
import tomllib

import numpy as np
import pytest

from mbsuite.engines import mujoco_engine
from mbsuite.errors import ParameterError, SceneError
from mbsuite.models.drives import controllers as C
from mbsuite.models.drives import drive
from mbsuite.models.drives.analysis import simulate_scene
from mbsuite.registry import get_model
from mbsuite.scenes import load_scene


def _sim(name, **solver):
    sc = load_scene(f"drives/{name}")
    if solver:
        if "duration" in solver and sc.solver.t_settle >= solver["duration"]:
            solver.setdefault("t_settle", 0.0)
        sc = sc.replace(solver=solver)
    return sc, *simulate_scene(sc)


def test_spec_and_scenes_registered():
    spec = get_model("drives")
    assert spec.paths and all(path.run is not None for path in spec.paths.values())
    assert {"step_up_pwm", "susd_100w_design", "susd_500w_step"} <= set(spec.scene_files())


@pytest.mark.parametrize("name", sorted(get_model("drives").scene_files()))
def test_shipped_scenes_close_their_energy_balance(name):
    """Every shipped scene on MuJoCo (the suite's menagerie test steps them; here the physical invariant): input -
    output - losses - stored energy change = 0. Measured over 0.15 s: <= 5.3e-8 of the energy turnover (step-up
    scenes); bound 5e-7, 9x. No MuJoCo warning, no callback left installed (the Modelica examples:
    tests/rotational/test_scenes.py)."""
    sc = load_scene(f"drives/{name}")
    sc = sc.replace(solver={"engine": "mujoco", "duration": 0.15, "t_settle": 0.0})
    res, _, sys_ = simulate_scene(sc)
    bal = drive.energy_balance(sys_, res)
    assert max(abs(bal.input), abs(bal.output), abs(bal.stored)) > 1e-3  # the scene moved: a balance to check
    assert abs(bal.relative) < 5e-7, bal
    assert res.stats["warnings"] == {}
    assert not mujoco_engine.active_callbacks()  # the drives install no MuJoCo callback at all


def test_effect_off_builds_nothing():
    p = load_scene("drives/step_up_pwm").build_params().resolved("table_4_2")
    on = drive.build_system("step_up", p, {"bearing_friction": True})
    off = drive.build_system("step_up", p, {"bearing_friction": False, "clutch_delays": False})
    assert {f.name for f in on.frictions} == {"motor_ground", "spring_ground", "clutch", "load_ground"}
    assert {f.name for f in off.frictions} == {"spring_ground", "clutch"}  # brake and clutch only
    assert [pt.label for pt in off.frictions[0].parts] == ["brake"]
    assert np.all(off.B == 0) and off.delays["brake"] == (0.0, 0.0)


@pytest.fixture(scope="module")
def step_up_pair():
    out = {}
    for eng in ("reference", "mujoco"):
        out[eng] = _sim("step_up_resonant_matched", engine=eng, duration=5.0, t_settle=0.5)
    return out


@pytest.fixture(scope="module")
def susd_pair():
    out = {}
    for eng in ("reference", "mujoco"):
        out[eng] = _sim("susd_100w_design", engine=eng, duration=2.5, t_settle=0.5)
    return out


def _balance_ok(sys_, res):
    """input - output - losses - stored change within 5e-6 of the input: measured <= 7.1e-7 (hand path, matched
    resonant step-up, default rtol), <= 1.9e-7 (motor-resonant), <= 8.5e-8 (MuJoCo); bound 7x the worst. A loss
    term of 1e-5 of the input left out of the books fails it."""
    b = drive.energy_balance(sys_, res)
    assert abs(b.relative) < 5e-6, b
    return b


def test_step_up_paths_agree(step_up_pair):
    """Over >= 20 energy cycles: same cycles, equal lock/release event counts, every lock-up and release within one
    MuJoCo step (1e-4 s; measured max 6.5e-5 s, 1.5x), load speed within 1e-4 (measured 9.8e-6, 10x), both balances
    closed (`_balance_ok`).

    At t = 3.668 s the sliding brake's slip reverses grazing (the spring end rises to +0.035 rad/s for 0.7 ms after a
    pass-through and comes back): both paths lock there and break loose again after 81 us (exact) and 146 us
    (MuJoCo, 1.5 steps); these short locks are paired like every other event."""
    (_, ra, ca, sys_), (_, rb, cb, _) = step_up_pair["reference"], step_up_pair["mujoco"]
    sa, sb = drive.cycle_stats(ra, ca, 0.5), drive.cycle_stats(rb, cb, 0.5)
    assert sa["n_cycles"] >= 20 and sa["n_cycles"] == sb["n_cycles"]
    assert abs(sa["mean_load_speed"] / sb["mean_load_speed"] - 1) < 1e-4
    cmd = drive.compare_commands(ca, cb)
    assert cmd["same_sequence"] and not cmd["flips"], cmd
    els = ["clutch", "spring_ground"]
    short_a, short_b = drive.short_locks(ra, els, 2e-4), drive.short_locks(rb, els, 2e-4)
    assert [s[0] for s in short_a] == [s[0] for s in short_b] == ["spring_ground"]
    assert abs(short_a[0][1] - short_b[0][1]) < 1e-4
    cmp = drive.compare_events(ra, rb, els)
    assert {"clutch->stuck", "clutch->free", "spring_ground->stuck"} <= set(cmp)
    for k, v in cmp.items():
        assert v["n_a"] == v["n_b"], (k, v)
        assert v["max_dt"] <= 1e-4, (k, v)  # one MuJoCo step (measured 6.5e-5 s); the controller sample is 2 ms
    _balance_ok(sys_, ra)
    _balance_ok(sys_, rb)


def test_susd_paths_agree(susd_pair):
    """The 100 W design over >= 20 energy cycles: equal event counts, energy packets (energy taken up by the spring
    system per extraction, `drive.energy_packets`) within 5e-3 (measured 1.0e-3, 5x), load speed within 3e-3
    (measured 8.0e-4, 3.75x), every lock-up/release within one controller sample (1 ms; median measured 4.5e-5 s,
    asserted 1e-4 s).

    Documented deviation (README "Deviations"): the controller turns a computed wait into samples with the thesis'
    int() truncation. Where the two paths' computed waits straddle an integer (here 11.990 vs 12.017 samples: the
    waits agree to 0.03 sample, the truncation does not) that command goes one sample apart and the lock-up it causes
    follows one sample + the slip-time difference apart (1.11 ms). The test admits exactly that: each command that
    differs must differ by one sample with both waits within 0.05 sample of each other and on both sides of an
    integer, and only lock-ups of that clutch within 10 ms after such a command may exceed one sample (< 2 samples).
    """
    (_, ra, ca, sys_), (_, rb, cb, _) = susd_pair["reference"], susd_pair["mujoco"]
    sa, sb = drive.cycle_stats(ra, ca, 0.5), drive.cycle_stats(rb, cb, 0.5)
    assert sa["n_cycles"] >= 20 and sa["n_cycles"] == sb["n_cycles"]
    assert abs(sa["mean_load_speed"] / sb["mean_load_speed"] - 1) < 3e-3
    pa, pb = drive.energy_packets(sys_, ra, ca, 0.5), drive.energy_packets(sys_, rb, cb, 0.5)
    assert pa["stored"].size == pb["stored"].size >= 20
    np.testing.assert_allclose(pa["t"], pb["t"], rtol=0, atol=1e-9)  # the same cycles
    assert np.all(pa["stored"] > 1.0)  # J: real packets (demand 12.8 J, the capacity 1/2 K x_max^2)
    assert np.max(np.abs(pa["stored"] / pb["stored"] - 1)) < 5e-3
    assert np.max(np.abs(pa["delivered"] / pb["delivered"] - 1)) < 5e-3
    dt_c = 1e-3
    cmd = drive.compare_commands(ca, cb)
    assert cmd["same_sequence"], cmd
    assert len(cmd["flips"]) <= 1, cmd["flips"]
    for f in cmd["flips"]:
        assert abs(abs(f["t_b"] - f["t_a"]) - dt_c) < 1e-9, f
        wa, wb = f["wait_a"], f["wait_b"]
        assert abs(wa - wb) < 0.05 and math.floor(wa) != math.floor(wb), f
    flip_t = [min(f["t_a"], f["t_b"]) for f in cmd["flips"]]
    cmp = drive.compare_events(ra, rb, ["clutch_a", "clutch_b"])
    assert len(cmp) == 4
    for k, v in cmp.items():
        assert v["n_a"] == v["n_b"], (k, v)
        for t_a, d in zip(v["t_a"], v["dt"], strict=True):
            if abs(d) > dt_c:
                after_flip = any(0 < t_a - tf < 0.01 for tf in flip_t)
                assert k.endswith("stuck") and after_flip and abs(d) < 2 * dt_c, (k, t_a, d)
        assert v["median_dt"] < 1e-4, (k, v)
    _balance_ok(sys_, ra)
    _balance_ok(sys_, rb)


def test_reference_energy_balance_is_exact(susd_pair):
    _, ra, _, sys_ = susd_pair["reference"]
    assert abs(drive.energy_balance(sys_, ra).relative) < 2e-7  # measured 1.8e-8 (100 W design, 2.5 s): 11x


# ---- controllers -----------------------------------------------------------------------------------------------------
def test_match_time_fixes_extraction_bug():
    """App. F `extraction_wait` returns -7.9 ms for w_e = -10, w_t = -5 (Omega = 132); Table B.1 gives +7.9 ms."""
    t, ok = C.match_time(132.0, 0.0, -10.0, -5.0, theta_sign=-1)
    assert ok and t == pytest.approx(2 / 132 * math.pi / 6, rel=1e-12)
    th = 0.0
    w = -10 * math.cos(132 * t)
    assert w == pytest.approx(-5.0, rel=1e-12)
    # the drives.md check: w_e = 10, w_t = -5, theta_e = 0 -> Omega t = 4 pi/3 with theta < 0
    t2, ok2 = C.match_time(132.0, th, 10.0, -5.0, theta_sign=-1)
    assert ok2 and 132 * t2 == pytest.approx(4 * math.pi / 3, rel=1e-12)


def test_match_time_general_and_no_root():
    rng = np.random.default_rng(1)
    Om = 132.0
    for _ in range(300):
        th, we, wt = rng.normal(0, 3), rng.normal(0, 300), rng.normal(0, 300)
        sgn = int(rng.choice([-1, 1]))
        t, ok = C.match_time(Om, th, we, wt, sgn)
        assert 0 <= t < 2 * math.pi / Om
        w = we * math.cos(Om * t) - Om * th * math.sin(Om * t)
        x = th * math.cos(Om * t) + we / Om * math.sin(Om * t)
        if ok:
            assert w == pytest.approx(wt, abs=1e-8 * (1 + abs(wt)))
            assert np.sign(x) == sgn or abs(x) < 1e-9
            # earliest: no earlier sample of the period satisfies both
            ts = np.linspace(0, t, 400)[:-1]
            ws = we * np.cos(Om * ts) - Om * th * np.sin(Om * ts)
            xs = th * np.cos(Om * ts) + we / Om * np.sin(Om * ts)
            assert not np.any((np.abs(ws - wt) < 1e-6 * (1 + abs(wt))) & (np.sign(xs) == sgn))
        else:
            # spring lacks the energy: wait for its peak speed toward the target (least slip)
            assert math.hypot(we, Om * th) < abs(wt)
            assert abs(w) == pytest.approx(math.hypot(we, Om * th), rel=1e-9) and np.sign(w) == np.sign(wt)


def test_clutch_loiter_eq_2_1():
    """Eq 2.1 against the free response (A.6) w_s = Omega th sin + w_m (1 - cos)."""
    Om, th, wm, wl = 65.6, 2.0, 60.0, 200.0
    t = C.clutch_loiter(Om, th, wm, wl)
    ws = Om * th * math.sin(Om * t) - wm * math.cos(Om * t) + wm
    assert ws == pytest.approx(wl, rel=1e-10)
    assert C.clutch_loiter(Om, th, wm, -5.0) == 0.0
    # no real root (spring cannot reach the load speed): clamped discriminant as the thesis code, finite time
    assert 0 <= C.clutch_loiter(Om, 0.1, 10.0, 500.0) < 2 * math.pi / Om


# ---- reproduction of published numbers (reference path) --------------------------------------------------------------
@pytest.fixture(scope="module")
def step_up_runs():
    out = {}
    for nm in ("step_up_pwm", "step_up_resonant", "step_up_resonant_matched", "step_up_added_inertia"):
        sc, res, ctrl, sys_ = _sim(nm)
        out[nm] = drive.cycle_stats(res, ctrl, sc.solver.t_settle)
    return out


def test_step_up_reproduction(step_up_runs):
    """Published numbers asserted to their printed precision: "~3" (Sec 4.2.1) is any ratio that rounds to 3, [2.5, 3.5)
    (measured 3.29); "~50 %" (Sec. 4.2.4) rounds to the nearest 10 %, [45, 55) % (measured 54 %); the qualitative
    orderings of Sec 4.2.2 (resonant above PWM; measured 212 vs 209 rad/s) and Sec 4.2.3 ("significant increase"
    by clutch matching; measured +12 %, asserted > 5 %)."""
    pwm = step_up_runs["step_up_pwm"]
    ratio = pwm["mean_load_speed"] / pwm["mean_motor_speed"]
    assert 2.5 <= ratio < 3.5
    assert step_up_runs["step_up_resonant"]["mean_load_speed"] > pwm["mean_load_speed"]  # Sec. 4.2.2
    assert (step_up_runs["step_up_resonant_matched"]["mean_load_speed"]
            > 1.05 * step_up_runs["step_up_resonant"]["mean_load_speed"])  # Sec. 4.2.3 "significant increase"
    gain = step_up_runs["step_up_added_inertia"]["mean_load_speed"] / pwm["mean_load_speed"] - 1
    assert 0.45 <= gain < 0.55


@pytest.fixture(scope="module")
def susd_design():
    sc, res, ctrl, sys_ = _sim("susd_100w_design")
    return sc, drive.cycle_stats(res, ctrl, sc.solver.t_settle), drive.cycle_phases(ctrl, sc.solver.t_settle)


def test_susd_100w_design_reproduction(susd_design):
    """+-400 rad/s and "~5 rad" extension as the thesis (Sec. 6.2), each to its printed precision.

    Switching rate: the thesis' ~14.5 cycles/s (Sec. 6.2; Table 6.2: 14.20) is asserted with the tolerance of a
    documented deviation, not an accuracy: ours is 12.8 (-11.7 %), README "Deviations" 3 - the whole difference is
    in the extraction (23.1 vs 18.1 ms in the design model, Eq 5.5); our slower motor (82 vs 96 rad/s) explains a
    1.17x longer extraction, the rest is not explained. The free phases of the cycle (waits, transfer, restart) are
    checked against the closed form instead: one free period 2 pi sqrt(J_s/K) plus one controller sample
    (measured -0.46 %, bound 2 %, 4x)."""
    sc, cs, ph = susd_design
    assert abs(cs["mean_load_speed"] / 400 - 1) < 0.05  # +-400 rad/s reached (Sec. 6.2); measured -0.76 %
    assert abs(cs["switching_rate"] / 14.5 - 1) < 0.15  # documented deviation (-11.7 %), see the docstring
    assert 4.5 <= cs["max_extension"] < 5.5  # "~5 rad" (Sec. 6.2) to its printed precision; measured 4.90
    p = sc.build_params().resolved()
    free = ph["wait_extraction"] + ph["wait_transfer"] + ph["transfer"] + ph["restart"]
    assert abs(free / (2 * math.pi * math.sqrt(p["J_s"] / p["K"]) + 1 / p["fs"]) - 1) < 0.02
    sc2, res2, ctrl2, _ = _sim("susd_100w_reverse")
    cs2 = drive.cycle_stats(res2, ctrl2, sc2.solver.t_settle)
    assert abs(cs2["mean_load_speed"] / -400 - 1) < 0.05  # measured +1.5 % (-406 rad/s)


def test_regression_susd_100w_switching_rate(susd_design):
    """Regression only (no outside source for this value): 12.81 cycles/s, cycle 78.1 ms, extraction 23.1 ms."""
    _, cs, ph = susd_design
    assert cs["switching_rate"] == pytest.approx(12.81, rel=0.01)
    assert ph["extraction"] == pytest.approx(0.0231, rel=0.02)


# ---- bad input -------------------------------------------------------------------------------------------------------
def test_bad_input():
    sc = load_scene("drives/step_up_pwm")
    with pytest.raises(ParameterError, match=r"\bJ_m = -0\.0001\b.* is invalid"):
        sc.replace(params={"J_m": -1e-4})
    with pytest.raises(ParameterError, match=r"\bK = 0\.0\b.* is invalid"):
        sc.replace(params={"K": 0.0})
    with pytest.raises(SceneError, match="controller"):
        sc.replace(effects={"controller": "fuzzy"})
    with pytest.raises(SceneError, match="controller = 'energy_packet' .*does not drive mechanism 'step_up'"):
        simulate_scene(sc.replace(effects={"controller": "energy_packet"}))
    with pytest.raises(ParameterError, match="longer than"):
        simulate_scene(load_scene("drives/susd_100w_design").replace(params={"d_on": 0.2}))
    with pytest.raises(ParameterError, match="longer than the PWM cycle"):
        simulate_scene(sc.replace(params={"d_on": 0.3, "t_l": 0.25}))
    with pytest.raises(SceneError, match="profile"):
        simulate_scene(load_scene("drives/susd_100w_design").replace(input={"profile": [[1.0, 2.0], [0.5, 1.0]]}))


@pytest.mark.parametrize("name,value", [
    ("K_ctrl", 0.0), ("K_ctrl", -1.0), ("Omega_ctrl", -132.0), ("Omega_ctrl", 0.0), ("spring_max", 0.0),
    ("spring_max", -2.0), ("max_tk", 0.0), ("min_vel", -1.0), ("max_vel", -1.0), ("tau_0", -10.0), ("tau_0", 0.0),
    ("tau_slope", 0.05), ("twist_tol", -0.1), ("min_motor_vel", -1.0),
])
def test_bad_parameter_values_named(name, value):
    with pytest.raises(ParameterError, match=rf"\b{name} = {re.escape(repr(value))}\b.* is invalid; valid: "):
        load_scene("drives/susd_100w_design").replace(params={name: value})


def test_non_finite_parameter_named_by_the_scene_loader():
    # a non-finite number is refused when the scene is built, naming the parameter
    with pytest.raises((SceneError, ParameterError), match="Kp"):
        load_scene("drives/susd_100w_design").replace(params={"Kp": float("nan")})


def test_bad_parameter_combinations():
    with pytest.raises(ParameterError, match="min_vel"):
        load_scene("drives/step_up_motor_resonant").replace(params={"min_vel": 70.0, "max_vel": 60.0})
    # twist_tol at or below the friction-held static twist (C_s + C_l)/K = 0.058 rad: the transfer would never end
    for tt in (0.0, 0.05):
        with pytest.raises(ParameterError, match="twist_tol"):
            simulate_scene(load_scene("drives/step_up_resonant").replace(params={"twist_tol": tt}))
    # 0 is a value, not "unset": a zero controller spring rate is rejected, not replaced by K
    p = load_scene("drives/susd_100w_design").build_params().resolved("design_100w")
    p["K_ctrl"] = 0.0
    with pytest.raises(ParameterError, match="K must be positive"):
        drive.build_controller("step_up_down", "energy_packet", p, {"clutch_delays": True})


def test_delay_samples_one_conversion():
    """0.3 ms at 10 kHz is 3 samples everywhere (int(0.0003 * 10000) = 2 in binary floating point)."""
    from mbsuite.components.rotational.commands import CommandQueue, delay_samples

    assert int(0.0003 * 10000) == 2  # the trap
    assert delay_samples(0.0003, 10000.0) == 3
    assert delay_samples(0.006, 500.0) == 3  # thesis App. C: 6 ms at 500 Hz = 3 samples
    assert delay_samples(0.0045, 1000.0) == 4  # truncation as the thesis' (int) cast
    assert delay_samples(0.0, 1000.0) == 0
    q = CommandQueue({"ca": (0.0003, 0.0003)}, 1e-4, {"ca": 0})
    assert q.counts["ca"] == (3, 3)
    ctrl = C.EnergyPacketController(fs=10000.0, K=1.0, Omega=100.0, clutch_delay=0.0003, spring_max=1.0)
    assert ctrl.cd == 3
    with pytest.raises(ParameterError):
        delay_samples(-1e-3, 1000.0)
    # the controller compensates the delay actually applied (quantised), the same as the queue
    p = load_scene("drives/susd_100w_design").build_params().resolved("design_100w")
    p.update(d_on=0.0045, d_off=0.0045)
    ctrl = drive.build_controller("step_up_down", "energy_packet", p, {"clutch_delays": True})
    assert ctrl.clutch_delay == pytest.approx(0.004) and ctrl.cd == 4


def test_anti_windup_default_and_printed_variant():
    """Energy-packet PI: anti-windup unless a scene asks otherwise; the step-up closed-loop scene selects
    the printed, winding-up t_k PI explicitly (the thesis reproduction)."""
    spec = get_model("drives")
    assert spec.effects["anti_windup"].default is True
    sc = load_scene("drives/susd_500w_step")
    with open(spec.scene_files()["susd_500w_step"], "rb") as fh:
        assert "anti_windup" not in tomllib.load(fh)["effects"]  # the scene does not ask: the default applies
    p = sc.build_params().resolved()
    unset = {k: v for k, v in sc.effects.items() if k != "anti_windup"}
    assert drive.build_controller("step_up_down", "energy_packet", p, unset).anti_windup is True
    _, ctrl, _ = simulate_scene(sc.replace(solver={"duration": 0.6, "t_settle": 0.0}))
    assert ctrl.anti_windup is True
    assert abs(ctrl.eps_state) <= ctrl.E_max * (1 + 1e-12)  # the stored state never leaves the clamp
    su = load_scene("drives/step_up_closed_loop")
    assert su.effects["anti_windup"] is False
    p = su.build_params().resolved("table_4_2")
    assert drive.build_controller("step_up", "resonant", p, dict(su.effects)).anti_windup is False
    # without anti-windup the same energy-packet run stores an unclamped (wound-up) state
    _, ctrl2, _ = simulate_scene(sc.replace(effects={"anti_windup": False}, solver={"duration": 0.6, "t_settle": 0.0}))
    assert ctrl2.anti_windup is False and abs(ctrl2.eps_state) > ctrl2.E_max


def test_windowed_energy_balance_and_zero_input(susd_pair):
    """Any window closes, including the kinetic energy removed by plastic locks inside it (MuJoCo).

    The recorded lock-impact energy against the energy the rest of the books leave unaccounted in the window: the
    source work minus every other recorded loss minus the change of 1/2 J w^2 + 1/2 K x^2 computed here from the
    recorded states. Measured relative differences 3.5e-4, 6.8e-4, 2.7e-5 over the three windows (1.4e-3, 5.3e-4,
    9.9e-4 J of lock impact; the difference is the balance residual, <= 4.9e-7 J of 252 J); bound 5e-3 (7.4x the
    worst)."""
    _, rb, _, sys_ = susd_pair["mujoco"]

    def stored(i: int) -> float:
        q, w = rb.q[:, i], rb.w[:, i]
        return 0.5 * float(np.sum(sys_.J * w * w)) + sum(
            0.5 * s.K * (q[s.a] - (q[s.b] if s.b >= 0 else 0.0)) ** 2 for s in sys_.springs)

    for a, b in ((0, rb.t.size - 1), (500, 1500), (1000, rb.t.size - 1)):
        bal = drive.energy_balance(sys_, rb, a, b)
        # measured 1.9e-9, 3.5e-9, 1.8e-10 over the three windows: bound 3e-8, 8.5x the worst
        assert bal.losses["lock_impact"] > 0 and abs(bal.relative) < 3e-8, (a, b, bal)
        d = {k: float(v[b] - v[a]) for k, v in rb.energy.items()}
        impact = d.pop("lock_impact")
        unaccounted = d.pop("source") - sum(d.values()) - (stored(b) - stored(a))
        assert impact > 1e-4 and abs(unaccounted / impact - 1) < 5e-3, (a, b, impact, unaccounted)
    zero = drive.Balance(0.0, 0.0, {}, 0.0, 0.0)
    assert zero.relative == 0.0
    assert drive.Balance(0.0, 0.0, {"x": 1.0}, 0.0, -1.0).relative == -1.0


def test_motor_resonant_keeps_motor_in_band():
    """switch_mv (App. E): storage ends below min_vel, the brake re-engages above max_vel, so the mean motor speed lies
    inside the scene's band [min_vel, max_vel] = [40, 60] rad/s (measured 52.9)."""
    sc, res, ctrl, sys_ = _sim("step_up_motor_resonant", duration=4.0, t_settle=2.0)
    cs = drive.cycle_stats(res, ctrl, 2.0)
    p = sc.build_params().resolved()
    assert p["min_vel"] < cs["mean_motor_speed"] < p["max_vel"]
    assert cs["n_cycles"] >= 8
    _balance_ok(sys_, res)


def test_velocity_band_scheme_compares():
    """The thesis' 0.01 rad/s locking band on CoupledClutches, against the Dymola result every 0.1 s: its error
    (measured 6.2e-3 rad/s) stays below 2e-2 (3.2x) and is at least 10x that of the event-exact hand path on the same
    grid (measured 6.0e-5: 103x) - the scheme creeps where the exact path holds."""
    from mbsuite.components.rotational.event_exact import simulate_reference
    from mbsuite.components.rotational.velocity_band import simulate_velocity_band
    from mbsuite.models.rotational import coupled_clutches as cc

    band = simulate_velocity_band(cc.build_system(), cc.Q0, cc.W0, 1.5, sample_dt=5e-4)
    exact = simulate_reference(cc.build_system(), cc.Q0, cc.W0, 1.5, sample_dt=5e-4)
    ref = cc.load_reference()
    grid = np.round(np.arange(0, 1.5 + 1e-9, 0.1), 10)
    j = [int(np.nonzero(np.isclose(ref["t"], tt))[0][-1]) for tt in grid]

    def err(res):
        i = [int(np.argmin(np.abs(res.t - tt))) for tt in grid]
        return float(np.max(np.abs(res.w[:, i] - ref["w"][:, j])))

    e_band, e_exact = err(band), err(exact)
    assert e_band < 2e-2
    assert e_band > 10 * e_exact, (e_band, e_exact)


def test_storage_time_nearest_sample_over_grid():
    """PWM storage time t_k = duty x t_l in samples: the integer nearest to duty x t_l x fs in exact rational
    arithmetic (decimal strings as fractions; ties up), over a grid of duty x t_l x fs, through the controller."""
    from fractions import Fraction

    from mbsuite.components.rotational.commands import time_to_samples

    q = w = np.zeros(3)
    n_trap = 0
    for fs in ("500", "1000", "10000"):
        for tl in ("0.05", "0.1", "0.15", "0.2", "0.25", "0.3", "0.35", "0.4", "0.5", "0.7"):
            for i in range(1, 100):
                duty = f"0.{i:02d}"
                exact = Fraction(duty) * Fraction(tl) * Fraction(fs)
                oracle = math.floor(exact + Fraction(1, 2))
                ctrl = C.StepUpController(kind="pwm", fs=float(fs), t_l=float(tl), duty=float(duty))
                ctrl(0, 0.0, q, w)
                ctrl(1, 1.0 / float(fs), q, w)
                assert ctrl.tk_samples == oracle, (duty, tl, fs)
                n_trap += int(float(duty) * float(tl) * float(fs)) != oracle
    assert n_trap > 100  # the grid exercises the truncation trap (int() would be wrong in these cases)
    # the case that was wrong: 0.35 x 0.2 x 500 = 34.99999999999999 in binary
    assert int(0.35 * 0.2 * 500) == 34 and time_to_samples(0.35 * 0.2, 500.0) == 35
    # truncation where the thesis means it (delays, computed waits), and bad input
    assert time_to_samples(0.0045, 1000.0, "floor") == 4 and time_to_samples(0.0045, 1000.0) == 5
    with pytest.raises(ParameterError, match="storage"):
        time_to_samples(-0.1, 500.0, what="storage time")
    with pytest.raises(ParameterError, match="rounding"):
        time_to_samples(0.1, 500.0, "up")


def test_parameter_and_input_limits_declared():
    """Every drives parameter declares its valid range; a value outside it names the field, value and range; the
    reference input is range-checked by the scene loader."""
    from mbsuite.limits import limit_of, undeclared
    from mbsuite.models.drives.params import PARAM_SETS, DriveParams

    assert undeclared(DriveParams) == []
    for name in PARAM_SETS:  # every shipped parameter set lies inside the declared ranges
        DriveParams().resolved(name)
    with pytest.raises(ParameterError, match=r"duty = 1.0 is invalid; valid: \(0, 1\)"):
        DriveParams(duty=1.0)
    assert limit_of(DriveParams, "tau_slope").hi == 0.0
    with pytest.raises(SceneError, match="input.value"):
        load_scene("drives/step_up_pwm").replace(input={"value": 1e9})
