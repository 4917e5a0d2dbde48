"""The wires of a line assembled: each wire's point-load defect at its nodes (`wire_defects`, `PointCorrection`) and
its cubic Hermite beam elements (`beam_matrices`: stiffness, consistent mass and consistent gravity load,
Przemieniecki / Cook, "Concepts and Applications of FE Analysis", ch. 16 and 18) on the full DOF vector."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .hermite_beam import beam_mass, beam_stiffness
from .line import Line
from .point_correction import PointCorrection


def wire_defects(line: Line, x: np.ndarray, ranges: list[tuple[int, int]], point_correction: bool
                 ) -> tuple[np.ndarray, list[PointCorrection]]:
    """The point-load defect of every wire at every node it has (0 where absent or uncorrected; `point_correction`
    False: the plain Hermite wires) and each wire's `PointCorrection`."""
    defect = np.zeros((len(line.wires), x.size))
    pcs = []
    for k, w in enumerate(line.wires):
        i0, i1 = ranges[k]
        xw = x[i0:i1 + 1]
        xm = 0.5 * (xw[:-1] + xw[1:])
        Te = w.tension_at(xm)
        if point_correction and w.tension > 0:
            # a wire with insulators: each element's own EI (the stiffened elements' entries tabulated)
            pc = PointCorrection.build(xw, Te, w.EI, line.beam_properties(w, xm)[0] if line.insulators_on(w) else None)
            defect[k, i0:i1 + 1] = pc.nodal()
        else:
            pc = PointCorrection.none(i1 - i0, w.tension)
        pcs.append(pc)
    return defect, pcs


def beam_matrices(line: Line, x: np.ndarray, slot: np.ndarray, ranges: list[tuple[int, int]], nfull: int, g: float
                  ) -> tuple[sp.csr_matrix, sp.csr_matrix, np.ndarray]:
    """The beams of every wire on the full DOF vector: stiffness (bending + tension) and consistent mass (CSR), and
    the consistent nodal load of the wires' weight (gravity `g`). Over a `SectionInsulator` an element has the wire's
    EI and mass per length plus the insulator's (`Line.beam_properties`: its mass spread over its length)."""
    h = np.diff(x)
    rows, cols, kv, mv = [], [], [], []
    qload = np.zeros(nfull)
    for k, w in enumerate(line.wires):
        # elements with equal length (to 1e-9 m) and tension share matrices: each element belongs to exactly one
        # group (lengths a last bit apart, e.g. 0.5 and 0.49999999999994 m, once fell into two groups that each
        # took both)
        i0, i1 = ranges[k]
        hw = h[i0:i1]
        xm = 0.5 * (x[i0:i1] + x[i0 + 1:i1 + 1])
        Te = w.tension_at(xm)
        stiffened = bool(line.insulators_on(w))
        if stiffened:  # and equal EI and mass per length (the insulators' elements)
            keys = np.stack([np.round(hw, 9), Te, *line.beam_properties(w, xm)], axis=1)
        else:
            keys = np.stack([np.round(hw, 9), Te], axis=1)
        groups, inverse = np.unique(keys, axis=0, return_inverse=True)
        inverse = inverse.ravel()
        for gi in range(groups.shape[0]):
            sel = np.nonzero(inverse == gi)[0]
            he = float(np.mean(hw[sel]))
            EI, rho = (float(groups[gi, 2]), float(groups[gi, 3])) if stiffened else (w.EI, w.mass)
            ke, me = beam_stiffness(EI, float(groups[gi, 1]), he), beam_mass(rho, he)
            a, b = slot[k, i0 + sel], slot[k, i0 + sel + 1]
            dofs = np.stack([a, a + 1, b, b + 1], axis=1)
            rows.append(np.repeat(dofs, 4, axis=1).ravel())
            cols.append(np.tile(dofs, (1, 4)).ravel())
            kv.append(np.tile(ke.ravel(), sel.size))
            mv.append(np.tile(me.ravel(), sel.size))
            q, hs = -rho * g, hw[sel]  # beam_load(q, h) of each element
            np.add.at(qload, a, q * (hs / 2))
            np.add.at(qload, a + 1, q * (hs * hs / 12))
            np.add.at(qload, b, q * (hs / 2))
            np.add.at(qload, b + 1, q * (-hs * hs / 12))
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    Kf = sp.coo_matrix((np.concatenate(kv), (rows, cols)), shape=(nfull, nfull)).tocsr()
    Mf = sp.coo_matrix((np.concatenate(mv), (rows, cols)), shape=(nfull, nfull)).tocsr()
    return Kf, Mf, qload
