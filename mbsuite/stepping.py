"""The contract every object that advances a simulation in time meets, whatever it steps (like scipy's `OdeSolver`).

A step object is created at its initial state and then driven with `step()` (one step of its own kind: a solver step
between events, a fixed time step, a chunk of native steps) or `run(t_end)`. Its `status` is "running" until it has
reached the end it was built for ("finished") or stopped on an error it raised ("failed")."""

from __future__ import annotations

from typing import Protocol, runtime_checkable

STATUSES = ("running", "finished", "failed")


@runtime_checkable
class StepObject(Protocol):
    """`t`: the current time (s); `status`: one of `STATUSES`; `step()`: advance one step;
    `run(t_end)`: step until `t >= t_end` or `status != "running"`."""

    t: float
    status: str

    def step(self) -> None:
        """Advance one step of the object's own kind (raises an `mbsuite.errors` exception on failure)."""

    def run(self, t_end: float) -> object:
        """Step until `t >= t_end` or `status != "running"`."""


class Stepping:
    """`step()` and `run(t_end)` of the protocol for a class that advances itself in `_one_step()` (one step of its own
    kind) and keeps `t` and `status`: stepping an object that is no longer running is an error, and an exception out
    of `_one_step()` leaves it "failed"."""

    t: float
    status: str

    def _one_step(self) -> None:
        raise NotImplementedError

    def step(self) -> None:
        """Advance one step (`_one_step`); `status` becomes "failed" if it raises."""
        if self.status != "running":
            raise RuntimeError(f"{type(self).__name__} is {self.status}; start a new one")
        try:
            self._one_step()
        except Exception:
            self.status = "failed"
            raise

    def run(self, t_end: float) -> None:
        """`step()` until `t >= t_end` or the object is no longer running."""
        while self.status == "running" and self.t < t_end:
            self.step()
