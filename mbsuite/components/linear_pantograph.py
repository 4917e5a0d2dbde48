"""Linear pantographs: the n-stage lumped pantograph and the transfer-function pantograph, run under the wire by the
catenary (its `[pantograph]` section) and fitted by the pantograph model (`mbsuite pantograph fit-lumped`).

Both are one linear state-space model of the head (`LinearPantograph`), x' = A x + b0 F0 - B f, head = c x, with f
the contact force (N, >= 0 pushes the head down) entering where it acts (B: the response to an upward force on the
head), F0 the static uplift entering through b0. A constant aerodynamic uplift (`aerodynamic(head, frame)`, N upward;
the catenary's `[aerodynamics]`) adds B Fa_h (on the head) + bf Fa_f (on the frame: the last stage of a lumped chain,
bf = b0; a transfer function has only its head port, so its frame force enters by the path F0 takes, bf = b0 = B:
the frame's uplift adds to the static force, one for one against a rigid wire) to the constant input. Integrated with
the wire's own trapezoidal rule,

    (I - h A) x1 = (I + h A) x0 + h (2 (b0 F0 + B Fa_h + bf Fa_f) - B (f0 + f1)),   h = dt / 2,

the head at t + dt is exactly affine in the end-of-step force f1 (`affine_map`), as the 2-mass reference pantograph's
(whose Newmark average-acceleration scheme is this rule on its first-order form: the same numbers to rounding).

- `LumpedParams`: stage 1 is the head (the contact point), stage i hangs on stage i + 1 through k_i, c_i and the last
  stage on the base through k_n, c_n; the static uplift F0 acts on the last stage, every spring
  unstretched at zero displacement (k_n is referenced to the undisturbed contact wire level, as the reference's k2;
  it may be 0 or negative: a static uplift that does not change, or rises, as the head falls).
  Two stages with the reference's m1 ... F0 are the EN 50318 2-mass pantograph.
- `TransferParams`: a strictly proper state-space model (A, B, C) of the head's receptance G(s) = head displacement
  per upward force on the head, m/N (a fitted or measured frequency response); the static uplift F0 is the contact
  force at the working height against a rigid wire and enters with B (the model's zero state is that equilibrium).

Parameters come from the scene's `[pantograph]` section, `params` only (`section`): `m`, `k`, `c` (lists, kg, N/m,
N s/m) and `F0` (N) of a lumped pantograph; `A`, `B`, `C` (lists; A square, in 1/s) and `F0` of a transfer-function
one. `mbsuite pantograph fit-lumped` writes both from the Eppinger model's linearised receptance.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError, SceneError, SolverError
from ..limits import Limit
from ..schema import Items, Rule, Section

#: the `pantograph` effect's values of the linear pantographs
LUMPED, TRANSFER = "lumped", "transfer"
#: the keys of `[pantograph] params` each takes
LUMPED_KEYS = ("m", "k", "c", "F0", "negative_base_spring")
TRANSFER_KEYS = ("A", "B", "C", "F0", "negative_static_stiffness")
#: the largest state a transfer-function pantograph may have (its step solves an n x n system once per time step)
MAX_STATES = 40
#: the largest number of stages of a lumped pantograph
MAX_STAGES = 20
#: the frequencies (Hz) on which a transfer-function pantograph's passivity is checked (besides its poles')
PASSIVITY_GRID = np.geomspace(1e-3, 1e3, 601)


def _lumped_rules(d: Mapping[str, Any]) -> str | None:
    m, k, c = d["m"], d["k"], d["c"]
    if not len(m) == len(k) == len(c):
        return f"m, k, c need one length (one entry per stage), got {len(m)}, {len(k)}, {len(c)}"
    bad = next((i for i, x in enumerate(k[:-1]) if not x > 0), None)
    if bad is not None:
        return f"k[{bad}] = {k[bad]!r} N/m must be > 0: only the last spring, to the base, may be <= 0"
    if k[-1] < 0 and not d["negative_base_spring"]:
        return (f"the base spring k[{len(k) - 1}] = {k[-1]!r} N/m is negative (a static uplift that rises as the head "
                "falls: the pantograph alone is statically unstable, held by the wire): state it with "
                "negative_base_spring = true")
    if d["negative_base_spring"] and not k[-1] < 0:
        return f"negative_base_spring = true, but the base spring k[{len(k) - 1}] = {k[-1]!r} N/m is not negative"
    den = 1.0 + k[-1] * sum(1.0 / x for x in k[:-1])
    if not den > 0:
        return (f"the base spring k[{len(k) - 1}] = {k[-1]!r} N/m outweighs the chain above it (1 + k_n sum 1/k_i = "
                f"{den:.3g} <= 0): the static force F0 / (1 + k_n sum 1/k_i) is not positive")
    return None


def _poles(poles: Sequence[complex]) -> list[complex]:
    """Poles (1/s) to 7 significant digits, for a message."""
    return [complex(float(f"{p.real:.7g}"), float(f"{p.imag:.7g}")) for p in poles]


def _transfer_rules(d: Mapping[str, Any]) -> str | None:
    A, B, C = d["A"], d["B"], d["C"]
    n = len(A)
    if any(len(r) != n for r in A) or len(B) != n or len(C) != n:
        return (f"A must be square and B, C of its size: A rows {[len(r) for r in A]}, B {len(B)}, C {len(C)} "
                f"entries")
    A, B, C = np.array(A, float), np.array(B, float), np.array(C, float)
    poles = np.linalg.eigvals(A)
    if not np.all(np.isfinite(poles)):
        return "the eigenvalues of A are not finite (its entries overflow)"
    scale = max(1.0, float(np.max(np.abs(poles))))
    zero = [p for p in poles if abs(p) <= 1e-12 * scale]
    if zero:
        return (f"A has {len(zero)} pole(s) at 0 (a rigid-body mode: G(0) infinite, no static stiffness); a "
                "transfer-function pantograph's receptance is finite at 0 Hz (a constant uplift is a lumped "
                "pantograph with its base spring k_n = 0)")
    oscillating = [p for p in poles if abs(p.imag) > 1e-9 * scale and p.real >= -1e-12 * scale]
    if oscillating:
        return (f"unstable: pole(s) {_poles(oscillating)} 1/s of A have a real part >= 0 (an oscillation that does "
                "not decay; a pantograph's modes decay)")
    rising = [float(p.real) for p in poles if abs(p.imag) <= 1e-9 * scale and p.real > 0]
    g0 = float(-C @ np.linalg.solve(A, B))
    if rising and not (d["negative_static_stiffness"] and g0 < 0 and len(rising) == 1):
        return (f"unstable: real pole(s) {[float(f'{p:.7g}') for p in rising]} 1/s >= 0; a pantograph alone is "
                "unstable only through a negative static stiffness (one real pole, G(0) < 0), stated with "
                f"negative_static_stiffness = true (here G(0) = {g0:.4g} m/N)")
    if d["negative_static_stiffness"] and not g0 < 0:
        return f"negative_static_stiffness = true, but G(0) = {g0:.4g} m/N is not negative"
    f = np.concatenate([PASSIVITY_GRID, np.abs(poles.imag) / (2 * np.pi)])
    f = np.unique(f[f > 0])
    G = np.array([C @ np.linalg.solve(2j * np.pi * x * np.eye(n) - A, B) for x in f])
    bad = np.flatnonzero(G.imag > 1e-9 * np.abs(G))
    if bad.size:
        i = int(bad[0])
        return (f"not passive: Im G = {G.imag[i]:.3g} m/N > 0 at {f[i]:.4g} Hz, the lowest of the {bad.size} checked "
                f"frequencies where it fails ({f[i]:.4g} to {f[bad[-1]]:.4g} Hz; the head would give energy to the "
                "wire there: negative damping)")
    # high frequencies, exactly: a positive-real mobility s G(s) falls at most as 1/s, so G(s) = C B / s + C A B / s^2
    # + ...: a massless head on a damper 1 / (C B) > 0, or C B = 0 and a head mass 1 / (C A B) > 0
    h1, h2 = float(C @ B), float(C @ A @ B)
    if h1 * scale > 1e-9 * abs(h2):
        return None
    if h1 * scale < -1e-9 * abs(h2):
        return (f"not passive at high frequencies: C B = {h1:.4g} m/(N s) < 0 (G(s) = C B / s there: a massless head "
                "on a negative damper)")
    if not h2 > 0:
        return (f"no positive head mass: C B = 0 and C A B = {h2:.4g} 1/kg (the head mass is 1 / (C A B); G(s) of a "
                "pantograph falls as 1 / (m s^2) with m > 0, or as 1 / (c s))")
    return None


def _lim(lo: float | None = None, hi: float | None = None, unit: str = "", doc: str = "", **kw: Any) -> Limit:
    return Limit(lo=lo, hi=hi, unit=unit, doc=doc, **kw)


#: the declaration of a lumped pantograph's `[pantograph] params`
LUMPED_SECTION = Section("[pantograph] params (lumped)", {
    "m": Items(_lim(1e-6, 1e4, "kg", "stage mass"), min=1, max=MAX_STAGES, unit="kg",
               doc="stage masses, stage 1 the head"),
    "k": Items(_lim(-1e9, 1e9, "N/m", "stage spring"), min=1, max=MAX_STAGES, unit="N/m",
               doc="springs: k_i joins stage i to stage i + 1, the last to the base (only it may be <= 0)"),
    "c": Items(_lim(0.0, 1e9, "N s/m", "stage damper"), min=1, max=MAX_STAGES, unit="N s/m",
               doc="dampers, beside the springs (>= 0: passive)"),
    "F0": _lim(0.0, 1e4, "N", "static uplift on the last stage", lo_open=True),
    "negative_base_spring": Limit(kind=bool, default=False,
                                  doc="states a negative base spring (a fitted pantograph's: uplift rising as the "
                                      "head falls)"),
}, required=("m", "k", "c", "F0"), rules=(
    Rule("m, k, c of one length; k_i > 0 but the base spring's; a negative base spring stated; a positive static "
         "force", _lumped_rules),),
    doc="an n-stage lumped pantograph", example={"m": [8.0, 12.0, 20.0], "k": [9000.0, 4000.0, 300.0],
                                                 "c": [30.0, 60.0, 120.0], "F0": 100.0})
#: the declaration of a transfer-function pantograph's `[pantograph] params`
TRANSFER_SECTION = Section("[pantograph] params (transfer function)", {
    "A": Items(Items(_lim(doc="state matrix entry"), min=1, max=MAX_STATES), min=1, max=MAX_STATES,
               doc="state matrix, its rows (square; 1/s where the states share a unit; a companion form's entries "
                   "grow as the poles' product: unbounded)"),
    "B": Items(_lim(), min=1, max=MAX_STATES, doc="input vector (state rate per N of upward force on the head)"),
    "C": Items(_lim(), min=1, max=MAX_STATES, doc="output vector (m of head per unit state)"),
    "F0": _lim(0.0, 1e4, "N", "contact force at the working height against a rigid wire", lo_open=True),
    "negative_static_stiffness": Limit(kind=bool, default=False,
                                       doc="states G(0) < 0 and its one real unstable pole (a fitted pantograph's)"),
}, required=("A", "B", "C", "F0"), rules=(
    Rule("A square, B and C of its size; stable (every pole of A has a real part < 0, but one real pole > 0 with "
         "negative_static_stiffness = true and G(0) < 0; no pole at 0); passive (Im G(j w) <= 0 on 1 mHz - 1 kHz and "
         "at the poles' frequencies; a head mass 1 / (C A B) > 0 or a head damper 1 / (C B) > 0)", _transfer_rules),),
    doc="a transfer-function pantograph G(s) = C (sI - A)^-1 B",
    example={"A": [[0.0, 1.0], [-500.0, -2.0]], "B": [0.0, 0.1], "C": [1.0, 0.0], "F0": 90.0})


def chain_receptance(m: Sequence[float], k: Sequence[float], c: Sequence[float], freqs: np.ndarray) -> np.ndarray:
    """The head's receptance G(j 2 pi f) (m/N) of the chain m, k, c (stage 1 the head, unchecked): the continued
    fraction of the dynamic stiffness seen from the head, S_n = m_n s^2 + c_n s + k_n, S_i = m_i s^2 + z_i S_{i+1} /
    (z_i + S_{i+1}) with z_i = k_i + c_i s, G = 1 / S_1."""
    s = 2j * np.pi * np.asarray(freqs, float)
    S = m[-1] * s * s + k[-1] + c[-1] * s
    for i in range(len(m) - 2, -1, -1):
        z = k[i] + c[i] * s
        S = m[i] * s * s + z * S / (z + S)
    return 1.0 / S


@dataclass(frozen=True)
class LumpedParams:
    """An n-stage lumped pantograph (module docstring): masses `m` (kg), springs `k` (N/m) and dampers `c` (N s/m),
    stage 1 the head; `F0` the static uplift on the last stage (N)."""

    m: tuple[float, ...]
    k: tuple[float, ...]
    c: tuple[float, ...]
    F0: float
    negative_base_spring: bool = False

    def __post_init__(self) -> None:
        d = LUMPED_SECTION.check({f: getattr(self, f) for f in LUMPED_KEYS}, "lumped pantograph", ParameterError)
        for f in LUMPED_KEYS:
            object.__setattr__(self, f, tuple(d[f]) if isinstance(d[f], list) else d[f])

    @property
    def stages(self) -> int:
        """The number of stages."""
        return len(self.m)

    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Mass, damping and stiffness matrices (M, C, K) of the chain."""
        n = self.stages

        def chain(v: tuple[float, ...]) -> np.ndarray:
            X = np.zeros((n, n))
            for i in range(n):
                X[i, i] += v[i]
                if i + 1 < n:
                    X[i + 1, i + 1] += v[i]
                    X[i, i + 1] = X[i + 1, i] = -v[i]
            return X

        return np.diag(self.m), chain(self.c), chain(self.k)

    def receptance(self, freqs: np.ndarray) -> np.ndarray:
        """Head displacement per upward force on the head, G(j 2 pi f) (m/N): `chain_receptance`."""
        return chain_receptance(self.m, self.k, self.c, freqs)

    def static_force(self) -> float:
        """The contact force (N) at the working height (head at zero) against a rigid wire: F0 k-weighted,
        F0 / (1 + k_n sum_{i<n} 1/k_i)."""
        return self.F0 / (1.0 + self.k[-1] * sum(1.0 / x for x in self.k[:-1]))

    def section(self) -> dict[str, Any]:
        """The scene's `[pantograph] params` of this pantograph."""
        return {"m": list(self.m), "k": list(self.k), "c": list(self.c), "F0": self.F0,
                **({"negative_base_spring": True} if self.negative_base_spring else {})}


