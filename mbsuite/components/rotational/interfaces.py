"""Coaxial rotor systems with Coulomb friction elements: the system both paths simulate, and the result of a run.

A `RotorSystem` is a set of rigid rotors (inertia J_i, viscous bearing B_i to ground), linear torsion springs (between
two rotors or a rotor and ground), torque sources tau = c0*shape(t) + c1*w, and *friction elements* (clutches between
two rotors, brakes/bearings/Coulomb loads between a rotor and ground). The modes follow Modelica's
`Rotational.Interfaces.PartialFriction`: -1 backward sliding, 0 stuck, 1 forward sliding, 2 free (the state machines:
`event_exact.py` for the hand path, `native/rotors.c` and `stepper.py` for MuJoCo).

Sign convention: an element between rotor a and rotor b (b = -1: ground) acts with +tau_e on a and -tau_e on b.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ...errors import ParameterError
from ...trust import perturbation

FWD, STUCK, BWD, FREE = 1, 0, -1, 2
MODE_NAME = {FWD: "forward", STUCK: "stuck", BWD: "backward", FREE: "free"}


@dataclass
class Part:
    """One contribution to a friction element's sliding torque: `level` N m, times the command `command` (0/1, None =
    always on) times `schedule(t)` (clipped at 0; None = 1). `output=True` marks a useful load (its work is output).

    A schedule is best an `mbsuite.engines.inputs` signal (Step, Sine, Ramp, Pulse, Table, ...): the hand path calls
    it, the MuJoCo path evaluates the same signal in C. Any other callable works too; the MuJoCo path then tabulates it
    on its half-step grid (`rotor_run.signal_for`)."""

    label: str
    level: float
    command: str | None = None
    schedule: Callable[[float], float] | None = None
    output: bool = False


@dataclass
class Friction:
    """A Coulomb friction element between rotor `a` and rotor `b` (-1 = ground). Breakaway = `peak` x sliding torque.

    `g` (optional, one coefficient per rotor) replaces a/b by a general relative speed w_rel = g . w, on which the
    element acts with the generalised torque -g tau_e (virtual work); a/b is the row g = e_b - e_a. It is what an
    element behind an ideal gear or planetary sees (Modelica `IdealPlanetary`: a massless ring eliminated).
    `one_way_hold` (N m, optional) makes it Modelica's `OneWayClutch` (a freewheel in parallel with a clutch): it
    slides only forward (w_rel > 0, torque = level), locks whenever w_rel reaches 0 and holds any torque toward
    w_rel < 0; it releases forward when the holding torque exceeds `peak` x level, or `one_way_hold`
    (= eps0 mu0 cgeo fn_max, Modelica's tau0_max_low) while disengaged (level 0)."""

    name: str
    a: int
    b: int
    parts: list[Part]
    peak: float = 1.0
    g: tuple[float, ...] | None = None
    one_way_hold: float | None = None


@dataclass
class Spring:
    """Linear torsion spring K (N m/rad) between rotor a and rotor b (-1 = ground): tau_a = -K (q_a - q_b), with an
    optional parallel damper D (N m s/rad; Modelica `SpringDamper`): tau_a -= D (w_a - w_b); its loss is the energy
    term `damper_<name>`."""

    name: str
    a: int
    b: int
    K: float
    D: float = 0.0


@dataclass
class Source:
    """Torque source on rotor `body`: tau = c0 * shape(t) + c1 * w + c2 * w^2 (a DC motor: c0 = Kt Vs / R,
    c1 = -Kt Ke / R; Modelica `QuadraticSpeedDependentTorque`: c2 = tau_nominal / w_nominal^2).
    `shape` (None = 1) is best a signal of `mbsuite.engines.inputs`, as `Part.schedule`."""

    label: str
    body: int
    c0: float
    c1: float = 0.0
    shape: Callable[[float], float] | None = None
    c2: float = 0.0


@dataclass
class RotorSystem:
    """Coaxial rotors (inertias J, viscous B) with friction elements, springs and torque sources: the
    system both paths simulate (a model builds it: e.g. a drive of Oldaker 1997, Eqs 3.1-3.6, or a Modelica example)."""
    names: list[str]
    J: np.ndarray
    B: np.ndarray
    springs: list[Spring] = field(default_factory=list)
    frictions: list[Friction] = field(default_factory=list)
    sources: list[Source] = field(default_factory=list)
    breaks: list[float] = field(default_factory=list)  # times where a schedule jumps or crosses zero
    delays: dict[str, tuple[float, float]] = field(default_factory=dict)  # command -> (engage, release) delay (s)

    def __post_init__(self) -> None:
        self.J = np.asarray(self.J, float)
        self.B = np.asarray(self.B, float)
        if perturbation.active():  # the stability check: every coefficient perturbed (copies; callers' objects kept)
            pv = perturbation.value
            self.J, self.B = perturbation.state(self.J, "rotor.J"), perturbation.state(self.B, "rotor.B")
            self.springs = [replace(s, K=pv(s.K, key=f"{s.name}.K"), D=pv(s.D, key=f"{s.name}.D"))
                            for s in self.springs]
            self.frictions = [replace(f, parts=[replace(p, level=pv(p.level, key=f"{p.label}.level")) for p in f.parts])
                              for f in self.frictions]
            self.sources = [replace(s, c0=pv(s.c0, key=f"{s.label}.c0"), c1=pv(s.c1, key=f"{s.label}.c1"),
                                    c2=pv(s.c2, key=f"{s.label}.c2")) for s in self.sources]
        for nm, j in zip(self.names, self.J, strict=True):
            if not (np.isfinite(j) and j > 0):
                raise ParameterError(f"inertia of rotor '{nm}' must be positive, got {j!r} kg m^2")
        for nm, b in zip(self.names, self.B, strict=True):
            if not (np.isfinite(b) and b >= 0):
                raise ParameterError(f"viscous bearing coefficient of rotor '{nm}' must be >= 0, got {b!r} N m s/rad")
        for s in self.springs:
            if not (np.isfinite(s.K) and s.K > 0):
                raise ParameterError(f"spring rate of '{s.name}' must be positive, got {s.K!r} N m/rad")
        for s in self.springs:
            if not (np.isfinite(s.D) and s.D >= 0):
                raise ParameterError(f"damping of '{s.name}' must be >= 0, got {s.D!r} N m s/rad")
        for s in self.sources:
            if not all(np.isfinite(x) for x in (s.c0, s.c1, s.c2)):
                raise ParameterError(f"torque source '{s.label}': c0, c1, c2 must be finite, got {s}")
        rows = []
        for f in self.frictions:
            if f.peak < 1.0:
                raise ParameterError(f"breakaway factor of '{f.name}' must be >= 1, got {f.peak!r}")
            if f.one_way_hold is not None and not (np.isfinite(f.one_way_hold) and f.one_way_hold > 0):
                raise ParameterError(f"one-way hold torque of '{f.name}' must be > 0, got {f.one_way_hold!r} N m")
            if f.g is None:
                row = np.zeros(self.n)
                row[f.a] -= 1.0
                if f.b >= 0:
                    row[f.b] += 1.0
            else:
                row = np.asarray(f.g, float)
                if row.shape != (self.n,) or not np.all(np.isfinite(row)) or not np.any(row):
                    raise ParameterError(f"relative-speed row g of '{f.name}' must be {self.n} finite numbers, not "
                                         f"all zero, got {f.g!r}")
            rows.append(row)
            for p in f.parts:
                if not (np.isfinite(p.level) and p.level >= 0):
                    raise ParameterError(f"friction torque '{p.label}' of '{f.name}' must be >= 0, got {p.level!r} N m")
        self.rows = np.array(rows).reshape(len(self.frictions), self.n)

    @property
    def n(self) -> int:
        """Number of rotors."""
        return len(self.names)

    def commands(self) -> list[str]:
        """The command names (clutch/brake switches) of the system's parts."""
        return sorted({p.command for f in self.frictions for p in f.parts if p.command})

    def part_labels(self) -> list[str]:
        """The labels of all friction parts, in element order (the loss terms)."""
        return [p.label for f in self.frictions for p in f.parts]

    def levels(self, t: float, u: dict[str, float]) -> np.ndarray:
        """Sliding torque of every part at time t under engagement states u (flattened over elements)."""
        out = []
        for f in self.frictions:
            for p in f.parts:
                v = p.level
                if p.command is not None:
                    v *= u.get(p.command, 0.0)
                if p.schedule is not None:
                    v *= max(0.0, p.schedule(t))
                out.append(v)
        return np.asarray(out, float)

    def w_rel(self, w: np.ndarray) -> np.ndarray:
        """Slip speed of every friction element [rad/s] (w_b - w_a, or the element's row times w)."""
        return np.array([((w[f.b] if f.b >= 0 else 0.0) - w[f.a]) if f.g is None else float(self.rows[e] @ w)
                         for e, f in enumerate(self.frictions)])

    def G(self, idx: Sequence[int]) -> np.ndarray:
        """Constraint rows (d/dt w_rel) of the friction elements `idx`."""
        return self.rows[list(idx)].reshape(len(idx), self.n)

    def apply(self, f: np.ndarray, e: int, tau: float) -> None:
        """Add element e's torque tau_e to the rotor torques f (+tau on a, -tau on b; -g tau for a general row)."""
        fr = self.frictions[e]
        if fr.g is None:
            f[fr.a] += tau
            if fr.b >= 0:
                f[fr.b] -= tau
        else:
            f -= self.rows[e] * tau

    def dampers(self) -> list[Spring]:
        """The springs with damping (their viscous loss is a term of the balance)."""
        return [s for s in self.springs if s.D > 0]

    def stored_energy(self, q: np.ndarray, w: np.ndarray) -> tuple[float, float]:
        """Kinetic and spring energy (ke, pe) [J] at state (q, w)."""
        ke = 0.5 * float(np.sum(self.J * w**2))
        pe = 0.0
        for s in self.springs:
            d = q[s.a] - (q[s.b] if s.b >= 0 else 0.0)
            pe += 0.5 * s.K * d * d
        return ke, pe

    def free_torque(self, t: float, q: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, float]:
        """Torques of sources, springs and viscous bearings on each rotor, and the source power."""
        f = -self.B * w
        p_src = 0.0
        for s in self.sources:
            tau = s.c0 * (s.shape(t) if s.shape is not None else 1.0) + s.c1 * w[s.body]
            if s.c2:
                tau += s.c2 * w[s.body] * w[s.body]
            f[s.body] += tau
            p_src += tau * w[s.body]
        for s in self.springs:
            d = q[s.a] - (q[s.b] if s.b >= 0 else 0.0)
            if s.D:
                d_w = w[s.a] - (w[s.b] if s.b >= 0 else 0.0)
                f[s.a] -= s.K * d + s.D * d_w
                if s.b >= 0:
                    f[s.b] += s.K * d + s.D * d_w
                continue
            f[s.a] -= s.K * d
            if s.b >= 0:
                f[s.b] += s.K * d
        return f, p_src



@dataclass
class RefResult:
    """A run of either path: time t [s], angles q [rad] and speeds w [rad/s] per rotor, command states u,
    mode-change events, cumulative energy terms [J] and solver statistics."""
    t: np.ndarray
    q: np.ndarray
    w: np.ndarray
    modes: np.ndarray  # (n_elements, n_samples)
    energy: dict[str, np.ndarray]
    events: list[dict[str, Any]]
    u: dict[str, np.ndarray]
    stats: dict[str, Any]

