"""The pantograph's linearisation about a static equilibrium, from the hand-derived equations: x' = A x + B y_w,
outputs (F1, F2, HD, y_d) = C x; its modes, its frequency response and the fastest mode a fixed step must resolve.

Coulomb friction is not linearisable and is left out (the modes are those of the viscous model); the contact is taken
as closed (bilateral). MuJoCo's own linearisation is `mujoco.mujoco_modes`.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .equations import PantographConfig, PantographODE
from .params import PantographParams


def linearize(ode: PantographODE, x0: np.ndarray, y_w0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A = df/dx, B = df/dy_w at the equilibrium (central differences), C for (F1, F2, HD, y_d).

    Coulomb friction is not linearisable and is left out (the modes are those of the viscous model); the contact is
    taken as closed (bilateral)."""
    lin = PantographODE(ode.p, PantographConfig(**{**ode.cfg.__dict__, "coulomb": False, "contact": "bilateral"}))
    n = lin.n
    A = np.zeros((n, n))
    for i in range(n):
        h = 1e-6 * max(1.0, abs(x0[i]))
        e = np.zeros(n)
        e[i] = h
        A[:, i] = (lin.rhs(0.0, x0 + e, y_w0) - lin.rhs(0.0, x0 - e, y_w0)) / (2 * h)
    h = 1e-7
    B = (lin.rhs(0.0, x0, y_w0 + h) - lin.rhs(0.0, x0, y_w0 - h)) / (2 * h)
    p = ode.p
    J, _ = lin.theta_jacobian(x0[: lin.nq])
    th = lin.theta(x0[: lin.nq])
    Ct = np.diag([p.l1 * math.cos(th[0]), p.l2 * math.cos(th[1]), p.lh * math.cos(th[2])]) @ J
    C = np.zeros((4, n))
    C[:3, : lin.nq] = Ct
    C[3, : lin.nq] = Ct.sum(axis=0)
    return A, B, C


def _linear_config(cfg: PantographConfig) -> PantographConfig:
    """The effects the linearisation keeps (Coulomb friction excluded, contact closed): one cache entry for all."""
    return PantographConfig(**{**cfg.__dict__, "coulomb": False, "contact": "bilateral"})


@functools.lru_cache(maxsize=256)
def _linear_cached(p: PantographParams, cfg: PantographConfig, y_w: float) -> tuple[np.ndarray, ...]:
    ode = PantographODE(p, cfg)
    x0 = ode.equilibrium(y_w)
    A, B, C = linearize(ode, x0, y_w)
    lam = np.linalg.eigvals(A)
    for a in (x0, A, B, C, lam):
        a.flags.writeable = False
    return x0, A, B, C, lam


def linear_model(p: PantographParams, cfg: PantographConfig, y_w: float) -> tuple[np.ndarray, ...]:
    """(x0, A, B, C, eigenvalues of A) about the static equilibrium at ram height y_w; cached per parameter set,
    effects and height (read-only arrays; one equilibrium and 2n + 2 right-hand sides, ~10 ms, on a miss)."""
    return _linear_cached(p, _linear_config(cfg), float(y_w))


def omega_max(p: PantographParams, cfg: PantographConfig, y_w: float) -> float:
    """The largest |eigenvalue| of the linearised model (rad/s): the fastest mode a fixed step must resolve (lab
    scene: the 19.4 Hz head mode, 121.9 rad/s; the nonlinear cylinder adds its real pole, 163 rad/s with the default
    laminar band)."""
    return float(np.max(np.abs(linear_model(p, cfg, y_w)[4])))


def stiffest_pole(p: PantographParams, cfg: PantographConfig, y_w: float) -> float:
    """The largest |real eigenvalue| of the linearised model (1/s): the cylinder's pole (0 if it has none)."""
    lam = linear_model(p, cfg, y_w)[4]
    real = np.abs(lam[np.abs(lam.imag) <= 1e-9 * np.maximum(np.abs(lam), 1.0)])
    return float(np.max(real)) if real.size else 0.0


def modes_from_eigs(lam: np.ndarray) -> list[dict]:
    """Natural frequency (Hz) and damping ratio of each complex pair; time constant of each real pole."""
    out = []
    for v in sorted(lam, key=lambda z: abs(z)):
        if v.imag < -1e-9:
            continue
        wn = abs(v)
        if abs(v.imag) > 1e-9:
            out.append({"kind": "oscillatory", "f_n": wn / (2 * math.pi), "zeta": -v.real / wn,
                        "f_d": v.imag / (2 * math.pi)})
        elif wn > 0:
            out.append({"kind": "first-order", "f_n": wn / (2 * math.pi), "tau": -1.0 / v.real, "zeta": 1.0})
    return out


def linear_response(A: np.ndarray, B: np.ndarray, C: np.ndarray, freqs: np.ndarray) -> np.ndarray:
    """H(j w) = C (j w I - A)^-1 B per frequency, (nf, 4) complex, relative to the input y_w."""
    n = A.shape[0]
    return np.array([C @ np.linalg.solve(1j * 2 * math.pi * f * np.eye(n) - A, B) for f in freqs])