@dataclass(frozen=True)
class TransferParams:
    """A transfer-function pantograph (module docstring): x' = A x + B u, head = C x (A in 1/s, B x per N, C m per
    unit x), u the upward force on the head; `F0` the contact force (N) at the working height against a rigid wire."""

    A: tuple[tuple[float, ...], ...]
    B: tuple[float, ...]
    C: tuple[float, ...]
    F0: float
    negative_static_stiffness: bool = False

    def __post_init__(self) -> None:
        A = self.A.tolist() if isinstance(self.A, np.ndarray) else self.A
        d = TRANSFER_SECTION.check({**{f: getattr(self, f) for f in TRANSFER_KEYS}, "A": A},
                                   "transfer-function pantograph", ParameterError)
        object.__setattr__(self, "A", tuple(tuple(r) for r in d["A"]))
        for f in ("B", "C"):
            object.__setattr__(self, f, tuple(d[f]))
        object.__setattr__(self, "F0", d["F0"])
        object.__setattr__(self, "negative_static_stiffness", d["negative_static_stiffness"])

    @classmethod
    def from_tf(cls, num: Sequence[float], den: Sequence[float], F0: float,
                negative_static_stiffness: bool = False) -> TransferParams:
        """The controllable realisation of G(s) = num(s) / den(s) (coefficients highest power first, s in rad/s;
        strictly proper)."""
        from scipy.signal import tf2ss

        num, den = np.atleast_1d(np.asarray(num, float)), np.atleast_1d(np.asarray(den, float))
        if len(np.trim_zeros(num, "f")) >= len(np.trim_zeros(den, "f")):
            raise ParameterError("a transfer-function pantograph needs a strictly proper G(s) (numerator degree below "
                                 "the denominator's)")
        A, B, C, D = tf2ss(num, den)
        return cls(A.tolist(), B[:, 0].tolist(), C[0].tolist(), F0, negative_static_stiffness)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, C) as arrays."""
        return np.array(self.A, float), np.array(self.B, float), np.array(self.C, float)

    def receptance(self, freqs: np.ndarray) -> np.ndarray:
        """G(j 2 pi f) = C (j 2 pi f I - A)^-1 B (m/N)."""
        A, B, C = self.arrays()
        eye = np.eye(len(B))
        return np.array([C @ np.linalg.solve(2j * np.pi * f * eye - A, B) for f in np.asarray(freqs, float)])

    def static_force(self) -> float:
        """The contact force (N) at the working height against a rigid wire: F0."""
        return self.F0

    def section(self) -> dict[str, Any]:
        """The scene's `[pantograph] params` of this pantograph."""
        return {"A": [list(r) for r in self.A], "B": list(self.B), "C": list(self.C), "F0": self.F0,
                **({"negative_static_stiffness": True} if self.negative_static_stiffness else {})}


