"""Chapter 5 design tools (Oldaker 1997 §5.1-5.3, App. I toolbox), with the corrected equations of drives.md §5.

* `srmin` (5.1): minimum switching rate from the ripple specification.
* `cadjs` (5.9-5.11, 5.13 corrected): for each spring-system inertia J_s the spring rate K, clutch torque, maximum
  extension and maximum switching rate; `at_clutch_torque` reads the family at a given clutch torque (Tables 5.2, 6.2).
* `js_from_k` (5.12 corrected): J_s for a given K (quadratic with a spurious root rejected by (5.11)).
* `springsz` (5.14-5.21): wire diameter, D*N and volume of a helical torsion spring with a fatigue factor.
* Discrete controller model (5.22-5.25), gain selection (5.32-5.37) and the stability line (5.36).
Assumptions of the component-selection model (Sec. 5.1.1): frictionless, instant clutches, constant motor speed.
For w_l < V_m the residual extension (5.8) is clamped at x_s = 0 ([DERIVED]; reproduces the tables).
"""

from __future__ import annotations

import decimal
import math
import numbers
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import brentq

from ...errors import ParameterError


def _real(name: str, v: Any) -> float:
    """`v` as a float: any real number (int, float, numpy scalar or 0-d array, Fraction, Decimal); a bool, string,
    complex or array is a ParameterError naming `name`."""
    if isinstance(v, np.ndarray) and v.ndim == 0:
        v = v[()]
    if isinstance(v, bool | np.bool_) or not isinstance(v, numbers.Real | decimal.Decimal):
        raise ParameterError(f"{name} must be a real number, got {v!r}")
    return float(v)


def _pos(name: str, v: Any) -> float:
    x = _real(name, v)
    if not (math.isfinite(x) and x > 0):
        raise ParameterError(f"{name} must be a positive number, got {v!r}")
    return x


def srmin(P: float, w_min: float, w_rip: float, J_l: float) -> float:
    """Eq 5.1: Sr_min = P / (w_min w_rip J_l)."""
    return _pos("P", P) / (_pos("w_min", w_min) * _pos("w_rip", w_rip) * _pos("J_l", J_l))


def _W(w_l: float, V_m: float) -> float:
    return max(0.0, w_l * w_l - V_m * V_m)  # x_s = 0 for w_l < V_m


def k_from_js(P: float, Sr: float, w_l: float, V_m: float, J_s: float) -> float:
    """Eq 5.11 (corrected): K = [Sr sqrt(J_s) A + sqrt(2 P Sr + J_s W Sr^2)]^2 / V_m^2, A = 2 pi V_m - sqrt(W)."""
    W = _W(w_l, V_m)
    A = 2 * math.pi * V_m - math.sqrt(W)
    return (Sr * math.sqrt(J_s) * A + math.sqrt(2 * P * Sr + J_s * W * Sr * Sr)) ** 2 / V_m**2


def js_from_k(P: float, Sr: float, w_l: float, V_m: float, K: float) -> float:
    """Eq 5.12 (corrected): a J_s^2 + b J_s + c = 0; the root satisfying (5.11) is returned."""
    W = _W(w_l, V_m)
    A = 2 * math.pi * V_m - math.sqrt(W)
    Bq = 2 * P * Sr - V_m**2 * K
    a = Sr**4 * (W - A * A) ** 2
    b = 2 * Sr**2 * (W - A * A) * Bq - 4 * A * A * V_m**2 * K * Sr**2
    c = Bq * Bq
    roots = np.roots([a, b, c]) if a != 0 else np.array([-c / b])
    good = [float(r.real) for r in roots if abs(r.imag) < 1e-12 * max(1.0, abs(r.real)) and r.real > 0]
    good = [r for r in good if abs(k_from_js(P, Sr, w_l, V_m, r) - K) <= 1e-6 * K]
    if not good:
        raise ParameterError(f"no spring-system inertia gives K = {K} N m/rad at Sr = {Sr}, P = {P}")
    return good[0]


