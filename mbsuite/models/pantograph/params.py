"""Brecknell-Willis pantograph parameters: Table 3-I of Eppinger (1984), seed 000 lines 560-600, SI units.

Angles are measured from the horizontal (Fig 3-3): the lower arm points forward, the upper arm backward, the head
forward.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from ...errors import ParameterError


@dataclass(frozen=True)
class PantographParams:
    """Table 3-I (seed 000, l.560-600). Every field in SI units."""

    l1: float = 1.95  #: lower link length (m)
    l2: float = 1.95  #: upper link length (m)
    lh: float = 0.40  #: head link length, knuckle-to-contact (m)
    m1: float = 31.5  #: lower link mass (kg)
    m2: float = 25.2  #: upper link mass (kg)
    mh: float = 13.5  #: head mass (kg)
    I1: float = 11.7  #: lower link moment of inertia about its centre of mass (kg m^2)
    I2: float = 8.10  #: upper link moment of inertia (kg m^2)
    Ih: float = 0.432  #: head moment of inertia (kg m^2)
    d1: float = 1.10  #: base pivot to lower link mass centre (m)
    d2: float = 0.80  #: elbow to upper link mass centre (m)
    dh: float = 0.35  #: knuckle to head mass centre (m)
    ks: float = 180000.0  #: input (catenary/shoe) spring constant (N/m)
    kh: float = 2250.0  #: head spring constant, to the datum (N m/rad)
    ke: float = 44640.0  #: elbow stiffness (N m/rad)
    be: float = 0.0  #: elbow viscous damping (N m s/rad); not in Table 3-I nor EQSIM, hence 0
    b1: float = 36.0  #: base viscous damping (N m s/rad)
    b2: float = 157.5  #: knuckle viscous damping (N m s/rad)
    bh: float = 10.8  #: head viscous damping (N m s/rad)
    c1: float = 0.9  #: base Coulomb friction (N m)
    c2: float = 0.45  #: knuckle Coulomb friction (N m)
    ch: float = 0.45  #: head Coulomb friction (N m)
    xf: float = 0.120  #: x-coordinate of the base link of the elbow chain (m)
    yf: float = 0.170  #: y-coordinate (below the pivot) of the base link (m)
    le: float = 0.082  #: elbow link length = pinion radius (m)
    theta_e0: float = -0.164  #: theta_e at theta_1 = 0 (rad)
    lb: float = 0.235  #: cylinder moment arm (m)
    alpha: float = 1.82  #: angle between lower link and moment arm (rad)
    Ap: float = 0.0123  #: piston area (m^2)
    Ao: float = 3.14e-6  #: orifice area (m^2)
    V0: float = 0.000996  #: cylinder volume when alpha - theta_1 = pi/2 (m^3)
    Pg: float = 710185.0  #: supply gauge pressure (Pa)
    R_gas: float = 287.0  #: specific gas constant of air (J/(kg K)); "universal" in Table 3-I is erratum 19
    gamma: float = 1.40  #: specific heat ratio (-)
    cd: float = 0.60  #: orifice discharge coefficient (-)
    Pa: float = 101000.0  #: atmospheric pressure (Pa)
    T: float = 293.0  #: cylinder temperature (K)
    kc: float = 162000.0  #: linear cylinder spring (N/m)
    bc: float = 90000.0  #: linear cylinder damper (N s/m)
    g: float = 9.80665  #: gravitational acceleration (m/s^2)
    y_op: float = 1.58  #: static operating (wire/ram) height above the base pivot (m), Chapter 5
    r_laminar: float = 0.999  #: pressure ratio above which the orifice flow is linearised in dp (laminar band)
    omega_s: float = 1e-3  #: velocity scale of the optional smooth Coulomb law tanh(w/omega_s) (rad/s)

    def __post_init__(self) -> None:
        positive = ("l1", "l2", "lh", "m1", "m2", "mh", "I1", "I2", "Ih", "d1", "d2", "dh", "le", "lb", "Ap", "Ao",
                    "V0", "Pg", "R_gas", "Pa", "T", "kc", "bc", "y_op", "omega_s")
        non_negative = ("ks", "kh", "ke", "be", "b1", "b2", "bh", "c1", "c2", "ch", "g")
        for name in positive + non_negative:
            v = getattr(self, name)
            if not isinstance(v, int | float) or not math.isfinite(v):
                raise ParameterError(f"pantograph parameter {name} must be a finite number, got {v!r}")
        for name in positive:
            if getattr(self, name) <= 0:
                raise ParameterError(f"pantograph parameter {name} must be > 0, got {getattr(self, name)!r}")
        for name in non_negative:
            if getattr(self, name) < 0:
                raise ParameterError(f"pantograph parameter {name} must be >= 0, got {getattr(self, name)!r}")
        if not 1.0 < self.gamma < 2.0:
            raise ParameterError(f"pantograph parameter gamma must be in (1, 2), got {self.gamma!r}")
        if not 0.0 < self.cd <= 1.0:
            raise ParameterError(f"pantograph parameter cd must be in (0, 1], got {self.cd!r}")
        if not 0.5283 < self.r_laminar < 1.0:
            raise ParameterError(f"pantograph parameter r_laminar must be in (0.5283, 1), got {self.r_laminar!r}")
        for name, dist, length in (("d1", self.d1, self.l1), ("d2", self.d2, self.l2), ("dh", self.dh, self.lh)):
            if dist > length:
                raise ParameterError(f"pantograph parameter {name} = {dist} lies beyond its link (length {length})")
        if self.y_op >= self.l1 + self.l2 + self.lh:
            raise ParameterError(
                f"operating height y_op = {self.y_op} m cannot be reached: the linkage reaches at most "
                f"l1 + l2 + lh = {self.l1 + self.l2 + self.lh} m"
            )

    @property
    def Ps(self) -> float:
        """Absolute supply pressure Ps = Pg + Pa (Pa)."""
        return self.Pg + self.Pa

    @property
    def F_static(self) -> float:
        """Static cylinder force Pg*Ap (Eqs 3.23, 3.27) (N)."""
        return self.Pg * self.Ap

    def replace(self, **changes: float) -> PantographParams:
        return dataclasses.replace(self, **changes)
