"""The pantograph's work-precision study (quick mode: lab at 4.25 Hz, Coulomb off, 1 s): the reference is checked
against a second method, every setting's error against it is bounded, and the errors fall with the step at the
methods' orders (RK4 with the half-step ram hold: second; implicitfast: first)."""

from __future__ import annotations

import math

import pytest

from mbsuite import load_scene
from mbsuite.analysis.workprecision import find_row as _row
from mbsuite.analysis.workprecision import workprecision


@pytest.fixture(scope="module")
def panto():
    return workprecision(load_scene("pantograph"), repeats=1, quick=True)


def test_reference_agrees_with_a_second_method(panto):
    """Radau rtol 1e-12 (the reference) against DOP853 rtol 1e-12: measured physics 9.9e-13, state 8.3e-11 (/A)."""
    d = panto.data
    assert d["check_physics_error"] < 1e-11  # 10x
    assert d["check_state_error"] < 1e-9  # 12x


# (engine, method, setting): measured physics error, state error (/A) against the Radau reference; each bound is
# about 3x the measured value
BOUNDS = {
    ("mujoco", "implicitfast", 1e-3): (2e-2, 1e-1),      # measured 7.7e-3, 3.2e-2
    ("mujoco", "implicitfast", 5e-4): (1e-2, 5e-2),      # measured 3.9e-3, 1.6e-2
    ("mujoco", "rk4", 1e-3): (1.5e-4, 3.5e-4),           # measured 5.2e-5, 1.15e-4
    ("mujoco", "rk4", 5e-4): (4e-5, 9e-5),               # measured 1.3e-5, 2.9e-5
    ("reference", "DOP853", 1e-4): (1e-6, 2.5e-5),       # measured 2.1e-7, 7.2e-6
    ("reference", "DOP853", 1e-6): (5e-7, 1.5e-5),       # measured 1.3e-7, 4.2e-6; below rtol itself
}


@pytest.mark.parametrize("key", list(BOUNDS), ids=lambda k: f"{k[0]}-{k[1]}-{k[2]:g}")
def test_every_setting_within_its_measured_error(panto, key):
    row = _row(panto, *key)
    physics, state = BOUNDS[key]
    assert row["error"] is None
    assert row["physics_error"] < physics and row["state_error"] < state


@pytest.mark.parametrize("method,order,slack", [
    # RK4 with the ram held at t_k + h/2: second order in h (README). Measured p = 1.994 (physics), 1.995 (state)
    ("rk4", 2, 0.05),
    # implicitfast (the Euler family): first order. Measured p = 0.979 (physics), 0.985 (state)
    ("implicitfast", 1, 0.1),
])
def test_errors_fall_at_the_method_order(panto, method, order, slack):
    """Halving h from 1 ms to 0.5 ms divides the error by 2^p: the observed order p = log2(e(h) / e(h/2)) lies within
    `slack` of the method's order (slack about 8x / 5x the measured deviation)."""
    coarse, fine = _row(panto, "mujoco", method, 1e-3), _row(panto, "mujoco", method, 5e-4)
    for what in ("physics_error", "state_error"):
        p = math.log2(coarse[what] / fine[what])
        assert abs(p - order) < slack, (what, p)


def test_rk4_beats_the_euler_family_at_equal_step(panto):
    """At h = 1 ms RK4's physics error is 150x below implicitfast's (5.2e-5 against 7.7e-3); asserted 20x."""
    rk4, imp = _row(panto, "mujoco", "rk4", 1e-3), _row(panto, "mujoco", "implicitfast", 1e-3)
    assert 20 * rk4["physics_error"] < imp["physics_error"]
