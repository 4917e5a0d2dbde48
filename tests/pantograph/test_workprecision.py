"""The pantograph's work-precision study (quick mode): errors against the reference fall as settings tighten at the
expected rates, and the reference is checked against a second method."""

from __future__ import annotations

import pytest

from mbsuite import load_scene
from mbsuite.analysis.workprecision import find_row as _row
from mbsuite.analysis.workprecision import workprecision


@pytest.fixture(scope="module")
def panto():
    return workprecision(load_scene("pantograph"), repeats=1, quick=True)


def test_pantograph_reference_checked_and_orders(panto):
    d = panto.data
    assert d["check_physics_error"] < 1e-8 and d["check_state_error"] < 1e-8  # Radau vs DOP853 at rtol 1e-12
    r1, r2 = _row(panto, "mujoco", "rk4", 1e-3), _row(panto, "mujoco", "rk4", 5e-4)
    # RK4 with the half-step input hold: second order in h (README), so halving h divides the error by ~4
    assert 2.5 < r1["physics_error"] / r2["physics_error"] < 6
    e1, e2 = _row(panto, "mujoco", "implicitfast", 1e-3), _row(panto, "mujoco", "implicitfast", 5e-4)
    assert 1.5 < e1["physics_error"] / e2["physics_error"] < 2.5  # first order
    assert r1["physics_error"] < e1["physics_error"]  # RK4 beats the Euler family at equal step
    dop = _row(panto, "reference", "DOP853", 1e-6)
    assert dop["physics_error"] < 1e-5 and dop["state_error"] < 1e-4
    for r in d["rows"]:
        assert r["error"] is None and r["time_min"] <= r["time_s"] <= r["time_max"]


