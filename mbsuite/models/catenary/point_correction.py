"""The point-load correction of a Hermite wire (`PointCorrection`): a point force on a tensioned beam bends it in a
boundary layer of width sqrt(EI/T) (0.1 m for the contact wire) that a cubic element of 0.5 m cannot represent: the
Hermite wire is locally too stiff under a point load, by a compliance d(x) (0.5 m elements: 3.0e-7 m/N at a node of
the contact wire, 5.9e-7 m/N mid-element, 4.2e-7 m/N at a node of the messenger wire; at a node of the contact wire
4.3e-8 and 3.8e-9 m/N at 0.25 and 0.125 m). In series with a dropper (1e-5 m/N) that makes the droppers 7 % too stiff.
Every point spring on a wire therefore gets the wire's defect at its point in series (`series`). d is the exact static
compliance of the continuous tensioned beam minus the Hermite elements' (`tensioned_beam_compliance`), on a pinned
reference beam of the local mesh (8 elements each side; the defect is local: it changes by < 1e-6 relative beyond 8).

A wire stiffened over part of its length (a `line.SectionInsulator`: elements of their own EI) has no closed form: an
entry whose reference beam holds an element of another EI than the wire's is *tabulated*. Its "exact" compliance is
that of the same reference beam refined (each element split into `REFINE` Hermite sub-elements of its EI; against
the closed form on a uniform beam this refinement is exact to 5.4e-12 m/N) and its defect is stored as `SAMPLES`
samples at xi = 0, 1/(SAMPLES-1), ..., 1, evaluated by Lagrange interpolation (`lagrange`): the Hermite part
N(xi) . Q N(xi) is a polynomial of degree 6 and the exact part smooth. Such an entry has ref[k, 1] = -L (< 0: tabulated)
and its samples in the first SAMPLES of its 16 Q slots (`Q[k].flat`); the other entries keep the closed form bit for
bit (model README, "Section insulators and point masses", for the measured interpolation error).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .hermite_beam import beam_stiffness, hermite, tensioned_beam_compliance

#: elements of the local mesh on each side of an element in the reference beam of `PointCorrection`
REF_ELEMENTS = 8
#: Hermite sub-elements per element of the refined reference beam of a tabulated entry (module docstring)
REFINE = 24
#: samples of a tabulated entry's defect over its element (xi = j / (SAMPLES - 1)), at most 16 (the Q slots)
SAMPLES = 13
#: the Lagrange weights' denominators prod_{m != j} (j - m) of the samples (exact integers)
_DENOM = tuple(float(math.prod(j - m for m in range(SAMPLES) if m != j)) for j in range(SAMPLES))


def lagrange(s: np.ndarray, xi: float) -> float:
    """The Lagrange interpolant at xi of the samples s[j] taken at xi_j = j / (SAMPLES - 1), in the compiled core's
    order of operations (native/catenary.c `point_defect`); exactly s[0] at xi = 0 and s[-1] at xi = 1."""
    t = xi * (SAMPLES - 1)
    q = 0.0
    for j in range(SAMPLES):
        p = 1.0
        for m in range(SAMPLES):
            if m != j:
                p *= t - m
        q += s[j] * (p / _DENOM[j])
    return q


@dataclass
class PointCorrection:
    """The point-load compliance defect of one wire's Hermite mesh (module docstring): at local coordinate xi of
    element e, d = tensioned_beam_compliance(a0 + xi h, L) - N(xi) . Q N(xi) on the element's reference beam (the
    wire's own elements up to REF_ELEMENTS on each side, pinned at its ends; at the line's ends, the line's pins), Q
    the Hermite elements' static compliance of the element's four DOFs (w, theta at both nodes) on that beam. Elements
    with the same reference beam (lengths equal to 1e-9 m, same place in it) share one entry of the tables."""

    T: float
    EI: float
    sig: np.ndarray  # (n_elements,) int: each element's entry in Q and ref
    Q: np.ndarray  # (n_entries, 4, 4)
    ref: np.ndarray  # (n_entries, 3): a0 (the element's left node on the reference beam), L, h (element length)
    Tk: np.ndarray | None = None  # (n_entries,) the tension of each entry's reference beam (None: T)

    @classmethod
    def build(cls, x: np.ndarray, T: float | np.ndarray, EI: float, EIe: np.ndarray | None = None
              ) -> PointCorrection:
        """The tables of a wire through the nodes `x` (m), pinned (w = 0) at the first and the last node, tension T
        (N; one per element where it varies: each element's reference beam carries its own element's tension, the
        defect being local), bending stiffness EI (N m^2; `EIe`: one per element where insulators stiffen it, the
        entries whose reference beam holds one tabulated, module docstring)."""
        h = np.diff(x)
        ne, m = h.size, REF_ELEMENTS
        Te = np.broadcast_to(np.asarray(T, dtype=float), (ne,))
        uniform = bool(np.all(Te == Te[0])) if ne else True
        EIe = None if EIe is None or bool(np.all(np.asarray(EIe) == EI)) else np.asarray(EIe, dtype=float)
        hr = np.round(h, 9)
        sig = np.empty(ne, dtype=int)
        Qs, refs, Tk = [], [], []
        ke: dict[tuple[float, float], np.ndarray] = {}

        def entry(lo: int, hi: int, e: int) -> int:
            if EIe is not None and np.any(EIe[lo:hi] != EI):
                Q, a0, L = _tabulated(h[lo:hi], e - lo, float(Te[e]), EIe[lo:hi])
                L = -L  # tabulated
            else:
                Q, a0, L = _reference_beam(h[lo:hi], e - lo, float(Te[e]), EI, ke)
            Qs.append(Q)
            refs.append((a0, L, h[e]))
            Tk.append(float(Te[e]))
            return len(Qs) - 1

        inner = np.arange(m, ne - m)
        if inner.size:  # a full reference beam: elements with equal windows of lengths share an entry
            codes = np.unique(hr, return_inverse=True)[1].astype(np.int64)
            windows = np.ascontiguousarray(np.lib.stride_tricks.sliding_window_view(codes, 2 * m + 1))
            if not uniform:  # and equal tensions
                tcode = np.unique(Te, return_inverse=True)[1].astype(np.int64)
                windows = np.ascontiguousarray(np.hstack([windows, tcode[m:ne - m, None]]))
            if EIe is not None:  # and equal windows of bending stiffnesses
                ecode = np.unique(EIe, return_inverse=True)[1].astype(np.int64)
                ewin = np.lib.stride_tricks.sliding_window_view(ecode, 2 * m + 1)
                windows = np.ascontiguousarray(np.hstack([windows, ewin]))
            rows = windows.view(np.dtype((np.void, windows.shape[1] * windows.itemsize))).ravel()
            _, first, inverse = np.unique(rows, return_index=True, return_inverse=True)
            ks = np.array([entry(i, i + 2 * m + 1, i + m) for i in first])
            sig[inner] = ks[inverse.ravel()]
        keys: dict[tuple, int] = {}
        for e in np.setdiff1d(np.arange(ne), inner):  # next to the line's ends: the beam ends at the line's pin
            lo, hi = max(0, e - m), min(ne, e + m + 1)
            key = (hr[lo:hi].tobytes(), e - lo, float(Te[e]), None if EIe is None else EIe[lo:hi].tobytes())
            if key not in keys:
                keys[key] = entry(lo, hi, e)
            sig[e] = keys[key]
        return cls(T=float(Te[0]) if ne else 0.0, EI=float(EI), sig=sig, Q=np.array(Qs).reshape(-1, 4, 4),
                   ref=np.array(refs, dtype=float).reshape(-1, 3), Tk=np.array(Tk, dtype=float))

    @classmethod
    def none(cls, n_elements: int, T: float) -> PointCorrection:
        """No correction (the plain Hermite wire): d = 0 everywhere."""
        return cls(T=float(T), EI=0.0, sig=np.zeros(n_elements, dtype=int), Q=np.zeros((1, 4, 4)),
                   ref=np.zeros((1, 3)))

    @property
    def active(self) -> bool:
        """Whether the tables hold a correction (False: `none`)."""
        return bool(self.ref[0, 1] > 0.0)

    def defect(self, e: int, xi: float) -> float:
        """The defect d (m/N) at local coordinate xi of element e (0 without a correction)."""
        k = self.sig[e]
        a0, L, h = self.ref[k]
        if L == 0.0:
            return 0.0
        if L < 0.0:  # tabulated (module docstring)
            return lagrange(self.Q[k].reshape(-1), xi)
        N = hermite(xi, h)
        Q = self.Q[k]
        q = 0.0
        for r in range(4):  # the compiled core's order (native/catenary.c, point_defect)
            q += N[r] * (((Q[r, 0] * N[0] + Q[r, 1] * N[1]) + Q[r, 2] * N[2]) + Q[r, 3] * N[3])
        return tensioned_beam_compliance(a0 + xi * h, L, self._T(k), self.EI) - q

    def _T(self, k: int) -> float:
        return self.T if self.Tk is None else float(self.Tk[k])

    def nodal(self) -> np.ndarray:
        """The defect at every node (m/N), `defect(e, 0)` at the left node of each element and `defect(e, 1)` at the
        last node (N = e_1 or e_3 there; a tabulated entry's first and last sample); 0 at the pinned ends."""
        if not self.active:
            return np.zeros(self.sig.size + 1)
        left = np.array([tensioned_beam_compliance(a0, L, self._T(k), self.EI) - self.Q[k, 0, 0] if L > 0.0
                         else self.Q[k].flat[0] for k, (a0, L, _) in enumerate(self.ref)])
        k = self.sig[-1]
        a0, L, h = self.ref[k]
        last = (tensioned_beam_compliance(a0 + h, L, self._T(k), self.EI) - self.Q[k, 2, 2] if L > 0.0
                else self.Q[k].flat[SAMPLES - 1])
        return np.append(left[self.sig], last)


def _reference_beam(h: np.ndarray, e: int, T: float, EI: float,
                    ke: dict[tuple[float, float], np.ndarray]) -> tuple[np.ndarray, float, float]:
    """Hermite elements of lengths `h` of a wire (T, EI), pinned at both ends: the static compliance Q (4 x 4) of the
    DOFs of element e, the position a0 of its left node and the beam's length. `ke` caches element stiffnesses by
    (length, tension)."""
    ne = h.size
    n = 2 * (ne + 1)
    for hi in set(h.tolist()):
        if (hi, T) not in ke:
            ke[hi, T] = beam_stiffness(EI, T, hi)
    K = np.zeros((n, n))
    d = 2 * np.arange(ne)[:, None] + np.arange(4)
    np.add.at(K, (d[:, :, None], d[:, None, :]), np.array([ke[hi, T] for hi in h.tolist()]))
    K[[0, n - 2], :] = 0.0  # pinned: w = 0 at both ends (identity rows and columns)
    K[:, [0, n - 2]] = 0.0
    K[0, 0] = K[n - 2, n - 2] = 1.0
    rhs = np.zeros((n, 4))
    rhs[2 * e:2 * e + 4] = np.eye(4)
    rhs[[0, n - 2]] = 0.0
    Q = np.linalg.solve(K, rhs)[2 * e:2 * e + 4]
    return Q, float(np.sum(h[:e])), float(np.sum(h))


def _stiffness(h: np.ndarray, T: float, EI: np.ndarray) -> np.ndarray:
    """The stiffness of Hermite elements of lengths `h` and bending stiffnesses `EI` (tension T, `beam_stiffness`)
    on a beam pinned at both ends (identity rows and columns there), in the upper band form of
    `scipy.linalg.solveh_banded` (3 superdiagonals)."""
    ne = h.size
    n = 2 * (ne + 1)
    pairs = list(zip(np.asarray(h, float).tolist(), np.broadcast_to(EI, (ne,)).tolist(), strict=True))
    one = {(hi, Ei): beam_stiffness(Ei, T, hi) for hi, Ei in set(pairs)}  # the element matrices, once each
    ke = np.array([one[q] for q in pairs])
    ab = np.zeros((4, n))
    for r in range(4):
        for c in range(r, 4):  # K[i, j] (i <= j) at ab[3 + i - j, j]
            np.add.at(ab[3 + r - c], 2 * np.arange(ne) + c, ke[:, r, c])
    for d in (0, n - 2):  # pinned: w = 0 (identity row and column)
        for k in range(4):
            if d + k < n:
                ab[3 - k, d + k] = 0.0
            if d - k >= 0:
                ab[3 - k, d] = 0.0
        ab[3, d] = 1.0
    return ab


def _solve(ab: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    from scipy.linalg import solveh_banded  # here: scipy.linalg is only needed for a stiffened wire

    return solveh_banded(ab, rhs)


def _tabulated(h: np.ndarray, e: int, T: float, EI: np.ndarray, refine: int = REFINE
               ) -> tuple[np.ndarray, float, float]:
    """A tabulated entry (module docstring) of element e on the reference beam of elements `h` with bending
    stiffnesses `EI`: its 4 x 4 slot array holding the defect at xi = j / (SAMPLES - 1) in its first SAMPLES slots,
    the position a0 of the element's left node and the beam's length."""
    n = 2 * (h.size + 1)
    rhs = np.zeros((n, 4))
    rhs[2 * e:2 * e + 4] = np.eye(4)
    rhs[[0, n - 2]] = 0.0
    Q = _solve(_stiffness(h, T, EI), rhs)[2 * e:2 * e + 4]
    xi = np.arange(SAMPLES) / (SAMPLES - 1)
    exact = refined_compliance(h, e, T, EI, xi, refine)
    out = np.zeros(16)
    for j, v in enumerate(xi):
        N = hermite(float(v), float(h[e]))
        out[j] = exact[j] - N @ Q @ N
    return out.reshape(4, 4), float(np.sum(h[:e])), float(np.sum(h))


def refined_compliance(h: np.ndarray, e: int, T: float, EI: np.ndarray, xi: np.ndarray, refine: int = REFINE
                       ) -> np.ndarray:
    """The static compliance (m/N) at local coordinates `xi` of element e (each a multiple of 1/refine) of the beam
    of elements `h` (bending stiffnesses `EI`, tension T, pinned at both ends), each element split into `refine`
    Hermite sub-elements: the "exact" compliance of a tabulated entry (module docstring)."""
    ab = _stiffness(np.repeat(np.asarray(h, float) / refine, refine), T, np.repeat(EI, refine))
    n = ab.shape[1]
    nodes = e * refine + np.rint(np.asarray(xi) * refine).astype(int)
    if np.any(np.abs(nodes - e * refine - np.asarray(xi) * refine) > 1e-9):
        raise ValueError(f"xi = {xi} are not multiples of 1/{refine}")
    rhs = np.zeros((n, nodes.size))
    rhs[2 * nodes, np.arange(nodes.size)] = 1.0
    rhs[[0, n - 2]] = 0.0
    return _solve(ab, rhs)[2 * nodes, np.arange(nodes.size)]


def series(k: float | np.ndarray, d: float | np.ndarray) -> float | np.ndarray:
    """A spring k (N/m) in series with a compliance d (m/N): k / (1 + k d) (k = 0 stays 0; d = 0 leaves k as it is)."""
    return k / (1.0 + k * d)
