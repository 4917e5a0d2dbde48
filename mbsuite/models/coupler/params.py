"""Parameters of the single and double 4-link (SS-link) coupler.

Geometry follows Maniowski & Czauderna, "Spatial kinematic analysis of double 4-link coupler used in low-floor tram
powertrains" (Sect. 2, Table 1), with the platform layout stated in the model README: joint centres on a circle of
radius R at polar angles pi/2 +- gamma, -pi/2 +- gamma,
link k joins A-point k to B-point k+1. Lengths are in metres; the paper's non-dimensional model is R = 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...errors import ParameterError
from ...limits import check_fields, param

GAMMA_17DEG = math.radians(17.0)  # 0.29671 rad: the value that reproduces Eq (15) (README, erratum 7)
GAMMAS_PAPER = (0.11, 0.297, 0.391)  # the paper's Sect. 3.1 and 3.4
#: the smallest mass [kg] and principal inertia [kg m^2] a moving body may get: MuJoCo refuses a body whose mass or
#: inertia is below mjMINVAL = 1e-15 ("mass and inertia of moving bodies must be larger than mjMINVAL"), which names
#: no parameter; these floors (the pantograph's) refuse such values by name, well above it
MASS_MIN, INERTIA_MIN = 1e-6, 1e-9
#: the smallest principal inertia of an SS link (axial, m r^2 / 2; in the massless limit the mass is scaled too:
#: `link_floor`, checked where the effect is known)
LINK_INERTIA_MIN = 1e-12


@dataclass(frozen=True)
class CouplerParams:
    """Design and dynamic parameters (SI units).

    Geometry (the paper's Table 1):
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
      solref_friction_timeconst    time constant of MuJoCo's dry-friction constraints [s] (friction effect); None (the
                                   default): 2 timesteps, the stiffest MuJoCo allows, so it follows the timestep
    """

    gamma: float = param(GAMMA_17DEG, lo=0.0, hi=math.pi / 4, lo_open=True, hi_open=True, unit="rad",
                         doc="platform proportion angle (Eq 1: a positive link length only in (0, pi/4))")
    e_y: float = param(0.1, lo=0.0, hi=1000.0, unit="m", doc="axial shift between the platforms of one coupler")
    R: float = param(1.0, lo=0.0, hi=1000.0, lo_open=True, unit="m", doc="radius of the circle through the joints")
    l_b: float = param(2.0, lo=0.0, hi=1000.0, lo_open=True, unit="m", doc="length of the intermediate shaft b")
    phi_bc: float = param(0.0, lo=-math.pi, hi=math.pi, unit="rad", doc="angle between platforms BA and BC")
    m_link: float = param(5.0, lo=MASS_MIN, hi=1e6, unit="kg", doc="mass of one SS link")
    link_radius: float = param(0.02, lo=1e-4, hi=10.0, unit="m", doc="capsule radius of one SS link")
    massless_factor: float = param(1e-3, lo=1e-6, hi=1.0, doc="link mass scale of the massless limit")
    m_shaft_b: float = param(80.0, lo=MASS_MIN, hi=1e7, unit="kg", doc="mass of the intermediate shaft b")
    i_shaft_b_axial: float = param(20.0, lo=INERTIA_MIN, hi=1e7, unit="kg m^2", doc="axial inertia of shaft b")
    i_shaft_b_trans: float = param(40.0, lo=INERTIA_MIN, hi=1e7, unit="kg m^2",
                                   doc="transverse inertia of shaft b about its centre")
    i_shaft_a: float = param(10.0, lo=INERTIA_MIN, hi=1e7, unit="kg m^2", doc="axial inertia of input shaft a")
    i_shaft_c: float = param(30.0, lo=INERTIA_MIN, hi=1e7, unit="kg m^2", doc="axial inertia of output shaft c")
    joint_friction: float = param(2.0, lo=0.0, hi=1e6, unit="N m", doc="dry friction in every S joint and bearing")
    joint_damping: float = param(0.05, lo=0.0, hi=1e6, unit="N m s/rad", doc="viscous damping in the S joints")
    kv_drive: float = param(2.0e5, lo=0.0, hi=1e12, lo_open=True, unit="N m s/rad",
                            doc="velocity-servo gain of the input drive")
    solref_timeconst: float = param(2.0e-3, lo=0.0, hi=1.0, lo_open=True, unit="s",
                                    doc="time constant of the soft link closures")
    solref_dampratio: float = param(1.0, lo=0.0, hi=100.0, lo_open=True, doc="damping ratio of the link closures")
    solref_friction_timeconst: float | None = param(
        None, lo=0.0, hi=1.0, lo_open=True, unit="s",
        doc="time constant of the dry-friction constraints (S joints, output bearing); None: 2 timesteps")

    def __post_init__(self) -> None:
        check_fields(self, "coupler parameter")  # solref_friction_timeconst may stay None (2 timesteps)
        # cross-field checks (each message names the fields involved)
        if self.l_b <= 2.0 * self.link_radius:
            raise ParameterError(f"coupler parameter l_b = {self.l_b!r} m is too short for link_radius = "
                                 f"{self.link_radius!r} m (need l_b > 2 link_radius)")
        self.link_floor(massless=False)
        if self.i_shaft_b_axial > 2.0 * self.i_shaft_b_trans:
            raise ParameterError(
                f"coupler parameters i_shaft_b_axial = {self.i_shaft_b_axial!r} kg m^2 > 2 i_shaft_b_trans = "
                f"{2.0 * self.i_shaft_b_trans!r} kg m^2: no rigid body has these principal inertias (A + B >= C)")

    def link_floor(self, massless: bool) -> None:
        """Refuse, naming the parameters, an SS link whose axial inertia m r^2 / 2 (m = m_link, times massless_factor
        in the massless limit) is below LINK_INERTIA_MIN: a body MuJoCo cannot move."""
        factor, scaled = (self.massless_factor, " massless_factor") if massless else (1.0, "")
        ia = self.m_link * factor * self.link_radius ** 2 / 2
        if ia < LINK_INERTIA_MIN:
            named = f", massless_factor = {self.massless_factor!r}" if massless else ""
            raise ParameterError(
                f"coupler parameters m_link = {self.m_link!r} kg{named}, link_radius = {self.link_radius!r} m give "
                f"the {'massless' if massless else 'real'} link an axial inertia m_link{scaled} link_radius^2 / 2 = "
                f"{ia:.3g} kg m^2 below {LINK_INERTIA_MIN:g} (a body MuJoCo cannot move): raise one of them")

    @property
    def l0(self) -> float:
        """Coplanar link length, Eq (1): (l0/R)^2 = 2 (1 - sin 2 gamma), i.e. l0 = 2 R sin(pi/4 - gamma)."""
        return 2.0 * self.R * math.sin(math.pi / 4 - self.gamma)

    @property
    def link_length(self) -> float:
        """Link length with the axial shift: l = sqrt(l0^2 + e_y^2) (README, "Conventions and geometry")."""
        return math.hypot(self.l0, self.e_y)

    def geometry(self) -> dict[str, float]:
        """The geometric design (gamma, e_y, R, l_b, phi_bc) as a dict (SI units)."""
        return {"gamma": self.gamma, "e_y": self.e_y, "R": self.R, "l_b": self.l_b, "phi_bc": self.phi_bc}


GEOMETRY_KEYS = ("gamma", "e_y", "R", "l_b", "phi_bc")


def geometry_params(**kw: float) -> CouplerParams:
    """A CouplerParams with geometry overrides only; unknown names raise ParameterError listing the valid ones."""
    bad = sorted(set(kw) - set(GEOMETRY_KEYS))
    if bad:
        raise ParameterError(f"unknown coupler geometry parameter(s) {bad}; valid: {list(GEOMETRY_KEYS)}")
    return CouplerParams(**kw)
