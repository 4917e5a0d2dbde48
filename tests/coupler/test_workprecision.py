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