def sr_from_kjs(P: float, w_l: float, V_m: float, K: float, J_s: float) -> float:
    """Eq 5.13 (corrected): a Sr^2 + b Sr + c = 0 with a = J_s (W - A^2), b = 2 V_m sqrt(K J_s) A + 2 P,
    c = -K V_m^2; positive root."""
    W = _W(w_l, V_m)
    A = 2 * math.pi * V_m - math.sqrt(W)
    a = J_s * (W - A * A)
    b = 2 * V_m * math.sqrt(K * J_s) * A + 2 * P
    c = -K * V_m**2
    if abs(a) < 1e-300:
        return -c / b
    disc = b * b - 4 * a * c
    roots = [(-b + s * math.sqrt(disc)) / (2 * a) for s in (1, -1)] if disc >= 0 else []
    pos = [r for r in roots if r > 0]
    if not pos:
        raise ParameterError(f"no positive switching rate for K = {K}, J_s = {J_s} at w_l = {w_l}")
    return min(pos)


def x_f(P: float, Sr: float, w_l: float, V_m: float, K: float, J_s: float) -> float:
    """Eq 5.9: maximum extension x_f = sqrt(2P/(Sr K) + J_s W / K)."""
    return math.sqrt(2 * P / (Sr * K) + J_s * _W(w_l, V_m) / K)


@dataclass
class Design:
    """One CADJS design point: spring-system inertia J_s [kg m^2], spring rate K [N m/rad], highest
    switching rate Sr_max [1/s], clutch torque tau_c [N m], largest twist x_max [rad] (Eqs 5.9-5.13 corrected)."""
    J_s: float
    K: float
    Sr_max: float
    x_max: float
    tau_c: float

    @property
    def capacity(self) -> float:
        """Spring capacity 1/2 K x_max^2 [J]."""
        return 0.5 * self.K * self.x_max**2


def design_point(P: float, Sr_min: float, w_min: float, w_max: float, V_m: float, J_s: float) -> Design:
    """One CADJS point: K at (w_min, Sr_min) (5.11), Sr_max at w_max (5.13), x_max (5.9) and tau_c = K x_max (5.10)."""
    P, Sr_min, w_max, V_m, J_s = (_pos(nm, v) for nm, v in (("P", P), ("Sr_min", Sr_min), ("w_max", w_max),
                                                              ("V_m", V_m), ("J_s", J_s)))
    w_min = _real("w_min", w_min)
    if not (math.isfinite(w_min) and w_min >= 0):
        raise ParameterError(f"w_min must be a number >= 0, got {w_min!r}")
    if not w_min < w_max:
        raise ParameterError(f"w_min = {w_min:g} rad/s must be below w_max = {w_max:g} rad/s (the load speed range)")
    K = k_from_js(P, Sr_min, w_min, V_m, J_s)
    Sr = sr_from_kjs(P, w_max, V_m, K, J_s)
    x = x_f(P, Sr, w_max, V_m, K, J_s)
    return Design(J_s, K, Sr, x, K * x)


def cadjs(P: float, Sr_min: float, w_min: float, w_max: float, V_m: float, J_s=None) -> list[Design]:
    """CADJS: the family over J_s (default 1e-5 ... 1e-4 as the toolbox)."""
    J_s = np.arange(1, 11) * 1e-5 if J_s is None else np.atleast_1d(J_s)
    return [design_point(P, Sr_min, w_min, w_max, V_m, float(j)) for j in J_s]


