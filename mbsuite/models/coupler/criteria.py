"""Quality criteria c1-c5 of the single and double coupler over one revolution (Maniowski & Czauderna, Eqs 16-20,
Figs 6-10).

Definitions (README has the discussion):
- c1 = max |(phi_a - phi_b) - mean| over a revolution (Eq 16 without the pi/2 mounting offset); c1_pp = peak-to-peak.
- c2 = max(x_b) - min(x_b) (Eq 17); the z-range is also reported (the path of O_b is a closed curve).
- beta1/beta2 (Fig 3c is not in the text): at each end of each link, with u = R_P^T l_hat the link direction in the
  platform P's own frame (y = platform normal), beta2 = asin(u_y) is the elevation out of the platform plane and
  beta1 = atan2(u_z, u_x) the azimuth in the platform plane. c3 = max |beta1 - beta1_0|, c4 = max |beta2 - beta2_0|
  (deviations from the aligned pose, i.e. the bushing deflection), maxima over links, both ends and the revolution.
- c5 = max |(phi_a - phi_c) - mean| (Eq 20 without the constant offset -phi_bc).
c1 and c5 are the extrema of a smooth periodic function located between the samples (`refined_extremum`), the mean is
taken over one period without the closing sample (`periodic_mean`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .double import DOUBLE_TURN, double_revolution, solve_double
from .geometry import NEXT, rot_y
from .params import CouplerParams
from .single import SingleRevolution, single_points, single_revolution, solve_single

#: inclinations alpha_b [rad] of Figs 6-8 (1, 2 and 3 degrees)
FIG_ALPHAS = (0.0175, 0.035, 0.0525)


def link_angles(R_P: np.ndarray, lhat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(beta1, beta2) of unit link vectors lhat (k, 3) at a platform with rotation R_P (module docstring)."""
    u = lhat @ R_P
    return np.arctan2(u[:, 2], u[:, 0]), np.arcsin(np.clip(u[:, 1], -1, 1))


def single_angles(p: CouplerParams, rev: SingleRevolution) -> tuple[np.ndarray, np.ndarray]:
    """beta1, beta2 over the revolution: arrays (n, 8) = 4 links x (end A, end B)."""
    b1, b2 = [], []
    for phi, u in zip(rev.phi_a, rev.u, strict=True):
        a, b, _, Rb = single_points(p, phi, rev.alpha_bx, rev.alpha_bz, u)
        lv = b[NEXT] - a
        lh = lv / np.linalg.norm(lv, axis=1)[:, None]
        x1, x2 = link_angles(rot_y(phi), lh)
        y1, y2 = link_angles(Rb, lh)
        b1.append(np.r_[x1, y1])
        b2.append(np.r_[x2, y2])
    return np.array(b1), np.array(b2)


def _dev(x: np.ndarray, x0: np.ndarray) -> np.ndarray:
    return (x - x0 + math.pi) % (2 * math.pi) - math.pi


def periodic_mean(values: np.ndarray) -> float:
    """Mean over one period of samples at phi_a = phi_0 + 2 pi k / (n - 1), k = 0..n-1, whose last sample closes the
    revolution (the same pose as the first): the closing sample is left out, so no point counts twice. For a smooth
    periodic function this rectangle rule on the open grid is spectrally accurate (it is exact for every harmonic
    below n - 1), unlike a trapezoid over the closed grid counted naively."""
    v = np.asarray(values, float)
    return float(v[:-1].mean())


def refined_extremum(g, phis: np.ndarray, vals: np.ndarray, guess_at, sign: float) -> tuple[float, float]:
    """The extremum (sign = +1: maximum, -1: minimum) of a smooth periodic g(phi_a) sampled as `vals` at `phis` (closed
    grid): the best sample is refined by bounded Brent minimisation of -sign g over its two neighbouring intervals
    (scipy `minimize_scalar`, xatol 1e-12 rad), each evaluation an FPP solve started from `guess_at(phi)`. The
    sampled maximum misses a peak between samples by ~g'' (dphi/2)^2 / 2 (0.55 % for c5 with 61 samples); the
    refined value is the peak to rounding. Returns (phi at the extremum, value)."""
    from scipy.optimize import minimize_scalar

    i = int(np.argmax(sign * vals[:-1]))
    dphi = phis[1] - phis[0]
    lo, hi = phis[i] - dphi, phis[i] + dphi
    res = minimize_scalar(lambda x: -sign * g(x, guess_at(x)), bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-12})
    val = -sign * float(res.fun)
    if sign * val < sign * vals[i]:  # never below the best sample (a flat, rounding-level g)
        return float(phis[i]), float(vals[i])
    return float(res.x), val


