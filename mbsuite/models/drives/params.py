"""Parameters of the switched-mode drives (R. S. Oldaker, The Design and Control of Mechanical Switched Mode Drives,
PhD thesis, University of Hull, 1997).

`DriveParams` holds scene overrides (SI units); every field left at None takes the value of the scene's parameter set:
the data table `PARAM_SETS`, a set chosen by name in the scene's `[params] set` (a declared value: an unknown name is an
error listing the valid ones). `Lnnn` are line numbers of the thesis' plain-text transcription.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from ...errors import ParameterError
from ...limits import param

# ---- parameter sets -------------------------------------------------------------------------------------------------
# Step-up prototype, Table 4.2. J_l printed 6.76e-5 is a typo: load disk A is 6.76e-4; the clutch parts
# J_c = 1.81e-5 ride on the load (both Sec. 4.3.2). B units are N m s/rad (printed "kg m^2"), delays 0.006 s
# (printed "0.006 ms").
TABLE_4_2: dict[str, float] = dict(
    K_t=0.1101, K_e=0.1043, R=1.1, V_s=12.0,  # Table 4.2, 12 V supply (Sec. 4.2.1)
    J_m=1.4e-4, C_m=0.0246, B_m=7.95e-5,  # Table 4.2
    K=0.26, J_s=6.04e-5, C_s=0.0075, B_s=3.33e-5,  # Table 4.2
    J_l=6.76e-4 + 1.81e-5, C_l=0.0075, B_l=3.33e-5,  # Table 4.2 (J_l typo fixed, + J_c)
    tau_b=1.1, tau_c=1.1, d_on=0.006, d_off=0.006,  # Table 4.2, Sec. 4.3.4
    fs=500.0, tau_l=0.0, J_add=0.0,  # Sec. 4.1
    t_l=0.2, duty=0.5, t_n=0.048, twist_tol=0.15, Kp=0.12, Ki=4.4e-5, ref=287.0,  # Sec. 4.2.1; t_n = pi/Omega (derived)
    min_vel=40.0, max_vel=60.0,
)
# 100 W step-up/step-down, design-stage simulation (Sec. 6.2; Table 6.2, row Sr = 10): same motor at 21 V,
# added motor inertia 1.6e-3, bearing friction = step-up values x2, 5 N m clutches, 4 ms delays, J_l = 0.0023.
DESIGN_100W: dict[str, float] = dict(
    K_t=0.1101, K_e=0.1043, R=1.1, V_s=21.0,
    J_m=1.4e-4, J_add=1.6e-3, C_m=0.0246, B_m=7.95e-5,
    K=0.98, J_s=7.3e-5, C_s=0.015, B_s=6.66e-5,
    J_l=0.0023, C_l=0.015, B_l=6.66e-5, tau_l=0.15,
    tau_c1=5.0, tau_c2=5.0, d_on=0.004, d_off=0.004, fs=1000.0,
    Kp=0.00112, Ki=0.0161, ref=400.0, min_motor_vel=70.0, min_load_vel=0.0,  # Eq 6.1; fs not stated (1 kHz assumed)
)
# 100 W prototype as fitted to the 100 W open-loop test (Sec. 6.4.3: B_s = 107e-5, K = 1.2; J_s = 7.76e-5 from
# K/J = 18038, Sec. 6.3; output bearing Cl = 0.0025, Bl = 8.9e-5 (App. J "from MSD data"); spring
# bearings = spring+output pair minus output (Sec. 6.4.1); input bearing = spring+input minus spring (Sec. 6.4.1)).
PROTO_100W: dict[str, float] = dict(
    DESIGN_100W,
    K=1.2, J_s=7.76e-5, B_s=107e-5, C_s=0.0078 - 0.0025, C_l=0.0025, B_l=8.9e-5,
    C_m=0.0246 + (0.009 - 0.0053), B_m=7.95e-5 + (14.05e-5 - 7.2e-5), tau_l=0.0,
    K_ctrl=1.32, Omega_ctrl=132.0,  # controller values on the prototype (Sec. 6.3)
)
# 50 W open-loop fit (Sec. 6.4.3): spring viscous B_s = 67.6e-5 from the first free-vibration cycle, measured K = 1.40.
PROTO_50W: dict[str, float] = dict(PROTO_100W, B_s=67.6e-5, K=1.40)
# 500 W example design, App. J parameter file and Sec. 5.4.
EXAMPLE_500W: dict[str, float] = dict(
    tau_0=10.0, tau_slope=-0.05, J_m=0.005, J_add=0.0, C_m=0.0025, B_m=8.9e-5,  # T_m = 10 - 0.05 w (App. J)
    K=7.07, J_s=1e-4, C_s=0.005, B_s=1.78e-4,
    J_l=0.005, C_l=0.0025, B_l=8.9e-5, tau_l=0.8,
    tau_c1=20.0, tau_c2=20.0, d_on=0.004, d_off=0.004, fs=1000.0,
    Kp=0.00222, Ki=0.075, ref=400.0, min_motor_vel=70.0, min_load_vel=0.0, spring_max=2.86,
)

PARAM_SETS: dict[str, dict[str, float]] = {
    "table_4_2": TABLE_4_2,
    "design_100w": DESIGN_100W,
    "proto_100w": PROTO_100W,
    "proto_50w": PROTO_50W,
    "example_500w": EXAMPLE_500W,
}

#: the parameter sets whose motor, bearings, delays and controller rate a design scene may take (step-up/step-down;
#: `design_scene.py`)
BASE_SETS = ("design_100w", "proto_100w", "proto_50w", "example_500w")


#: the least rotor inertia [kg m^2]: far below any drive of this kind, far above MuJoCo's mjMINVAL (1e-15), which a
#: rotor's inertia must exceed (the same floor as the coupler's)
J_FLOOR = 1e-9
BIG = 1e6  # generous upper ends: far above any drive of this kind, low enough to catch unit slips (mm for m, ...)


def _p(lo: float | None, hi: float | None, unit: str, doc: str, *, lo_open: bool = False,
       hi_open: bool = False) -> Any:
    """A scene override (default None: the parameter set's value) with its valid range."""
    return param(None, lo=lo, hi=hi, lo_open=lo_open, hi_open=hi_open, unit=unit, doc=doc)


@dataclass(frozen=True)
class DriveParams:
    """Scene overrides; None = value of the parameter set. Units SI (kg m^2, N m, N m s/rad, N m/rad, s, Hz, rad/s).
    Every field declares its valid range (`mbsuite.limits.param`); a set value outside it is a ParameterError naming
    the field, the value and the range."""

    # the parameter set the other fields override (a row of the data table PARAM_SETS)
    set: str = param("table_4_2", kind=str, choices=tuple(PARAM_SETS),
                     doc="parameter set: table_4_2 (Table 4.2, step-up prototype), design_100w (Sec. 6.2, 100 W "
                         "design), proto_100w / proto_50w (Sec. 6.4.3 fits), example_500w (App. J)")
    # motor (Eq 4.1: tau = K_t (V_s - K_e w) / R, or tau = tau_0 + tau_slope w)
    K_t: float | None = _p(0.0, 100.0, "N m/A", "motor torque constant (Eq 4.1)", lo_open=True)
    K_e: float | None = _p(0.0, 100.0, "V s/rad", "motor back-emf constant (Eq 4.1)")
    R: float | None = _p(0.0, 1e3, "ohm", "armature resistance (Eq 4.1)", lo_open=True)
    V_s: float | None = _p(-1e4, 1e4, "V", "supply voltage (Eq 4.1)")
    tau_0: float | None = _p(0.0, 1e4, "N m", "stall torque of the straight-line motor (App. J)", lo_open=True)
    tau_slope: float | None = _p(-1e3, 0.0, "N m s/rad", "torque-speed slope of the straight-line motor (<= 0: a "
                                 "torque rising with speed runs away)")
    J_m: float | None = _p(J_FLOOR, 1e3, "kg m^2", "motor inertia")
    J_add: float | None = _p(0.0, 1e3, "kg m^2", "added motor inertia (Sec. 4.2.4: 1.42e-3; Sec. 6.2: 1.6e-3)")
    C_m: float | None = _p(0.0, 1e3, "N m", "motor bearing Coulomb torque")
    B_m: float | None = _p(0.0, 1e3, "N m s/rad", "motor bearing viscous coefficient")
    # spring system and load
    K: float | None = _p(0.0, BIG, "N m/rad", "torsion spring rate", lo_open=True)
    J_s: float | None = _p(J_FLOOR, 1e3, "kg m^2", "spring-system inertia")
    C_s: float | None = _p(0.0, 1e3, "N m", "spring bearing Coulomb torque")
    B_s: float | None = _p(0.0, 1e3, "N m s/rad", "spring viscous coefficient")
    J_l: float | None = _p(J_FLOOR, 1e3, "kg m^2", "load inertia")
    C_l: float | None = _p(0.0, 1e3, "N m", "load bearing Coulomb torque")
    B_l: float | None = _p(0.0, 1e3, "N m s/rad", "load bearing viscous coefficient")
    tau_l: float | None = _p(0.0, 1e4, "N m", "Coulomb load torque (useful output)")
    # clutches / brake (rated dynamic torques) and actuation delays
    tau_b: float | None = _p(0.0, 1e4, "N m", "brake sliding torque (step-up)")
    tau_c: float | None = _p(0.0, 1e4, "N m", "clutch sliding torque (step-up)")
    tau_c1: float | None = _p(0.0, 1e4, "N m", "input clutch sliding torque (step-up/step-down)")
    tau_c2: float | None = _p(0.0, 1e4, "N m", "output clutch sliding torque (step-up/step-down)")
    peak: float | None = _p(1.0, 100.0, "1", "breakaway / sliding torque ratio (thesis: 1)")
    d_on: float | None = _p(0.0, 1.0, "s", "engagement delay (quantised to controller samples)")
    d_off: float | None = _p(0.0, 1.0, "s", "release delay (quantised to controller samples)")
    # controller
    fs: float | None = _p(0.0, BIG, "Hz", "controller sample rate", lo_open=True)
    t_l: float | None = _p(0.0, 100.0, "s", "PWM cycle time", lo_open=True)
    duty: float | None = _p(0.0, 1.0, "1", "PWM duty (storage time t_k = duty t_l)", lo_open=True, hi_open=True)
    t_n: float | None = _p(0.0, 100.0, "s", "resonant controller's dead time")
    twist_tol: float | None = _p(0.0, 100.0, "rad", "transfer ends below this spring twist (must exceed the "
                                 "friction-held twist (C_s + C_l)/K)")
    min_vel: float | None = _p(0.0, 1e5, "rad/s", "motor-resonant: restart speed")
    max_vel: float | None = _p(0.0, 1e5, "rad/s", "motor-resonant: switch speed")
    Kp: float | None = _p(0.0, BIG, "", "PI proportional gain (step-up: s per rad/s; energy packet: J per (rad/s)^2)")
    Ki: float | None = _p(0.0, BIG, "", "PI integral gain")
    ref: float | None = _p(-1e5, 1e5, "rad/s", "speed reference when the scene's input gives none")
    max_tk: float | None = _p(0.0, 100.0, "s", "upper clamp of the storage time t_k (default t_l / 2)", lo_open=True)
    min_motor_vel: float | None = _p(0.0, 1e5, "rad/s", "energy packet: least motor speed to extract from")
    min_load_vel: float | None = _p(0.0, 1e5, "rad/s", "energy packet: least load speed to regenerate from")
    K_ctrl: float | None = _p(0.0, BIG, "N m/rad", "spring rate the controller assumes", lo_open=True)
    Omega_ctrl: float | None = _p(0.0, BIG, "rad/s", "free frequency the controller assumes", lo_open=True)
    spring_max: float | None = _p(0.0, 1e3, "rad", "largest spring twist of a packet", lo_open=True)

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if v is None:
                continue
            lim = f.metadata["limit"]
            v2 = lim.check(f"drives parameter {f.name}", v)
            if v2 is not v:
                object.__setattr__(self, f.name, v2)
        if self.min_vel is not None and self.max_vel is not None and self.min_vel > self.max_vel:
            raise ParameterError(f"parameter min_vel = {self.min_vel!r} must not exceed max_vel = {self.max_vel!r}")

    def resolved(self, param_set: str | None = None) -> dict[str, Any]:
        """The parameter set (`param_set`, default the scene's `set`) with the overrides applied, validated as a whole
        (the declared ranges, and min_vel <= max_vel). Combinations that depend on the mechanism and effects (delay vs
        PWM cycle / free oscillation period, twist_tol vs the friction-held twist) are checked by
        `drive.build_controller`."""
        param_set = self.set if param_set is None else param_set
        if param_set not in PARAM_SETS:
            raise ParameterError(f"unknown parameter set {param_set!r}; valid: {sorted(PARAM_SETS)}")
        p: dict[str, Any] = {f.name: None for f in dataclasses.fields(self)}
        p.update(PARAM_SETS[param_set])
        p.update({k: v for k, v in dataclasses.asdict(self).items() if v is not None})
        p["peak"] = p["peak"] if p["peak"] is not None else 1.0
        p["set"] = param_set
        DriveParams(**p)  # validate the merged set too
        return p


def motor_line(p: dict[str, Any]) -> tuple[float, float]:
    """Motor torque tau = c0 + c1 w: Eq 4.1 (armature inductance neglected, N = 1), or the App. J straight line."""
    if p.get("tau_0") is not None:
        return float(p["tau_0"]), float(p.get("tau_slope") or 0.0)
    return p["K_t"] * p["V_s"] / p["R"], -p["K_t"] * p["K_e"] / p["R"]