def at_clutch_torque(P: float, Sr_min: float, w_min: float, w_max: float, V_m: float, tau_c: float) -> Design:
    """The CADJS family read at a given clutch torque (how Tables 5.2 and 6.2 were read off the plots)."""
    f = lambda js: design_point(P, Sr_min, w_min, w_max, V_m, js).tau_c - tau_c  # noqa: E731
    lo, hi = 1e-8, 1e-1
    if f(lo) > 0 or f(hi) < 0:
        raise ParameterError(f"clutch torque {tau_c} N m is outside the family for Sr_min = {Sr_min}")
    js = brentq(f, lo, hi, xtol=1e-14, rtol=1e-12)
    return design_point(P, Sr_min, w_min, w_max, V_m, js)


# ---- spring sizing ---------------------------------------------------------------------------------------------------
SIGMA_UTS_CALIBRATED = 1.465e9  # Pa: calibrated so that the 100 W design gives the thesis' V = 1.58e-4 m^3 (Sec. 6.3)
E_TABLE_6_3 = 209e9  # Pa: implied by the Table 6.3 spring via (5.14): d 3.43 mm, D 27.81 mm, N 12.3, K 1.32 N m/rad


def springsz(K: float, x_max: float, fatigue: float = 0.25, sigma_uts: float = SIGMA_UTS_CALIBRATED,
             E: float = E_TABLE_6_3, U: float = 1 / 8) -> dict[str, float]:
    """SPRINGSZ (5.14-5.21) for a material (sigma_uts, E): allowed stress sf = fatigue * sigma_uts,
    V = E/(U sf^2) 1/2 K x^2 (5.19), d = (32 K^2 x^2 / (U sf^2 pi^2))^(1/6) (5.21), DN = d^4 E / (64 K) (5.14, equal
    to (5.20)). The thesis prints no material data. The defaults are not a material: E = 209 GPa is implied by the
    Table 6.3 spring ([DERIVED]) and sigma_uts = 1.465 GPa is a *calibration*, backed out of the recommended volume
    1.58e-4 m^3 for the 100 W design (Sec. 6.3) - so that volume is reproduced by construction, not predicted."""
    K, x_max, sigma_uts, E, U = (_pos(nm, v) for nm, v in (("K", K), ("x_max", x_max), ("sigma_uts", sigma_uts),
                                                           ("E", E), ("U", U)))
    fatigue = _real("fatigue factor", fatigue)
    if not 0 < fatigue <= 1:
        raise ParameterError(f"fatigue factor must be in (0, 1], got {fatigue!r}")
    sf = fatigue * sigma_uts
    d = (32 * K * K * x_max * x_max / (U * sf * sf * math.pi**2)) ** (1 / 6)
    DN = d**4 * E / (64 * K)
    V = E / (U * sf * sf) * 0.5 * K * x_max**2
    return {"d": d, "DN": DN, "V": V, "V_check": math.pi**2 * DN * d * d}


# ---- discrete controller model and gains -----------------------------------------------------------------------------
def _plant_args(J_l: float, t_s: float, B_total: float, tau_l: float, w0: float) -> None:
    _pos("J_l", J_l)
    _pos("t_s", t_s)
    for nm, v in (("B_total", B_total), ("tau_l", tau_l)):
        if not (math.isfinite(_real(nm, v)) and v >= 0):
            raise ParameterError(f"{nm} must be a number >= 0, got {v!r}")
    if not (math.isfinite(_real("w0", w0)) and w0 != 0):
        raise ParameterError(f"w0 (operating speed) must be a nonzero number, got {w0!r}")


def plant_AB(J_l: float, t_s: float, B_total: float, tau_l: float, w0: float) -> tuple[float, float]:
    """Eq 5.25: G(z) = A / (z - 1 + B), A = 2/J_l, B = t_s/J_l (2 B_total + tau_l / x0^(1/2)), x0 = w0^2."""
    _plant_args(J_l, t_s, B_total, tau_l, w0)
    J_l, t_s, B_total, tau_l, w0 = (float(x) for x in (J_l, t_s, B_total, tau_l, w0))
    return 2.0 / J_l, t_s / J_l * (2 * B_total + tau_l / abs(w0))


