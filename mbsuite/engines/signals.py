"""Time signals that Python and the native core evaluate alike: torque-source shapes, normal-force schedules, inputs.

Each signal is a frozen dataclass, callable on a float or an array of times, with `spec()` giving the flat array the
C side reads (`mbs_signal` in `native/core.c`; kinds and parameter order in `native/mbsuite.h`). A test holds the two
evaluations equal to 1e-15. Anything else callable can be tabulated with `Table.sample(fn, times)`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError


def _finite(name: str, **values: float) -> None:
    for k, v in values.items():
        if not (isinstance(v, int | float) and math.isfinite(v)):
            raise ParameterError(f"{name} signal: {k} must be a finite number, got {v!r}")


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

    value: float
    kind = 0

    def __post_init__(self) -> None:
        _finite("constant", value=self.value)

    def values(self, t):
        """The formula in the class docstring at the times `t` (vectorised)."""
        return np.full_like(t, self.value)

    def params(self):
        """The parameters in the order the C evaluator reads them."""
        return (self.value,)


@dataclass(frozen=True)
class Step(Signal):
    """offset + height for t >= t0 (Modelica `Blocks.Sources.Step`)."""

    height: float = 1.0
    offset: float = 0.0
    t0: float = 0.0
    kind = 1

    def __post_init__(self) -> None:
        _finite("step", height=self.height, offset=self.offset, t0=self.t0)

    def values(self, t):
        """The formula in the class docstring at the times `t` (vectorised)."""
        return self.offset + np.where(t >= self.t0, self.height, 0.0)

    def params(self):
        """The parameters in the order the C evaluator reads them."""
        return (self.offset, self.height, self.t0)


@dataclass(frozen=True)
class Sine(Signal):
    """offset + amplitude sin(2 pi f (t - t0) + phase) for t >= t0, offset before (Modelica `Blocks.Sources.Sine`)."""

    amplitude: float = 1.0
    frequency: float = 1.0
    phase: float = 0.0
    offset: float = 0.0
    t0: float = 0.0
    kind = 2

    def __post_init__(self) -> None:
        _finite("sine", amplitude=self.amplitude, frequency=self.frequency, phase=self.phase, offset=self.offset,
                t0=self.t0)

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

    height: float = 1.0
    duration: float = 1.0
    offset: float = 0.0
    t0: float = 0.0
    kind = 3

    def __post_init__(self) -> None:
        _finite("ramp", height=self.height, duration=self.duration, offset=self.offset, t0=self.t0)
        if self.duration < 0:
            raise ParameterError(f"ramp signal: duration must be >= 0, got {self.duration!r}")

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

    amplitude: float = 1.0
    width: float = 0.5
    period: float = 1.0
    offset: float = 0.0
    t0: float = 0.0
    n: int = 0
    kind = 4

    def __post_init__(self) -> None:
        _finite("pulse", amplitude=self.amplitude, width=self.width, period=self.period, offset=self.offset,
                t0=self.t0)
        if isinstance(self.n, bool) or not isinstance(self.n, int | float) or self.n != int(self.n):
            raise ParameterError(f"pulse signal: n = {self.n!r} must be a whole number >= 0 (the number of periods; "
                                 "0: unlimited)")
        if not (0.0 <= self.width <= 1.0 and self.period > 0 and self.n >= 0):
            raise ParameterError(f"pulse signal: need 0 <= width <= 1, period > 0, n >= 0; got {self}")

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

    times: tuple[float, ...]
    points: tuple[float, ...]
    kind = 5

    def __post_init__(self) -> None:
        try:
            ts, ys = np.asarray(self.times, float), np.asarray(self.points, float)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"table signal: times and values must be numbers ({exc})") from exc
        if ts.ndim != 1 or ts.size < 1 or ts.shape != ys.shape or not np.all(np.isfinite(ts)) or \
                not np.all(np.isfinite(ys)) or np.any(np.diff(ts) < 0):
            raise ParameterError("table signal: times and values must be equal-length finite sequences with "
                                 "non-decreasing times")

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
