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

The pieces live by concern: the element matrices in `hermite_beam.py`, the point-load correction in
`point_correction.py`, the mesh and DOF layout in `mesh.py`, the wires' beams in `wire_assembly.py`, the supports,
clamps and droppers in `point_springs.py`, the static state in `static_state.py`; this module holds the assembled
catenary (`CatenaryFE`) and `assemble`, and keeps the pieces' public names importable from here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ...errors import ParameterError
from .hermite_beam import beam_load, beam_mass, beam_stiffness, hermite, tensioned_beam_compliance
from .line import Irregularity, Line
from .mesh import CW_T, CW_W, MW_T, MW_W, NDOF_NODE, build_nodes, layout, line_of, node_index
from .params import CatenaryParams
from .point_correction import REF_ELEMENTS, PointCorrection, series
from .point_springs import PointSprings, point_springs
from .static_state import check_compression, static_state
from .wire_assembly import beam_matrices, wire_defects

__all__ = [
    "CW_T", "CW_W", "MW_T", "MW_W", "NDOF_NODE", "REF_ELEMENTS", "CatenaryFE", "PointCorrection", "assemble",
    "beam_load", "beam_mass", "beam_stiffness", "build_nodes", "hermite", "line_of", "series",
    "tensioned_beam_compliance",
]


@dataclass
class CatenaryFE:
    """Assembled catenary matrices on the free DOFs (pinned end w's removed) and its static state.

    DOF layout (`mesh.layout`): at node i (position `x[i]`) each wire present there has two DOFs (w, theta), in
    blocks of a mechanical component (wires joined by droppers or clamps) and node, in the line's wire order (the
    contact wire first); block b's DOFs are `node_offset[b] .. node_offset[b + 1] - 1` of the full vector. A line of
    one component has a block per node (the simple line: 4 DOFs per node, [w_cw, theta_cw, w_mw, theta_mw]); a
    route's sections follow one another, each over its nodes (`component_blocks`: each one's block range). `slot`
    gives every wire's w at every node; `free` lists the full index of each free DOF.

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
    node_offset: np.ndarray  # (nblock + 1,) full index of each block's first DOF (a block per node on one section)
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
    #: every contact wire's point-load defect (a route's, in `line.contacts` order; `contact` is the first) and node
    #: range [i0, i1]
    contacts: tuple[PointCorrection, ...] = ()
    contact_ranges: tuple[tuple[int, int], ...] = ()
    #: (ncomp, 2) each mechanical component's block range [first, end) (`mesh.layout`)
    component_blocks: np.ndarray | None = None

    @property
    def n_contact_wires(self) -> int:
        """Number of contact wires (1 on a tension section; a route's sections' own)."""
        return len(self.line.contacts)

    def cw_dof_of(self, c: int) -> np.ndarray:
        """(nnode, 2) free index of contact wire c's (w, theta) at each node, -1 where pinned or absent."""
        s = self.slot[c]
        ok = s >= 0
        w = np.where(ok, self.full_to_free[np.maximum(s, 0)], -1)
        t = np.where(ok, self.full_to_free[np.maximum(s, 0) + 1], -1)
        return np.stack([w, t], axis=1)

    def cw_w0_of(self, c: int) -> np.ndarray:
        """(nnode, 2) static (w, theta) of contact wire c at each node (0 where absent)."""
        s = self.slot[c]
        ok = s >= 0
        return np.stack([np.where(ok, self.w0_full[np.maximum(s, 0)], 0.0),
                         np.where(ok, self.w0_full[np.maximum(s, 0) + 1], 0.0)], axis=1)

    @property
    def arms(self) -> tuple[np.ndarray, np.ndarray]:
        """The uplift points: (support index, contact wire index) of each contact wire at each support its x-range
        holds, support by support (on a tension section: every support, the contact wire)."""
        si, ci = [], []
        for i, xs in enumerate(self.x[self.supports]):
            for c, w in enumerate(self.line.contacts):
                if w.x0 - 1e-9 <= xs <= w.x1 + 1e-9:
                    si.append(i)
                    ci.append(c)
        return np.array(si, dtype=int), np.array(ci, dtype=int)

    @property
    def arm_cw(self) -> np.ndarray:
        """(narm,) free index of the contact wire's w at each uplift point (`arms`), -1 where pinned."""
        si, ci = self.arms
        return self.full_to_free[self.slot[ci, self.supports[si]]]

    @property
    def arm_names(self) -> list[str]:
        """The name of each uplift point (`arms`): its x (m, "%g"), with its contact wire's name where several
        contact wires have one at that support ("360_contact_a")."""
        si, ci = self.arms
        xs = self.x[self.supports[si]]
        names = []
        for j, (i, c) in enumerate(zip(si, ci, strict=True)):
            shared = int(np.sum(si == i)) > 1
            names.append(f"{xs[j]:g}_{self.line.contacts[c].name}" if shared else f"{xs[j]:g}")
        return names

    @property
    def arm_x(self) -> np.ndarray:
        """(narm,) position of each uplift point (`arms`, m)."""
        return self.x[self.supports[self.arms[0]]]

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
        check_compression(self.line, self.T0, mask)
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


