"""The drives' declared accuracy (`mbsuite/models/drives/accuracy.py`) and their error estimate.

Default suite: the declaration (names per scene, tolerances per path), the headline values against an independent
computation from the run's own signals and events, and `--error-estimate` on the `drive` commands that run a scene
(the Modelica examples' headlines: tests/rotational/test_accuracy.py).
Slow (`make test-slow`): every shipped scene's headlines at its default settings against a much refined run (hand
path rtol 1e-12), the estimate bracketing the true error, and the MuJoCo path's branch flip on step_up_closed_loop."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import mbsuite
from mbsuite.analysis.errorestimate import error_estimate, run_values
from mbsuite.models.drives import accuracy as acc
from mbsuite.scenes import load_scene
from mbsuite.trust.estimate import declared
from mbsuite.trust.health import AccuracyError

SCENES = sorted(load_scene("drives").spec.scene_files())


def _names(sc) -> list[str]:
    return [h.name for h in declared(sc)]


@pytest.mark.parametrize("name", SCENES)
def test_declared_headlines_of_every_shipped_scene(name):
    """n_events first (a count that changes fails before any time is compared); drives: the cycle-mean speeds, the
    efficiency where there is a load torque, the first lock-up of each switched element. MuJoCo's tolerances are the
    looser ones."""
    sc = load_scene(f"drives/{name}")
    names = _names(sc)
    assert names[0] == "n_events" and declared(sc)[0].tol == 0.5
    mech = sc.effects["mechanism"]
    tau_l = sc.build_params().resolved()["tau_l"]
    expect = ["n_events", "mean_load_speed", "mean_motor_speed"] + (["efficiency"] if tau_l else []) + [
        f"t_lock_{k}" for k in acc.SWITCHED[mech]]
    assert names == expect
    mj = {h.name: h.tol for h in declared(sc.replace(solver={"engine": "mujoco"}))}
    for h in declared(sc)[1:]:
        assert 0 < h.tol < mj[h.name], h.name


def test_drive_values_against_the_runs_signals():
    """A 0.6 s step-up run with a load torque (0.03 N m, so it has an efficiency): the headline values recomputed
    from the result's signals and events by their definitions (mean speeds: angle travelled over [t_settle, T] / time;
    energy differences; the first lock-up at t >= t_settle). Same run, other arithmetic: agreement to round-off. The
    sampled speeds' trapezoidal mean differs from the exact mean by the 2 ms grid's quadrature error only (measured
    4.9e-3 rad/s on the load, 3.1e-4 on the motor, whose speeds change by up to 3.3 / 4.5 rad/s per sample; bound
    5e-2, 10x)."""
    sc = load_scene("drives/step_up_pwm").replace(
        params={"tau_l": 0.03}, solver={"duration": 0.6, "t_settle": 0.3},
        outputs=["w_motor", "w_load", "theta_motor", "theta_load", "E_in", "E_out"])
    res = mbsuite.run(sc)
    v = acc.values(sc, res)
    m = res.t >= 0.3
    span = res.t[m][-1] - res.t[m][0]
    for k in ("load", "motor"):
        th = res[f"theta_{k}"][m]
        assert v[f"mean_{k}_speed"] == pytest.approx((th[-1] - th[0]) / span, rel=1e-12)
        assert abs(v[f"mean_{k}_speed"] - np.trapezoid(res[f"w_{k}"][m], res.t[m]) / span) <= 5e-2
    e_in, e_out = res["E_in"][m], res["E_out"][m]
    assert v["efficiency"] == pytest.approx((e_out[-1] - e_out[0]) / (e_in[-1] - e_in[0]), rel=1e-12)
    assert 0 < v["efficiency"] < 1
    for k, el in (("brake", "spring_ground"), ("clutch", "clutch")):
        assert v[f"t_lock_{k}"] == min(e["t"] for e in res.events if e["element"] == el and e["to"] == "stuck"
                                       and e["t"] >= 0.3)
    assert v["n_events"] == len(res.events) > 0


def test_efficiency_command_estimates_every_point(capsys):
    """`drive efficiency --error-estimate`: each load point's efficiency-curve headlines with their estimate."""
    from mbsuite.cli import main

    assert main(["drive", "efficiency", "drives/step_up_efficiency", "--loads", "0.1", "--duration", "0.6",
                 "--error-estimate", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    (pt,) = d["points"]
    rows = {r["name"]: r for r in pt["error_estimate"]["rows"]}
    assert list(rows) == ["n_events", "mean_load_speed", "mean_motor_speed", "efficiency"]
    assert rows["efficiency"]["value"] == pytest.approx(pt["efficiency"], rel=1e-12)
    assert all(r["ok"] for r in rows.values())


# ---------------------------------------------------------------------------------------------------- slow proofs
@pytest.mark.slow
@pytest.mark.parametrize("name", SCENES)
def test_declared_tolerances_hold_against_a_refined_run(name):
    """Every headline at the scene's defaults (hand path, rtol 1e-9) within its declared tolerance of the same
    scene at rtol 1e-12, atol 1e-14 (1000x tighter), with the same number of events."""
    sc = load_scene(f"drives/{name}")
    assert sc.solver.engine == "reference"
    v0 = run_values(sc.to_dict())
    vf = run_values(sc.replace(solver={"rtol": 1e-12, "atol": 1e-14}).to_dict())
    assert v0["n_events"] == vf["n_events"]
    for h in declared(sc):
        assert math.isfinite(v0[h.name]), h.name
        assert abs(v0[h.name] - vf[h.name]) <= h.tol, (h.name, v0[h.name], vf[h.name], h.tol)


@pytest.mark.slow
@pytest.mark.parametrize("name,engine,heads", [
    ("step_up_pwm", "reference", ("mean_load_speed", "mean_motor_speed")),
])
def test_estimate_brackets_the_true_error(name, engine, heads):
    """The estimate against the true error (hand path: rtol 1e-12; MuJoCo: 1/16 of the step) on headlines whose
    error is well above round-off: true <= estimate <= 10 x true. Measured ratios (scripts/drives_accuracy.py):
    step_up_pwm hand 3.0 / 1.33."""
    sc = load_scene(f"drives/{name}").replace(solver={"engine": engine})
    est = error_estimate(sc, workers=2)
    fine_sc = (sc.replace(solver={"timestep": sc.solver.timestep / 16, "max_steps": sc.solver.max_steps * 16})
               if engine == "mujoco" else sc.replace(solver={"rtol": 1e-12, "atol": 1e-14}))
    fine = run_values(fine_sc.to_dict())
    for h in heads:
        r = est[h]
        true = abs(r.value - fine[h])
        assert true <= r.error <= 10 * true, (h, r.error, true)


@pytest.mark.slow
def test_mujoco_closed_loop_step_up_flips_a_lock_trial_under_refinement():
    """step_up_closed_loop on MuJoCo: at t = 4.32 s the brake's lock trial on the stopping spring end is a near tie
    (the hand path locks and breaks loose 61 ms later); MuJoCo passes through at 1e-4 s, locks at 5e-5 s: 311 vs 310
    events. The estimate says so by n_events instead of comparing lock-ups of different lists (README, Declared
    accuracy)."""
    sc = load_scene("drives/step_up_closed_loop").replace(solver={"engine": "mujoco"})
    with pytest.raises(AccuracyError, match=r"error_estimate\[n_events\]"):
        mbsuite.run(sc, error_estimate=True, workers=2)
