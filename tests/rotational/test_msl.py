"""Modelica Rotational examples (MSL 4.1.0) as rotational scenes, on the hand path and MuJoCo.

Friction and OneWayClutch: against the Modelica Association's reference results (`data/msl/`): the same mode
sequence, every mode change within 1e-5 s (hand path; the reference is a tolerance-1e-6 DASSL result, its event times
good to a few microseconds; measured <= 1.7e-6 s) and within one MuJoCo timestep (measured <= 5e-5 s at 1e-4 s);
every compared signal inside the Association's regression tube (2e-3 of the signal's range; measured <= 0.30 of it
on both paths). OneWayClutchDisengaged and SimpleGearShift have no published reference: closed forms of their
phases (freewheel, rigid planetary) and the mode sequence derived from the MSL equations are the checks. Energy
balance per example about 10x its measured residual; the `energy_residual` health figure. The freewheel's grazing
lock and the planetary hand-over are hard cases (`mbsuite.models.rotational.cases`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from mbsuite.components.rotational import components
from mbsuite.components.rotational.energy import energy_balance
from mbsuite.components.rotational.event_exact import simulate_reference
from mbsuite.components.rotational.mujoco_sim import MujocoRotorSim
from mbsuite.errors import ParameterError
from mbsuite.models.rotational import examples as msl
from mbsuite.models.rotational.analysis import simulate_scene
from mbsuite.paths import mjcf_path
from mbsuite.scenes import load_scene

DT = 1e-4  # the MuJoCo timestep of the scenes
_RUNS: dict = {}


def _run(name: str, engine: str):
    """Both paths of an example, on a 1e-4 s output grid (cached for the module)."""
    key = (name, engine)
    if key not in _RUNS:
        ex = msl.example(name)
        if engine == "reference":
            res = simulate_reference(ex.system, ex.q0, ex.w0, ex.t_end, sample_dt=1e-4, rtol=1e-10, atol=1e-12)
        else:
            res = MujocoRotorSim(ex.system, mjcf_path(f"drive_{name}"), timestep=DT).run(
                ex.q0, ex.w0, ex.t_end, sample_dt=1e-4)
        _RUNS[key] = (ex, res)
    return _RUNS[key]


# the OneWayClutch's grazing lock: released at t_r = 7/6 + asin(3e-5)/(6 pi) (holding torque 5 sin(6 pi (t - 7/6))
# reaching tau0_max_low = 1.5e-4), the free slip w_rel = (10/6pi)(cos 6 pi t - cos 6 pi t_r) closes again at
# t = 8/3 - t_r, where the input torque is about to reverse: a tangency (hard case rotational_freewheel_grazing_lock)
T_GRAZE = 1.5 - math.asin(3e-5) / (6 * math.pi)


@pytest.mark.parametrize("name", ["msl_friction", "msl_one_way_clutch"])
def test_mode_sequence_matches_reference(name):
    ex, hand = _run(name, "reference")
    _, mj = _run(name, "mujoco")
    ref = msl.load_reference(ex)
    rev = msl.reference_events(ex, ref)
    assert len(rev) == {"msl_friction": 7, "msl_one_way_clutch": 9}[name]
    for res, path in ((hand, "hand"), (mj, "mujoco")):
        rows = msl.pair_events(msl.events_as_codes(res.events), rev)
        assert all(r["t"] is not None and r["t_ref"] is not None for r in rows), (path, rows)
        for r in rows:
            if abs(r["t_ref"] - T_GRAZE) < 1e-3 and name == "msl_one_way_clutch" and r["to"] == 0:
                continue  # the grazing lock: against its closed form in the hard case rotational_freewheel_grazing_lock
            tol = 1e-5 if path == "hand" else DT
            assert abs(r["t"] - r["t_ref"]) <= tol, (path, r)


def test_reference_grazing_lock_offset_explained():
    """The tangential lock at t = 1.5 s: both paths against the closed form are the hard case
    `rotational_freewheel_grazing_lock` (one source of truth). Here the reference itself: it has the lock 3.0e-4 s
    early, explained by its w_rel error of ~1e-5 rad/s at a tangency where the slip's curvature is 188 rad/s^3, which
    moves the crossing by sqrt(2 x 8.5e-6 / 188) = 3.0e-4 s (asserted 2.5e-4 ... 3.5e-4 s, the spread of that
    estimate)."""
    ex = msl.example("msl_one_way_clutch")
    ref = msl.reference_events(ex, msl.load_reference(ex))
    t_ref = [r["t"] for r in ref if abs(r["t"] - 1.4997) < 1e-3 and r["to"] == 0]
    assert len(t_ref) == 1
    assert 2.5e-4 < T_GRAZE - t_ref[0] < 3.5e-4


@pytest.mark.parametrize("engine", ["reference", "mujoco"])
@pytest.mark.parametrize("name", ["msl_friction", "msl_one_way_clutch"])
def test_signals_inside_regression_tube(name, engine):
    ex, res = _run(name, engine)
    ref = msl.load_reference(ex)
    tube = msl.tube_check(ex, res, ref)
    assert set(tube) == set(ex.compared)
    for k, v in tube.items():
        assert v["ratio"] <= 1.0, (k, v)


# energy residual / input, hand path (rtol 1e-10) and MuJoCo, measured: Friction 1.2e-7 / 2.0e-6 (the clutch and
# brake dissipate 400x the input), OneWayClutch 3.1e-9 / 2.0e-9, Disengaged 8.4e-12 / 6.2e-10, SimpleGearShift
# 1.2e-11 / 1.8e-11; bounds about 10x (5x for MuJoCo Friction), round-off floors at 1e-10
BALANCE_BOUND = {"msl_friction": (1e-6, 1e-5), "msl_one_way_clutch": (3e-8, 2e-8),
                 "msl_one_way_clutch_disengaged": (1e-10, 6e-9), "msl_simple_gear_shift": (1e-10, 2e-10)}


@pytest.mark.parametrize("name", sorted(msl.EXAMPLES))
def test_energy_balance(name):
    for engine, bound in zip(("reference", "mujoco"), BALANCE_BOUND[name], strict=True):
        ex, res = _run(name, engine)
        bal = energy_balance(ex.system, res)
        assert bal.input > 0.1
        assert abs(bal.residual) <= bound * bal.input, (engine, bal)


def _disengaged_closed_form(t_end: float = 2.0) -> list[tuple[float, str]]:
    """OneWayClutchDisengaged by closed form + root finding: free slip w_rel' = -0.6 - 10 sin(4 pi t) (input torque
    0.3 + 10 sin(4 pi t), load -0.3, J = 1 each); locked: holding torque tau = -0.3 - 5 sin(4 pi t), released when it
    exceeds tau0_max_low = 1e-4 x 0.5 x 3."""
    c = 10.0 / (4 * math.pi)
    hold = 1e-4 * 0.5 * 3.0
    events, t, wr0, stuck = [], 0.0, 0.5, False
    grid = np.arange(0.0, t_end + 1e-9, 1e-4)
    while t < t_end:
        if not stuck:
            def f(x, t=t, wr0=wr0):
                return wr0 - 0.6 * (x - t) + c * (math.cos(4 * math.pi * x) - math.cos(4 * math.pi * t))
        else:
            def f(x):
                return hold - (-0.3 - 5.0 * math.sin(4 * math.pi * x))
        g = grid[grid > t + 1e-9]
        vals = np.array([f(x) for x in g])
        i = np.nonzero(vals <= 0)[0]
        if not i.size:
            break
        j = int(i[0])
        te = brentq(f, g[j - 1] if j else t + 1e-12, g[j], xtol=1e-16)
        events.append((te, "forward" if stuck else "stuck"))
        t, wr0, stuck = te, 0.0, not stuck
    return events


@pytest.mark.literal_inputs("event times against the MSL closed form of the literal constants to 2e-14 s")
def test_one_way_clutch_disengaged_against_closed_form():
    expected = _disengaged_closed_form()
    assert len(expected) == 8  # lock/release four times (the expected sequence from the MSL equations)
    # hand path: measured 2.7e-15 s (round-off of the root finding at t <= 2 s, 6 ulp), bound 2e-14 s (7.5x);
    # MuJoCo: one step (measured 5.0e-5 s, 2x)
    for engine, tol in (("reference", 2e-14), ("mujoco", DT)):
        _, res = _run("msl_one_way_clutch_disengaged", engine)
        got = [(e["t"], e["to"]) for e in res.events]
        assert [x[1] for x in got] == [x[1] for x in expected], engine
        assert max(abs(a[0] - b[0]) for a, b in zip(got, expected, strict=True)) <= tol, engine


@pytest.mark.literal_inputs("speeds against the closed forms of the literal constants to 3e-12")
def test_simple_gear_shift_phases():
    """Expected sequence from the MSL equations: the brake holds the ring until 2 s (gear ratio load/engine =
    1/(1 + ratio) = 0.4); the ramp engages the clutch (backward: the sun turns faster than the held ring), the brake
    lets the ring go forward as its normal force falls, is free at 2.1 s, and the clutch locks sun and ring (ratio 1).
    Closed forms: before 2 s, 16.25 w_l' = 50 - k w_l^2 (J_l + (1 + r)^2 J_e, torque (1 + r) 20, k = 20/w_n^2); after
    the clutch lock, 11 w' = 20 - k w^2. The sequence, the 1:1 end state and the paths' event times against each other
    are the hard case `rotational_planetary_handover`.

    Measured, relative to the closed form's asymptote (hand path rtol 1e-10 / MuJoCo RK4 1e-4 s): before 2 s
    2.8e-13 / 4.0e-12, gear constraint 1.3e-15 / 7.8e-13; after the lock 7.1e-12 / 4.0e-11, 1:1 8.5e-16 / 1.5e-12.
    Bounds 10x (round-off floors 1e-11)."""
    r = msl.RATIO_PLANETARY
    k = 20.0 / 10.471975511966**2
    for engine, tol_pre, tol_post in (("reference", 3e-12, 7e-11), ("mujoco", 4e-11, 4e-10)):
        _, res = _run("msl_simple_gear_shift", engine)
        assert len(res.events) == 4, engine
        t_ev = [e["t"] for e in res.events]
        assert 2.0 <= t_ev[0] <= 2.0 + DT + 1e-12 and 2.0 < t_ev[1] < 2.1 and abs(t_ev[2] - 2.1) <= DT and t_ev[3] > 2.1
        we, wl = res.w
        m = (res.t > 0.6) & (res.t < 1.99)
        a = math.sqrt(50.0 / k)
        w_exact = a * np.tanh(math.sqrt(50.0 * k) / 16.25 * (res.t[m] - 0.5))
        assert np.max(np.abs(wl[m] - w_exact)) <= tol_pre * a, engine
        assert np.max(np.abs(we[m] - (1 + r) * wl[m])) <= 1e-11 * a, engine
        t_lock = t_ev[3]
        i0 = int(np.searchsorted(res.t, t_lock + 0.01))
        m2 = res.t >= res.t[i0]
        w0 = wl[i0]
        A, B = math.sqrt(20.0 / k), math.sqrt(20.0 * k) / 11.0
        w2 = A * np.tanh(B * (res.t[m2] - res.t[i0]) + math.atanh(w0 / A))
        assert np.max(np.abs(wl[m2] - w2)) <= tol_post * A, engine
        assert np.max(np.abs(we[m2] - wl[m2])) <= 2e-11 * A, engine


def test_scenes_run_with_health_and_mode_list():
    import mbsuite

    for name in sorted(msl.EXAMPLES):
        sc = load_scene(f"rotational/{name}")
        res = mbsuite.run(sc.replace(solver={"duration": 0.7}))
        fig = [h for h in res.health if h.name == "energy_residual"]
        assert len(fig) == 1 and fig[0].bound == 1e-6 and fig[0].ok
        assert all({"t", "component", "from", "to"} <= set(e) for e in res.stats["mode_changes"])
        assert set(res.stats["final"]) >= set(msl.example(name).compared)
    sc = load_scene("rotational/msl_friction")
    out, _ = simulate_scene(sc.replace(solver={"engine": "mujoco", "duration": 0.2}))
    assert [e["element"] for e in out.events][:2] == ["clutch", "clutch"]


def test_components_refuse_bad_input():
    with pytest.raises(ParameterError, match="planetary ratio"):
        components.planetary_ring_row(0.0, 0, 1, 2)
    with pytest.raises(ParameterError, match="w_nominal"):
        components.quadratic_speed_torque("q", 0, -20.0, 0.0)
    with pytest.raises(ParameterError, match="fn_max"):
        components.clutch("c", 0, 1, -1.0)
    with pytest.raises(ParameterError, match="gear ratio"):
        components.ideal_gear_row(0.0, 0, 2)
    with pytest.raises(ParameterError, match="unknown MSL example"):
        msl.example("msl_nothing")


def test_native_equals_python_twin():
    """The C stepper and its Python twin on the general (planetary, tendon locks), one-way and damper code paths."""
    for name in ("msl_friction", "msl_one_way_clutch", "msl_simple_gear_shift"):
        ex = msl.example(name)
        t_end = {"msl_friction": 0.7, "msl_one_way_clutch": 0.5, "msl_simple_gear_shift": 0.75}[name]
        if name == "msl_simple_gear_shift":  # the gear shift moved from 2.0 s to 0.6 s (a shorter run)
            for f in ex.system.frictions:
                for pt in f.parts:
                    pt.schedule = dataclasses.replace(pt.schedule, t0=0.6)
        a = MujocoRotorSim(ex.system, mjcf_path(f"drive_{name}")).run(ex.q0, ex.w0, t_end, sample_dt=1e-3)
        b = MujocoRotorSim(ex.system, mjcf_path(f"drive_{name}")).run(ex.q0, ex.w0, t_end, sample_dt=1e-3,
                                                                        stepper="python")
        assert len(a.events) >= 3
        assert [(e["element"], e["to"]) for e in a.events] == [(e["element"], e["to"]) for e in b.events]
        assert max((abs(x["t"] - y["t"]) for x, y in zip(a.events, b.events, strict=True)), default=0.0) <= 1e-12
        assert np.max(np.abs(a.w - b.w)) <= 1e-9
        for k in a.energy:
            assert np.max(np.abs(a.energy[k] - b.energy[k])) <= 1e-9, k
