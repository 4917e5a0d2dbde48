"""Time signals that Python and the native core evaluate alike: torque-source shapes, normal-force schedules, inputs.

Each signal is a frozen dataclass, callable on a float or an array of times, with `spec()` giving the flat array the
C side reads (`mbs_signal` in `native/core.c`; kinds and parameter order in `native/mbsuite.h`). A test holds the two
evaluations equal to 1e-15. Anything else callable can be tabulated with `Table.sample(fn, times)`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..limits import Limit, param
from ..schema import Items, Rule, Section, of_dataclass

#: the longest table a signal may hold (a run's tabulation grid: two instants per step of `solver.max_steps`)
TABLE_MAX = 100_000_000


def _check(obj: Any, section: Section) -> None:
    """Check the fields of signal `obj` by its declaration `section` (a ParameterError naming the field, its value,
    what is valid and the unit) and store the Python numbers it holds."""
    data = {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}
    for k, v in section.check(data, section.title, ParameterError).items():
        object.__setattr__(obj, k, tuple(v) if isinstance(v, list) else v)


class Signal:
    """Base class: `__call__(t)` (float or array) and `spec()` (flat float64 array for the native core)."""

    kind: int = -1

    def values(self, t: np.ndarray) -> np.ndarray:
        """The signal at the times `t` (vectorised; equal to the C evaluation to rounding)."""
        raise NotImplementedError

    def params(self) -> Sequence[float]:
        """The parameters in the order the C evaluator reads them."""
        raise NotImplementedError

    def __call__(self, t):
        y = self.values(np.asarray(t, dtype=float))
        return float(y) if np.ndim(y) == 0 else y

    def spec(self) -> np.ndarray:
        """The signal as the C evaluator's parameter row (kind code, then parameters)."""
        return np.array([float(self.kind), *map(float, self.params())], dtype=np.float64)


@dataclass(frozen=True)
class Constant(Signal):
    """c."""

    value: float = param(doc="the constant value")
    kind = 0

    def __post_init__(self) -> None:
        _check(self, CONSTANT_INPUTS)

    def values(self, t):
        """The formula in the class docstring at the times `t` (vectorised)."""
        return np.full_like(t, self.value)

    def params(self):
        """The parameters in the order the C evaluator reads them."""
        return (self.value,)


@dataclass(frozen=True)
class Step(Signal):
    """offset + height for t >= t0 (Modelica `Blocks.Sources.Step`)."""

    height: float = param(1.0, doc="step height")
    offset: float = param(0.0, doc="value before t0")
    t0: float = param(0.0, unit="s", doc="time of the step")
    kind = 1

    def __post_init__(self) -> None:
        _check(self, STEP_INPUTS)

    def values(self, t):
        """The formula in the class docstring at the times `t` (vectorised)."""
        return self.offset + np.where(t >= self.t0, self.height, 0.0)

    def params(self):
        """The parameters in the order the C evaluator reads them."""
        return (self.offset, self.height, self.t0)


@dataclass(frozen=True)
class Sine(Signal):
    """offset + amplitude sin(2 pi f (t - t0) + phase) for t >= t0, offset before (Modelica `Blocks.Sources.Sine`)."""

    amplitude: float = param(1.0, doc="amplitude")
    frequency: float = param(1.0, unit="Hz", doc="frequency")
    phase: float = param(0.0, unit="rad", doc="phase at t0")
    offset: float = param(0.0, doc="offset")
    t0: float = param(0.0, unit="s", doc="start time")
    kind = 2

    def __post_init__(self) -> None:
        _check(self, SINE_INPUTS)

    def values(self, t):
        """The formula in the class docstring at the times `t` (vectorised)."""
        return self.offset + np.where(t >= self.t0, self.amplitude * np.sin(
            2.0 * math.pi * self.frequency * (t - self.t0) + self.phase), 0.0)

    def params(self):
        """The parameters in the order the C evaluator reads them."""
        return (self.offset, self.amplitude, self.frequency, self.phase, self.t0)


@dataclass(frozen=True)
class Ramp(Signal):
    """offset before t0, rising linearly by `height` over `duration`, then held (Modelica `Blocks.Sources.Ramp`)."""

    height: float = param(1.0, doc="rise")
    duration: float = param(1.0, lo=0.0, unit="s", doc="rise time (0: a step)")
    offset: float = param(0.0, doc="value before t0")
    t0: float = param(0.0, unit="s", doc="start of the rise")
    kind = 3

    def __post_init__(self) -> None:
        _check(self, RAMP_INPUTS)

    def values(self, t):
        """The formula in the class docstring at the times `t` (vectorised)."""
        if self.duration <= 0:
            return self.offset + np.where(t >= self.t0, self.height, 0.0)
        frac = np.clip((t - self.t0) / self.duration, 0.0, 1.0)
        return self.offset + self.height * frac

    def params(self):
        """The parameters in the order the C evaluator reads them."""
        return (self.offset, self.height, self.t0, self.duration)


