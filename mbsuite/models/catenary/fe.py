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
    T0 + k delta pulls the CW node up and the MW node down. `w0` is the static CW shape (full DOF vector, w and theta
    of both wires; the MW static shape does not enter the dynamics and is left at 0), `T0` the droppers' static
    tensions.
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

    @property
    def n(self) -> int:
        """Number of free DOFs (pinned-end w DOFs removed)."""
        return self.free.size

    def cw_dofs_of_node(self, i: int) -> tuple[int, int]:
        """Free indices (w, theta) of the CW at node i (-1 if pinned)."""
        return int(self.full_to_free[NDOF_NODE * i + CW_W]), int(self.full_to_free[NDOF_NODE * i + CW_T])

    def element_at(self, xp: float) -> tuple[int, float, float]:
        """Element index e (nodes e, e+1), local coordinate xi in [0, 1] and element length at position xp."""
        x = self.x
        if not x[0] <= xp <= x[-1]:
            raise ParameterError(f"position {xp} m is outside the catenary [{x[0]}, {x[-1]}] m")
        e = int(np.searchsorted(x, xp, side="right") - 1)
        e = min(max(e, 0), x.size - 2)
        h = x[e + 1] - x[e]
        return e, (xp - x[e]) / h, h


def assemble(p: CatenaryParams) -> CatenaryFE:
    """Mesh, assemble and solve the static state of the catenary described by `p`."""
    x, supports, droppers = build_nodes(p)
    nn = x.size
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
    ground[NDOF_NODE * supports + CW_W] += p.k_steady_arm
    ground[NDOF_NODE * supports + MW_W] += p.k_messenger_support
    Kf = (Kf + sp.diags(ground)).tocsr()
    # droppers: k (e_mw - e_cw)(e_mw - e_cw)^T
    nd = droppers.size
    bfull = sp.coo_matrix(
        (np.concatenate([np.ones(nd), -np.ones(nd)]),
         (np.concatenate([NDOF_NODE * droppers + MW_W, NDOF_NODE * droppers + CW_W]), np.tile(np.arange(nd), 2))),
        shape=(nfull, nd)).tocsc()
    Kdf = (p.k_dropper * (bfull @ bfull.T)).tocsr()
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
                      support_preload=preload)


def _static_cw(p: CatenaryParams, x: np.ndarray, supports: np.ndarray, droppers: np.ndarray,
               Kbeam: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Static CW under its own weight, held at w = 0 at every dropper and support (catenary.md).

    Returns the full DOF vector of the static shape (CW entries only), the dropper tensions and the support reactions
    (the reactions r = K w - f of the constraints: upward forces on the CW)."""
    nn = x.size
    cw = np.arange(nn) * NDOF_NODE
    idx = np.concatenate([cw + CW_W, cw + CW_T])
    idx.sort()
    K = Kbeam[idx][:, idx].tocsr()
    loc = {int(d): i for i, d in enumerate(idx)}
    f = np.zeros(idx.size)
    h = np.diff(x)
    q = -p.cw_mass * p.g
    for e in range(nn - 1):
        fe = beam_load(q, h[e])
        for a, d in enumerate((cw[e] + CW_W, cw[e] + CW_T, cw[e + 1] + CW_W, cw[e + 1] + CW_T)):
            f[loc[int(d)]] += fe[a]
    held = np.array([loc[int(NDOF_NODE * i + CW_W)] for i in np.concatenate([supports, droppers])])
    mask = np.ones(idx.size, bool)
    mask[held] = False
    w = np.zeros(idx.size)
    fr = np.nonzero(mask)[0]
    w[fr] = spsolve(K[fr][:, fr].tocsc(), f[fr])
    r = K @ w - f
    w_full = np.zeros(NDOF_NODE * nn)
    w_full[idx] = w
    T0 = np.array([r[loc[int(NDOF_NODE * i + CW_W)]] for i in droppers])
    preload = np.array([r[loc[int(NDOF_NODE * i + CW_W)]] for i in supports])
    return w_full, T0, preload
