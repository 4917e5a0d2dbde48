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

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import ParameterError
from ...limits import Limit, positive
from ...schema import Rule, Section

#: every input of the design tools, declared once (SI units); each tool's `Section` below takes its keys from here
INPUT_LIMITS: dict[str, Limit] = {
    "P": positive("W", "design power"),
    "Sr_min": positive("1/s", "lowest switching rate (Eq 5.1)"),
    "w_min": Limit(lo=0.0, unit="rad/s", doc="lowest load speed"),
    "w_max": positive("rad/s", "highest load speed"),
    "w_rip": positive("rad/s", "allowed speed ripple"),
    "V_m": positive("rad/s", "motor speed"),
    "J_s": positive("kg m^2", "spring-system inertia"),
    "J_l": positive("kg m^2", "load inertia"),
    "tau_c": positive("N m", "clutch torque"),
    "K": positive("N m/rad", "spring rate"),
    "x_max": positive("rad", "largest spring twist"),
    "fatigue": Limit(lo=0.0, lo_open=True, hi=1.0, unit="1", doc="fatigue factor: allowed stress / sigma_uts"),
    "sigma_uts": positive("Pa", "ultimate tensile stress"),
    "E": positive("Pa", "Young's modulus"),
    "U": positive("1", "spring energy utilisation factor"),
    "t_s": positive("s", "energy-cycle period 1/Sr"),
    "B_total": Limit(lo=0.0, unit="N m s/rad", doc="total viscous loss coefficient"),
    "tau_l": Limit(lo=0.0, unit="N m", doc="Coulomb load torque"),
    "w0": Limit(unit="rad/s", doc="operating speed (nonzero)"),
    "Kp": positive("J/(rad/s)^2", "proportional gain"),
    "Ki": Limit(lo=0.0, unit="J/(rad/s)^2/s", doc="integral gain"),
}


def _below(lo: str, hi: str, why: str) -> Rule:
    def test(c: dict[str, Any]) -> str | None:
        return None if c[lo] < c[hi] else f"{lo} = {c[lo]:g} rad/s must be below {hi} = {c[hi]:g} rad/s ({why})"
    return Rule(f"{lo} < {hi} ({why})", test)


W0_NONZERO = Rule("w0 nonzero (the operating speed)",
                  lambda c: None if c["w0"] != 0 else f"w0 (operating speed) = {c['w0']!r} rad/s must be nonzero")


def _tool(title: str, keys: tuple[str, ...], rules: tuple[Rule, ...] = (), **own: Limit) -> Section:
    """The inputs of one design tool: `keys` from `INPUT_LIMITS` (or `own`), all required."""
    return Section(title, {k: own.get(k, INPUT_LIMITS.get(k)) for k in keys}, required=keys, rules=rules)


SRMIN_INPUTS = _tool("srmin (Eq 5.1)", ("P", "w_min", "w_rip", "J_l"),
                     w_min=positive("rad/s", "lowest load speed (divides Eq 5.1)"))
DESIGN_POINT_INPUTS = _tool("CADJS design point (Eqs 5.9-5.13)", ("P", "Sr_min", "w_min", "w_max", "V_m", "J_s"),
                            (_below("w_min", "w_max", "the load speed range"),))
CLUTCH_TORQUE_INPUTS = _tool("CADJS at a clutch torque", ("P", "Sr_min", "w_min", "w_max", "V_m", "tau_c"),
                             (_below("w_min", "w_max", "the load speed range"),))
SPRING_INPUTS = _tool("springsz (Eqs 5.14-5.21)", ("K", "x_max", "fatigue", "sigma_uts", "E", "U"))
PLANT_INPUTS = _tool("discrete controller model (Eqs 5.25-5.37)", ("J_l", "t_s", "B_total", "tau_l", "w0"),
                     (W0_NONZERO,))
B_TOTAL_INPUTS = _tool("B_total (Eq 5.38)", ("P", "w0", "tau_l"), (W0_NONZERO,))
GAIN_INPUTS = _tool("closed-loop gains", ("Kp", "Ki"))


def _checked(section: Section, **values: Any) -> tuple[float, ...]:
    """`values` checked by `section` (a ParameterError naming the key, its value, the valid range and the unit), as
    Python floats in the order given."""
    out = section.check(values, section.title, ParameterError)
    return tuple(out[k] for k in values)


