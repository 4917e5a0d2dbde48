"""Parameters of the IFToMM gates (the benchmark's bars are fixed in the MJCF files: 1 m, 1 kg uniform rods)."""

from __future__ import annotations

from dataclasses import dataclass

from ...limits import check_fields, param


@dataclass(frozen=True)
class IftommParams:
    """gravity            acceleration of gravity along -y [m/s^2] (benchmark: 9.81)
    solref_timeconst      MuJoCo soft-closure time constant [s] (>= 2 timestep; 4 ms with the 1 ms default step)
    penalty               Pinocchio reference: penalty factor p of the closure formulation [1/m^2 scale, -]
    penalty_omega         Pinocchio reference: closure-error natural frequency w [rad/s] (critically damped)"""

    gravity: float = param(9.81, lo=0.0, hi=1000.0, unit="m/s^2", doc="acceleration of gravity along -y")
    solref_timeconst: float = param(0.004, lo=0.0, hi=1.0, lo_open=True, unit="s",
                                    doc="MuJoCo soft-closure time constant (>= 2 timestep)")
    penalty: float = param(1e7, lo=0.0, hi=1e15, lo_open=True, doc="Pinocchio reference: closure penalty factor p")
    penalty_omega: float = param(10.0, lo=0.0, hi=1e6, lo_open=True, unit="rad/s",
                                 doc="Pinocchio reference: closure-error natural frequency w (critically damped)")

    def __post_init__(self) -> None:
        check_fields(self, "iftomm parameter")
