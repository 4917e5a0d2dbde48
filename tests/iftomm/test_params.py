"""Every IFToMM parameter and the input at a non-default value, each against a closed form or the other path:
gravity and the initial rate against the four-bar's closed form on the parallelogram branch (both paths) and the
hand-computed energy scale, the MuJoCo closures' time constant against the closed form, and the Pinocchio penalty
factor and closure frequency against the scaling of the penalty formulation's closure error, r ~ 1 / (p w^2)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbsuite
from mbsuite.models.iftomm.mujoco import initial_velocity, mujoco_model


def _closed_form(g: float, rate: float, t: np.ndarray) -> np.ndarray:
    """Crank angle from upright on the parallelogram branch: psi'' = -(6/5) g cos psi (M = (1/3 + 1/3 + 1) m L^2,
    V = 2 m g L sin psi), psi(0) = pi/2, psi'(0) = rate; returned as psi - pi/2 (the crank joint's angle)."""
    sol = solve_ivp(lambda _, x: [x[1], -1.2 * g * math.cos(x[0])], (0.0, float(t[-1])), [math.pi / 2, rate],
                    method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
    return sol.y[0] - math.pi / 2


def _fourbar(params: dict, rate: float, paths: tuple[str, ...] = ("mujoco", "reference")):
    sc = mbsuite.load_scene("iftomm/fourbar").replace(solver={"duration": 1.0}, params=params,
                                                        input={"type": "initial", "rate": rate})
    return sc, *(mbsuite.run(sc, engine=e) if e in paths else None for e in ("mujoco", "reference"))


# (params, rate, g, bound MuJoCo, bound Pinocchio [rad]); measured over 1 s: MuJoCo 7.93e-4 / 4.60e-4 rad,
# Pinocchio (DOP853 rtol 1e-8) 4.53e-8 / 2.27e-8 rad; bounds 3.8x / 4.3x (MuJoCo), 4.4x (Pinocchio)
CASES = [({"gravity": 3.71}, 6.0, 3.71, 3e-3, 2e-7), ({}, -4.0, 9.81, 2e-3, 1e-7)]


@pytest.mark.parametrize("params, rate, g, bound_mj, bound_pin", CASES, ids=["gravity_3.71", "rate_-4"])
def test_gravity_and_rate_against_the_closed_form_on_both_paths(params, rate, g, bound_mj, bound_pin):
    """Martian gravity, and the crank started backwards at 4 rad/s: both paths against the closed form; the energy
    scale E_kin(0) + 3 m g L with E_kin(0) = (1/2)(5/3) m L^2 rate^2 (41.13 J and 42.76 J)."""
    _, mj, pin = _fourbar(params, rate)
    assert np.max(np.abs(mj["input_angle"] - _closed_form(g, rate, mj.t))) < bound_mj
    assert np.max(np.abs(pin["input_angle"] - _closed_form(g, rate, pin.t))) < bound_pin
    for r in (mj, pin):
        assert r.statistics["energy_scale"] == pytest.approx(0.5 * (5.0 / 3.0) * rate**2 + 3 * g, rel=1e-12)
        assert r["input_rate"][0] == pytest.approx(rate, rel=1e-12)


@pytest.mark.parametrize("mechanism, rate", [("fourbar", -2.5), ("bricard", 0.7)])
def test_initial_rates_lie_on_the_free_motion_with_the_input_joint_at_the_rate(mechanism, rate):
    """The input joint turns at `rate` and the closures' velocity constraint holds: the four-bar's parallelogram
    moves as (r, -r, r) (closed form); the Bricard's rates lie in the null space of its 6 x 5 closure Jacobian,
    joints 1, 3, 5 turning by +-the same rate (the symmetric motion q1 + q3 = 0). Measured 1e-15; bound 1e-12."""
    import mujoco

    m = mujoco_model(mechanism, 1e-3, "rk4", 0.004, 9.81)
    v = initial_velocity(m, rate)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    J = d.efc_J.reshape(d.nefc, m.nv)[d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY]
    assert v[0] == pytest.approx(rate, rel=1e-12)
    assert np.max(np.abs(J @ v)) < 1e-12 * abs(rate)
    if mechanism == "fourbar":
        np.testing.assert_allclose(v, [rate, -rate, rate], rtol=0, atol=1e-12)
    else:
        assert abs(v[0] + v[2]) < 1e-12 and abs(abs(v[4]) - abs(rate)) < 1e-12


def test_mujoco_closure_time_constant_against_the_closed_form():
    """solref_timeconst 2 ms (half the default; the smallest the 1 ms step allows): the stiffer closures lose less
    energy. MuJoCo against the closed form over 1 s: measured 3.18e-4 rad (2 ms), 1.55e-3 rad (4 ms): bound 8e-4
    (2.5x). The closure gap of a soft constraint grows as timeconst^2: measured 2.11e-5 m vs 8.07e-5 m at 4 ms
    (ratio 3.8, closed form 4): bounds 3 and 5."""
    _, mj2, _ = _fourbar({"solref_timeconst": 0.002}, 6.0, paths=("mujoco",))  # MuJoCo's setting: refused elsewhere
    sc4 = mbsuite.load_scene("iftomm/fourbar").replace(solver={"duration": 1.0})
    mj4 = mbsuite.run(sc4)
    assert np.max(np.abs(mj2["input_angle"] - _closed_form(9.81, 6.0, mj2.t))) < 8e-4
    ratio = mj4.statistics["closure_residual_max"] / mj2.statistics["closure_residual_max"]
    assert 3.0 < ratio < 5.0


@pytest.fixture(scope="module")
def bricard_penalties() -> dict:
    sc = mbsuite.load_scene("iftomm/bricard").replace(solver={"duration": 0.3})
    return {(p, w): mbsuite.run(sc.replace(params={"penalty": p, "penalty_omega": w}), engine="reference")
            for p, w in ((1e7, 10.0), (1e5, 10.0), (1e7, 30.0))} | {"mujoco": mbsuite.run(sc)}


def test_penalty_factor_and_frequency_against_the_closure_error_scaling(bricard_penalties):
    """The penalty formulation holds r'' + 2 w r' + w^2 r = O(1/p): the Bricard's closure gap scales as 1/(p w^2).
    p 100x smaller: 100x the gap (measured 85.7 over 0.3 s); w 3x larger: 1/9 of it (measured 8.37). Bounds [70, 130]
    and [7, 11]. The motion itself is the MuJoCo path's (joint 1 within 1e-5 rad: measured 2.0e-6 over 0.3 s, 5x)."""
    r = {k: v.statistics["closure_residual_max"] for k, v in bricard_penalties.items() if k != "mujoco"}
    assert 70.0 < r[(1e5, 10.0)] / r[(1e7, 10.0)] < 130.0
    assert 7.0 < r[(1e7, 10.0)] / r[(1e7, 30.0)] < 11.0
    mj = bricard_penalties["mujoco"]
    for k in r:
        assert np.max(np.abs(bricard_penalties[k]["input_angle"] - mj["input_angle"])) < 1e-5
