"""EN 50318:2002 reference catenary and reference pantograph, as fixed by mbsuite (see the model README).

Every default below is the reference scene; SI units throughout. The dropper positions are measured from the support
at the start of each span and repeat in every span. Validation raises `ParameterError` naming the parameter and value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ...errors import ParameterError

#: EN 50318 reference dropper positions from the span's first support (m), catenary.md "Model data"
EN50318_DROPPERS = (5.0, 10.5, 17.0, 23.5, 30.0, 36.5, 43.0, 49.5, 55.0)


@dataclass(frozen=True)
class CatenaryParams:
    """Catenary (2-D, vertical plane), 2-mass reference pantograph, contact and analysis settings (catenary.md)."""

    # --- catenary geometry and wires -------------------------------------------------------------------------------
    n_spans: int = 10  #: number of spans (-)
    span_length: float = 60.0  #: span length (m)
    cw_mass: float = 1.35  #: contact wire mass per length (kg/m)
    cw_tension: float = 20000.0  #: contact wire tension (N)
    cw_EI: float = 195.0  #: contact wire bending stiffness (N m^2)
    mw_mass: float = 1.07  #: messenger wire mass per length (kg/m)
    mw_tension: float = 16000.0  #: messenger wire tension (N)
    mw_EI: float = 131.7  #: messenger wire bending stiffness (N m^2)
    dropper_positions: list[float] = field(default_factory=lambda: list(EN50318_DROPPERS))  #: from support (m)
    k_dropper: float = 1.0e5  #: dropper axial stiffness (N/m), massless
    k_steady_arm: float = 300.0  #: steady arm: CW to ground at each support (N/m)
    k_messenger_support: float = 5.0e4  #: messenger support: MW to ground at each support (N/m)
    zeta: float = 0.005  #: Rayleigh damping ratio matched at f_damp1 and f_damp2 (-)
    f_damp1: float = 1.0  #: first Rayleigh matching frequency (Hz)
    f_damp2: float = 20.0  #: second Rayleigh matching frequency (Hz)
    g: float = 9.81  #: gravitational acceleration for the static state (m/s^2)
    element_length: float = 0.25  #: target FE element length (m); key points (supports, droppers) are always nodes
    # --- reference pantograph (two lumped masses on a fixed base) ----------------------------------------------------
    m1: float = 7.2  #: head mass (kg)
    k1: float = 4200.0  #: head suspension stiffness, head to frame (N/m)
    c1: float = 10.0  #: head suspension damping (N s/m)
    m2: float = 15.0  #: frame mass (kg)
    k2: float = 50.0  #: frame stiffness to the base, referenced to the undisturbed CW level (N/m)
    c2: float = 90.0  #: frame damping to the base (N s/m)
    F0: float = 120.0  #: static uplift force on the frame mass (N)
    # --- contact and run ------------------------------------------------------------------------------------------
    k_contact: float = 5.0e4  #: penalty contact stiffness (N/m)
    x_start: float = 0.0  #: pantograph start position (m)
    x_end: float = 420.0  #: pantograph end position (m)
    # --- analysis (EN 50318 statistics) -------------------------------------------------------------------------
    window_start: float = 240.0  #: start of the statistics window (m)
    window_end: float = 360.0  #: end of the statistics window (m)
    filter_cutoff: float = 20.0  #: low-pass cut-off of the contact force (Hz)
    filter_order: int = 4  #: Butterworth order (applied forwards and backwards)

    def __post_init__(self) -> None:
        positive = ("span_length", "cw_mass", "cw_tension", "mw_mass", "mw_tension", "k_dropper", "f_damp1",
                    "f_damp2", "element_length", "m1", "k1", "m2", "k_contact", "filter_cutoff")
        non_negative = ("cw_EI", "mw_EI", "k_steady_arm", "k_messenger_support", "zeta", "g", "c1", "c2", "k2")
        finite = ("F0", "x_start", "x_end", "window_start", "window_end")
        for name in positive + non_negative + finite:
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ParameterError(f"catenary parameter {name} must be a finite number, got {v!r}")
        for name in positive:
            if getattr(self, name) <= 0:
                what = "tension" if "tension" in name else "value"
                raise ParameterError(
                    f"catenary parameter {name} must be > 0 (a positive {what}), got {getattr(self, name)!r}")
        for name in non_negative:
            if getattr(self, name) < 0:
                raise ParameterError(f"catenary parameter {name} must be >= 0, got {getattr(self, name)!r}")
        for name in ("n_spans", "filter_order"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise ParameterError(f"catenary parameter {name} must be a positive integer, got {v!r}")
        if not self.f_damp2 > self.f_damp1:
            raise ParameterError(f"f_damp2 ({self.f_damp2}) must be above f_damp1 ({self.f_damp1})")
        dp = self.dropper_positions
        if not isinstance(dp, list | tuple) or any(isinstance(x, bool) or not isinstance(x, int | float) for x in dp):
            raise ParameterError(f"dropper_positions must be a list of numbers (m from the support), got {dp!r}")
        for i, x in enumerate(dp):
            if not (math.isfinite(x) and 0.0 < x < self.span_length):
                raise ParameterError(
                    f"dropper_positions[{i}] = {x!r} m lies outside its span (0, {self.span_length}) m"
                )
        for i in range(1, len(dp)):
            if not dp[i] > dp[i - 1]:
                raise ParameterError(
                    f"dropper_positions must be strictly increasing; dropper_positions[{i}] = {dp[i]!r} "
                    f"<= dropper_positions[{i - 1}] = {dp[i - 1]!r}"
                )
        if self.element_length > self.span_length:
            raise ParameterError(f"element_length ({self.element_length}) must not exceed span_length")
        L = self.length
        if not 0.0 <= self.x_start < self.x_end <= L:
            raise ParameterError(
                f"pantograph run must satisfy 0 <= x_start < x_end <= {L} m, got x_start={self.x_start}, "
                f"x_end={self.x_end}"
            )
        if not self.x_start <= self.window_start < self.window_end <= self.x_end:
            raise ParameterError(
                f"statistics window [{self.window_start}, {self.window_end}] m must lie inside the run "
                f"[{self.x_start}, {self.x_end}] m and be non-empty"
            )

    @property
    def length(self) -> float:
        """Total catenary length (m)."""
        return self.n_spans * self.span_length

    @property
    def cw_wave_speed(self) -> float:
        """Transverse wave speed of the contact wire sqrt(T/rho) (m/s)."""
        return math.sqrt(self.cw_tension / self.cw_mass)

    @property
    def mw_wave_speed(self) -> float:
        return math.sqrt(self.mw_tension / self.mw_mass)

    def rayleigh(self) -> tuple[float, float]:
        """(alpha, beta) of C = alpha M + beta K giving ratio zeta at f_damp1 and f_damp2."""
        w1, w2 = 2 * math.pi * self.f_damp1, 2 * math.pi * self.f_damp2
        return 2 * self.zeta * w1 * w2 / (w1 + w2), 2 * self.zeta / (w1 + w2)
