"""The coupler's work-precision study (quick mode): errors against the reference fall as settings tighten, at the
rates the methods promise."""

from __future__ import annotations

import math

from mbsuite import load_scene
from mbsuite.analysis.workprecision import find_row as _row
from mbsuite.analysis.workprecision import workprecision


def test_coupler_fpp_tolerance_and_mujoco_step():
    rep = workprecision(load_scene("coupler/double_lateral"), repeats=1, quick=True)
    loose, tight = _row(rep, "fpp", "gauss-newton", "tol 0.0001, 37 steps"), _row(rep, "fpp", "gauss-newton",
                                                                                  "tol 1e-08, 37 steps")
    # the Gauss-Newton stopping tolerance bounds the residual (measured 3.0e-6 at 1e-4, 2.3e-10 at 1e-8)
    assert loose["details"]["closure_residual"] <= 1e-4 and tight["details"]["closure_residual"] <= 1e-8
    # and the pose error against scipy's least_squares follows (measured 1.5e-5 and 1.1e-9 rad/R; bound 5-10x)
    assert loose["state_error"] < 1e-4 and tight["state_error"] < 1e-8
    # implicitfast is first order in the timestep: error ratio 1 ms / 0.5 ms = 2^p, measured p = 1.17 (5.65e-3 ->
    # 2.51e-3, against RK4 at 0.1 ms); p = 1 +- 0.4 rules out a stalled (p ~ 0) or a second-order-looking (p ~ 2) study
    a, b = _row(rep, "mujoco", "implicitfast", 1e-3), _row(rep, "mujoco", "implicitfast", 5e-4)
    assert 0.6 < math.log2(a["state_error"] / b["state_error"]) < 1.4


def test_friction_scene_study_holds_the_friction_model_and_converges():
    """double_friction (quick: implicitfast at 1 ms and 0.5 ms against RK4 at 0.1 ms): the study sets the friction
    time constant to 2 ms, 2x the largest timestep, for every MuJoCo setting and its reference, so the settings
    converge toward one model. The settled wind-up (phi_c - phi_c,kin) max, where the S joints' friction shows, relative
    to the reference: measured 5.8e-5 (1 ms) and 1.6e-5 (0.5 ms), bounds 3e-4 and 1e-4 (5-6x); with the time constant
    following the timestep (2 h: three friction models) 2.1e-3 and 8.9e-4. The state error is first order: measured
    p = 1.17, bound 1 +- 0.4 (as double_lateral)."""
    rep = workprecision(load_scene("coupler/double_friction"), repeats=1, quick=True)
    assert "friction time constant 0.002 s as every MuJoCo setting" in rep.data["reference"]
    a, b = _row(rep, "mujoco", "implicitfast", 1e-3), _row(rep, "mujoco", "implicitfast", 5e-4)
    assert a["details"]["phi_c_err_rel"] < 3e-4 and b["details"]["phi_c_err_rel"] < 1e-4
    assert b["details"]["phi_c_err_rel"] < a["details"]["phi_c_err_rel"]
    assert 0.6 < math.log2(a["state_error"] / b["state_error"]) < 1.4
