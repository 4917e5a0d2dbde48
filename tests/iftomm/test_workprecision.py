"""The IFToMM four-bar's work-precision study (quick mode) against its closed form on the parallelogram branch."""

from __future__ import annotations

from mbsuite import load_scene
from mbsuite.analysis.workprecision import find_row as _row
from mbsuite.analysis.workprecision import workprecision


def test_fourbar_against_closed_form():
    rep = workprecision(load_scene("iftomm/fourbar"), repeats=1, quick=True)
    pin = _row(rep, "pinocchio", "DOP853", 1e-6)
    mj = _row(rep, "mujoco", "rk4", 1e-3)
    assert pin["state_error"] < 1e-4  # the branch-reduced Pinocchio path follows the closed form
    assert mj["details"]["branch_rad"] < 0.01 and mj["state_error"] < 0.05  # MuJoCo stays on the branch (2 s)
