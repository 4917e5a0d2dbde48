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
Every criterion is an extremum of a smooth periodic function of phi_a located between the samples (`refined_extremum`:
bounded Brent search on the FPP), not read off the grid; the grid of `n` samples only brackets the extrema, so the
values do not depend on it (to ~1e-12). The means are taken over one period without the closing sample
(`periodic_mean`). `SAMPLES_SINGLE`, `SAMPLES_DOUBLE`: the one default grid of every entry point (`single_criteria`,
`double_c5`, `analysis.criteria_report`, `mbsuite coupler criteria`).
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
#: samples per revolution bracketing the extrema (single coupler, double coupler): one default for every entry point
SAMPLES_SINGLE, SAMPLES_DOUBLE = 121, 61
#: Brent's tolerance on the location of c2-c4's extrema [rad]: a location off by dx changes the value at a peak by
#: |g''| dx^2 / 2, below 1e-14 of the amplitude here (c1 and c5 keep 1e-12: their location is reported)
XATOL_VALUE = 1e-7


def link_angles(R_P: np.ndarray, lhat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(beta1, beta2) of unit link vectors lhat (k, 3) at a platform with rotation R_P (module docstring)."""
    u = lhat @ R_P
    return np.arctan2(u[:, 2], u[:, 0]), np.arcsin(np.clip(u[:, 1], -1, 1))


def pose_angles(p: CouplerParams, phi_a: float, alpha_bx: float, alpha_bz: float,
                u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """beta1, beta2 at one pose: arrays (8,) = 4 links at end A, then the 4 at end B."""
    a, b, _, Rb = single_points(p, phi_a, alpha_bx, alpha_bz, u)
    lv = b[NEXT] - a
    lh = lv / np.linalg.norm(lv, axis=1)[:, None]
    x1, x2 = link_angles(rot_y(phi_a), lh)
    y1, y2 = link_angles(Rb, lh)
    return np.r_[x1, y1], np.r_[x2, y2]


def single_angles(p: CouplerParams, rev: SingleRevolution) -> tuple[np.ndarray, np.ndarray]:
    """beta1, beta2 over the revolution: arrays (n, 8) = 4 links x (end A, end B)."""
    b1, b2 = zip(*(pose_angles(p, phi, rev.alpha_bx, rev.alpha_bz, u) for phi, u in zip(rev.phi_a, rev.u,
                                                                                         strict=True)), strict=True)
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


def refined_extremum(g, phis: np.ndarray, vals: np.ndarray, guess_at, sign: float,
                     xatol: float = 1e-12) -> tuple[float, float]:
    """The extremum (sign = +1: maximum, -1: minimum) of a smooth periodic g(phi_a) sampled as `vals` at `phis` (closed
    grid): the best sample is refined by bounded Brent minimisation of -sign g over its two neighbouring intervals
    (scipy `minimize_scalar`, `xatol` in rad), each evaluation an FPP solve started from `guess_at(phi)`. The
    sampled maximum misses a peak between samples by ~g'' (dphi/2)^2 / 2 (0.55 % for c5 with 61 samples); the
    refined value is the peak to rounding. Returns (phi at the extremum, value)."""
    from scipy.optimize import minimize_scalar

    i = int(np.argmax(sign * vals[:-1]))
    dphi = phis[1] - phis[0]
    lo, hi = phis[i] - dphi, phis[i] + dphi
    res = minimize_scalar(lambda x: -sign * g(x, guess_at(x)), bounds=(lo, hi), method="bounded",
                          options={"xatol": xatol})
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


def located_range(g, phis: np.ndarray, vals: np.ndarray, guess_at) -> float:
    """max - min of a smooth periodic g sampled as `vals` on the closed grid `phis`, both extrema located between the
    samples (`refined_extremum`)."""
    return (refined_extremum(g, phis, vals, guess_at, 1.0, XATOL_VALUE)[1]
            - refined_extremum(g, phis, vals, guess_at, -1.0, XATOL_VALUE)[1])


def located_max_abs(g, phis: np.ndarray, D: np.ndarray, guess_at) -> float:
    """max over the columns j of D (n, m) and the revolution of |g_j|, g(phi, guess) -> (m,) smooth and periodic,
    sampled as D on the closed grid `phis`. A sampled extremum y1 with neighbours y0, y2 misses its peak by about
    |y0 - 2 y1 + y2| / 8 (|g''| (dphi / 2)^2 / 2); every (column, sign) whose sample plus twice that reaches the
    largest value found so far is located between the samples (`refined_extremum`), largest bound first."""
    m = D.shape[0] - 1  # the closing sample repeats the first
    cands = []
    for j in range(D.shape[1]):
        for sign in (1.0, -1.0):
            y = sign * D[:m, j]
            i = int(np.argmax(y))
            cands.append((y[i] + abs(y[i - 1] - 2 * y[i] + y[(i + 1) % m]) / 4, j, sign))
    out = float(np.max(np.abs(D[:m])))
    for bound, j, sign in sorted(cands, reverse=True):
        if bound < out:
            break
        _, v = refined_extremum(lambda x, guess, j=j: float(g(x, guess)[j]), phis, D[:, j], guess_at, sign,
                                XATOL_VALUE)
        out = max(out, sign * v)
    return out


def _single_pose_fns(p: CouplerParams, rev: SingleRevolution):
    """(guess_at, pose) of a solved revolution: the pose guessed linearly between its samples at any phi_a, and the
    FPP solved from a guess at phi_a (the revolution's inclination)."""
    per = rev.u - np.outer(rev.phi_a, [1.0, 0.0, 0.0, 0.0])  # the 2 pi-periodic part of the pose

    def guess_at(x: float) -> np.ndarray:
        return np.array([np.interp(x, rev.phi_a, per[:, j], period=2 * math.pi) for j in range(4)]) + [x, 0, 0, 0]

    def pose(x: float, guess: np.ndarray) -> np.ndarray:
        return solve_single(p, x, rev.alpha_bx, rev.alpha_bz, guess).u

    return guess_at, pose


def single_c1(p: CouplerParams, rev: SingleRevolution) -> dict:
    """c1 = max |(phi_a - phi_b) - mean| over a solved revolution, its extrema located between the samples (dict of
    `_fluctuation`: c, pp, mean, phi_a_at, c_sampled)."""
    guess_at, pose = _single_pose_fns(p, rev)
    return _fluctuation(lambda x, guess: x - pose(x, guess)[0], rev.phi_a, rev.phi_a - rev.u[:, 0], guess_at)


def revolution_angles(p: CouplerParams, alpha_b: float, n: int) -> dict:
    """The single coupler over one revolution at inclination alpha_b (= alpha_bx), n samples: `rev`, the link angles'
    deviations from the aligned pose `dbeta1`, `dbeta2` (n, 8), and the aligned pose's angles `aligned` (beta1_0,
    beta2_0, each (8,))."""
    rev = single_revolution(p, alpha_b, 0.0, n)
    b10, b20 = (b[0] for b in single_angles(p, single_revolution(p, 0.0, 0.0, 3)))
    b1, b2 = single_angles(p, rev)
    return {"rev": rev, "dbeta1": _dev(b1, b10), "dbeta2": b2 - b20, "aligned": (b10, b20)}


def single_criteria(p: CouplerParams, alpha_b: float, n: int = SAMPLES_SINGLE) -> dict:
    """c1-c4 of the single coupler for inclination alpha_b (= alpha_bx) over one revolution, every extremum located
    between the n samples (`refined_extremum`); the sampled values `c1_sampled` ... `c4_sampled` are kept beside."""
    r = revolution_angles(p, alpha_b, n)
    rev, db1, db2, (b10, b20) = r["rev"], r["dbeta1"], r["dbeta2"], r["aligned"]
    guess_at, pose = _single_pose_fns(p, rev)

    def dev1(x: float, guess: np.ndarray) -> np.ndarray:
        return _dev(pose_angles(p, x, alpha_b, 0.0, pose(x, guess))[0], b10)

    def dev2(x: float, guess: np.ndarray) -> np.ndarray:
        return pose_angles(p, x, alpha_b, 0.0, pose(x, guess))[1] - b20

    fl = single_c1(p, rev)
    return {
        "c1": fl["c"], "c1_pp": fl["pp"], "c1_sampled": fl["c_sampled"], "mean_phi_a_minus_phi_b": fl["mean"],
        "c2": located_range(lambda x, gs: pose(x, gs)[1], rev.phi_a, rev.u[:, 1], guess_at),
        "c2_z": located_range(lambda x, gs: pose(x, gs)[3], rev.phi_a, rev.u[:, 3], guess_at),
        "c3": located_max_abs(dev1, rev.phi_a, db1, guess_at), "c4": located_max_abs(dev2, rev.phi_a, db2, guess_at),
        "c2_sampled": float(np.ptp(rev.u[:, 1])), "c3_sampled": float(np.max(np.abs(db1))),
        "c4_sampled": float(np.max(np.abs(db2))), "samples": n,
        **r,
    }


def double_c5(p: CouplerParams, z_c: float, alpha_cx: float = 0.0, alpha_cz: float = 0.0, x_c: float = 0.0,
              n: int = SAMPLES_DOUBLE) -> dict:
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

    def gb(x: float, guess: np.ndarray) -> float:
        return x - solve_double(p, np.concatenate([[x], rest]), guess)[5]

    fl = _fluctuation(g, rev.phi_a, d, guess_at)
    return {"c5": fl["c"], "c5_pp": fl["pp"], "c5_sampled": fl["c_sampled"], "mean": fl["mean"],
            "phi_a_at_c5": fl["phi_a_at"], "c1_intermediate": _fluctuation(gb, rev.phi_a, db, guess_at)["c"],
            "samples": n, "rev": rev}


def revolutions(p: CouplerParams, alphas: Sequence[float] = FIG_ALPHAS, n: int = 181) -> list[dict]:
    """`revolution_angles` at each inclination alpha_b, with the inclination as "alpha_b" (the data of Figs 6-8; n: the
    samples of the drawn curves)."""
    return [revolution_angles(p, a, n) | {"alpha_b": a} for a in alphas]
