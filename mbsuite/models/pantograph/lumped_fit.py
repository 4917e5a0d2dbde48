"""Lumped and transfer-function pantographs fitted to this model's driving-point receptance (the standards' three ways
of describing a pantograph: lumped masses, a multibody model, a transfer function).

`driving_point`: the receptance G(j w) of the contact point, head displacement per upward force on the head (m/N),
of the model linearised about its static equilibrium at a working height (ram spring ks at that height, the force
input `PantographODE.rhs_with_force` then replaces it: the pantograph alone, as under the wire). As `linearise.py`:
Coulomb friction is not linearisable and is left out, the contact is closed. Under the catenary the head carries
the contact force f = -f_up.

`fit_lumped`: an n-stage chain (`LumpedParams` of the catenary: stage 1 the head, the last stage on the base) by
least squares on the complex receptance (`scipy.optimize.least_squares`, trust-region reflective, the Jacobian
exact: `_chain_jacobian`), every mass, spring and damper positive through its logarithm; the residual is the relative
complex error (G_fit - G) / |G| at every frequency of the band (weight 1 / |G|, all frequencies alike), from `STARTS`
log-uniform starts (seeded), the best polished. By default the base spring k_n is not fitted: it holds the chain's
static stiffness at the head at the model's (`static_stiffness`; negative for this pantograph, whose uplift rises as
the head falls), so that the static uplift varies with the height as the model's. The static uplift F0 makes the
chain's static contact force at the working height (head at zero, rigid wire) the model's.

`fit_transfer`: a rational G(s) = N(s) / D(s) of stated order n (numerator degree n - 2: a mass's roll-off) by the
Sanathanan-Koerner iteration (linear least squares with the previous denominator as weight, on the same relative
error, s scaled by the band's top) and a least-squares polish of its coefficients; unstable poles are reported (the
model's own receptance has one: its uplift falls as the head rises, a negative static stiffness), its state-space
form is `TransferParams.from_tf`.

The fit error: the largest relative error of |G| and the largest phase error (deg) over the band (`fit_error`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from ...components.linear_pantograph import LumpedParams, TransferParams, chain_receptance
from ...errors import ParameterError
from ...limits import Limit
from .equations import PantographConfig, PantographODE
from .fit_defaults import BAND, DEFAULT_ORDER, DF, POLISH_NFEV, POLISHED, START_NFEV, START_POINTS, STARTS  # noqa: F401
from .params import PantographParams

#: the log-uniform box of the starts: masses (kg), springs (N/m), dampers (N s/m)
START_BOX = {"m": (1.0, 100.0), "k": (10.0, 1e6), "c": (1.0, 1e4)}


@dataclass(frozen=True)
class DrivingPoint:
    """The linearised receptance of the contact point at a working height: `freqs` (Hz), `G` (m/N, head up per upward
    force), `height` (m, ram/wire height above the base pivot), `static_force` (N, the contact force there) and the
    linear model (A, B, C) with input the upward force and output the head."""

    freqs: np.ndarray
    G: np.ndarray
    height: float
    static_force: float
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray

    @property
    def static_stiffness(self) -> float:
        """The static stiffness at the head (N/m), 1 / G(0) = -1 / (C A^-1 B): negative where the uplift rises as the
        head falls."""
        return -1.0 / float(self.C @ np.linalg.solve(self.A, self.B))


#: the stages of a lumped fit and the order of a transfer-function fit
STAGES = Limit(lo=1, hi=6, kind=int, doc="stages of a lumped fit")
ORDER = Limit(lo=2, hi=16, kind=int, doc="order of a transfer-function fit")

def band_freqs(band: tuple[float, float] = BAND, df: float = DF) -> np.ndarray:
    """The frequencies f_lo, f_lo + df, ..., f_hi (Hz), checked."""
    lo, hi = (float(b) for b in band)
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 <= lo < hi <= 1000.0):
        raise ParameterError(f"band {band!r}: need 0 <= f_lo < f_hi <= 1000 Hz")
    if not (math.isfinite(df) and 0.0 < df <= hi - lo):
        raise ParameterError(f"frequency step df = {df!r} Hz: need 0 < df <= f_hi - f_lo")
    n = int(round((hi - lo) / df)) + 1
    if n > 20000:
        raise ParameterError(f"band {band!r} with df = {df} Hz gives {n} frequencies; at most 20000")
    return np.linspace(lo, hi, n)


def driving_point(params: Mapping[str, Any] | PantographParams | None = None,
                  effects: Mapping[str, Any] | None = None, height: float | None = None,
                  freqs: np.ndarray | None = None) -> DrivingPoint:
    """The contact point's linearised receptance (module docstring) at ram height `height` (m; default the operating
    height y_op) at `freqs` (Hz; default `band_freqs()`). `params` override Table 3-I, `effects` are the model's
    (Coulomb friction dropped, contact closed)."""
    p = params if isinstance(params, PantographParams) else PantographParams(**dict(params or {}))
    eff = {**dict(effects or {}), "coulomb": False, "contact": "bilateral"}
    ode = PantographODE(p, PantographConfig(**eff))
    y_w = p.y_op if height is None else float(height)
    x0 = ode.equilibrium(y_w)
    f_up = ode.contact_force(y_w, ode.contact_height(x0))
    n = ode.n
    A, C = np.zeros((n, n)), np.zeros(n)
    for i in range(n):
        h = 1e-6 * max(1.0, abs(x0[i]))
        e = np.zeros(n)
        e[i] = h
        A[:, i] = (ode.rhs_with_force(0.0, x0 + e, f_up) - ode.rhs_with_force(0.0, x0 - e, f_up)) / (2 * h)
        C[i] = (ode.contact_height(x0 + e) - ode.contact_height(x0 - e)) / (2 * h)
    B = (ode.rhs_with_force(0.0, x0, f_up + 1.0) - ode.rhs_with_force(0.0, x0, f_up - 1.0)) / 2.0
    freqs = band_freqs() if freqs is None else np.asarray(freqs, float)
    eye = np.eye(n)
    G = np.array([C @ np.linalg.solve(2j * math.pi * f * eye - A, B) for f in freqs])
    return DrivingPoint(freqs, G, y_w, -float(f_up), A, B, C)


def fit_error(freqs: np.ndarray, G_fit: np.ndarray, G: np.ndarray) -> dict[str, float]:
    """The largest relative error of |G| and the largest phase error (deg) over `freqs`, and where they occur."""
    ra = np.abs(np.abs(G_fit) / np.abs(G) - 1.0)
    dp = np.abs(np.degrees(np.angle(G_fit / G)))
    return {"max_amplitude_rel": float(np.max(ra)), "at_f_amplitude_hz": float(freqs[int(np.argmax(ra))]),
            "max_phase_deg": float(np.max(dp)), "at_f_phase_hz": float(freqs[int(np.argmax(dp))]),
            "rms_complex_rel": float(np.sqrt(np.mean(np.abs(G_fit / G - 1.0) ** 2)))}


@dataclass(frozen=True)
class LumpedFit:
    """A fitted lumped pantograph: its parameters, the fit error over the band, the least-squares cost and the
    starts tried."""

    params: LumpedParams
    error: dict[str, float]
    cost: float
    starts: int
    nfev: int


#: the bounds of the fitted values: masses (kg; a stage lighter than 0.1 kg is not one), springs (N/m), dampers
#: (N s/m)
BOUNDS = {"m": (0.1, 1e4), "k": (1e-2, 1e9), "c": (1e-3, 1e7)}


def _box(box: dict[str, tuple[float, float]], n: int) -> tuple[np.ndarray, np.ndarray]:
    return (np.log([box[k][0] for k in ("m", "k", "c") for _ in range(n)]),
            np.log([box[k][1] for k in ("m", "k", "c") for _ in range(n)]))


def _chain_jacobian(m: np.ndarray, k: np.ndarray, c: np.ndarray, freqs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The chain's receptance G (nf,) and its derivatives with respect to log m, log k, log c (nf, 3n), forward
    through the continued fraction of `chain_receptance`: dG/dS_1 = -G^2, dS_i/dS_{i+1} = z_i^2 / (z_i + S_{i+1})^2,
    dS_i/dz_i = S_{i+1}^2 / (z_i + S_{i+1})^2, dS_i/dm_i = s^2."""
    n = len(m)
    s = 2j * np.pi * np.asarray(freqs, float)
    S = [None] * n
    S[n - 1] = m[-1] * s * s + k[-1] + c[-1] * s
    for i in range(n - 2, -1, -1):
        z = k[i] + c[i] * s
        S[i] = m[i] * s * s + z * S[i + 1] / (z + S[i + 1])
    G = 1.0 / S[0]
    J = np.empty((s.size, 3 * n), complex)
    P = -G * G  # dG/dS_j, carried down the chain
    for j in range(n):
        if j < n - 1:
            z = k[j] + c[j] * s
            q = 1.0 / (z + S[j + 1]) ** 2
            dz = P * S[j + 1] ** 2 * q
        else:
            dz = P
        J[:, j] = P * s * s * m[j]
        J[:, n + j] = dz * k[j]
        J[:, 2 * n + j] = dz * s * c[j]
        if j < n - 1:
            P = P * z * z * q
    return G, J


