"""Long drive studies (make test-slow): efficiency curves, closed loops, 500 W robustness, full cross-checks."""

from __future__ import annotations

import numpy as np
import pytest

from mbsuite.models.drives import drive
from mbsuite.models.drives.analysis import efficiency_point
from mbsuite.models.drives.model import reference_signal, simulate_scene
from mbsuite.scenes import load_scene

pytestmark = pytest.mark.slow


def test_susd_100w_efficiency_band():
    pts = [efficiency_point(load_scene("drives/susd_100w_efficiency").replace(params={"tau_l": tl}))
           for tl in (0.3, 0.5, 0.8, 1.2)]
    for p in pts:
        assert 60 < abs(p["load_speed"]) < 260
        assert 0.65 < p["efficiency"] < 0.85  # thesis: 70-80 % over ~60-260 rad/s (L2269-2277)
        assert abs(p["balance_relative"]) < 0.005
    fast = efficiency_point(load_scene("drives/susd_100w_efficiency").replace(params={"tau_l": 0.1}))
    assert abs(fast["load_speed"]) > 330 and fast["efficiency"] < 0.45  # ~40 % near 400 rad/s


def test_step_up_efficiency_peak():
    pts = [efficiency_point(load_scene("drives/step_up_efficiency").replace(params={"tau_l": tl}))
           for tl in (0.0, 0.1, 0.15, 0.2)]
    assert pts[0]["efficiency"] == 0.0
    peak = max(pts, key=lambda p: p["efficiency"])
    assert 0.7 < peak["efficiency"] < 0.82 and 110 < peak["load_speed"] < 240


def test_susd_closed_loop_tracking_and_regeneration():
    sc = load_scene("drives/susd_100w_closed_loop")
    res, ctrl, _ = simulate_scene(sc)
    ref = reference_signal(dict(sc.input), 0.0)
    r = np.array([ref(t) for t in res.t])
    hold = ((res.t % 4.0 > 2.0) & (res.t < 8.0)) | (res.t > 12.5)
    assert np.max(np.abs(res.w[2][hold] - r[hold])) < 0.085 * 400  # L2297-2311
    assert min(e["eps"] for e in ctrl.log if e["event"] == "cycle") < 0  # energy returned to the motor
    assert np.max(res.w[0][(res.t > 8) & (res.t < 10)]) > 197  # motor driven above its no-load speed


@pytest.mark.parametrize("tau_l", [0.4, 0.8])
def test_500w_step_little_overshoot(tau_l):
    sc = load_scene("drives/susd_500w_step").replace(params={"tau_l": tau_l}, solver={"duration": 4.0})
    res, ctrl, _ = simulate_scene(sc)
    cyc = np.array([e["t"] for e in ctrl.log if e["event"] == "cycle"])
    cm = np.array([res.w[2][(res.t >= a) & (res.t < b)].mean() for a, b in zip(cyc[:-1], cyc[1:], strict=True)])
    assert cm.max() < 1.03 * 400 and abs(cm[-5:].mean() / 400 - 1) < 0.01


def test_500w_open_loop_reaches_500():
    sc = load_scene("drives/susd_500w_open").replace(input={"value": -500.0}, solver={"duration": 10.0,
                                                                                        "t_settle": 7.0})
    res, ctrl, _ = simulate_scene(sc)
    cs = drive.cycle_stats(res, ctrl, 7.0)
    assert abs(cs["mean_load_speed"] / -500 - 1) < 0.03 and 24 < cs["switching_rate"] < 32
    assert cs["max_extension"] < 3.0


@pytest.mark.parametrize("name,duration", [("step_up_pwm", 5.0), ("susd_100w_design", 3.0), ("susd_500w_step", 3.0)])
def test_full_crosscheck(name, duration):
    runs = {}
    for eng in ("reference", "mujoco"):
        sc = load_scene(f"drives/{name}").replace(solver={"engine": eng, "duration": duration, "t_settle": 0.3})
        runs[eng] = simulate_scene(sc)
    (ra, ca, sys_), (rb, cb, _) = runs["reference"], runs["mujoco"]
    sa, sb = drive.cycle_stats(ra, ca, 0.3), drive.cycle_stats(rb, cb, 0.3)
    assert sa["n_cycles"] >= 20 and sa["n_cycles"] == sb["n_cycles"]  # issue: >= 20 energy cycles
    assert abs(sa["mean_load_speed"] / sb["mean_load_speed"] - 1) < 0.005
    # energy packets (energy taken up per extraction) within 1 % in open loop. In closed loop near the set point the
    # packets are the PI's answer to speed errors of the order of the paths' 0.2 % speed difference, and single packets
    # differ by up to 3x (500 W step, t > 2.5 s; README Deviations 5): compared there only while the PI is saturated.
    if name.startswith("susd") and not sc.effects["closed_loop"]:
        pa, pb = drive.energy_packets(sys_, ra, ca, 0.3), drive.energy_packets(sys_, rb, cb, 0.3)
        assert pa["stored"].size == pb["stored"].size >= 20
        assert np.max(np.abs(pa["stored"] / pb["stored"] - 1)) < 0.01
    for b in (drive.energy_balance(sys_, ra), drive.energy_balance(sys_, rb)):
        assert abs(b.relative) < 0.005
