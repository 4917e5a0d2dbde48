"""Brecknell-Willis pantograph parameters: Table 3-I of Eppinger (1984), SI units.

Angles are measured from the horizontal (Fig 3-3): the lower arm points forward, the upper arm backward, the head
forward.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from ...errors import ParameterError
from ...limits import check_fields, param

#: default laminar band of the orifice: Pd/Pu > R_LAMINAR (band 1e-5), from the convergence study in the README
R_LAMINAR = 0.99999


def critical_ratio(gamma: float) -> float:
    """Critical (choking) pressure ratio Pd/Pu = (2 / (gamma + 1))^(gamma / (gamma - 1)) of an isentropic nozzle."""
    return (2.0 / (gamma + 1.0)) ** (gamma / (gamma - 1.0))


#: the declared lower end of r_laminar: the infimum of `critical_ratio` over the valid gamma in (1, 2), approached as
#: gamma -> 2: (2/3)^2 = 4/9 (the ratio falls with gamma: 0.6065 at gamma -> 1, 0.5283 at 1.4). `__post_init__` holds
#: the real bound, the critical ratio of the parameters' own gamma
R_LAMINAR_LO = critical_ratio(2.0)


def _pos(default: float, unit: str, doc: str, hi: float | None = None) -> float:
    """A parameter > 0 (optionally <= hi)."""
    return param(default, lo=0.0, lo_open=True, hi=hi, unit=unit, doc=doc)


def _nonneg(default: float, unit: str, doc: str, hi: float | None = None) -> float:
    """A parameter >= 0 (optionally <= hi)."""
    return param(default, lo=0.0, hi=hi, unit=unit, doc=doc)


@dataclass(frozen=True)
class PantographParams:
    """Table 3-I of Eppinger (1984). Every field in SI units, declared with its valid range
    (`mbsuite.limits.param`); `__post_init__` checks them, then the geometry across fields."""

    l1: float = _pos(1.95, "m", "lower link length")
    l2: float = _pos(1.95, "m", "upper link length")
    lh: float = _pos(0.40, "m", "head link length, knuckle-to-contact")
    m1: float = param(31.5, lo=1e-6, hi=1e3, unit="kg", doc="lower link mass")
    m2: float = param(25.2, lo=1e-6, hi=1e3, unit="kg", doc="upper link mass")
    mh: float = param(13.5, lo=1e-6, hi=1e3, unit="kg", doc="head mass")
    I1: float = param(11.7, lo=1e-9, hi=1e3, unit="kg m^2", doc="lower link moment of inertia about its centre of mass")
    I2: float = param(8.10, lo=1e-9, hi=1e3, unit="kg m^2", doc="upper link moment of inertia about its centre of mass")
    Ih: float = param(0.432, lo=1e-9, hi=1e3, unit="kg m^2", doc="head moment of inertia about its centre of mass")
    d1: float = _pos(1.10, "m", "base pivot to lower link mass centre (<= l1)")
    d2: float = _pos(0.80, "m", "elbow to upper link mass centre (<= l2)")
    dh: float = _pos(0.35, "m", "knuckle to head mass centre (<= lh)")
    ks: float = _nonneg(180000.0, "N/m", "input (catenary/shoe) spring constant", hi=1e9)
    kh: float = _nonneg(2250.0, "N m/rad", "head spring constant, to the datum")
    ke: float = _nonneg(44640.0, "N m/rad", "elbow stiffness")
    be: float = _nonneg(0.0, "N m s/rad", "elbow viscous damping; not in Table 3-I nor EQSIM, hence 0")
    b1: float = _nonneg(36.0, "N m s/rad", "base viscous damping")
    b2: float = _nonneg(157.5, "N m s/rad", "knuckle viscous damping")
    bh: float = _nonneg(10.8, "N m s/rad", "head viscous damping")
    c1: float = _nonneg(0.9, "N m", "base Coulomb friction")
    c2: float = _nonneg(0.45, "N m", "knuckle Coulomb friction")
    ch: float = _nonneg(0.45, "N m", "head Coulomb friction")
    xf: float = param(0.120, lo=-1.0, hi=1.0, unit="m", doc="x-coordinate of the base link of the elbow chain")
    yf: float = param(0.170, lo=-1.0, hi=1.0, unit="m", doc="y-coordinate (below the pivot) of the base link")
    le: float = _pos(0.082, "m", "elbow link length = pinion radius")
    theta_e0: float = param(-0.164, lo=-math.pi, hi=math.pi, unit="rad", doc="theta_e at theta_1 = 0")
    lb: float = _pos(0.235, "m", "cylinder moment arm")
    alpha: float = param(1.82, lo=0.0, hi=math.pi, lo_open=True, hi_open=True, unit="rad",
                         doc="angle between lower link and moment arm")
    Ap: float = _pos(0.0123, "m^2", "piston area")
    Ao: float = _pos(3.14e-6, "m^2", "orifice area")
    V0: float = _pos(0.000996, "m^3", "cylinder volume when alpha - theta_1 = pi/2")
    Pg: float = _pos(710185.0, "Pa", "supply gauge pressure")
    R_gas: float = _pos(287.0, "J/(kg K)", "specific gas constant of air (\"universal\" in Table 3-I: erratum 19)")
    gamma: float = param(1.40, lo=1.0, hi=2.0, lo_open=True, hi_open=True, unit="-", doc="specific heat ratio")
    cd: float = param(0.60, lo=0.0, hi=1.0, lo_open=True, unit="-", doc="orifice discharge coefficient")
    Pa: float = _pos(101000.0, "Pa", "atmospheric pressure")
    T: float = _pos(293.0, "K", "cylinder temperature")
    kc: float = _pos(162000.0, "N/m", "linear cylinder spring")
    bc: float = _pos(90000.0, "N s/m", "linear cylinder damper")
    g: float = _nonneg(9.80665, "m/s^2", "gravitational acceleration")
    y_op: float = _pos(1.58, "m", "static operating (wire/ram) height above the base pivot, Chapter 5")
    r_laminar: float = param(R_LAMINAR, lo=R_LAMINAR_LO, hi=1.0, lo_open=True, hi_open=True, unit="-",
                             doc="pressure ratio Pd/Pu above which the orifice flow is linear in dp (laminar band "
                                 "1 - r_laminar, chosen by convergence: README)")
    omega_s: float = _pos(1e-3, "rad/s", "velocity scale of the optional smooth Coulomb law tanh(w/omega_s)")

    def __post_init__(self) -> None:
        check_fields(self, "pantograph parameter")
        for name, dist, length in (("d1", self.d1, self.l1), ("d2", self.d2, self.l2), ("dh", self.dh, self.lh)):
            if dist > length:
                raise ParameterError(f"pantograph parameter {name} = {dist} lies beyond its link (length {length})")
        if self.r_laminar <= critical_ratio(self.gamma):
            raise ParameterError(
                f"pantograph parameter r_laminar = {self.r_laminar} must exceed the critical pressure ratio "
                f"{critical_ratio(self.gamma):.6g} of gamma = {self.gamma} (the laminar band lies in subsonic flow)"
            )
        if self.y_op >= self.l1 + self.l2 + self.lh:
            raise ParameterError(
                f"operating height y_op = {self.y_op} m cannot be reached: the linkage reaches at most "
                f"l1 + l2 + lh = {self.l1 + self.l2 + self.lh} m"
            )

    @property
    def Ps(self) -> float:
        """Absolute supply pressure Ps = Pg + Pa (Pa)."""
        return self.Pg + self.Pa

    def replace(self, **changes: float) -> PantographParams:
        """A copy with some fields changed (checked again)."""
        return dataclasses.replace(self, **changes)