class LinearPantograph:
    """A linear pantograph under the wire (module docstring): x' = A x + b0 F0 + B Fa_h + bf Fa_f - B f, the outputs
    `Cout` x (row 0 the head, the last row the frame), named `names`; `energy_of(x)` (J) where the model has one;
    `b_frame` (bf) where a force on the frame enters (default b0, F0's path)."""

    affine = True
    engine = "reference"

    def __init__(self, A: np.ndarray, B: np.ndarray, b0: np.ndarray, F0: float, Cout: np.ndarray,
                 names: Sequence[str], name: str, energy_of: Callable[[np.ndarray], float] | None = None,
                 b_frame: np.ndarray | None = None):
        self.name = name
        self.A, self.B, self.b0 = np.asarray(A, float), np.asarray(B, float), np.asarray(b0, float)
        self.b_frame = self.b0 if b_frame is None else np.asarray(b_frame, float)
        self.aero = (0.0, 0.0)  # the aerodynamic uplift (N, upward) on the head and on the frame
        self.F0 = float(F0)
        self.Cout = np.atleast_2d(np.asarray(Cout, float))
        self.c = self.Cout[0]
        self.names = tuple(names)
        self._energy_of = energy_of
        self.x = np.zeros(len(self.B))
        self._dt = None
        self._pending = None

    def aerodynamic(self, head: float, frame: float) -> None:
        """The constant aerodynamic uplift (N, upward) on the head and on the frame (before `static`)."""
        self.aero = (float(head), float(frame))
        self._dt = None  # the step's constant term changes

    def _aero_input(self) -> np.ndarray:
        """The aerodynamic uplift's constant input B Fa_h + bf Fa_f (zeros without one)."""
        fa_h, fa_f = self.aero
        return self.B * fa_h + self.b_frame * fa_f

    def _prepare(self, dt: float) -> None:
        h = dt / 2
        n = len(self.B)
        lu = np.linalg.inv(np.eye(n) - h * self.A)
        self._Phi = lu @ (np.eye(n) + h * self.A)
        self._G0 = 2 * h * self.F0 * (lu @ self.b0) + 2 * h * (lu @ self._aero_input())
        self._Gf = h * (lu @ self.B)
        self._cPhi, self._cG0, self._cGf = self.c @ self._Phi, float(self.c @ self._G0), float(self.c @ self._Gf)
        self._dt = dt

    def static(self, y_wire: float, k_wire: float) -> float:
        """Static state pressing on a wire at y_wire through k_wire: A x + b0 F0 + B Fa_h + bf Fa_f - B f = 0,
        f = k_wire (c x - y_wire) (k_wire = 0: free, f = 0); returns f."""
        n = len(self.B)
        M = np.zeros((n + 1, n + 1))
        M[:n, :n], M[:n, n] = self.A, -self.B
        M[n, :n], M[n, n] = k_wire * self.c, -1.0
        rhs = np.concatenate([-self.b0 * self.F0 - self._aero_input(), [k_wire * y_wire]])
        try:
            z = np.linalg.solve(M, rhs)
        except np.linalg.LinAlgError:
            raise SolverError(f"the {self.name} pantograph has no static equilibrium against a wire of stiffness "
                              f"{k_wire:g} N/m (its model is singular there)") from None
        if k_wire > 0:  # pressed on the wire: the pantograph and the wire's static stiffness together must be stable
            poles = np.linalg.eigvals(self.A - k_wire * np.outer(self.B, self.c))
            worst = poles[np.argmax(poles.real)]  # a lossless chain (c = 0) neither grows nor decays: it stands
            if worst.real > 1e-9 * max(1.0, float(np.max(np.abs(poles)))):
                raise ParameterError(f"the {self.name} pantograph pressed on the wire (static stiffness {k_wire:.4g} "
                                     f"N/m) is unstable: pole {complex(worst):.4g} 1/s; its parameters describe no "
                                     "pantograph that can run under this line")
            if not z[n] > 0:
                raise ParameterError(f"the {self.name} pantograph's static contact force on the wire is {z[n]:.4g} "
                                     "N (not positive): it would leave the wire at rest (F0 and the springs)")
        self.x = z[:n]
        return float(z[n])

    def affine_map(self, dt: float, f0: float) -> tuple[float, float]:
        """(P, g): head height at t + dt is P - g f1 (exact, the scheme is linear)."""
        if dt != self._dt:
            self._prepare(dt)
        return float(self._cPhi @ self.x) + self._cG0 - self._cGf * f0, self._cGf

    def trial(self, t: float, dt: float, f0: float, f1: float) -> float:
        """Head height at t + dt by the trapezoidal rule under f0 -> f1 (pending until `commit`)."""
        if dt != self._dt:
            self._prepare(dt)
        x = self._Phi @ self.x + self._G0 - self._Gf * (f0 + f1)
        self._pending = x
        return float(self.c @ x)

    def commit(self) -> None:
        """Accept the last trial."""
        self.x = self._pending

    def head(self) -> float:
        """Head displacement (m) of the committed state."""
        return float(self.c @ self.x)

    def native(self, dt: float) -> LinearNativePort:
        """This pantograph as the linear one-port of a compiled host loop at time step `dt`."""
        return LinearNativePort(self, dt)

    def signals(self) -> dict[str, float]:
        """The named outputs of the committed state (m)."""
        y = self.Cout @ self.x
        return {k: float(v) for k, v in zip(self.names, y, strict=True)}

    def energy(self) -> float:
        """The model's energy (J): kinetic + springs - work of F0 and of the aerodynamic uplift on the head (row 0 of
        `Cout`) and the frame (its last row) (lumped pantographs only)."""
        if self._energy_of is None:
            raise SolverError(f"the {self.name} pantograph (a transfer function) has no energy to report")
        fa_h, fa_f = self.aero
        return self._energy_of(self.x) - fa_h * float(self.c @ self.x) - fa_f * float(self.Cout[-1] @ self.x)