@dataclass(frozen=True)
class Pulse(Signal):
    """offset + amplitude during the first `width` (fraction 0..1) of each `period` from t0, for `n` periods (0 =
    unlimited) (Modelica `Blocks.Sources.Pulse`, width given as a fraction)."""

    amplitude: float = param(1.0, doc="pulse height")
    width: float = param(0.5, lo=0.0, hi=1.0, unit="1", doc="fraction of each period the pulse is on")
    period: float = param(1.0, lo=0.0, lo_open=True, unit="s", doc="period")
    offset: float = param(0.0, doc="value outside the pulses")
    t0: float = param(0.0, unit="s", doc="start of the first pulse")
    n: int = param(0, lo=0, kind=int, doc="number of periods (0: unlimited)")
    kind = 4

    def __post_init__(self) -> None:
        _check(self, PULSE_INPUTS)

    def values(self, t):
        """The formula in the class docstring at the times `t` (vectorised)."""
        k = np.floor((t - self.t0) / self.period)
        phase = (t - self.t0) - k * self.period
        on = (t >= self.t0) & (phase < self.width * self.period)
        if self.n > 0:
            on &= k < self.n
        return self.offset + np.where(on, self.amplitude, 0.0)

    def params(self):
        """The parameters in the order the C evaluator reads them."""
        return (self.offset, self.amplitude, self.width, self.period, self.t0, self.n)


@dataclass(frozen=True)
class Table(Signal):
    """Piecewise linear through (times[i], values[i]), held outside (Modelica `CombiTimeTable`, linear, hold)."""

    times: tuple[float, ...] = dataclasses.field(metadata={"schema": Items(
        Limit(unit="s"), min=1, max=TABLE_MAX, doc="times, non-decreasing", unit="s", rules=(Rule(
            "times non-decreasing", lambda ts: next((f"times must be non-decreasing: times[{i}] = {ts[i]!r} < "
                                                     f"times[{i - 1}] = {ts[i - 1]!r}"
                                                     for i in range(1, len(ts)) if ts[i] < ts[i - 1]), None)),))})
    points: tuple[float, ...] = dataclasses.field(metadata={"schema": Items(
        Limit(), min=1, max=TABLE_MAX, doc="values at the times")})
    kind = 5

    def __post_init__(self) -> None:
        for k in ("times", "points"):  # numpy arrays as the lists they hold (a 2-d array: rows, refused)
            v = getattr(self, k)
            if isinstance(v, np.ndarray) and v.ndim >= 1:
                object.__setattr__(self, k, v.tolist())
        if not _plain_table(self.times, self.points):
            _check(self, TABLE_INPUTS)

    @classmethod
    def sample(cls, fn: Callable[[float], float], times: Sequence[float]) -> Table:
        """Tabulate any callable at `times` (exact there, linear between)."""
        ts = tuple(float(x) for x in times)
        return cls(ts, tuple(float(fn(x)) for x in ts))

    def values(self, t):
        """The formula in the class docstring at the times `t` (vectorised)."""
        return np.interp(t, self.times, self.points)

    def params(self):
        """The parameters in the order the C evaluator reads them."""
        return (len(self.times), *self.times, *self.points)


def _plain_table(times: Any, points: Any) -> bool:
    """True for what `TABLE_INPUTS` accepts as given, checked vectorised (a tabulated run has millions of points):
    equal-length tuples of 1 to `TABLE_MAX` finite Python floats, times non-decreasing. Anything else goes through
    the declaration's check (which converts or names what is wrong)."""
    if not (isinstance(times, tuple) and isinstance(points, tuple) and 1 <= len(times) == len(points) <= TABLE_MAX):
        return False
    if not all(type(x) is float for x in times) or not all(type(x) is float for x in points):
        return False
    ts, ys = np.array(times), np.array(points)
    return bool(np.all(np.isfinite(ts)) and np.all(np.isfinite(ys)) and not np.any(np.diff(ts) < 0))


def _same_length(c: dict[str, Any]) -> str | None:
    n, m = len(c["times"]), len(c["points"])
    return None if n == m else f"times ({n} values) and points ({m} values) must have equal lengths"


#: the declared parameters of each signal (`mbsuite.schema.Section`s, checked in `__post_init__`)
CONSTANT_INPUTS = of_dataclass(Constant, "constant signal")
STEP_INPUTS = of_dataclass(Step, "step signal")
SINE_INPUTS = of_dataclass(Sine, "sine signal")
RAMP_INPUTS = of_dataclass(Ramp, "ramp signal")
PULSE_INPUTS = of_dataclass(Pulse, "pulse signal")
TABLE_INPUTS = of_dataclass(Table, "table signal", rules=(Rule("times and points of equal length", _same_length),))