def srmin(P: float, w_min: float, w_rip: float, J_l: float) -> float:
    """Eq 5.1: Sr_min = P / (w_min w_rip J_l)."""
    P, w_min, w_rip, J_l = _checked(SRMIN_INPUTS, P=P, w_min=w_min, w_rip=w_rip, J_l=J_l)
    return P / (w_min * w_rip * J_l)


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
    P, Sr_min, w_min, w_max, V_m, J_s = _checked(DESIGN_POINT_INPUTS, P=P, Sr_min=Sr_min, w_min=w_min, w_max=w_max,
                                                 V_m=V_m, J_s=J_s)
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
    P, Sr_min, w_min, w_max, V_m, tau_c = _checked(CLUTCH_TORQUE_INPUTS, P=P, Sr_min=Sr_min, w_min=w_min,
                                                   w_max=w_max, V_m=V_m, tau_c=tau_c)
    f = lambda js: design_point(P, Sr_min, w_min, w_max, V_m, js).tau_c - tau_c  # noqa: E731
    lo, hi = 1e-8, 1e-1
    if f(lo) > 0 or f(hi) < 0:
        raise ParameterError(f"clutch torque {tau_c} N m is outside the family for Sr_min = {Sr_min}")
    from scipy.optimize import brentq  # here: the design module is read by the command line's help

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
    K, x_max, fatigue, sigma_uts, E, U = _checked(SPRING_INPUTS, K=K, x_max=x_max, fatigue=fatigue,
                                                  sigma_uts=sigma_uts, E=E, U=U)
    sf = fatigue * sigma_uts
    d = (32 * K * K * x_max * x_max / (U * sf * sf * math.pi**2)) ** (1 / 6)
    DN = d**4 * E / (64 * K)
    V = E / (U * sf * sf) * 0.5 * K * x_max**2
    return {"d": d, "DN": DN, "V": V, "V_check": math.pi**2 * DN * d * d}


# ---- discrete controller model and gains -----------------------------------------------------------------------------
def _plant_args(J_l: float, t_s: float, B_total: float, tau_l: float, w0: float) -> tuple[float, ...]:
    return _checked(PLANT_INPUTS, J_l=J_l, t_s=t_s, B_total=B_total, tau_l=tau_l, w0=w0)


def plant_AB(J_l: float, t_s: float, B_total: float, tau_l: float, w0: float) -> tuple[float, float]:
    """Eq 5.25: G(z) = A / (z - 1 + B), A = 2/J_l, B = t_s/J_l (2 B_total + tau_l / x0^(1/2)), x0 = w0^2."""
    J_l, t_s, B_total, tau_l, w0 = _plant_args(J_l, t_s, B_total, tau_l, w0)
    return 2.0 / J_l, t_s / J_l * (2 * B_total + tau_l / abs(w0))


def gains(J_l: float, t_s: float, B_total: float, tau_l: float, w0: float) -> tuple[float, float]:
    """Eqs 5.32-5.37: K_p = J_l/2 - t_s (B_total + tau_l / (2 x0^(1/2))) (one pole at the origin) and the largest
    K_I = J_l / (2 t_s) keeping the other pole on the positive real axis. A non-positive K_p (dissipation per cycle
    above the load's kinetic energy: open loop unstable, (5.27)) is an error."""
    J_l, t_s, B_total, tau_l, w0 = _plant_args(J_l, t_s, B_total, tau_l, w0)
    kp = J_l / 2 - t_s * (B_total + tau_l / (2 * abs(w0)))
    if kp <= 0:
        raise ParameterError(f"no positive K_p: t_s (B_total + tau_l/(2|w0|)) = {J_l / 2 - kp:.4g} >= J_l/2 = "
                             f"{J_l / 2:.4g} (open-loop pole outside the unit circle, Eq 5.27)")
    return kp, J_l / (2 * t_s)


def b_total(P: float, w0: float, tau_l: float) -> float:
    """Eq 5.38: B_total = (P/w0 - tau_l) / w0 (all power not spent on the load is viscous loss at w0)."""
    P, w0, tau_l = _checked(B_TOTAL_INPUTS, P=P, w0=w0, tau_l=tau_l)
    bt = (P / abs(w0) - tau_l) / abs(w0)
    if bt < 0:
        raise ParameterError(f"B_total = (P/|w0| - tau_l)/|w0| = {bt:.4g} < 0: the load torque {tau_l} N m takes more "
                             f"than the power P = {P} W at w0 = {w0} rad/s")
    return bt


def closed_loop_poles(Kp: float, Ki: float, J_l: float, t_s: float, B_total: float, tau_l: float, w0: float
                      ) -> np.ndarray:
    """Roots of Eq 5.31: z^2 + z (B - 2 + Kp A / C) + 1 - B - Kp A, C = Kp / (Kp + Ki t_s)."""
    A, B = plant_AB(J_l, t_s, B_total, tau_l, w0)
    Kp, Ki = _checked(GAIN_INPUTS, Kp=Kp, Ki=Ki)
    t_s = float(t_s)
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