def lumped(p: LumpedParams, name: str = LUMPED) -> LinearPantograph:
    """The lumped pantograph of `p` under the wire: state (x_1 .. x_n, v_1 .. v_n), outputs every stage's
    displacement (`head_displacement`, `stage_2_displacement`, ..., `frame_displacement` for the last)."""
    M, C, K = p.matrices()
    n = p.stages
    Mi = np.diag(1.0 / np.asarray(p.m))
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ K, -Mi @ C]])
    B = np.zeros(2 * n)
    B[n] = 1.0 / p.m[0]
    b0 = np.zeros(2 * n)
    b0[2 * n - 1] = 1.0 / p.m[-1]
    names = ["head_displacement"] + [f"stage_{i + 1}_displacement" for i in range(1, n - 1)]
    names += ["frame_displacement"] if n > 1 else []
    Cout = np.eye(n, 2 * n)

    def energy(x: np.ndarray) -> float:
        q, v = x[:n], x[n:]
        return float(0.5 * v @ M @ v + 0.5 * q @ K @ q - p.F0 * q[-1])

    return LinearPantograph(A, B, b0, p.F0, Cout, names, name, energy, b_frame=b0)


def transfer(p: TransferParams, name: str = TRANSFER) -> LinearPantograph:
    """The transfer-function pantograph of `p` under the wire: its state is the model's, its output the head; a
    force on the frame enters by F0's path (B: the model has only its head port)."""
    A, B, C = p.arrays()
    return LinearPantograph(A, B, B, p.F0, C[None, :], ["head_displacement"], name, b_frame=B)


