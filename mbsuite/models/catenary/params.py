"""EN 50318:2002 reference catenary and reference pantograph, as fixed by mbsuite (see the model README).

Every default below is the reference scene; SI units throughout. The dropper positions are measured from the support
at the start of each span and repeat in every span. Validation raises `ParameterError` naming the parameter and value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ...errors import ParameterError
from ...limits import check_fields, param, real
from ...trust.perturbation import POSITION
from .line import Line

#: default of `max_element_steps`: about 10 minutes of one core at ~120 ns per element-step (0.5 m elements at
#: dt 2e-4 s, 250 km/h: 7.3e7; 0.125 m at 5e-5 s: 1.2e9)
MAX_ELEMENT_STEPS = 5e9
#: most further statistics windows (`windows`)
MAX_WINDOWS = 100

#: EN 50318 reference dropper positions from the span's first support (m), catenary.md "Model data"
EN50318_DROPPERS = (5.0, 10.5, 17.0, 23.5, 30.0, 36.5, 43.0, 49.5, 55.0)


@dataclass(frozen=True)
class CatenaryParams:
    """Catenary (2-D, vertical plane), 2-mass reference pantograph, contact and analysis settings (catenary.md)."""

    # --- catenary geometry and wires -------------------------------------------------------------------------------
    n_spans: int = param(10, lo=1, hi=1000, kind=int, unit="-", doc="number of spans")
    span_length: float = param(60.0, lo=0.0, lo_open=True, hi=1000.0, unit="m", doc="span length")
    cw_mass: float = param(1.35, lo=0.0, lo_open=True, hi=100.0, unit="kg/m", doc="contact wire mass per length")
    cw_tension: float = param(20000.0, lo=0.0, lo_open=True, hi=1e6, unit="N", doc="contact wire tension")
    cw_EI: float = param(195.0, lo=0.0, hi=1e6, unit="N m^2", doc="contact wire bending stiffness")
    mw_mass: float = param(1.07, lo=0.0, lo_open=True, hi=100.0, unit="kg/m", doc="messenger wire mass per length")
    mw_tension: float = param(16000.0, lo=0.0, lo_open=True, hi=1e6, unit="N", doc="messenger wire tension")
    mw_EI: float = param(131.7, lo=0.0, hi=1e6, unit="N m^2", doc="messenger wire bending stiffness")
    #: dropper positions from the span's first support (m); checked below (inside the span, increasing)
    dropper_positions: list[float] = field(default_factory=lambda: list(EN50318_DROPPERS), metadata={
        "valid": "increasing, each inside (0, span_length)", "unit": "m",
        "doc": "dropper positions from each span's first support (default: the EN 50318 line's nine in its 60 m span)"})
    k_dropper: float = param(1.0e5, lo=0.0, lo_open=True, hi=1e10, unit="N/m", doc="dropper axial stiffness "
                                                                                       "(massless)")
    k_steady_arm: float = param(300.0, lo=0.0, hi=1e10, unit="N/m", doc="steady arm: CW to ground at each support")
    k_messenger_support: float = param(5.0e4, lo=0.0, hi=1e10, unit="N/m",
                                       doc="messenger support: MW to ground at each support")
    zeta: float = param(0.005, lo=0.0, hi=1.0, unit="-", doc="Rayleigh damping ratio at f_damp1 and f_damp2")
    f_damp1: float = param(1.0, lo=0.0, lo_open=True, hi=1e4, unit="Hz", doc="first Rayleigh matching frequency")
    f_damp2: float = param(20.0, lo=0.0, lo_open=True, hi=1e4, unit="Hz", doc="second Rayleigh matching frequency")
    g: float = param(9.81, lo=0.0, hi=100.0, unit="m/s^2", doc="gravitational acceleration for the static state")
    #: the shipped default (every catenary scene): with the point-load correction (`fe.PointCorrection`) 0.5 m is
    #: within 1 N / 0.5 mm of the converged statistics (model README, "Convergence")
    element_length: float = param(0.5, lo=0.0, lo_open=True, hi=1000.0, unit="m",
                                  doc="target FE element length; key points (supports, droppers) are always nodes")
    # --- reference pantograph (two lumped masses on a fixed base) ----------------------------------------------------
    m1: float = param(7.2, lo=1e-6, hi=1e4, unit="kg", doc="head mass (>= 1e-6 kg, the other models' floor)")
    k1: float = param(4200.0, lo=0.0, lo_open=True, hi=1e9, unit="N/m", doc="head suspension stiffness")
    c1: float = param(10.0, lo=0.0, hi=1e7, unit="N s/m", doc="head suspension damping")
    m2: float = param(15.0, lo=1e-6, hi=1e4, unit="kg", doc="frame mass (>= 1e-6 kg, the other models' floor)")
    k2: float = param(50.0, lo=0.0, hi=1e9, unit="N/m",
                      doc="frame stiffness to the base, referenced to the undisturbed CW level")
    c2: float = param(90.0, lo=0.0, hi=1e7, unit="N s/m", doc="frame damping to the base")
    F0: float = param(120.0, lo=-1e5, hi=1e5, unit="N", doc="static uplift force on the frame mass (<= 0: the head "
                                                                "leaves the wire)")
    # --- contact and run ------------------------------------------------------------------------------------------
    k_contact: float = param(5.0e4, lo=0.0, lo_open=True, hi=1e10, unit="N/m", doc="penalty contact stiffness")
    x_start: float = param(0.0, lo=0.0, hi=1e6, unit="m", doc="pantograph start position", draw=POSITION)
    x_end: float = param(420.0, lo=0.0, hi=1e6, unit="m", doc="pantograph end position", draw=POSITION)
    # --- analysis (EN 50318 statistics) -------------------------------------------------------------------------
    window_start: float = param(240.0, lo=0.0, hi=1e6, unit="m", doc="start of the statistics window", draw=POSITION)
    window_end: float = param(360.0, lo=0.0, hi=1e6, unit="m", doc="end of the statistics window", draw=POSITION)
    #: further statistics windows [[start, end], ...] (m), each inside the run; checked below. Each gets the
    #: statistics of the window above (`stats.window_statistics`; a route's contact wires their own too)
    windows: list[list[float]] = field(default_factory=list, metadata={
        "valid": f"[[start, end], ...], each inside the run, start < end (at most {MAX_WINDOWS})", "unit": "m",
        "doc": "further statistics windows (a route's sections and overlaps), each with the eight statistics"})
    filter_cutoff: float = param(20.0, lo=0.0, lo_open=True, hi=1e4, unit="Hz",
                                 doc="low-pass cut-off of the contact force")
    filter_order: int = param(4, lo=1, hi=10, kind=int, unit="-", doc="Butterworth order (forwards and backwards)")
    # --- size guard -------------------------------------------------------------------------------------------
    max_element_steps: float = param(MAX_ELEMENT_STEPS, lo=1.0, hi=1e15, unit="-",
                                     doc="size guard: FE elements x time steps a passage may take")
    # --- the sections of a route the compiled core steps -----------------------------------------------------------
    step_sections: str = param("in play", kind=str, choices=("in play", "reached", "all"),
                          doc="a route's sections the compiled core steps: 'in play' (from the step a pantograph "
                              "reaches one until every pantograph has passed it: the pantographs' forces exact, a "
                              "section's records end when it is left), 'reached' (from then on: every record "
                              "exact) or 'all'")
    # --- the line ------------------------------------------------------------------------------------------------
    #: a line of its own (`line.Line`: a scene's [line] section, `lines.py`, `linefile.py`); None: the simple line of
    #: the fields above (n_spans ... k_messenger_support, the EN 50318:2002 line by default)
    line: Line | None = None

    def __post_init__(self) -> None:
        check_fields(self, "catenary parameter")
        if self.line is not None and not isinstance(self.line, Line):
            raise ParameterError(f"line must be a mbsuite.models.catenary.line.Line, got {type(self.line).__name__}")
        if not self.f_damp2 > self.f_damp1:
            raise ParameterError(f"f_damp2 ({self.f_damp2}) must be above f_damp1 ({self.f_damp1})")
        dp = self.dropper_positions
        if hasattr(dp, "tolist") and not isinstance(dp, str):  # a numpy array: its numbers
            dp = dp.tolist()
        if not isinstance(dp, list | tuple) or any(real(x) is None for x in dp):
            raise ParameterError(f"dropper_positions must be a list of numbers (m from the support), got {dp!r}")
        dp = [float(real(x)) for x in dp]
        object.__setattr__(self, "dropper_positions", dp)
        for i, x in enumerate(dp):
            if not (math.isfinite(x) and 0.0 < x < self.span_length):
                default = dp == list(EN50318_DROPPERS)
                raise ParameterError(
                    f"dropper_positions[{i}] = {x!r} m lies outside its span (0, {self.span_length}) m"
                    + (f" (the EN 50318 line's nine positions in its 60 m span, the default: set [params] "
                       f"dropper_positions for spans of {self.span_length:g} m)" if default else "")
                )
        for i in range(1, len(dp)):
            if not dp[i] > dp[i - 1]:
                raise ParameterError(
                    f"dropper_positions must be strictly increasing; dropper_positions[{i}] = {dp[i]!r} "
                    f"<= dropper_positions[{i - 1}] = {dp[i - 1]!r}"
                )
        self._check_windows()
        if self.line is None and self.element_length > self.span_length:
            raise ParameterError(f"element_length ({self.element_length}) must not exceed span_length")
        L = self.length
        if L < self.x_end <= L * (1.0 + 1e-9):  # an end within 1e-9 of the line's length is its end (rounding)
            object.__setattr__(self, "x_end", L)
        if not 0.0 <= self.x_start < self.x_end <= L:
            raise ParameterError(
                f"params.x_start = {self.x_start} m, params.x_end = {self.x_end} m: the pantograph run must satisfy "
                f"0 <= x_start < x_end <= {L:g} m (the line's length)"
            )
        if self.x_end < self.window_end <= self.x_end * (1.0 + 1e-9):  # the run's end, up to rounding
            object.__setattr__(self, "window_end", self.x_end)
        if not self.x_start <= self.window_start < self.window_end <= self.x_end:
            if not self.window_start < self.window_end:
                culprit = (f"params.window_start = {self.window_start} m must be below params.window_end = "
                           f"{self.window_end} m")
            elif self.window_start < self.x_start:
                culprit = f"params.window_start = {self.window_start} m lies before params.x_start = {self.x_start} m"
            else:
                culprit = f"params.window_end = {self.window_end} m lies beyond params.x_end = {self.x_end} m"
            raise ParameterError(
                f"{culprit}: the statistics window [window_start, window_end] must be non-empty and lie inside the "
                f"run [x_start, x_end] = [{self.x_start}, {self.x_end}] m"
            )
        self._check_windows_in_run()

    def _check_windows(self) -> None:
        ws = self.windows
        if hasattr(ws, "tolist") and not isinstance(ws, str):  # a numpy array: its numbers
            ws = ws.tolist()
        if isinstance(ws, str) or not isinstance(ws, list | tuple) or len(ws) > MAX_WINDOWS:
            raise ParameterError(f"windows must be a list of at most {MAX_WINDOWS} [start, end] pairs (m), got "
                                 f"{ws!r}")
        out = []
        for i, w in enumerate(ws):
            if hasattr(w, "tolist") and not isinstance(w, str):
                w = w.tolist()
            if isinstance(w, str) or not isinstance(w, list | tuple) or len(w) != 2 or any(real(v) is None for v in w):
                raise ParameterError(f"windows[{i}] = {w!r} must be a [start, end] pair of numbers (m)")
            a, b = (float(real(v)) for v in w)
            if not (math.isfinite(a) and math.isfinite(b) and a < b):
                raise ParameterError(f"windows[{i}] = [{a}, {b}] m: start must be finite and below end")
            out.append([a, b])
        object.__setattr__(self, "windows", out)

    def _check_windows_in_run(self) -> None:
        for i, (a, b) in enumerate(self.windows):
            if not (self.x_start <= a and b <= self.x_end * (1.0 + 1e-9)):
                raise ParameterError(f"windows[{i}] = [{a:g}, {b:g}] m must lie inside the run [x_start, x_end] = "
                                     f"[{self.x_start:g}, {self.x_end:g}] m")

    @property
    def length(self) -> float:
        """Total catenary length (m): the line's, else n_spans x span_length."""
        return self.line.length if self.line is not None else self.n_spans * self.span_length

    @property
    def cw_wave_speed(self) -> float:
        """Transverse wave speed of the contact wire sqrt(T/rho) (m/s)."""
        if self.line is not None:
            return self.line.contact.wave_speed
        return math.sqrt(self.cw_tension / self.cw_mass)

    @property
    def mw_wave_speed(self) -> float:
        """Messenger-wire transverse wave speed sqrt(T_mw / rho_mw) (m/s)."""
        return math.sqrt(self.mw_tension / self.mw_mass)

    @property
    def max_wave_speed(self) -> float:
        """The fastest wire's transverse wave speed (m/s): what the FE time step must resolve."""
        if self.line is not None:
            return self.line.wave_speed
        return max(self.cw_wave_speed, self.mw_wave_speed)

    def rayleigh(self) -> tuple[float, float]:
        """(alpha, beta) of C = alpha M + beta K giving ratio zeta at f_damp1 and f_damp2."""
        w1, w2 = 2 * math.pi * self.f_damp1, 2 * math.pi * self.f_damp2
        return 2 * self.zeta * w1 * w2 / (w1 + w2), 2 * self.zeta / (w1 + w2)
