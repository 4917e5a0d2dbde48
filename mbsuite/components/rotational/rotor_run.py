"""One MuJoCo run of a rotor system, as both steppers share it: the run's set-up (`RotorRun`), its signals and the
constants of the stick/slip state machine (`native_stepper.py` packs it for `native/rotors.c`, `stepper.py` is the
Python twin, `mujoco.py` compiles the model and runs it)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, Protocol

import mujoco
import numpy as np

from ...engines.inputs import Signal, Table
from ...errors import ParameterError, SceneError
from .commands import CommandQueue, Controller
from .interfaces import MODE_NAME, RefResult, RotorSystem

HINT = "reduce solver.timestep"
#: steps between two drains of the native event buffer when no controller sets the pace
CHUNK = 4096
#: chattering: an element changing mode CHATTER_N + 1 times within CHATTER_WINDOW steps stops the run
CHATTER_N, CHATTER_WINDOW = 16, 64


class CompiledRotors(Protocol):
    """A rotor system on its compiled MJCF (`mujoco_sim.MujocoRotorSim`): the model and data with the system's numbers,
    and the MuJoCo indices of its rotors, locks, actuators and sources."""

    sys: RotorSystem
    m: mujoco.MjModel
    d: mujoco.MjData
    dof: list[int]
    qadr: list[int]
    eq: list[int]
    act: list[int]
    act_sign: list[float]
    eq_sign: list[float]
    src: list[int]
    general: bool


def signal_for(fn: Callable[[float], float] | Signal, grid: np.ndarray, what: str) -> Signal:
    """A signal the native state machine can evaluate: `fn` itself if it is a `mbsuite.engines.inputs` signal, else
    `fn` tabulated on `grid` (the run's instants t_k and t_k + dt/2, at which the state machine evaluates schedules
    and shapes: exact there, linear between). A non-finite value is refused, naming `what` and the time."""
    if isinstance(fn, Signal):
        return fn
    if not callable(fn):
        raise ParameterError(f"{what} must be a signal (mbsuite.engines.inputs) or a callable of time, got {fn!r}")
    vals = np.array([float(fn(float(x))) for x in grid])
    bad = np.nonzero(~np.isfinite(vals))[0]
    if bad.size:
        raise ParameterError(f"{what} is not finite at t = {grid[bad[0]]:.6g} s (value {float(vals[bad[0]])!r})")
    return Table(tuple(grid.tolist()), tuple(vals.tolist()))
class RotorRun:
    """One run's set-up, used by the native stepper and its Python twin: step counts, the command states and the
    controller with its actuation queue, the schedules and shapes as signals, the initial state, and the assembly of
    the recorded rows into a `RefResult`.

    Recorded row: q (n), w (n), modes (n_elements), command states, energy terms [source, viscous per rotor, per part]
    (cumulative, before the step's work), lock-impact energy (cumulative)."""

    def __init__(self, sim: CompiledRotors, q0: Sequence[float], w0: Sequence[float], t_end: float, *,
                 controller: Controller | None = None, u0: dict[str, int] | None = None, sample_dt: float = 1e-3):
        self.sim = sim
        self.sys = sys = sim.sys
        self.m, self.d = m, d = sim.m, sim.d
        n = sys.n
        self.dt = dt = float(m.opt.timestep)
        q0, w0 = self._state("initial positions q0", q0, n), self._state("initial speeds w0", w0, n)
        if not (math.isfinite(t_end) and t_end >= 0):
            raise SceneError(f"duration must be a finite number >= 0 s, got {t_end!r}")
        if not (math.isfinite(sample_dt) and sample_dt > 0):
            raise SceneError(f"sample_dt must be positive, got {sample_dt!r}")
        self.nstep = int(round(t_end / dt))
        self.every = max(1, int(round(sample_dt / dt)))
        self.u = {c: 0 for c in sys.commands()}
        self.u.update(u0 or {})
        self.commands = list(self.u)
        self.u_arr = np.array([float(v) for v in self.u.values()])
        self.controller = controller
        self.period = CHUNK
        self.queue = None
        if controller is not None:
            ratio = controller.dt / dt
            if abs(ratio - round(ratio)) > 1e-9:
                raise SceneError(f"controller period {controller.dt} s is not a multiple of the MuJoCo timestep {dt} s")
            self.period = int(round(ratio))
            self.queue = CommandQueue(sys.delays, controller.dt, self.u)
        self.part_owner = [e for e, f in enumerate(sys.frictions) for _ in f.parts]
        self.labels = sys.part_labels()
        self.timevar = any(pt.schedule is not None for f in sys.frictions for pt in f.parts)
        k = np.arange(self.nstep + 1) * dt
        grid = np.empty(2 * k.size)
        grid[0::2], grid[1::2] = k, k + 0.5 * dt  # the instants t_k and t_k + dt/2 the state machine evaluates
        self.schedules = [None if pt.schedule is None else
                          signal_for(pt.schedule, grid, f"schedule of friction part '{pt.label}'")
                          for f in sys.frictions for pt in f.parts]
        self.shapes = [None if s.shape is None else signal_for(s.shape, grid, f"shape of torque source '{s.label}'")
                       for s in sys.sources]
        self.dampers = sys.dampers()
        self.e_names = (["source"] + [f"viscous_{nm}" for nm in sys.names] + self.labels
                        + [f"damper_{s.name}" for s in self.dampers])
        self.nrec = 2 * n + len(sys.frictions) + len(self.commands) + len(self.e_names) + 1
        mujoco.mj_resetData(m, d)
        for i in range(n):
            d.qpos[sim.qadr[i]] = q0[i]
            d.qvel[sim.dof[i]] = w0[i]
        self._qadr = np.array(sim.qadr, int)
        self._dof = np.array(sim.dof, int)

    @staticmethod
    def _state(what: str, x: Sequence[float], n: int) -> np.ndarray:
        a = np.asarray(x, dtype=float)
        if a.shape != (n,) or not np.all(np.isfinite(a)):
            raise ParameterError(f"{what} must be {n} finite numbers (one per rotor), got {x!r}")
        return a

    def sample(self, k: int) -> None:
        """The controller at step k (a multiple of its period): it sees the state at t_k; the commands due by then
        (quantised actuation delays) take effect for this step."""
        t = k * self.dt
        kc = k // self.period
        d = self.d
        self.queue.issue(kc, self.controller(kc, t, d.qpos[self._qadr], d.qvel[self._dof]))
        pending = self.queue.pending
        while pending and pending[0][0] <= t + 0.5 * self.dt:
            _, c, v = pending.pop(0)
            if c not in self.u:
                raise SceneError(f"the controller commands {c!r}, which no friction part of the system obeys "
                                 f"(commands: {self.commands})")
            self.u[c] = v
            self.u_arr[self.commands.index(c)] = v

    def event(self, t: float, t_step: float, e: int, old: int, new: int) -> dict[str, Any]:
        """An event record: interpolated time t, the step boundary t_step where it was applied, modes."""
        return {"t": float(t), "element": self.sys.frictions[e].name, "from": MODE_NAME[int(old)],
                "to": MODE_NAME[int(new)], "t_step": float(t_step)}

    def result(self, rows: np.ndarray, events: list[dict[str, Any]], stats: dict[str, Any]) -> RefResult:
        """The recorded rows (one per `every` steps from step 0) as a RefResult; times are step x dt."""
        n, ne = self.sys.n, len(self.sys.frictions)
        t = np.arange(rows.shape[0]) * self.every * self.dt
        c0 = 2 * n + ne
        e0 = c0 + len(self.commands)
        energy = {k: rows[:, e0 + i].copy() for i, k in enumerate(self.e_names)}
        energy["lock_impact"] = rows[:, -1].copy()
        return RefResult(t=t, q=rows[:, :n].T.copy(), w=rows[:, n:2 * n].T.copy(),
                         modes=rows[:, 2 * n:c0].T.astype(int), energy=energy, events=events,
                         u={c: rows[:, c0 + i].copy() for i, c in enumerate(self.commands)}, stats=stats)