# --- the scene's [pantograph] section ----------------------------------------------------------------------------
#: kind -> (the keys of its `[pantograph] params`, its parameter class)
KINDS: dict[str, tuple[tuple[str, ...], type]] = {LUMPED: (LUMPED_KEYS, LumpedParams),
                                                  TRANSFER: (TRANSFER_KEYS, TransferParams)}


def params_of(kind: str, value: Any) -> LumpedParams | TransferParams:
    """The parameters of the linear pantograph `kind` from the scene's `[pantograph]` section `value` (`params` only;
    SceneError naming the missing, unknown or bad key)."""
    keys, cls = KINDS[kind]
    if not isinstance(value, Mapping) or not value:
        raise SceneError(f"the {kind} pantograph takes its parameters from the scene's [pantograph] section: params "
                         f"= {{{', '.join(keys)}}} (got {value!r})")
    bad = sorted(set(value) - {"effects", "params"})
    if bad:
        raise SceneError(f"unknown key(s) {bad} in [pantograph]; valid keys: ['params'] (the {kind} pantograph)")
    if value.get("effects"):
        raise SceneError(f"the {kind} pantograph has no effects: remove [pantograph] effects = "
                         f"{dict(value['effects'])!r}")
    params = value.get("params")
    section = LUMPED_SECTION if cls is LumpedParams else TRANSFER_SECTION
    d = section.check(params, "[pantograph] params")
    try:
        return cls(**d)
    except ParameterError as exc:
        raise SceneError(f"[pantograph] params: {exc}") from None


