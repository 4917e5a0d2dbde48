"""The Bricard (A04) on both paths: MuJoCo (soft connects, redundant rows) against the Pinocchio path (penalty
formulation, DOP853 rtol 1e-8), 2 s from rest under gravity."""

from __future__ import annotations

import numpy as np
import pytest

import mbsuite


@pytest.fixture(scope="module")
def bricard():
    sc = mbsuite.load_scene("iftomm/bricard").replace(solver={"duration": 2.0})
    return mbsuite.run(sc), mbsuite.run(sc, engine="reference")


def test_bricard_mujoco_against_pinocchio(bricard):
    mj, pin = bricard
    assert np.array_equal(mj.t, pin.t)
    # it moves: joint 1 swings over 4.19 rad in the first 2 s
    assert np.ptp(pin["input_angle"]) > 4.0
    # joint 1, MuJoCo against Pinocchio: measured 6.13e-4 rad over 2 s (the soft closures' dissipation); 3.3x
    assert np.max(np.abs(mj["input_angle"] - pin["input_angle"])) < 2e-3


def test_bricard_symmetric_motion_on_both_paths(bricard):
    """The orthogonal Bricard released from the cube pose moves symmetrically, q1 + q3 = 0 (the branch figure)."""
    mj, pin = bricard
    # measured 4.30e-4 rad (MuJoCo), 3.02e-7 rad (Pinocchio: the penalty closure error, 3e-7 m); 3.5x / 6.6x
    assert mj.statistics["branch_angle_max"] < 1.5e-3
    assert pin.statistics["branch_angle_max"] < 2e-6