def gains(J_l: float, t_s: float, B_total: float, tau_l: float, w0: float) -> tuple[float, float]:
    """Eqs 5.32-5.37: K_p = J_l/2 - t_s (B_total + tau_l / (2 x0^(1/2))) (one pole at the origin) and the largest
    K_I = J_l / (2 t_s) keeping the other pole on the positive real axis. A non-positive K_p (dissipation per cycle
    above the load's kinetic energy: open loop unstable, (5.27)) is an error."""
    _plant_args(J_l, t_s, B_total, tau_l, w0)
    J_l, t_s, B_total, tau_l, w0 = (float(x) for x in (J_l, t_s, B_total, tau_l, w0))
    kp = J_l / 2 - t_s * (B_total + tau_l / (2 * abs(w0)))
    if kp <= 0:
        raise ParameterError(f"no positive K_p: t_s (B_total + tau_l/(2|w0|)) = {J_l / 2 - kp:.4g} >= J_l/2 = "
                             f"{J_l / 2:.4g} (open-loop pole outside the unit circle, Eq 5.27)")
    return kp, J_l / (2 * t_s)


def b_total(P: float, w0: float, tau_l: float) -> float:
    """Eq 5.38: B_total = (P/w0 - tau_l) / w0 (all power not spent on the load is viscous loss at w0)."""
    _pos("P", P)
    _plant_args(1.0, 1.0, 0.0, tau_l, w0)
    bt = (P / abs(w0) - tau_l) / abs(w0)
    if bt < 0:
        raise ParameterError(f"B_total = (P/|w0| - tau_l)/|w0| = {bt:.4g} < 0: the load torque {tau_l} N m takes more "
                             f"than the power P = {P} W at w0 = {w0} rad/s")
    return bt


def closed_loop_poles(Kp: float, Ki: float, J_l: float, t_s: float, B_total: float, tau_l: float, w0: float
                      ) -> np.ndarray:
    """Roots of Eq 5.31: z^2 + z (B - 2 + Kp A / C) + 1 - B - Kp A, C = Kp / (Kp + Ki t_s)."""
    A, B = plant_AB(J_l, t_s, B_total, tau_l, w0)
    _pos("Kp", Kp)
    if not (math.isfinite(Ki) and Ki >= 0):
        raise ParameterError(f"Ki must be a number >= 0, got {Ki!r}")
    C = Kp / (Kp + Ki * t_s)
    return np.roots([1.0, B - 2 + Kp * A / C, 1 - B - Kp * A])


def stability_kp(Ki: float, J_l: float, t_s: float, B_total: float, tau_l: float, w0: float) -> float:
    """Eq 5.36: the marginal K_p (pole at z = -1) for a given K_I: K_p = (2 - B)/A - K_I t_s / 2."""
    A, B = plant_AB(J_l, t_s, B_total, tau_l, w0)
    return (2 - B) / A - Ki * t_s / 2


def energy_cycle_response(Kp: float, Ki: float, J_l: float, t_s: float, B_total: float, tau_l: float, r: float,
                          n: int = 60, eps_max: float = np.inf) -> np.ndarray:
    """Iterate the nonlinear per-cycle model (5.22) under the discrete PI (5.29) with the bi-directional
    velocity-squared error; returns the load speed at each energy cycle (starting from rest)."""
    w = 0.0
    eps = 0.0
    e_prev = 0.0
    out = [w]
    for _ in range(n):
        e = math.copysign(1.0, r) * (abs(r) * r - abs(w) * w)
        eps = max(-eps_max, min(eps_max, eps + (Kp + Ki * t_s) * e - Kp * e_prev))
        e_prev = e
        ke = 0.5 * J_l * w * w + eps - t_s * B_total * w * w - t_s * tau_l * abs(w)
        w = math.copysign(math.sqrt(max(ke, 0.0) * 2 / J_l), r if w == 0 else w)
        out.append(w)
    return np.array(out)