def make(kind: str, section: Mapping[str, Any], name: str | None = None) -> LinearPantograph:
    """The linear pantograph `kind` (`LUMPED` or `TRANSFER`) of the scene's `[pantograph]` section."""
    p = params_of(kind, section)
    return lumped(p, name or kind) if isinstance(p, LumpedParams) else transfer(p, name or kind)


class LinearNativePort:
    """A `LinearPantograph` as the linear one-port (`engines/native/oneport.c`) at time step `dt`: the same Phi, G0,
    Gf and head-map numbers as its `affine_map / trial`, its outputs `Cout` x."""

    def __init__(self, panto: LinearPantograph, dt: float):
        from ..engines.native.oneport import LinearPort

        if dt != panto._dt:
            panto._prepare(dt)
        self.panto = panto
        self._lp = LinearPort(panto._Phi, panto._G0, panto._Gf, panto.c, panto.Cout, panto.x, panto._cPhi,
                              panto._cG0, panto._cGf)
        self.port = self._lp.port

    def load(self) -> None:
        """The pantograph's committed state into the port."""
        self._lp.set_state(self.panto.x)

    def pull(self) -> None:
        """The port's committed state back into the pantograph."""
        self.panto.x = self._lp.state()

    def signals(self, rows: np.ndarray) -> dict[str, np.ndarray]:
        """Recorded output rows (`Cout` x) under the pantograph's output names."""
        return {k: rows[:, i].copy() for i, k in enumerate(self.panto.names)}

    def failure(self, code: int) -> str:
        """The words of a failed trial (code `code` of the C step)."""
        return f"the {self.panto.name} pantograph's state became non-finite"
