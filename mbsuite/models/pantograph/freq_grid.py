"""The frequency-response grid and its vocabulary: the signals, the methods, the thesis' resonances and forcing
frequencies, the defaults and valid ranges of the grid and the peak search (`check_grid`), shared by every module of
the `freqresp` analysis and the command line."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from ...errors import SceneError
from ...limits import Limit

if TYPE_CHECKING:  # numpy where the grid is made: the command line's help reads the declarations here without it
    import numpy as np

FR_SIGNALS = ("F1", "F2", "HD", "y_d")
#: each response signal in words (axes of the figures, a study's curves); every one is a height in m, as is the
#: ram input: its amplitude ratio is in m/m
SIGNAL_WORDS = {"F1": "lower-arm height F1 = l1 sin(theta_1)", "F2": "upper-arm height F2 = l2 sin(theta_2)",
                "HD": "head height HD = lh sin(theta_h)", "y_d": "contact-point height y_d = F1 + F2 + HD"}
#: the signals whose peaks are searched and whose response is estimated (the report's table columns)
PEAK_SIGNALS = ("F1", "HD")
THESIS_RESONANCES_SIM = (4.25, 8.75, 19.5)
THESIS_RESONANCES_MEAS = (4.0, 8.25)
#: the forcing frequencies of the thesis' time histories (Figs 5-1..5-6)
THESIS_FREQS = (2.0, 3.5, 4.5, 6.5, 8.5, 10.0)
METHODS = ("linear", "mujoco", "reference")
TIME_METHODS = ("mujoco", "reference")

#: the one default of each frequency-response question, shared by `freqresp(...)` and `mbsuite pantograph freqresp`:
#: the thesis' 1-30 Hz sweep on its 0.5 Hz grid, every method, peaks of the time paths to 0.005 Hz
DEFAULTS: dict[str, Any] = {"f_min": 1.0, "f_max": 30.0, "df": 0.5, "methods": METHODS, "peak_tol": 5e-3}
#: valid ranges of the grid and the peak search (the CLI's flags and the Python arguments alike)
LIMITS = {
    "f_min": Limit(lo=1e-3, hi=1e3, unit="Hz", doc="lowest frequency"),
    "f_max": Limit(lo=1e-3, hi=1e3, unit="Hz", doc="highest frequency"),
    "df": Limit(lo=1e-3, hi=1e3, unit="Hz", doc="frequency step"),
    "peak_tol": Limit(lo=0.0, hi=10.0, unit="Hz",
                      doc="resolution the peak search refines the time paths' peaks to (0: grid maxima, +-df/2)"),
}
MAX_FREQUENCIES = 2000


def check_grid(f_min: float, f_max: float, df: float, peak_tol: float, methods: str | Sequence[str],
               err: type[Exception] = SceneError) -> tuple[np.ndarray, tuple[str, ...]]:
    """The grid `f_min:df:f_max` and the methods, each value checked against `LIMITS` (an `err` naming it)."""
    import numpy as np

    for k, v in (("f_min", f_min), ("f_max", f_max), ("df", df), ("peak_tol", peak_tol)):
        LIMITS[k].check(k, v, err)
    if f_max < f_min:
        raise err(f"f_max {f_max:g} Hz is below f_min {f_min:g} Hz")
    n = int((f_max - f_min) / df + 1e-9) + 1
    if n > MAX_FREQUENCIES:
        raise err(f"f_min/f_max/df give {n} frequencies; at most {MAX_FREQUENCIES} (enlarge df)")
    if isinstance(methods, str):
        methods = tuple(m.strip() for m in methods.split(",") if m.strip())
    bad = sorted(set(methods) - set(METHODS))
    if bad or not methods:
        raise err(f"unknown frequency-response method(s) {bad or list(methods)}; valid: {list(METHODS)}")
    return np.round(np.arange(f_min, f_max + 0.5 * df, df), 10), tuple(methods)
