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
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from ...errors import ParameterError
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

    @classmethod
    def build(cls, x: np.ndarray, T: float, EI: float) -> PointCorrection:
        """The tables of a wire through the nodes `x` (m), pinned (w = 0) at the first and the last node."""
        h = np.diff(x)
        ne, m = h.size, REF_ELEMENTS
        hr = np.round(h, 9)
        sig = np.empty(ne, dtype=int)
        Qs, refs = [], []
        ke: dict[float, np.ndarray] = {}

        def entry(lo: int, hi: int, e: int) -> int:
            Q, a0, L = _reference_beam(h[lo:hi], e - lo, T, EI, ke)
            Qs.append(Q)
            refs.append((a0, L, h[e]))
            return len(Qs) - 1

        inner = np.arange(m, ne - m)
        if inner.size:  # a full reference beam: elements with equal windows of lengths share an entry
            codes = np.unique(hr, return_inverse=True)[1].astype(np.int64)
            windows = np.ascontiguousarray(np.lib.stride_tricks.sliding_window_view(codes, 2 * m + 1))
            rows = windows.view(np.dtype((np.void, windows.shape[1] * windows.itemsize))).ravel()
            _, first, inverse = np.unique(rows, return_index=True, return_inverse=True)
            ks = np.array([entry(i, i + 2 * m + 1, i + m) for i in first])
            sig[inner] = ks[inverse.ravel()]
        keys: dict[tuple, int] = {}
        for e in np.setdiff1d(np.arange(ne), inner):  # next to the line's ends: the beam ends at the line's pin
            lo, hi = max(0, e - m), min(ne, e + m + 1)
            key = (hr[lo:hi].tobytes(), e - lo)
            if key not in keys:
                keys[key] = entry(lo, hi, e)
            sig[e] = keys[key]
        return cls(T=float(T), EI=float(EI), sig=sig, Q=np.array(Qs).reshape(-1, 4, 4),
                   ref=np.array(refs, dtype=float).reshape(-1, 3))

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
        return tensioned_beam_compliance(a0 + xi * h, L, self.T, self.EI) - q

    def nodal(self) -> np.ndarray:
        """The defect at every node (m/N), `defect(e, 0)` at the left node of each element and `defect(e, 1)` at the
        last node (N = e_1 or e_3 there); 0 at the pinned ends."""
        if not self.active:
            return np.zeros(self.sig.size + 1)
        left = np.array([tensioned_beam_compliance(a0, L, self.T, self.EI) for a0, L, _ in self.ref]) - self.Q[:, 0, 0]
        k = self.sig[-1]
        a0, L, h = self.ref[k]
        last = tensioned_beam_compliance(a0 + h, L, self.T, self.EI) - self.Q[k, 2, 2]
        return np.append(left[self.sig], last)


def _reference_beam(h: np.ndarray, e: int, T: float, EI: float,
                    ke: dict[float, np.ndarray]) -> tuple[np.ndarray, float, float]:
    """Hermite elements of lengths `h` of a wire (T, EI), pinned at both ends: the static compliance Q (4 x 4) of the
    DOFs of element e, the position a0 of its left node and the beam's length. `ke` caches element stiffnesses by
    length."""
    ne = h.size
    n = 2 * (ne + 1)
    for hi in set(h.tolist()) - set(ke):
        ke[hi] = beam_stiffness(EI, T, hi)
    K = np.zeros((n, n))
    d = 2 * np.arange(ne)[:, None] + np.arange(4)
    np.add.at(K, (d[:, :, None], d[:, None, :]), np.array([ke[hi] for hi in h.tolist()]))
    K[[0, n - 2], :] = 0.0  # pinned: w = 0 at both ends (identity rows and columns)
    K[:, [0, n - 2]] = 0.0
    K[0, 0] = K[n - 2, n - 2] = 1.0
    rhs = np.zeros((n, 4))
    rhs[2 * e:2 * e + 4] = np.eye(4)
    rhs[[0, n - 2]] = 0.0
    Q = np.linalg.solve(K, rhs)[2 * e:2 * e + 4]
    return Q, float(np.sum(h[:e])), float(np.sum(h))