def assemble(p: CatenaryParams, point_correction: bool = True) -> CatenaryFE:
    """Mesh, assemble and solve the static state of the line of `p` (`line_of`). `point_correction`: every point
    spring gets its wires' point-load defect in series (module docstring); False gives the plain Hermite wires."""
    line = line_of(p)
    x, supports, droppers = build_nodes(line, p.element_length)
    offset, slot, ranges, cblocks = layout(line, x)
    nfull = int(offset[-1])
    defect, pcs = wire_defects(line, x, ranges, point_correction)
    Kf, Mf, qload = beam_matrices(line, x, slot, ranges, nfull, p.g)  # qload: gravity on the wires, then the points
    Kbeams = Kf.copy()
    ps = point_springs(line, slot, defect, node_index(x), nfull)
    qload -= p.g * ps.point_mass
    Kf = (Kf + sp.diags(ps.ground) + ps.Kclamp).tocsr()
    if np.any(ps.point_mass):
        Mf = (Mf + sp.diags(ps.point_mass)).tocsr()
    nd = len(line.droppers)
    bfull = sp.coo_matrix(
        (np.concatenate([np.ones(nd), -np.ones(nd)]), (np.concatenate([ps.up, ps.low]), np.tile(np.arange(nd), 2))),
        shape=(nfull, nd)).tocsc()
    Kdf = (bfull @ sp.diags(ps.k_drop) @ bfull.T).tocsr()
    pinned, free, full_to_free = _free_dofs(line, slot, ranges, ps, nfull)
    M = Mf[free][:, free].tocsr()
    K0 = Kf[free][:, free].tocsr()
    Kd = Kdf[free][:, free].tocsr()
    B = bfull[free].tocsc()

    Kst = (Kbeams + sp.diags(ps.ground_static) + ps.Kclamp).tocsr()
    w0_full, T0, preload = static_state(line, x, slot, supports, ps.up, ps.low, Kst, qload, pinned)
    slack = np.array([d.law != "linear" for d in line.droppers], dtype=bool)
    check_compression(line, T0, np.array([d.law == "slack" for d in line.droppers], dtype=bool))
    return CatenaryFE(params=p, line=line, x=x, supports=supports, droppers=droppers, node_offset=offset, slot=slot,
                      free=free, full_to_free=full_to_free, M=M, K0=K0, Kd=Kd, B=B,
                      dropper_upper=full_to_free[ps.up], dropper_lower=full_to_free[ps.low], dropper_slack=slack,
                      w0_full=w0_full, T0=T0, support_preload=preload, k_drop=ps.k_drop, contact=pcs[0],
                      irregularity=line.irregularity, contacts=tuple(pcs[:len(line.contacts)]),
                      contact_ranges=tuple(ranges[:len(line.contacts)]), component_blocks=cblocks)


def _free_dofs(line: Line, slot: np.ndarray, ranges: list[tuple[int, int]], ps: PointSprings,
               nfull: int) -> tuple[list[int], np.ndarray, np.ndarray]:
    """The pinned DOFs (w of a wire at a pinned end), the free DOFs and the free index of each full DOF (-1 pinned);
    a `ParameterError` for a dropper on a pinned wire end."""
    pinned = sorted(int(slot[k, i]) for k, w in enumerate(line.wires)
                    for i, end in zip(ranges[k], w.ends, strict=True) if end == "pinned")
    mask = np.ones(nfull, bool)
    mask[pinned] = False
    for j, d in enumerate(line.droppers):
        if not (mask[ps.up[j]] and mask[ps.low[j]]):
            raise ParameterError(f"line {line.name!r}: the dropper at x = {d.x} m ({d.upper} -> {d.lower}) sits on a "
                                 "pinned wire end: it can carry nothing there (move it off the end)")
    free = np.nonzero(mask)[0]
    full_to_free = -np.ones(nfull, dtype=int)
    full_to_free[free] = np.arange(free.size)
    return pinned, free, full_to_free
