"""Work-precision studies (quick mode): errors against the reference fall as settings tighten at the expected rates,
the reference is checked against a second method, and the cheapest-setting table is right."""

from __future__ import annotations

import math

import pytest

from mbsuite import load_scene
from mbsuite.analysis.workprecision import Row, cheapest, workprecision


def _row(rep, engine, method, setting):
    rows = [r for r in rep.data["rows"] if (r["engine"], r["method"], r["setting"]) == (engine, method, setting)]
    assert len(rows) == 1
    return rows[0]


def test_coupler_fpp_tolerance_and_mujoco_step():
    rep = workprecision(load_scene("coupler/double_lateral"), repeats=1, quick=True)
    loose, tight = _row(rep, "fpp", "gauss-newton", "tol 0.0001, 37 steps"), _row(rep, "fpp", "gauss-newton",
                                                                                  "tol 1e-08, 37 steps")
    assert tight["physics_error"] < 1e-3 * loose["physics_error"]
    assert tight["details"]["closure_residual"] <= 1e-8  # the Gauss-Newton tolerance bounds the residual
    a, b = _row(rep, "mujoco", "implicitfast", 1e-3), _row(rep, "mujoco", "implicitfast", 5e-4)
    assert b["state_error"] < a["state_error"]


def test_drives_paths_against_exact_reference():
    rep = workprecision(load_scene("drives/step_up_pwm"), repeats=1, quick=True)
    hand = _row(rep, "reference", "event-exact DOP853", 1e-6)
    mj = _row(rep, "mujoco", "rk4", 1e-4)
    assert hand["details"]["n_locks_ref"] > 0  # lock-ups are compared, not an empty metric
    assert hand["physics_error"] < 1e-4 and mj["physics_error"] < 1e-3
    assert rep.data["check_physics_error"] < 1e-6


def test_cheapest_picks_the_fastest_row_meeting_each_tolerance():
    rows = [Row("a", "x", 1, 1.0, 1.0, 1.0, 0.1, 1e-3), Row("a", "x", 2, 0.5, 0.5, 0.5, 0.1, 5e-2),
            Row("b", "y", 3, 2.0, 2.0, 2.0, 0.1, 1e-7), Row("b", "y", 4, 0.1, 0.1, 0.1, math.nan, math.nan)]
    best = {(b["tol"], b["engine"]): b for b in cheapest(rows)}
    assert best[(1e-2, "any")]["setting"] == 1  # 2 is faster but misses 1e-2; NaN never qualifies
    assert best[(1e-4, "any")]["setting"] == 3
    assert best[(1e-6, "a")]["setting"] is None


def test_unknown_model_is_a_clear_error():
    from mbsuite import MbsuiteError

    with pytest.raises(MbsuiteError, match="no work-precision study"):
        workprecision(load_scene("catenary"), repeats=1, quick=True)
    with pytest.raises(MbsuiteError, match="four-bar"):
        workprecision(load_scene("iftomm/bricard"), repeats=1, quick=True)


def test_fourbar_against_closed_form():
    rep = workprecision(load_scene("iftomm/fourbar"), repeats=1, quick=True)
    pin = _row(rep, "pinocchio", "DOP853", 1e-6)
    mj = _row(rep, "mujoco", "rk4", 1e-3)
    assert pin["state_error"] < 1e-4  # the branch-reduced Pinocchio path follows the closed form
    assert mj["details"]["branch_rad"] < 0.01 and mj["state_error"] < 0.05  # MuJoCo stays on the branch (2 s)
