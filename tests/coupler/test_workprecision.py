"""The coupler's work-precision study (quick mode): errors against the reference fall as settings tighten."""

from __future__ import annotations

from mbsuite import load_scene
from mbsuite.analysis.workprecision import find_row as _row
from mbsuite.analysis.workprecision import workprecision


def test_coupler_fpp_tolerance_and_mujoco_step():
    rep = workprecision(load_scene("coupler/double_lateral"), repeats=1, quick=True)
    loose, tight = _row(rep, "fpp", "gauss-newton", "tol 0.0001, 37 steps"), _row(rep, "fpp", "gauss-newton",
                                                                                  "tol 1e-08, 37 steps")
    assert tight["physics_error"] < 1e-3 * loose["physics_error"]
    assert tight["details"]["closure_residual"] <= 1e-8  # the Gauss-Newton tolerance bounds the residual
    a, b = _row(rep, "mujoco", "implicitfast", 1e-3), _row(rep, "mujoco", "implicitfast", 5e-4)
    assert b["state_error"] < a["state_error"]
