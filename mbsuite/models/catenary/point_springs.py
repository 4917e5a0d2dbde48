"""The point elements of a line on the full DOF vector: ground springs and point masses at the supports (steady arms,
messenger supports), the line's point masses, clamps between wires and droppers, each spring with its wires'
point-load defects in series (`series`, `PointCorrection`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .line import Line
from .point_correction import series


@dataclass
class PointSprings:
    """The point elements of a line (full DOF indices): ground springs in the dynamics (`ground`) and in the static
    state (`ground_static`: without the contact wire's steady arms, which are holds there), point masses, the clamps'
    stiffness, and each dropper's upper and lower w DOF and its stiffness `k_drop`."""

    ground: np.ndarray
    ground_static: np.ndarray
    point_mass: np.ndarray
    Kclamp: sp.csr_matrix
    up: np.ndarray
    low: np.ndarray
    k_drop: np.ndarray


def point_springs(line: Line, slot: np.ndarray, defect: np.ndarray, at: Callable[[float], int],
                  nfull: int) -> PointSprings:
    """The supports, point masses, clamps and droppers of `line`, in that order (`slot`: each wire's w slot at each
    node; `defect`: each wire's point-load defect at each node; `at`: the node at a position)."""
    wi = {w.name: k for k, w in enumerate(line.wires)}

    def wslot(name: str, xp: float) -> tuple[int, int, float]:
        k, i = wi[name], at(xp)
        return int(slot[k, i]), i, float(defect[k, i])

    ground, ground_static, point_mass = _supports(line, wi, wslot, nfull)
    Kclamp = _clamps(line, wslot, nfull)
    up = np.array([wslot(d.upper, d.x)[0] for d in line.droppers], dtype=int)
    low = np.array([wslot(d.lower, d.x)[0] for d in line.droppers], dtype=int)
    k_drop = _droppers(line, wslot, up, low, point_mass)
    return PointSprings(ground, ground_static, point_mass, Kclamp, up, low, k_drop)


def _supports(line: Line, wi: dict[str, int], wslot: Callable[[str, float], tuple[int, int, float]],
              nfull: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ground springs at the supports (the contact wire's steady arms are holds in the static state), the supports'
    and the line's point masses."""
    ground = np.zeros(nfull)
    ground_static = np.zeros(nfull)
    point_mass = np.zeros(nfull)
    for s in line.supports:
        for name, k in s.k.items():
            d, _, dd = wslot(name, s.x)
            ground[d] += series(k, dd)
            if line.wires[wi[name]].role != "contact":  # a contact wire's steady arm is a hold there
                ground_static[d] += series(k, dd)
        for name, m in s.m.items():
            point_mass[wslot(name, s.x)[0]] += m
    for pm in line.masses:
        point_mass[wslot(pm.wire, pm.x)[0]] += pm.m
    return ground, ground_static, point_mass


def _clamps(line: Line, wslot: Callable[[str, float], tuple[int, int, float]], nfull: int) -> sp.csr_matrix:
    """Clamps: k (e_a - e_b)(e_a - e_b)^T with both wires' defects in series."""
    cr, cc, cv = [], [], []
    for c in line.clamps:
        (da, _, fa), (db, _, fb) = wslot(c.a, c.x), wslot(c.b, c.x)
        kc = float(series(c.k, fa + fb))
        cr += [da, da, db, db]
        cc += [da, db, da, db]
        cv += [kc, -kc, -kc, kc]
    return sp.coo_matrix((cv, (cr, cc)), shape=(nfull, nfull)).tocsr()


def _droppers(line: Line, wslot: Callable[[str, float], tuple[int, int, float]], up: np.ndarray, low: np.ndarray,
              point_mass: np.ndarray) -> np.ndarray:
    """Droppers (upper and lower w DOFs `up`, `low`): each one's stiffness k_j with both wires' defects in series
    (the spring k_j (e_up - e_low)(e_up - e_low)^T); their masses, half on each end, and clamp masses added to
    `point_mass`."""
    nd = len(line.droppers)
    dsum = np.array([wslot(d.upper, d.x)[2] + wslot(d.lower, d.x)[2] for d in line.droppers])
    kraw = np.array([d.k for d in line.droppers], dtype=float)
    k_drop = np.asarray(series(kraw, dsum), dtype=float) if nd else np.zeros(0)
    for d, a, b in zip(line.droppers, up, low, strict=True):
        point_mass[a] += 0.5 * d.mass + d.clamp_upper
        point_mass[b] += 0.5 * d.mass + d.clamp_lower
    return k_drop
