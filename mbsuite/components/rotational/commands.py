"""Discrete control: the controller protocol, times in controller samples and the command queue with the thesis'
quantised actuation delays (App. C) - shared by both paths and the controllers."""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np

from ...errors import ParameterError


class Controller(Protocol):
    """A discrete controller sampled every `dt` seconds; returns the commanded states {command: 0/1} (or None)."""

    dt: float

    def __call__(self, k: int, t: float, q: np.ndarray, w: np.ndarray) -> dict[str, int] | None: ...


def time_to_samples(duration: float, fs: float, rounding: str = "nearest", what: str = "duration") -> int:
    """A time in controller samples - the one conversion of every controller of both paths (the MuJoCo path's C
    stepper converts no time: it reads the command states the same Python controllers set).

    `rounding = "nearest"` for a **duration the thesis means as a whole number of samples** (storage time t_k =
    duty x t_l, cycle t_l, dead time t_n): the sample nearest to duration x fs, ties up. The thesis' code computes
    these counts as `(int)(tk*sample_rate)` in single precision, where 0.35 x 0.2 x 500 is exactly 35.0; in double
    precision the product is 34.99999999999999 and a plain int() would lose a sample.
    `rounding = "floor"` where the thesis **means truncation**: the actuation delays of its shift registers (App. C,
    `count = (int)(delay*sample_rate)`) and the waits computed from the state (clutch loiter Eq 2.1, extraction and
    transfer waits of App. F: the last sample not after the computed instant).
    Both round the product to 9 decimals first, so a time that is a whole number of samples in decimal stays one
    (0.3 ms at 10 kHz: 0.0003 x 10000 = 2.9999999999999996 in binary gives 3)."""
    if not (math.isfinite(duration) and duration >= 0.0):
        raise ParameterError(f"{what} must be a finite number >= 0 s, got {duration!r}")
    if not (math.isfinite(fs) and fs > 0.0):
        raise ParameterError(f"controller sample rate must be positive, got {fs!r}")
    x = round(duration * fs, 9)
    if rounding == "nearest":
        return int(math.floor(x + 0.5))
    if rounding == "floor":
        return int(math.floor(x))
    raise ParameterError(f"rounding must be 'nearest' or 'floor', got {rounding!r}")


def delay_samples(delay: float, fs: float) -> int:
    """Actuation delay in controller samples, as the thesis' shift registers: `count = (int)(delay*sample_rate)`
    (App. C): truncation (`time_to_samples(delay, fs, "floor")`). The one conversion used by the command
    queue, the controllers and `drive.build_controller`."""
    return time_to_samples(delay, fs, "floor", "actuation delay")


class CommandQueue:
    """Commands with pure actuation delays quantised to controller samples (`delay_samples`, thesis App. C)."""

    def __init__(self, delays: dict[str, tuple[float, float]], dt: float, initial: dict[str, int]):
        fs = 1.0 / dt
        self.counts = {c: (delay_samples(d_on, fs), delay_samples(d_off, fs)) for c, (d_on, d_off) in delays.items()}
        self.dt = dt
        self.commanded = dict(initial)
        self.pending: list[tuple[float, str, int]] = []

    def issue(self, k: int, cmds: dict[str, int] | None) -> None:
        """Queue the controller's commands of sample k; each takes effect after its quantised delay."""
        if not cmds:
            return
        for c, v in cmds.items():
            if self.commanded.get(c, 0) != v:
                self.commanded[c] = v
                n_on, n_off = self.counts.get(c, (0, 0))
                n = n_on if v else n_off
                self.pending.append(((k + n) * self.dt, c, int(v)))
        self.pending.sort()


