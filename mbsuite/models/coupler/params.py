"""Parameters of the single and double 4-link (SS-link) coupler.

Geometry follows Maniowski & Czauderna, "Spatial kinematic analysis of double 4-link coupler used in low-floor tram
powertrains" (Sect. 2, Table 1), with the platform layout stated in the model README: joint centres on a circle of
radius R at polar angles pi/2 +- gamma, -pi/2 +- gamma,
link k joins A-point k to B-point k+1. Lengths are in metres; the paper's non-dimensional model is R = 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ...errors import ParameterError

GAMMA_17DEG = math.radians(17.0)  # 0.29671 rad: the value that reproduces Eq (15) (reference B1)
GAMMAS_PAPER = (0.11, 0.297, 0.391)  # seed l.212, l.292


@dataclass(frozen=True)
class CouplerParams:
    """Design and dynamic parameters (SI units).

    Geometry (seed Table 1, l.96-101):
      gamma   platform proportion angle [rad], 0 < gamma < pi/4 (Eq 1 gives a positive link length only there)
      e_y     axial shift between the platforms of one coupler [m], >= 0 (0 = coplanar singular pose)
      R       radius of the circle through the S-joint centres [m] (Eq 1; the paper's R = 1)
      l_b     length of the intermediate shaft b between platforms BA and BC [m] (double coupler)
      phi_bc  angle between platforms BA and BC on shaft b [rad] (paper: 0 or pi/2)
    Dynamics (MuJoCo double-coupler scene; not in the paper, chosen for a tram-like drive scaled to R = 1 m):
      m_link, link_radius          mass [kg] and capsule radius [m] of one SS link (real inertia case)
      massless_factor              link mass scale used by the 'massless' link-inertia effect (massless limit)
      m_shaft_b, i_shaft_b_axial, i_shaft_b_trans   mass [kg] and inertias [kg m^2] of the intermediate shaft b
      i_shaft_a, i_shaft_c         axial inertias of input and output shafts [kg m^2]
      joint_friction               dry-friction torque in every S joint and shaft bearing [N m] (friction effect)
      joint_damping                viscous damping in the S joints [N m s/rad] (regularises the free link spin)
      kv_drive                     velocity-servo gain of the input drive [N m s/rad]
      solref_timeconst, solref_dampratio   soft-constraint parameters of the link closures (see README)
    """

    gamma: float = GAMMA_17DEG
    e_y: float = 0.1
    R: float = 1.0
    l_b: float = 2.0
    phi_bc: float = 0.0
    m_link: float = 5.0
    link_radius: float = 0.02
    massless_factor: float = 1e-3
    m_shaft_b: float = 80.0
    i_shaft_b_axial: float = 20.0
    i_shaft_b_trans: float = 40.0
    i_shaft_a: float = 10.0
    i_shaft_c: float = 30.0
    joint_friction: float = 2.0
    joint_damping: float = 0.05
    kv_drive: float = 2.0e5
    solref_timeconst: float = 2.0e-3
    solref_dampratio: float = 1.0

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ParameterError(f"coupler parameter {f.name} must be a finite number, got {v!r}")
        if not 0.0 < self.gamma < math.pi / 4:
            raise ParameterError(
                f"coupler parameter gamma = {self.gamma!r} rad is outside (0, pi/4): Eq (1) gives link length "
                f"l0 = 2 R sin(pi/4 - gamma) = {2 * self.R * math.sin(math.pi / 4 - self.gamma):.6g} (must be > 0 and "
                "shorter than the platform diameter)"
            )
        if self.e_y < 0.0:
            raise ParameterError(f"coupler parameter e_y = {self.e_y!r} m is negative; the axial shift must be >= 0")
        for name in ("R", "l_b", "m_link", "link_radius", "massless_factor", "m_shaft_b", "i_shaft_b_axial",
                     "i_shaft_b_trans", "i_shaft_a", "i_shaft_c", "kv_drive", "solref_timeconst", "solref_dampratio"):
            if getattr(self, name) <= 0.0:
                raise ParameterError(f"coupler parameter {name} = {getattr(self, name)!r} must be positive")
        for name in ("joint_friction", "joint_damping"):
            if getattr(self, name) < 0.0:
                raise ParameterError(f"coupler parameter {name} = {getattr(self, name)!r} must be >= 0")
        if self.massless_factor > 1.0:
            raise ParameterError(f"coupler parameter massless_factor = {self.massless_factor!r} must be <= 1")
        if self.l_b <= 2.0 * self.link_radius:
            raise ParameterError(f"coupler parameter l_b = {self.l_b!r} m is too short for the link radius")

    @property
    def l0(self) -> float:
        """Coplanar link length, Eq (1): (l0/R)^2 = 2 (1 - sin 2 gamma), i.e. l0 = 2 R sin(pi/4 - gamma)."""
        return 2.0 * self.R * math.sin(math.pi / 4 - self.gamma)

    @property
    def link_length(self) -> float:
        """Link length with the axial shift: l = sqrt(l0^2 + e_y^2) (reference B1)."""
        return math.hypot(self.l0, self.e_y)

    def geometry(self) -> dict[str, float]:
        return {"gamma": self.gamma, "e_y": self.e_y, "R": self.R, "l_b": self.l_b, "phi_bc": self.phi_bc}


GEOMETRY_KEYS = ("gamma", "e_y", "R", "l_b", "phi_bc")


def geometry_params(**kw: float) -> CouplerParams:
    """A CouplerParams with geometry overrides only; unknown names raise ParameterError listing the valid ones."""
    bad = sorted(set(kw) - set(GEOMETRY_KEYS))
    if bad:
        raise ParameterError(f"unknown coupler geometry parameter(s) {bad}; valid: {list(GEOMETRY_KEYS)}")
    return CouplerParams(**kw)