def _fluctuation(g, phis: np.ndarray, d: np.ndarray, guess_at) -> dict:
    """c = max |d - mean| over the revolution with both extrema of d refined (`refined_extremum`), and the mean by
    `periodic_mean`."""
    mean = periodic_mean(d)
    phi_hi, hi = refined_extremum(g, phis, d, guess_at, 1.0)
    phi_lo, lo = refined_extremum(g, phis, d, guess_at, -1.0)
    c, at = (hi - mean, phi_hi) if hi - mean >= mean - lo else (mean - lo, phi_lo)
    return {"c": float(c), "pp": float(hi - lo), "mean": mean, "phi_a_at": float(at),
            "c_sampled": float(np.max(np.abs(d - mean)))}


def single_criteria(p: CouplerParams, alpha_b: float, n: int = 181) -> dict:
    """c1-c4 of the single coupler for inclination alpha_b (= alpha_bx) over one revolution; c1 with its extrema
    refined between samples (`refined_extremum`), c2-c4 the sampled extremes."""
    rev = single_revolution(p, alpha_b, 0.0, n)
    nom = single_revolution(p, 0.0, 0.0, 3)
    b10, b20 = single_angles(p, nom)
    b1, b2 = single_angles(p, rev)
    d = rev.phi_a - rev.u[:, 0]
    db1, db2 = _dev(b1, b10[0]), b2 - b20[0]

    def guess_at(x: float) -> np.ndarray:
        i = int(np.argmin(np.abs(rev.phi_a - x)))
        return rev.u[i] + np.array([x - rev.phi_a[i], 0.0, 0.0, 0.0])

    def g(x: float, guess: np.ndarray) -> float:
        return x - solve_single(p, x, alpha_b, 0.0, guess).u[0]

    fl = _fluctuation(g, rev.phi_a, d, guess_at)
    return {
        "c1": fl["c"], "c1_pp": fl["pp"], "c1_sampled": fl["c_sampled"], "mean_phi_a_minus_phi_b": fl["mean"],
        "c2": float(np.ptp(rev.u[:, 1])), "c2_z": float(np.ptp(rev.u[:, 3])),
        "c3": float(np.max(np.abs(db1))), "c4": float(np.max(np.abs(db2))),
        "rev": rev, "dbeta1": db1, "dbeta2": db2,
    }


def double_c5(p: CouplerParams, z_c: float, alpha_cx: float = 0.0, alpha_cz: float = 0.0, x_c: float = 0.0,
              n: int = 91) -> dict:
    """c5 = max |(phi_a - phi_c) - mean| of the double coupler over one revolution (Eq 20 without the constant -phi_bc):
    n samples by continuation, then both extrema of phi_a - phi_c refined between samples (`refined_extremum`; at
    phi_bc = pi/2 the peaks sit at phi_a = k 45 deg). Also the sampled value `c5_sampled`, the peak-to-peak
    fluctuation, the mean (`periodic_mean`), the input angle of the extremum, and the intermediate shaft's c1."""
    rev = double_revolution(p, alpha_cx, alpha_cz, x_c, z_c, n)
    rest = np.array([alpha_cx, alpha_cz, x_c, z_c], float)
    d = rev.phi_a - rev.u[:, 0]
    db = rev.phi_a - rev.u[:, 5]
    slope = DOUBLE_TURN / (2 * math.pi)

    def guess_at(x: float) -> np.ndarray:
        i = int(np.argmin(np.abs(rev.phi_a - x)))
        return rev.u[i] + (x - rev.phi_a[i]) * slope

    def g(x: float, guess: np.ndarray) -> float:
        return x - solve_double(p, np.concatenate([[x], rest]), guess)[0]

    fl = _fluctuation(g, rev.phi_a, d, guess_at)
    return {"c5": fl["c"], "c5_pp": fl["pp"], "c5_sampled": fl["c_sampled"], "mean": fl["mean"],
            "phi_a_at_c5": fl["phi_a_at"], "c1_intermediate": float(np.max(np.abs(db - periodic_mean(db)))),
            "rev": rev}


def revolutions(p: CouplerParams, alphas: Sequence[float] = FIG_ALPHAS, n: int = 181) -> list[dict]:
    """`single_criteria` at each inclination alpha_b, with the inclination as "alpha_b" (the data of Figs 6-8)."""
    return [single_criteria(p, a, n) | {"alpha_b": a} for a in alphas]
