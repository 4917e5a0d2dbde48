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
