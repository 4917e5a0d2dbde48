"""Elbow (lower-arm chain) kinematics, Appendix B (Eqs B.1-B.6) of Eppinger (1984).

The pinion (radius le) sits at the elbow C = (l1 cos th1, l1 sin th1); the chain ("fourth bar") runs from the base point
F = (xf, -yf) tangent to the pinion. With t = tan(phi1) the tangency condition B.2 is the quadratic B.3,
    A t^2 + B t + C = 0,  A = (l1 c1 - xf)^2 - le^2,  B = -2 (l1 c1 - xf)(l1 s1 + yf),  C = (l1 s1 + yf)^2 - le^2,
of which B.4 takes the negative root, phi1 = atan2(-B - sqrt(B^2 - 4AC), 2A) (the EQSIM form). The fourth-bar length
B.5 is
    lfb = sqrt((l1 c1 + le sin phi1 - xf)^2 + (l1 s1 - le cos phi1 + yf)^2)
and the pinion rotation B.6 is   theta_e = theta_e0 + (lfb - lfb0)/le - theta_1.
B.6 approximates d(phi1)/d(theta1) = 1 (erratum 22); the exact chain wrap is theta_e = theta_e0 + (lfb - lfb0)/le -
(phi1 - phi1_0).
Derivatives come from implicit differentiation of the quadratic: t' = -(A' t^2 + B' t + C')/(2 A t + B).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import GeometryError
from .params import PantographParams


@dataclass(frozen=True)
class ElbowState:
    """The elbow at one theta_1: theta_e (B.3-B.6) and its derivative dtheta_e/dtheta_1."""
    theta_e: float  #: pinion angle (rad)
    dtheta_e: float  #: d theta_e / d theta_1 (-)
    phi1: float  #: chain angle (rad)
    lfb: float  #: fourth-bar length (m)


def _chain(theta1: float, p: PantographParams) -> tuple[float, float, float]:
    """(phi1, dphi1/dth1, lfb, dlfb/dth1) from B.3-B.5 and their implicit derivatives."""
    c1, s1 = math.cos(theta1), math.sin(theta1)
    X = p.l1 * c1 - p.xf
    Y = p.l1 * s1 + p.yf
    A = X * X - p.le**2
    B = -2.0 * X * Y
    C = Y * Y - p.le**2
    disc = B * B - 4.0 * A * C  # = 4 le^2 (X^2 + Y^2 - le^2)
    if disc <= 0.0 or A == 0.0:
        raise GeometryError(
            f"elbow chain geometry has no tangent line at theta_1 = {theta1:.6g} rad "
            f"(B^2-4AC = {disc:.3g}, A = {A:.3g}):"
            " the chain base point lies inside the pinion circle or the chain is vertical"
        )
    sq = math.sqrt(disc)
    phi1 = math.atan2(-B - sq, 2.0 * A)
    t = math.tan(phi1)
    dX, dY = -p.l1 * s1, p.l1 * c1
    dA, dB, dC = 2 * X * dX, -2.0 * (dX * Y + X * dY), 2 * Y * dY
    dt = -(dA * t * t + dB * t + dC) / (2.0 * A * t + B)
    dphi1 = dt / (1.0 + t * t)
    gx = X + p.le * math.sin(phi1)
    gy = Y - p.le * math.cos(phi1)
    lfb = math.hypot(gx, gy)
    dgx = dX + p.le * math.cos(phi1) * dphi1
    dgy = dY + p.le * math.sin(phi1) * dphi1
    dlfb = (gx * dgx + gy * dgy) / lfb
    return phi1, dphi1, lfb, dlfb


class Elbow:
    """theta_e(theta_1) and its derivative; `exact=False` is the thesis' B.6, `exact=True` the chain-wrap relation."""

    def __init__(self, p: PantographParams, exact: bool = False):
        self.p = p
        self.exact = exact
        self.phi1_0, _, self.lfb0, _ = _chain(0.0, p)

    def __call__(self, theta1: float) -> ElbowState:
        phi1, dphi1, lfb, dlfb = _chain(theta1, self.p)
        if self.exact:
            th = self.p.theta_e0 + (lfb - self.lfb0) / self.p.le - (phi1 - self.phi1_0)
            dth = dlfb / self.p.le - dphi1
        else:
            th = self.p.theta_e0 + (lfb - self.lfb0) / self.p.le - theta1
            dth = dlfb / self.p.le - 1.0
        return ElbowState(th, dth, phi1, lfb)

    def second_derivative(self, theta1: float, h: float = 1e-5) -> float:
        """d^2 theta_e / d theta_1^2 by a central difference of the analytic first derivative (error O(h^2) ~ 1e-10)."""
        return (self(theta1 + h).dtheta_e - self(theta1 - h).dtheta_e) / (2.0 * h)


def theta_e_array(p: PantographParams, theta1: np.ndarray, exact: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(theta_e, d theta_e / d theta_1) for an array of theta_1: the formulas of `Elbow.__call__`, vectorised (for
    post-processing recorded trajectories). Raises GeometryError where the chain has no tangent line."""
    th = np.asarray(theta1, dtype=float)
    c1, s1 = np.cos(th), np.sin(th)
    X = p.l1 * c1 - p.xf
    Y = p.l1 * s1 + p.yf
    A = X * X - p.le**2
    B = -2.0 * X * Y
    C = Y * Y - p.le**2
    disc = B * B - 4.0 * A * C
    bad = (disc <= 0.0) | (A == 0.0)
    if np.any(bad):
        Elbow(p, exact)(float(th[np.argmax(bad)]))  # raises GeometryError with the full message
    sq = np.sqrt(disc)
    phi1 = np.arctan2(-B - sq, 2.0 * A)
    t = (-B - sq) / (2.0 * A)
    dX, dY = -p.l1 * s1, p.l1 * c1
    dt = -(2 * X * dX * t * t - 2.0 * (dX * Y + X * dY) * t + 2 * Y * dY) / (2.0 * A * t + B)
    dphi1 = dt / (1.0 + t * t)
    sp, cp = np.sin(phi1), np.cos(phi1)
    gx, gy = X + p.le * sp, Y - p.le * cp
    lfb = np.sqrt(gx * gx + gy * gy)
    dlfb = (gx * (dX + p.le * cp * dphi1) + gy * (dY + p.le * sp * dphi1)) / lfb
    e0 = Elbow(p, exact)
    if exact:
        return p.theta_e0 + (lfb - e0.lfb0) / p.le - (phi1 - e0.phi1_0), dlfb / p.le - dphi1
    return p.theta_e0 + (lfb - e0.lfb0) / p.le - th, dlfb / p.le - 1.0
