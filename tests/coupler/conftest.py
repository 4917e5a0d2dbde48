"""Shared by the coupler's dissipation checks (test_dissipation.py, test_dynamics.py): the S joints' relative
motion over a revolution from the rigid mechanism's FPP (the reference path's kinematics, not MuJoCo's).

The S joint of link k is a ball at its driving point; its relative angular velocity is the rate of the link direction
d_k in the driving shaft's own frame, w_k = d_k x d_k' (the spin about the link is free: no torque drives it). From
the FPP, d_k' = w_a dd_k/dphi_a (central differences of converged poses)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mbsuite.models.coupler.double import double_points, ramp_double, solve_double
from mbsuite.models.coupler.geometry import NEXT, rot_y
from mbsuite.models.coupler.params import CouplerParams

TURN = np.array([1.0, 0, 0, 0, 0, 1.0, 0, 0])  # phi_c and phi_b advance with phi_a


def _directions(p: CouplerParams, rest: np.ndarray, phi: float, u: np.ndarray) -> np.ndarray:
    """(8, 3) unit link directions in their driving shaft's frame: links 1-4 in shaft a's R_y(phi_a), links 5-8 in
    shaft c's R_c (Eqs 2, 6-7)."""
    a, ba, bc, c, _, _, _, Rc = double_points(p, np.r_[phi, rest], u)
    l1, l2 = ba[NEXT] - a, bc[NEXT] - c
    l1 = l1 / np.linalg.norm(l1, axis=1)[:, None]
    l2 = l2 / np.linalg.norm(l2, axis=1)[:, None]
    return np.vstack([l1 @ rot_y(phi), l2 @ Rc])


def _z_to(d: np.ndarray, frm: np.ndarray | None = None) -> np.ndarray:
    """The minimal rotation taking `frm` (default +z) onto d."""
    frm = np.array([0.0, 0.0, 1.0]) if frm is None else frm
    ax = np.cross(frm, d)
    s = np.linalg.norm(ax)
    return np.eye(3) if s < 1e-15 else Rotation.from_rotvec(ax / s * math.atan2(s, float(frm @ d))).as_matrix()


def _swing(p: CouplerParams, rest: np.ndarray, n: int = 144, h: float = 1e-5) -> tuple[float, float]:
    """Means over one revolution (n points of phi_a) of sum_k |dd_k/dphi_a|^2 and of sum_k (|w_x| + |w_y|) / w_a, the
    relative angular velocity in the link's own frame (z along the link, as the model files mount it: the minimal
    rotation from +z at the aligned pose, carried along by the minimal rotation to the current direction; MuJoCo's
    friction acts on each of the ball's three axes)."""
    d0 = _directions(p, np.zeros(4), 0.0, ramp_double(p, np.zeros(5)))
    frames0 = [_z_to(d) for d in d0]
    u = ramp_double(p, np.r_[0.0, rest])
    sq, ab = [], []
    for phi in np.linspace(0.0, 2 * math.pi, n, endpoint=False):
        u = solve_double(p, np.r_[phi, rest], u)
        d = _directions(p, rest, phi, u)
        dd = (_directions(p, rest, phi + h, solve_double(p, np.r_[phi + h, rest], u))
              - _directions(p, rest, phi - h, solve_double(p, np.r_[phi - h, rest], u))) / (2 * h)
        w = np.cross(d, dd)
        sq.append(float(np.sum(dd**2)))
        ab.append(sum(float(np.sum(np.abs((_z_to(d[k], d0[k]) @ frames0[k]).T @ w[k])[:2])) for k in range(8)))
        u = u + 2 * math.pi / n * TURN
    return float(np.mean(sq)), float(np.mean(ab))


@pytest.fixture(scope="session")
def swing() -> tuple[float, float]:
    """`_swing` of the shipped lateral scenes' kinematics (default design, z_c = 0.05): 48 points (measured against
    144: sum |dd/dphi|^2 equal to 1e-10, the friction mean within 5e-4 relative)."""
    return _swing(CouplerParams(), np.array([0.0, 0.0, 0.0, 0.05]), n=48)