def fit_lumped(freqs: np.ndarray, G: np.ndarray, stages: int, static_force: float, *,
               static_stiffness: float | None = None, starts: int = STARTS, seed: int = 0,
               x_scale_tol: float = 1e-12) -> LumpedFit:
    """The n-stage lumped pantograph nearest the receptance `G` at `freqs` (module docstring), its F0 set so that
    its static contact force at the working height is `static_force` (N). `static_stiffness` (N/m): the chain's
    static stiffness at the head is held at this value through its base spring k_n (which may then be negative: an
    uplift that rises as the head falls) and k_n is not fitted; None: k_n is fitted as the others, positive."""
    stages = STAGES.check("stages", stages, ParameterError, " of a lumped fit")
    freqs, G = np.asarray(freqs, float), np.asarray(G, complex)
    if freqs.shape != G.shape or freqs.size < 3 * stages:
        raise ParameterError(f"a {stages}-stage fit needs at least {3 * stages} frequencies, as many as responses")
    pinned = static_stiffness is not None
    if pinned and not (math.isfinite(static_stiffness) and static_stiffness != 0.0):
        raise ParameterError(f"static_stiffness = {static_stiffness!r} N/m: a finite non-zero number")
    n = stages
    w = 1.0 / np.abs(G)

    def unpack(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        v = np.exp(theta)
        m, c = v[:n], v[-n:]
        k = v[n:-n]
        if pinned:  # 1 / K_s = sum 1/k_i: the base spring that holds the static stiffness
            d = 1.0 / static_stiffness - float(np.sum(1.0 / k))
            k = np.append(k, 1.0 / d if abs(d) > 1e-300 else 1e300)
        return m, k, c

    def residual(theta: np.ndarray, every: int = 1) -> np.ndarray:
        r = (chain_receptance(*unpack(theta), freqs[::every]) - G[::every]) * w[::every]
        return np.concatenate([r.real, r.imag])

    def jacobian(theta: np.ndarray, every: int = 1) -> np.ndarray:
        m, k, c = unpack(theta)
        J = _chain_jacobian(m, k, c, freqs[::every])[1]
        if pinned:  # k_n = 1 / (1/K_s - sum_{i<n} 1/k_i): d k_n / d log k_i = -k_n^2 / k_i
            J[:, n:2 * n - 1] -= J[:, [2 * n - 1]] * (k[-1] / k[:-1])[None, :]
            J = np.delete(J, 2 * n - 1, axis=1)
        J = J * w[::every, None]
        return np.vstack([J.real, J.imag])

    rng = np.random.default_rng(seed)
    keep = np.ones(3 * n, bool)
    if pinned:
        keep[2 * n - 1] = False
    lo, hi = (b[keep] for b in _box(START_BOX, n))
    bounds = tuple(b[keep] for b in _box(BOUNDS, n))
    # the starts on every `every`-th frequency (at most START_POINTS), the best few polished on all of them
    every = max(1, freqs.size // START_POINTS)
    sols, nfev = [], 0
    for _ in range(int(starts)):
        sol = least_squares(residual, rng.uniform(lo, hi), jac=jacobian, method="trf", bounds=bounds,
                            max_nfev=START_NFEV, kwargs={"every": every})
        nfev += sol.nfev
        sols.append(sol)
    best = None
    for sol in sorted(sols, key=lambda r: r.cost)[:POLISHED]:
        pol = least_squares(residual, sol.x, jac=jacobian, method="trf", bounds=bounds, xtol=x_scale_tol,
                            ftol=x_scale_tol, gtol=x_scale_tol, max_nfev=POLISH_NFEV)
        nfev += pol.nfev
        if best is None or pol.cost < best.cost:
            best = pol
    m, k, c = unpack(best.x)
    # LumpedParams.static_force is F0 / (1 + k_n sum_{i<n} 1/k_i): the F0 that gives `static_force`
    p = LumpedParams(tuple(m), tuple(k), tuple(c), float(static_force) * (1.0 + k[-1] * float(np.sum(1.0 / k[:-1]))),
                     negative_base_spring=bool(k[-1] < 0))  # stated: the fitted uplift rises as the head falls
    return LumpedFit(p, fit_error(freqs, p.receptance(freqs), G), float(best.cost), int(starts), int(nfev))


@dataclass(frozen=True)
class TransferFit:
    """A fitted transfer-function pantograph: G(s) = num / den (s in rad/s, highest power first), its state-space
    parameters, its poles (rad/s), the fit error over the band."""

    num: tuple[float, ...]
    den: tuple[float, ...]
    params: TransferParams
    poles: tuple[complex, ...]
    error: dict[str, float]
    iterations: int
    unstable: tuple[complex, ...] = field(default=())


def _tf_eval(num: np.ndarray, den: np.ndarray, s: np.ndarray) -> np.ndarray:
    return np.polyval(num, s) / np.polyval(den, s)


def fit_transfer(freqs: np.ndarray, G: np.ndarray, order: int, static_force: float, *, iterations: int = 30
                 ) -> TransferFit:
    """The rational G(s) of order `order` (denominator degree; numerator degree order - 2) nearest `G` at `freqs`
    (module docstring), as a transfer-function pantograph with static force `static_force` (N)."""
    order = ORDER.check("order", order, ParameterError, " of a transfer-function fit")
    freqs, G = np.asarray(freqs, float), np.asarray(G, complex)
    n, m = int(order), int(order) - 2
    if freqs.size < 2 * n:
        raise ParameterError(f"an order-{n} fit needs at least {2 * n} frequencies")
    w0 = 2 * math.pi * max(float(np.max(freqs)), 1e-3)
    g0 = float(np.median(np.abs(G)))
    s = 2j * math.pi * freqs / w0
    y = G / g0
    wr = 1.0 / np.abs(y)
    # unknowns: numerator b_m..b_0, denominator a_{n-1}..a_0 (monic): N(s) - y D(s) = y s^n
    Vn = np.vander(s, m + 1)
    Vd = np.vander(s, n + 1)[:, 1:]
    den_prev = np.ones(freqs.size, complex)
    coef = None
    for _it in range(int(iterations)):
        ww = wr / np.abs(den_prev)
        M = np.hstack([Vn, -y[:, None] * Vd]) * ww[:, None]
        rhs = y * s ** n * ww
        coef = np.linalg.lstsq(np.vstack([M.real, M.imag]), np.concatenate([rhs.real, rhs.imag]), rcond=None)[0]
        den_prev = np.polyval(np.concatenate([[1.0], coef[m + 1:]]), s)

    def residual(c: np.ndarray) -> np.ndarray:
        r = (_tf_eval(c[:m + 1], np.concatenate([[1.0], c[m + 1:]]), s) - y) * wr
        return np.concatenate([r.real, r.imag])

    coef = least_squares(residual, coef, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    # back to s in rad/s: a polynomial in s/w0 with coefficients c_j (power j) has c_j / w0^j
    num_s = coef[:m + 1] * g0 / w0 ** np.arange(m, -1, -1)
    den_s = np.concatenate([[1.0], coef[m + 1:]]) / w0 ** np.arange(n, -1, -1)
    num_s, den_s = num_s / den_s[0], den_s / den_s[0]
    g0 = float(np.polyval(num_s, 0.0) / np.polyval(den_s, 0.0)) if np.polyval(den_s, 0.0) != 0 else 0.0
    tp = TransferParams.from_tf(num_s, den_s, float(static_force), negative_static_stiffness=g0 < 0)
    poles = np.roots(den_s)
    G_fit = tp.receptance(freqs)
    return TransferFit(tuple(map(float, num_s)), tuple(map(float, den_s)), tp, tuple(complex(z) for z in poles),
                       fit_error(freqs, G_fit, G), int(iterations),
                       tuple(complex(z) for z in poles if z.real > 0))


def write_json(path: Path, obj: Any) -> Path:
    """`obj` as indented JSON at `path`."""
    import json

    path.write_text(json.dumps(obj, indent=2) + "\n")
    return path
