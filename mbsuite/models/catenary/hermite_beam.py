"""Cubic Hermite elements of a tensioned Euler-Bernoulli beam (nodal DOFs w, theta = dw/dx). Per element of length h
(Przemieniecki / Cook, "Concepts and Applications of FE Analysis", ch. 16 and 18):

    K_e = EI/h^3 [[12, 6h, -12, 6h], [6h, 4h^2, -6h, 2h^2], [-12, -6h, 12, -6h], [6h, 2h^2, -6h, 4h^2]]      (bending)
        + T/(30h) [[36, 3h, -36, 3h], [3h, 4h^2, -3h, -h^2], [-36, -3h, 36, -3h], [3h, -h^2, -3h, 4h^2]]   (geometric)
    M_e = rho h/420 [[156, 22h, 54, -13h], [22h, 4h^2, 13h, -3h^2], [54, 13h, 156, -22h], [-13h, -3h^2, -22h, 4h^2]]

and the exact static point compliance of the continuous tensioned beam (`tensioned_beam_compliance`) that the
point-load correction compares them with.
"""

from __future__ import annotations

import math

import numpy as np


def beam_stiffness(EI: float, T: float, h: float) -> np.ndarray:
    """Bending + geometric (tension) stiffness of a cubic Hermite element (module docstring)."""
    kb = EI / h**3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                               [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]])
    kg = T / (30 * h) * np.array([[36, 3 * h, -36, 3 * h], [3 * h, 4 * h * h, -3 * h, -h * h],
                                  [-36, -3 * h, 36, -3 * h], [3 * h, -h * h, -3 * h, 4 * h * h]])
    return kb + kg


def beam_mass(rho: float, h: float) -> np.ndarray:
    """Consistent mass matrix of a cubic Hermite element (module docstring)."""
    return rho * h / 420 * np.array([[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                                     [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]])


def beam_load(q: float, h: float) -> np.ndarray:
    """Consistent nodal load of a uniform distributed load q (N/m) on a Hermite element."""
    return q * np.array([h / 2, h * h / 12, h / 2, -h * h / 12])


def hermite(xi: float, h: float) -> np.ndarray:
    """Hermite shape functions at local coordinate xi in [0, 1] on an element of length h: w = N . [w1, t1, w2, t2]."""
    x2, x3 = xi * xi, xi * xi * xi
    return np.array([1 - 3 * x2 + 2 * x3, h * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, h * (x3 - x2)])


def tensioned_beam_compliance(a: float, L: float, T: float, EI: float) -> float:
    """Static deflection at x = a under a unit point force at x = a of a pinned-pinned tensioned Euler-Bernoulli beam
    of length L (EI w'''' - T w'' = delta(x - a), w = w'' = 0 at both ends), in closed form:

        w(a) = [a (L - a) / L - sinh(lam a) sinh(lam (L - a)) / (lam sinh(lam L))] / T,      lam = sqrt(T / EI),

    the string's deflection less the bending boundary layer's; EI = 0 is the string. Written with expm1 so that it
    holds for lam L >> 1: the sinh quotient is (1 - e^(-2 lam a)) (1 - e^(-2 lam (L - a))) / (2 lam (1 - e^(-2 lam L))).
    """
    s = a * (L - a) / L
    if EI > 0.0:
        lam = math.sqrt(T / EI)
        s -= (-math.expm1(-2 * lam * a)) * (-math.expm1(-2 * lam * (L - a))) / (2 * lam * (-math.expm1(-2 * lam * L)))
    return s / T
