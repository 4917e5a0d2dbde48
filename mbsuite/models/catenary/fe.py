"""2-D finite-element catenary: contact wire (CW) and messenger wire (MW) as tensioned Euler-Bernoulli beams.

Each wire is meshed with cubic Hermite elements (nodal DOFs w, theta = dw/dx). Per element of length h
(Przemieniecki / Cook, "Concepts and Applications of FE Analysis", ch. 16 and 18):

    K_e = EI/h^3 [[12, 6h, -12, 6h], [6h, 4h^2, -6h, 2h^2], [-12, -6h, 12, -6h], [6h, 2h^2, -6h, 4h^2]]      (bending)
        + T/(30h) [[36, 3h, -36, 3h], [3h, 4h^2, -3h, -h^2], [-36, -3h, 36, -3h], [3h, -h^2, -3h, 4h^2]]   (geometric)
    M_e = rho h/420 [[156, 22h, 54, -13h], [22h, 4h^2, 13h, -3h^2], [54, 13h, 156, -22h], [-13h, -3h^2, -22h, 4h^2]]

Both wires share the same nodes (supports and dropper positions are always nodes), ordered node by node as
[w_cw, theta_cw, w_mw, theta_mw], so the matrices are banded (half-bandwidth 7). Both wires are pinned (w = 0) at the
two ends; those DOFs are removed. Droppers (CW node to MW node), steady arms (CW to ground) and messenger supports
(MW to ground) are springs. The dynamic model is written for the displacement w from the static state.

Point springs on a wire (`PointCorrection`): a point force on a tensioned beam bends it in a boundary layer of width
sqrt(EI/T) (0.1 m for the contact wire) that a cubic element of 0.5 m cannot represent: the Hermite wire is locally
too stiff under a point load, by a compliance d(x) (0.5 m elements: 3.0e-7 m/N at a node of the contact wire,
5.9e-7 m/N mid-element, 4.2e-7 m/N at a node of the messenger wire; at a node of the contact wire 4.3e-8 and
3.8e-9 m/N at 0.25 and 0.125 m). In series with a dropper (1e-5 m/N) that makes the droppers 7 % too stiff. Every point
spring on a wire (droppers, steady arms, messenger supports, the contact spring) therefore gets the wire's defect at
its point in series: k_eff = 1 / (1/k + d_cw + d_mw) for a dropper, 1 / (1/k + d) for a support spring, and the
contact spring 1 / (1/k_c + d_cw(x)) wherever the contact point is. d is the exact static compliance of the continuous
tensioned beam minus the Hermite elements' (`tensioned_beam_compliance`, `PointCorrection`), on a pinned reference
beam of the local mesh (8 elements each side; the defect is local: it changes by < 1e-6 relative beyond 8).

Static state (catenary.md, "Choices mbsuite fixes"): no pre-sag; the CW is held level (w = 0) at every dropper and
support and sags under its own weight between them. The constraint reactions at the droppers are the droppers' static
tensions; those at the supports are the steady arms' static pre-loads (constant, they cancel in the dynamics).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from ...errors import ParameterError
from .line import Irregularity, Line
from .params import CatenaryParams

NDOF_NODE = 4  # w_cw, theta_cw, w_mw, theta_mw
CW_W, CW_T, MW_W, MW_T = range(4)
#: elements of the local mesh on each side of an element in the reference beam of `PointCorrection`
REF_ELEMENTS = 8


def beam_stiffness(EI: float, T: float, h: float) -> np.ndarray:
    """Bending + geometric (tension) stiffness of a cubic Hermite element (module docstring)."""
    kb = EI / h**3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                               [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]])
    kg = T / (30 * h) * np.array([[36, 3 * h, -36, 3 * h], [3 * h, 4 * h * h, -3 * h, -h * h],
                                  [-36, -3 * h, 36, -3 * h], [3 * h, -h * h, -3 * h, 4 * h * h]])
    return kb + kg


def beam_mass(rho: float, h: float) -> np.ndarray:
    """Consistent mass matrix of a cubic Hermite element (module docstring)."""
    return rho * h / 420 * np.array([[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                                     [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]])


def beam_load(q: float, h: float) -> np.ndarray:
    """Consistent nodal load of a uniform distributed load q (N/m) on a Hermite element."""
    return q * np.array([h / 2, h * h / 12, h / 2, -h * h / 12])


def hermite(xi: float, h: float) -> np.ndarray:
    """Hermite shape functions at local coordinate xi in [0, 1] on an element of length h: w = N . [w1, t1, w2, t2]."""
    x2, x3 = xi * xi, xi * xi * xi
    return np.array([1 - 3 * x2 + 2 * x3, h * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, h * (x3 - x2)])


def tensioned_beam_compliance(a: float, L: float, T: float, EI: float) -> float:
    """Static deflection at x = a under a unit point force at x = a of a pinned-pinned tensioned Euler-Bernoulli beam
    of length L (EI w'''' - T w'' = delta(x - a), w = w'' = 0 at both ends), in closed form:

        w(a) = [a (L - a) / L - sinh(lam a) sinh(lam (L - a)) / (lam sinh(lam L))] / T,      lam = sqrt(T / EI),

    the string's deflection less the bending boundary layer's; EI = 0 is the string. Written with expm1 so that it
    holds for lam L >> 1: the sinh quotient is (1 - e^(-2 lam a)) (1 - e^(-2 lam (L - a))) / (2 lam (1 - e^(-2 lam L))).
    """
    s = a * (L - a) / L
    if EI > 0.0:
        lam = math.sqrt(T / EI)
        s -= (-math.expm1(-2 * lam * a)) * (-math.expm1(-2 * lam * (L - a))) / (2 * lam * (-math.expm1(-2 * lam * L)))
    return s / T


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


def build_nodes(p: CatenaryParams | Line, element_length: float | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Node coordinates (m), indices of the support nodes and of the dropper nodes (in the line's dropper order) of
    the line of `p` (its `line`, else the simple line of its fields) or of a `Line` (then `element_length` is needed).

    Key points (`Line.key_points`: supports, droppers, clamps, masses, wire ends) are nodes; each interval between key
    points is split into ceil(length / element_length) equal elements (a length within 1e-6 of itself above a whole
    number of element lengths counts as that number)."""
    if isinstance(p, CatenaryParams):
        line, element_length = line_of(p), p.element_length
    else:
        line = p
    keys = line.key_points()
    pieces = []
    for a, b in zip(keys[:-1], keys[1:], strict=True):
        # a whole number of elements stays one under a relative change < 1e-6: the interval between two key points
        # 600 m out moves by 1e-7 of itself under the stability check's draws of 1e-10
        r = (b - a) / element_length
        n = max(1, math.ceil(r - 1e-6 * max(1.0, r)))
        pieces.append(a + (b - a) * np.arange(n) / n)
    pieces.append(keys[-1:])
    x = np.concatenate(pieces)
    at = _node_index(x)
    supports = np.array([at(s.x) for s in line.supports], dtype=int)
    droppers = np.array([at(d.x) for d in line.droppers], dtype=int)
    return x, supports, droppers


def _node_index(x: np.ndarray):
    idx = {float(v): i for i, v in enumerate(np.round(x, 9))}
    return lambda xp: idx[float(round(xp, 9))]


def line_of(p: CatenaryParams) -> Line:
    """The line of `p`: `p.line`, else the simple line of its fields (EN 50318:2002 by default)."""
    if p.line is not None:
        return p.line
    from .lines import simple  # here: lines.py builds from CatenaryParams

    return simple(p)


@dataclass
class CatenaryFE:
    """Assembled catenary matrices on the free DOFs (pinned end w's removed) and its static state.

    DOF layout: at node i (position `x[i]`) each wire present there has two DOFs (w, theta), in the line's wire order
    (the contact wire first); node i's DOFs are `node_offset[i] .. node_offset[i + 1] - 1` of the full vector (the
    simple line: 4 per node, [w_cw, theta_cw, w_mw, theta_mw]). `free` lists the full index of each free DOF.

    `M`, `K0` (beams, ground springs, clamps), `Kd` (droppers as linear springs) are CSR on free DOFs. `B`
    (n_free x n_droppers) maps DOFs to dropper elongations delta = B^T u (upper wire up minus lower wire up); a
    dropper's tension T0 + k delta pulls the lower wire up and the upper wire down, k = `k_drop` (with both wires'
    point-load defects in series, `PointCorrection`; ground springs and clamps in K0 carry theirs likewise), and
    `contact` gives the contact wire's defect under the contact point (`contact_defect`). `w0_full` is the static
    state of every wire (full DOF vector), `T0` the droppers' static tensions, `support_preload` the steady arms' static
    forces. `irregularity` (None or `line.Irregularity`) is the contact wire's height profile added in the contact
    gap.
    """

    params: CatenaryParams
    line: Line
    x: np.ndarray
    supports: np.ndarray
    droppers: np.ndarray
    node_offset: np.ndarray  # (nnode + 1,) full index of each node's first DOF
    slot: np.ndarray  # (n_wires, nnode) full index of each wire's w at each node, -1 where the wire is absent
    free: np.ndarray  # full DOF index of each free DOF
    full_to_free: np.ndarray  # free index of each full DOF, -1 if pinned
    M: sp.csr_matrix
    K0: sp.csr_matrix
    Kd: sp.csr_matrix
    B: sp.csc_matrix
    dropper_upper: np.ndarray  # free index of the upper wire's w DOF of each dropper
    dropper_lower: np.ndarray  # free index of the lower wire's w DOF of each dropper
    dropper_slack: np.ndarray  # (nd,) bool: the dropper may go slack (its law is not "linear")
    w0_full: np.ndarray  # static state on the full DOF vector
    T0: np.ndarray  # static dropper tensions (N)
    support_preload: np.ndarray  # static steady-arm forces (N), at every support node (ends: pin reactions)
    k_drop: np.ndarray  # dropper stiffnesses with both wires' point-load defects in series (N/m)
    contact: PointCorrection  # the contact wire's point-load defect under the contact point
    irregularity: Irregularity | None = None

    @property
    def n(self) -> int:
        """Number of free DOFs (pinned-end w DOFs removed)."""
        return self.free.size

    @property
    def cw_dof(self) -> np.ndarray:
        """(nnode, 2) free index of the contact wire's (w, theta) at each node, -1 where pinned."""
        c = self.slot[0]
        return np.stack([self.full_to_free[c], self.full_to_free[c + 1]], axis=1)

    @property
    def cw_w0(self) -> np.ndarray:
        """(nnode, 2) static (w, theta) of the contact wire at each node (presag included)."""
        c = self.slot[0]
        return np.stack([self.w0_full[c], self.w0_full[c + 1]], axis=1)

    @property
    def support_cw(self) -> np.ndarray:
        """(nsup,) free index of the contact wire's w at each support, -1 where pinned."""
        return self.full_to_free[self.slot[0, self.supports]]

    @property
    def dropper_mw(self) -> np.ndarray:
        """Alias of `dropper_upper` (the simple line: the messenger wire)."""
        return self.dropper_upper

    @property
    def dropper_cw(self) -> np.ndarray:
        """Alias of `dropper_lower` (the simple line: the contact wire)."""
        return self.dropper_lower

    @property
    def n_elements(self) -> int:
        """FE elements of all wires."""
        return int(np.sum(self.slot[:, :-1] >= 0) - np.sum((self.slot[:, :-1] >= 0) & (self.slot[:, 1:] < 0)))

    def slack_mask(self, effect: str) -> np.ndarray:
        """(nd,) bool: the droppers that may go slack under the scene's `droppers` effect ("slack" or "linear"): a
        dropper's own law where it has one, the effect's where it has none. Refuses (ParameterError) a dropper that
        may go slack but is in compression in the static state."""
        laws = np.array([d.law for d in self.line.droppers], dtype=object)
        mask = (laws == "slack") | ((laws == "") & (effect == "slack"))
        _check_compression(self.line, self.T0, mask)
        return mask.astype(bool)

    def cw_dofs_of_node(self, i: int) -> tuple[int, int]:
        """Free indices (w, theta) of the CW at node i (-1 if pinned)."""
        c = int(self.slot[0, i])
        return int(self.full_to_free[c]), int(self.full_to_free[c + 1])

    def contact_defect(self, e: int, xi: float) -> float:
        """The contact wire's point-load defect (m/N) at local coordinate xi of element e (`PointCorrection`)."""
        return self.contact.defect(e, xi)

    def element_at(self, xp: float) -> tuple[int, float, float]:
        """Element index e (nodes e, e+1), local coordinate xi in [0, 1] and element length at position xp."""
        x = self.x
        if not x[0] <= xp <= x[-1]:
            raise ParameterError(f"position {xp} m is outside the catenary [{x[0]}, {x[-1]}] m")
        e = int(np.searchsorted(x, xp, side="right") - 1)
        e = min(max(e, 0), x.size - 2)
        h = x[e + 1] - x[e]
        return e, (xp - x[e]) / h, h


def series(k: float | np.ndarray, d: float | np.ndarray) -> float | np.ndarray:
    """A spring k (N/m) in series with a compliance d (m/N): k / (1 + k d) (k = 0 stays 0; d = 0 leaves k as it is)."""
    return k / (1.0 + k * d)


def _layout(line: Line, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[tuple[int, int]]]:
    """Node offsets, the w slot of every wire at every node (-1 absent) and each wire's node range [i0, i1]."""
    at = _node_index(x)
    nw, nn = len(line.wires), x.size
    present = np.zeros((nw, nn), bool)
    ranges = []
    for k, w in enumerate(line.wires):
        i0, i1 = at(w.x0), at(w.x1)
        present[k, i0:i1 + 1] = True
        ranges.append((i0, i1))
    counts = 2 * present.sum(axis=0)
    offset = np.concatenate([[0], np.cumsum(counts)])
    rank = np.cumsum(present, axis=0) - 1
    slot = np.where(present, offset[:-1][None, :] + 2 * rank, -1)
    return offset, slot, ranges


def assemble(p: CatenaryParams, point_correction: bool = True) -> CatenaryFE:
    """Mesh, assemble and solve the static state of the line of `p` (`line_of`). `point_correction`: every point
    spring gets its wires' point-load defect in series (module docstring); False gives the plain Hermite wires."""
    line = line_of(p)
    x, supports, droppers = build_nodes(line, p.element_length)
    at = _node_index(x)
    nn = x.size
    offset, slot, ranges = _layout(line, x)
    nfull = int(offset[-1])
    h = np.diff(x)
    # the point-load defect of every wire at every node it has (0 where absent or uncorrected)
    defect = np.zeros((len(line.wires), nn))
    pcs = []
    for k, w in enumerate(line.wires):
        i0, i1 = ranges[k]
        xw = x[i0:i1 + 1]
        Te = w.tension_at(0.5 * (xw[:-1] + xw[1:]))
        if point_correction and w.tension > 0:
            pc = PointCorrection.build(xw, Te, w.EI)
            defect[k, i0:i1 + 1] = pc.nodal()
        else:
            pc = PointCorrection.none(i1 - i0, w.tension)
        pcs.append(pc)
    rows, cols, kv, mv = [], [], [], []
    qload = np.zeros(nfull)  # gravity: consistent loads of the wires, point and dropper masses
    g = p.g
    for k, w in enumerate(line.wires):
        # elements with equal length (to 1e-9 m) and tension share matrices: each element belongs to exactly one
        # group (lengths a last bit apart, e.g. 0.5 and 0.49999999999994 m, once fell into two groups that each
        # took both)
        i0, i1 = ranges[k]
        hw = h[i0:i1]
        Te = w.tension_at(0.5 * (x[i0:i1] + x[i0 + 1:i1 + 1]))
        keys = np.stack([np.round(hw, 9), Te], axis=1)
        groups, inverse = np.unique(keys, axis=0, return_inverse=True)
        inverse = inverse.ravel()
        for gi in range(groups.shape[0]):
            sel = np.nonzero(inverse == gi)[0]
            he = float(np.mean(hw[sel]))
            ke, me = beam_stiffness(w.EI, float(groups[gi, 1]), he), beam_mass(w.mass, he)
            a, b = slot[k, i0 + sel], slot[k, i0 + sel + 1]
            dofs = np.stack([a, a + 1, b, b + 1], axis=1)
            rows.append(np.repeat(dofs, 4, axis=1).ravel())
            cols.append(np.tile(dofs, (1, 4)).ravel())
            kv.append(np.tile(ke.ravel(), sel.size))
            mv.append(np.tile(me.ravel(), sel.size))
            q, hs = -w.mass * g, hw[sel]  # beam_load(q, h) of each element
            np.add.at(qload, a, q * (hs / 2))
            np.add.at(qload, a + 1, q * (hs * hs / 12))
            np.add.at(qload, b, q * (hs / 2))
            np.add.at(qload, b + 1, q * (-hs * hs / 12))
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    Kf = sp.coo_matrix((np.concatenate(kv), (rows, cols)), shape=(nfull, nfull)).tocsr()
    Mf = sp.coo_matrix((np.concatenate(mv), (rows, cols)), shape=(nfull, nfull)).tocsr()
    Kbeams = Kf.copy()
    wi = {w.name: k for k, w in enumerate(line.wires)}

    def wslot(name: str, xp: float) -> tuple[int, int, float]:
        k, i = wi[name], at(xp)
        return int(slot[k, i]), i, float(defect[k, i])

    # ground springs at the supports (the contact wire's steady arms are holds in the static state)
    ground = np.zeros(nfull)
    ground_static = np.zeros(nfull)
    point_mass = np.zeros(nfull)
    for s in line.supports:
        for name, k in s.k.items():
            d, _, dd = wslot(name, s.x)
            ground[d] += series(k, dd)
            if wi[name] != 0:
                ground_static[d] += series(k, dd)
        for name, m in s.m.items():
            point_mass[wslot(name, s.x)[0]] += m
    for pm in line.masses:
        point_mass[wslot(pm.wire, pm.x)[0]] += pm.m
    # clamps: k (e_a - e_b)(e_a - e_b)^T with both wires' defects in series
    cr, cc, cv = [], [], []
    for c in line.clamps:
        (da, _, fa), (db, _, fb) = wslot(c.a, c.x), wslot(c.b, c.x)
        kc = float(series(c.k, fa + fb))
        cr += [da, da, db, db]
        cc += [da, db, da, db]
        cv += [kc, -kc, -kc, kc]
    Kclamp = sp.coo_matrix((cv, (cr, cc)), shape=(nfull, nfull)).tocsr()
    # droppers: k_j (e_up - e_low)(e_up - e_low)^T, masses half on each end
    nd = len(line.droppers)
    up = np.array([wslot(d.upper, d.x)[0] for d in line.droppers], dtype=int)
    low = np.array([wslot(d.lower, d.x)[0] for d in line.droppers], dtype=int)
    dsum = np.array([wslot(d.upper, d.x)[2] + wslot(d.lower, d.x)[2] for d in line.droppers])
    kraw = np.array([d.k for d in line.droppers], dtype=float)
    k_drop = np.asarray(series(kraw, dsum), dtype=float) if nd else np.zeros(0)
    for d, a, b in zip(line.droppers, up, low, strict=True):
        point_mass[a] += 0.5 * d.mass + d.clamp_upper
        point_mass[b] += 0.5 * d.mass + d.clamp_lower
    qload -= g * point_mass
    Kf = (Kf + sp.diags(ground) + Kclamp).tocsr()
    if np.any(point_mass):
        Mf = (Mf + sp.diags(point_mass)).tocsr()
    bfull = sp.coo_matrix(
        (np.concatenate([np.ones(nd), -np.ones(nd)]), (np.concatenate([up, low]), np.tile(np.arange(nd), 2))),
        shape=(nfull, nd)).tocsc()
    Kdf = (bfull @ sp.diags(k_drop) @ bfull.T).tocsr()
    # pinned ends: w of the wire at its end node
    pinned = sorted(int(slot[k, i]) for k, w in enumerate(line.wires)
                    for i, end in zip(ranges[k], w.ends, strict=True) if end == "pinned")
    mask = np.ones(nfull, bool)
    mask[pinned] = False
    for j, d in enumerate(line.droppers):
        if not (mask[up[j]] and mask[low[j]]):
            raise ParameterError(f"line {line.name!r}: the dropper at x = {d.x} m ({d.upper} -> {d.lower}) sits on a "
                                 "pinned wire end: it can carry nothing there (move it off the end)")
    free = np.nonzero(mask)[0]
    full_to_free = -np.ones(nfull, dtype=int)
    full_to_free[free] = np.arange(free.size)
    M = Mf[free][:, free].tocsr()
    K0 = Kf[free][:, free].tocsr()
    Kd = Kdf[free][:, free].tocsr()
    B = bfull[free].tocsc()

    Kst = (Kbeams + sp.diags(ground_static) + Kclamp).tocsr()
    w0_full, T0, preload = _static_state(line, x, slot, supports, up, low, Kst, qload, pinned)
    slack = np.array([d.law != "linear" for d in line.droppers], dtype=bool)
    _check_compression(line, T0, np.array([d.law == "slack" for d in line.droppers], dtype=bool))
    return CatenaryFE(params=p, line=line, x=x, supports=supports, droppers=droppers, node_offset=offset, slot=slot,
                      free=free, full_to_free=full_to_free, M=M, K0=K0, Kd=Kd, B=B,
                      dropper_upper=full_to_free[up], dropper_lower=full_to_free[low], dropper_slack=slack,
                      w0_full=w0_full, T0=T0, support_preload=preload, k_drop=k_drop, contact=pcs[0],
                      irregularity=line.irregularity)


def _check_compression(line: Line, T0: np.ndarray, slack: np.ndarray) -> None:
    """A `ParameterError` naming the first dropper of mask `slack` whose static tension is negative."""
    bad = np.nonzero(slack & (T0 < 0))[0]
    if bad.size:
        d = line.droppers[int(bad[0])]
        raise ParameterError(
            f"line {line.name!r}: the dropper at x = {d.x} m ({d.upper} -> {d.lower}) is in compression in the static "
            f"state (T0 = {T0[int(bad[0])]:.4g} N): a slack dropper cannot hold the wire there (give it law = "
            "'linear' if it is a strut, or change the line)")


def _static_state(line: Line, x: np.ndarray, slot: np.ndarray, supports: np.ndarray, up: np.ndarray,
                  low: np.ndarray, K: sp.csr_matrix, f: np.ndarray, pinned: list[int]
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The static state of every wire (catenary.md, "Choices mbsuite fixes", generalised): each dropper holds its
    lower wire at its design height (the contact wire: `Line.design_height`, the presag; another wire: 0), the contact
    wire is held at its design height at every support, and the droppers' tensions and the steady arms' pre-loads are
    the holds' reactions r = K w - f. Wires joined by clamps form a group; a group is solved once every dropper
    hanging from it has its tension (the contact wire's group first), those tensions loading it where they hang:
    the simple line's contact wire is solved alone, exactly as before, and the messenger then carries its droppers.
    K holds the beams, the clamps and the ground springs of the wires other than the contact wire. Returns the full
    static state, the dropper tensions and the support reactions."""
    nw, nd = len(line.wires), up.size
    wi = {w.name: k for k, w in enumerate(line.wires)}
    parent = list(range(nw))

    def root(a: int) -> int:
        while parent[a] != a:
            a = parent[a]
        return a

    for c in line.clamps:
        parent[root(wi[c.a])] = root(wi[c.b])
    group = [root(k) for k in range(nw)]
    d_up = np.array([group[wi[d.upper]] for d in line.droppers], dtype=int)
    d_low = np.array([group[wi[d.lower]] for d in line.droppers], dtype=int)
    if np.any(d_up == d_low):
        j = int(np.nonzero(d_up == d_low)[0][0])
        raise ParameterError(f"line {line.name!r}: the dropper at x = {line.droppers[j].x} m joins wires that clamps "
                             "already join (a loop: it would hang a wire from itself)")
    z = line.design_height(np.array([d.x for d in line.droppers], dtype=float))
    z = np.where(d_low == group[0], z, 0.0)
    u = np.zeros(K.shape[0])
    T0 = np.full(nd, np.nan)
    preload = np.zeros(supports.size)
    f = f.copy()
    todo = sorted(set(group))
    while todo:
        ready = [g for g in todo if not np.any(np.isnan(T0[d_up == g]))]
        if not ready:
            raise ParameterError(f"line {line.name!r}: its droppers form a loop (a wire hangs from a wire that hangs "
                                 "from it)")
        g = ready[0]
        todo.remove(g)
        ks = [k for k in range(nw) if group[k] == g]
        sl = slot[ks]
        idx = np.sort(np.concatenate([sl[sl >= 0], sl[sl >= 0] + 1]))
        pos = -np.ones(K.shape[0], dtype=int)
        pos[idx] = np.arange(idx.size)
        held = {}
        for p in pinned:
            if pos[p] >= 0:
                held[int(pos[p])] = 0.0
        mine = np.nonzero(d_low == g)[0]
        for j in mine:
            held[int(pos[low[j]])] = float(z[j])
        if g == group[0]:  # the contact wire at each support with a steady arm (a ground spring on it)
            zs = line.design_height(x[supports])
            for i, s in enumerate(slot[0, supports]):
                if line.steady_arm(line.supports[i]):
                    held[int(pos[s])] = float(zs[i])
        Kg = K[idx][:, idx].tocsr()
        Kg.eliminate_zeros()
        fg = f[idx]
        hk = np.array(sorted(held), dtype=int)
        w = np.zeros(idx.size)
        w[hk] = [held[k] for k in hk]
        mask = np.ones(idx.size, bool)
        mask[hk] = False
        fr = np.nonzero(mask)[0]
        with warnings.catch_warnings():
            warnings.simplefilter("error", category=sp.linalg.MatrixRankWarning)
            try:
                w[fr] = spsolve(Kg[fr][:, fr].tocsc(), fg[fr] - Kg[fr][:, hk] @ w[hk]) if np.any(w[hk]) else \
                    spsolve(Kg[fr][:, fr].tocsc(), fg[fr])
            except (sp.linalg.MatrixRankWarning, RuntimeError):
                w[fr] = np.nan
        if not np.all(np.isfinite(w)):
            names = [line.wires[k].name for k in ks]
            raise ParameterError(f"line {line.name!r}: the static state of wire(s) {names} is singular: a part is held "
                                 "by nothing (no pinned end, ground spring, clamp or dropper carries it)")
        r = Kg @ w - fg
        u[idx] = w
        T0[mine] = r[pos[low[mine]]]
        for j in mine:  # the dropper now loads the wire it hangs from
            f[up[j]] -= T0[j]
        if g == group[0]:
            arm = np.array([line.steady_arm(sp_) for sp_ in line.supports], dtype=bool)
            preload = np.where(arm, r[pos[slot[0, supports]]], 0.0)
    return u, T0, preload
