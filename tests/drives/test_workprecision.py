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
    # step_up_pwm has no output torque: no efficiency to compare (the metric is left out, not a vacuous 0)
    assert set(hand["details"]) == {"load_speed_rel", "lock_time_rel", "n_locks_ref"}
    # measured (quick mode, 1 s): hand rtol 1e-6 1.0e-7, MuJoCo rk4 1e-4 s 8.5e-6, the reference's rtol 1e-11 check
    # 2.3e-10; bounds 10x, 6x, 8.5x
    assert hand["physics_error"] < 1e-6 and mj["physics_error"] < 5e-5
    assert rep.data["check_physics_error"] < 2e-9
