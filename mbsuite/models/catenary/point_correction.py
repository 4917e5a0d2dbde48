"""The point-load correction of a Hermite wire (`PointCorrection`): a point force on a tensioned beam bends it in a
boundary layer of width sqrt(EI/T) (0.1 m for the contact wire) that a cubic element of 0.5 m cannot represent: the
Hermite wire is locally too stiff under a point load, by a compliance d(x) (0.5 m elements: 3.0e-7 m/N at a node of
the contact wire, 5.9e-7 m/N mid-element, 4.2e-7 m/N at a node of the messenger wire; at a node of the contact wire
4.3e-8 and 3.8e-9 m/N at 0.25 and 0.125 m). In series with a dropper (1e-5 m/N) that makes the droppers 7 % too stiff.
Every point spring on a wire therefore gets the wire's defect at its point in series (`series`). d is the exact static
compliance of the continuous tensioned beam minus the Hermite elements' (`tensioned_beam_compliance`), on a pinned
reference beam of the local mesh (8 elements each side; the defect is local: it changes by < 1e-6 relative beyond 8).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .hermite_beam import beam_stiffness, hermite, tensioned_beam_compliance

#: elements of the local mesh on each side of an element in the reference beam of `PointCorrection`
REF_ELEMENTS = 8


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
    def build(cls, x: np.ndarray, T: float | np.ndarray, EI: float) -> PointCorrection:
        """The tables of a wire through the nodes `x` (m), pinned (w = 0) at the first and the last node, tension T
        (N; one per element where it varies: each element's reference beam carries its own element's tension, the
        defect being local)."""
        h = np.diff(x)
        ne, m = h.size, REF_ELEMENTS
        Te = np.broadcast_to(np.asarray(T, dtype=float), (ne,))
        uniform = bool(np.all(Te == Te[0])) if ne else True
        hr = np.round(h, 9)
        sig = np.empty(ne, dtype=int)
        Qs, refs, Tk = [], [], []
        ke: dict[tuple[float, float], np.ndarray] = {}

        def entry(lo: int, hi: int, e: int) -> int:
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
            rows = windows.view(np.dtype((np.void, windows.shape[1] * windows.itemsize))).ravel()
            _, first, inverse = np.unique(rows, return_index=True, return_inverse=True)
            ks = np.array([entry(i, i + 2 * m + 1, i + m) for i in first])
            sig[inner] = ks[inverse.ravel()]
        keys: dict[tuple, int] = {}
        for e in np.setdiff1d(np.arange(ne), inner):  # next to the line's ends: the beam ends at the line's pin
            lo, hi = max(0, e - m), min(ne, e + m + 1)
            key = (hr[lo:hi].tobytes(), e - lo, float(Te[e]))
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
        last node (N = e_1 or e_3 there); 0 at the pinned ends."""
        if not self.active:
            return np.zeros(self.sig.size + 1)
        left = np.array([tensioned_beam_compliance(a0, L, self._T(k), self.EI)
                         for k, (a0, L, _) in enumerate(self.ref)]) - self.Q[:, 0, 0]
        k = self.sig[-1]
        a0, L, h = self.ref[k]
        last = tensioned_beam_compliance(a0 + h, L, self._T(k), self.EI) - self.Q[k, 2, 2]
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


def series(k: float | np.ndarray, d: float | np.ndarray) -> float | np.ndarray:
    """A spring k (N/m) in series with a compliance d (m/N): k / (1 + k d) (k = 0 stays 0; d = 0 leaves k as it is)."""
    return k / (1.0 + k * d)
