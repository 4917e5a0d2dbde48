"""Pantographs that can run under the FE catenary: a small protocol and the EN 50318 2-mass reference pantograph.

The coupled integrator (`sim.py`) advances the catenary with the trapezoidal rule, so over one step the contact force
varies linearly from f_n to f_{n+1}. A pantograph only has to answer:

- `static(y_wire, k_wire)`: put yourself in static equilibrium pressing on a wire at height `y_wire` (m, relative to the
  undisturbed CW level) through a spring `k_wire` (the contact spring in series with the wire's static compliance);
  return the static contact force (N).
- `trial(t, dt, f0, f1)`: the contact-point height at t + dt (m, same datum) if the contact force pressing the head
  down (f >= 0 pushes the wire up) varied linearly from f0 to f1 over the step. The state is not changed; `commit()`
  accepts the last trial.
- `head()`, `signals()`: current contact-point height and named outputs.

`affine = True` tells the coupler that trial() is exactly affine in f1; such a pantograph may also offer
`affine_map(dt, f0) -> (P, g)` with head height P - g f1. A nonlinear pantograph (the Eppinger model, `eppinger.py`)
is coupled by a secant iteration on f1.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np


class Pantograph(Protocol):
    name: str
    affine: bool

    def static(self, y_wire: float, k_wire: float) -> float: ...

    def trial(self, t: float, dt: float, f0: float, f1: float) -> float: ...

    def commit(self) -> None: ...

    def head(self) -> float: ...

    def signals(self) -> dict[str, float]: ...


class TwoMassPantograph:
    """EN 50318 reference pantograph: head m1 on k1, c1 to the frame; frame m2 on k2, c2 to a fixed base; the static
    uplift F0 acts on the frame; k2 is referenced to the undisturbed CW level (catenary.md).

        m1 x1'' = -k1 (x1 - x2) - c1 (x1' - x2') - f
        m2 x2'' =  k1 (x1 - x2) + c1 (x1' - x2') - k2 x2 - c2 x2' + F0

    Integrated with the trapezoidal rule (the catenary's scheme), hence exactly affine in the contact force."""

    affine = True

    def __init__(self, m1: float, k1: float, c1: float, m2: float, k2: float, c2: float, F0: float,
                 name: str = "reference2mass"):
        self.name = name
        self.Mm = np.diag([m1, m2])
        self.Km = np.array([[k1, -k1], [-k1, k1 + k2]])
        self.Cm = np.array([[c1, -c1], [-c1, c1 + c2]])
        self.F0 = F0
        self.x = np.zeros(2)
        self.v = np.zeros(2)
        self._dt = None
        self._pending = None

    def _prepare(self, dt: float) -> None:
        h = dt / 2
        self._dt = dt
        Si = np.linalg.inv(self.Mm + h * self.Cm + h * h * self.Km)
        self._S = ((float(Si[0, 0]), float(Si[0, 1])), (float(Si[1, 0]), float(Si[1, 1])))
        self._m = (float(self.Mm[0, 0]), float(self.Mm[1, 1]))
        self._k = (float(self.Km[0, 0]), float(self.Km[0, 1]), float(self.Km[1, 1]))

    def _rhs(self, h: float, f0: float, f1: float) -> tuple[float, float]:
        (m1, m2), (k11, k12, k22) = self._m, self._k
        x1, x2 = float(self.x[0]), float(self.x[1])
        v1, v2 = float(self.v[0]), float(self.v[1])
        return (m1 * v1 - h * (k11 * x1 + k12 * x2) - h * (f0 + f1) / 2,
                m2 * v2 - h * (k12 * x1 + k22 * x2) + h * self.F0)

    def static(self, y_wire: float, k_wire: float) -> float:
        # K x = [-f, F0] with f = k_wire (x1 - y_wire)
        A = self.Km + np.array([[k_wire, 0.0], [0.0, 0.0]])
        self.x = np.linalg.solve(A, np.array([k_wire * y_wire, self.F0]))
        self.v = np.zeros(2)
        return float(k_wire * (self.x[0] - y_wire))

    def affine_map(self, dt: float, f0: float) -> tuple[float, float]:
        """(P, g): head height at t + dt is P - g f1 (exact, the scheme is linear)."""
        if dt != self._dt:
            self._prepare(dt)
        h = dt / 2
        r1, r2 = self._rhs(h, f0, 0.0)
        S = self._S
        return float(self.x[0]) + 2 * h * (S[0][0] * r1 + S[0][1] * r2), h * h * S[0][0]

    def trial(self, t: float, dt: float, f0: float, f1: float) -> float:
        if dt != self._dt:
            self._prepare(dt)
        h = dt / 2
        r1, r2 = self._rhs(h, f0, f1)
        S = self._S
        vb1 = S[0][0] * r1 + S[0][1] * r2
        vb2 = S[1][0] * r1 + S[1][1] * r2
        x_new = np.array([self.x[0] + 2 * h * vb1, self.x[1] + 2 * h * vb2])
        self._pending = (x_new, np.array([2 * vb1 - self.v[0], 2 * vb2 - self.v[1]]))
        return float(x_new[0])

    def commit(self) -> None:
        self.x, self.v = self._pending

    def head(self) -> float:
        return float(self.x[0])

    def signals(self) -> dict[str, float]:
        return {"head_displacement": float(self.x[0]), "frame_displacement": float(self.x[1])}

    def energy(self) -> float:
        """Kinetic + spring energy (J) minus the potential of F0."""
        return float(0.5 * self.v @ self.Mm @ self.v + 0.5 * self.x @ self.Km @ self.x - self.F0 * self.x[1])
