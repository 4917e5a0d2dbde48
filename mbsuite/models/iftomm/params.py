"""Parameters of the IFToMM gates (the benchmark's bars are fixed in the MJCF files: 1 m, 1 kg uniform rods)."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ...errors import ParameterError


@dataclass(frozen=True)
class IftommParams:
    """gravity            acceleration of gravity along -y [m/s^2] (benchmark: 9.81)
    solref_timeconst      MuJoCo soft-closure time constant [s] (>= 2 timestep; 4 ms with the 1 ms default step)
    penalty               Pinocchio reference: penalty factor p of the closure formulation [1/m^2 scale, -]
    penalty_omega         Pinocchio reference: closure-error natural frequency w [rad/s] (critically damped)"""

    gravity: float = 9.81
    solref_timeconst: float = 0.004
    penalty: float = 1e7
    penalty_omega: float = 10.0

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ParameterError(f"iftomm parameter {f.name} must be a finite number, got {v!r}")
        if self.gravity < 0:
            raise ParameterError(f"iftomm parameter gravity = {self.gravity!r} must be >= 0")
        for name in ("solref_timeconst", "penalty", "penalty_omega"):
            if getattr(self, name) <= 0:
                raise ParameterError(f"iftomm parameter {name} = {getattr(self, name)!r} must be positive")