def build_nodes(p: CatenaryParams) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Node coordinates (m), indices of the support nodes and of the dropper nodes (span by span).

    Key points (supports and droppers) are nodes; each interval between key points is split into
    ceil(length / element_length) equal elements."""
    L = p.span_length
    keys = []
    for s in range(p.n_spans):
        keys.append(s * L)
        keys += [s * L + d for d in p.dropper_positions]
    keys.append(p.n_spans * L)
    keys = np.asarray(keys)
    pieces = []
    for a, b in zip(keys[:-1], keys[1:], strict=True):
        r = (b - a) / p.element_length  # a whole number of elements stays one under a relative change < 1e-8
        n = max(1, math.ceil(r - 1e-8 * max(1.0, r)))
        pieces.append(a + (b - a) * np.arange(n) / n)
    pieces.append(keys[-1:])
    x = np.concatenate(pieces)
    idx = {float(v): i for i, v in enumerate(np.round(x, 9))}
    supports = np.array([idx[float(round(s * L, 9))] for s in range(p.n_spans + 1)])
    droppers = np.array([idx[float(round(s * L + d, 9))] for s in range(p.n_spans) for d in p.dropper_positions],
                        dtype=int)
    return x, supports, droppers


@dataclass
class CatenaryFE:
    """Assembled catenary matrices on the free DOFs (pinned end w's removed) and its static state.

    `M`, `K0` (beams + steady arms + messenger supports), `Kd` (droppers as linear springs) are CSR on free DOFs.
    `B` (n_free x n_droppers) maps DOFs to dropper elongations delta = B^T u (MW up minus CW up); a dropper's tension
    T0 + k delta pulls the CW node up and the MW node down, k = `k_drop` (the dropper with both wires' point-load
    defects in series, `PointCorrection`; the ground springs in K0 carry their wire's defect likewise), and `contact`
    gives the contact wire's defect under the contact point (`contact_defect`). `w0` is the static CW shape (full DOF
    vector, w and theta of both wires; the MW static shape does not enter the dynamics and is left at 0), `T0` the
    droppers' static tensions.
    """

    params: CatenaryParams
    x: np.ndarray
    supports: np.ndarray
    droppers: np.ndarray
    free: np.ndarray  # full DOF index of each free DOF
    full_to_free: np.ndarray  # free index of each full DOF, -1 if pinned
    M: sp.csr_matrix
    K0: sp.csr_matrix
    Kd: sp.csr_matrix
    B: sp.csc_matrix
    dropper_cw: np.ndarray  # free index of the CW w DOF of each dropper
    dropper_mw: np.ndarray  # free index of the MW w DOF of each dropper
    w0_full: np.ndarray  # static CW shape on the full DOF vector
    T0: np.ndarray  # static dropper tensions (N)
    support_preload: np.ndarray  # static steady-arm forces (N), at every support node (ends: pin reactions)
    k_drop: np.ndarray  # dropper stiffnesses with both wires' point-load defects in series (N/m)
    contact: PointCorrection  # the contact wire's point-load defect under the contact point

    @property
    def n(self) -> int:
        """Number of free DOFs (pinned-end w DOFs removed)."""
        return self.free.size

    def cw_dofs_of_node(self, i: int) -> tuple[int, int]:
        """Free indices (w, theta) of the CW at node i (-1 if pinned)."""
        return int(self.full_to_free[NDOF_NODE * i + CW_W]), int(self.full_to_free[NDOF_NODE * i + CW_T])

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


def assemble(p: CatenaryParams, point_correction: bool = True) -> CatenaryFE:
    """Mesh, assemble and solve the static state of the catenary described by `p`. `point_correction`: every point
    spring gets its wires' point-load defect in series (module docstring); False gives the plain Hermite wires."""
    x, supports, droppers = build_nodes(p)
    nn = x.size
    if point_correction:
        pc_cw = PointCorrection.build(x, p.cw_tension, p.cw_EI)
        d_cw, d_mw = pc_cw.nodal(), PointCorrection.build(x, p.mw_tension, p.mw_EI).nodal()
    else:
        pc_cw = PointCorrection.none(nn - 1, p.cw_tension)
        d_cw = d_mw = np.zeros(nn)
    nfull = NDOF_NODE * nn
    h = np.diff(x)
    groups, inverse = np.unique(np.round(h, 9), return_inverse=True)
    rows, cols, kv, mv = [], [], [], []
    for wire, (rho, T, EI) in ((CW_W, (p.cw_mass, p.cw_tension, p.cw_EI)), (MW_W, (p.mw_mass, p.mw_tension, p.mw_EI))):
        # elements with equal length (to 1e-9 m) share matrices: each element belongs to exactly one group (lengths
        # a last bit apart, e.g. 0.5 and 0.49999999999994 m, once fell into two groups that each took both)
        for g in range(groups.size):
            sel = np.nonzero(inverse == g)[0]
            he = float(np.mean(h[sel]))
            ke, me = beam_stiffness(EI, T, he), beam_mass(rho, he)
            dofs = np.stack([NDOF_NODE * sel + wire, NDOF_NODE * sel + wire + 1,
                             NDOF_NODE * (sel + 1) + wire, NDOF_NODE * (sel + 1) + wire + 1], axis=1)
            r = np.repeat(dofs, 4, axis=1).ravel()
            c = np.tile(dofs, (1, 4)).ravel()
            rows.append(r)
            cols.append(c)
            kv.append(np.tile(ke.ravel(), sel.size))
            mv.append(np.tile(me.ravel(), sel.size))
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    Kf = sp.coo_matrix((np.concatenate(kv), (rows, cols)), shape=(nfull, nfull)).tocsr()
    Mf = sp.coo_matrix((np.concatenate(mv), (rows, cols)), shape=(nfull, nfull)).tocsr()
    Kbeam_cw = Kf.copy()  # for the static CW problem (MW rows are decoupled)
    # ground springs at the supports
    ground = np.zeros(nfull)
    ground[NDOF_NODE * supports + CW_W] += series(p.k_steady_arm, d_cw[supports])
    ground[NDOF_NODE * supports + MW_W] += series(p.k_messenger_support, d_mw[supports])
    Kf = (Kf + sp.diags(ground)).tocsr()
    # droppers: k_j (e_mw - e_cw)(e_mw - e_cw)^T
    nd = droppers.size
    k_drop = np.asarray(series(p.k_dropper, d_cw[droppers] + d_mw[droppers]), dtype=float)
    bfull = sp.coo_matrix(
        (np.concatenate([np.ones(nd), -np.ones(nd)]),
         (np.concatenate([NDOF_NODE * droppers + MW_W, NDOF_NODE * droppers + CW_W]), np.tile(np.arange(nd), 2))),
        shape=(nfull, nd)).tocsc()
    Kdf = (bfull @ sp.diags(k_drop) @ bfull.T).tocsr()
    # pinned ends: w of both wires at the first and last node
    pinned = np.array([CW_W, MW_W, NDOF_NODE * (nn - 1) + CW_W, NDOF_NODE * (nn - 1) + MW_W])
    mask = np.ones(nfull, bool)
    mask[pinned] = False
    free = np.nonzero(mask)[0]
    full_to_free = -np.ones(nfull, dtype=int)
    full_to_free[free] = np.arange(free.size)
    M = Mf[free][:, free].tocsr()
    K0 = Kf[free][:, free].tocsr()
    Kd = Kdf[free][:, free].tocsr()
    B = bfull[free].tocsc()

    w0_full, T0, preload = _static_cw(p, x, supports, droppers, Kbeam_cw)
    return CatenaryFE(params=p, x=x, supports=supports, droppers=droppers, free=free, full_to_free=full_to_free,
                      M=M, K0=K0, Kd=Kd, B=B, dropper_cw=full_to_free[NDOF_NODE * droppers + CW_W],
                      dropper_mw=full_to_free[NDOF_NODE * droppers + MW_W], w0_full=w0_full, T0=T0,
                      support_preload=preload, k_drop=k_drop, contact=pc_cw)


def _static_cw(p: CatenaryParams, x: np.ndarray, supports: np.ndarray, droppers: np.ndarray,
               Kbeam: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Static CW under its own weight, held at w = 0 at every dropper and support (catenary.md).

    Returns the full DOF vector of the static shape (CW entries only), the dropper tensions and the support reactions
    (the reactions r = K w - f of the constraints: upward forces on the CW)."""
    nn = x.size
    cw = np.arange(nn) * NDOF_NODE
    idx = np.concatenate([cw + CW_W, cw + CW_T])
    idx.sort()
    K = Kbeam[idx][:, idx].tocsr()  # CW DOFs of node i at 2i (w) and 2i + 1 (theta)
    h = np.diff(x)
    q = -p.cw_mass * p.g
    f = np.zeros(idx.size)  # beam_load(q, h_e) of every element, in its order of terms
    f[0:-2:2] += q * (h / 2)
    f[1:-2:2] += q * (h * h / 12)
    f[2::2] += q * (h / 2)
    f[3::2] += q * (-h * h / 12)
    held = 2 * np.concatenate([supports, droppers])
    mask = np.ones(idx.size, bool)
    mask[held] = False
    w = np.zeros(idx.size)
    fr = np.nonzero(mask)[0]
    w[fr] = spsolve(K[fr][:, fr].tocsc(), f[fr])
    r = K @ w - f
    w_full = np.zeros(NDOF_NODE * nn)
    w_full[idx] = w
    return w_full, r[2 * droppers], r[2 * supports]
