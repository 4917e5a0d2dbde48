"""The drives' work-precision study (quick mode): errors against the reference fall as settings tighten."""

from __future__ import annotations

from mbsuite import load_scene
from mbsuite.analysis.workprecision import find_row as _row
from mbsuite.analysis.workprecision import workprecision


def test_drives_paths_against_exact_reference():
    rep = workprecision(load_scene("drives/step_up_pwm"), repeats=1, quick=True)
    hand = _row(rep, "reference", "event-exact DOP853", 1e-6)
    mj = _row(rep, "mujoco", "rk4", 1e-4)
    assert hand["details"]["n_locks_ref"] > 0  # lock-ups are compared, not an empty metric
    assert hand["physics_error"] < 1e-4 and mj["physics_error"] < 1e-3
    assert rep.data["check_physics_error"] < 1e-6
