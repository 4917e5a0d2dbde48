"""The FE mesh of a line and its DOF layout: the nodes (key points are nodes, `build_nodes`), the line of a
`CatenaryParams` (`line_of`), and where each wire's (w, theta) sit at each node (`layout`).

Both wires of the simple line share the same nodes (supports and dropper positions are always nodes), ordered node by
node as [w_cw, theta_cw, w_mw, theta_mw], so the matrices are banded (half-bandwidth 7).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .line import Line
from .params import CatenaryParams

NDOF_NODE = 4  # w_cw, theta_cw, w_mw, theta_mw
CW_W, CW_T, MW_W, MW_T = range(4)


def build_nodes(p: CatenaryParams | Line, element_length: float | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Node coordinates (m), indices of the support nodes and of the dropper nodes (in the line's dropper order) of
    the line of `p` (its `line`, else the simple line of its fields) or of a `Line` (then `element_length` is needed).

    Key points (`Line.key_points`: supports, droppers, clamps, masses, insulator ends, wire ends) are nodes; each
    interval between key points is split into ceil(length / element_length) equal elements (a length within 1e-6 of
    itself above a whole number of element lengths counts as that number)."""
    if isinstance(p, CatenaryParams):
        line, element_length = line_of(p), p.element_length
    else:
        line = p
    keys = line.key_points()
    pieces = []
    for a, b in zip(keys[:-1], keys[1:], strict=True):
        n = elements_between(a, b, element_length)
        pieces.append(a + (b - a) * np.arange(n) / n)
    pieces.append(keys[-1:])
    x = np.concatenate(pieces)
    at = node_index(x)
    supports = np.array([at(s.x) for s in line.supports], dtype=int)
    droppers = np.array([at(d.x) for d in line.droppers], dtype=int)
    return x, supports, droppers


def elements_between(a: float, b: float, element_length: float) -> int:
    """How many equal elements the interval [a, b] between two key points gets: ceil((b - a) / element_length), at
    least 1; a whole number of elements stays one under a relative change < 1e-6 (the interval between two key points
    600 m out moves by 1e-7 of itself under the stability check's draws of 1e-10)."""
    r = (b - a) / element_length
    return max(1, math.ceil(r - 1e-6 * max(1.0, r)))


def coarsening_misfit(line: Line, element_length: float, factor: int) -> tuple[float, float, int] | None:
    """Where a mesh `factor` times coarser does not nest in the mesh of `element_length` on `line`: the first
    interval (a, b) between key points whose elements at `element_length` are not `factor` times those at
    `factor * element_length`, with its element count at `element_length`; None where every interval nests (each
    coarse element is exactly `factor` elements of the finer mesh)."""
    keys = line.key_points()
    for a, b in zip(keys[:-1], keys[1:], strict=True):
        n = elements_between(a, b, element_length)
        if elements_between(a, b, factor * element_length) * factor != n:
            return float(a), float(b), n
    return None


def node_index(x: np.ndarray) -> Callable[[float], int]:
    """The index of the node at a position (m, to 1e-9 m) among the nodes `x`."""
    idx = {float(v): i for i, v in enumerate(np.round(x, 9))}
    return lambda xp: idx[float(round(xp, 9))]


def line_of(p: CatenaryParams) -> Line:
    """The line of `p`: `p.line`, else the simple line of its fields (EN 50318:2002 by default)."""
    if p.line is not None:
        return p.line
    from .lines import simple  # here: lines.py builds from CatenaryParams

    return simple(p)


def layout(line: Line, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[tuple[int, int]], np.ndarray]:
    """The DOF layout of `line` on the nodes `x`: DOFs in blocks, a block per mechanical component
    (`Line.wire_components`) and node, holding (w, theta) of each of the component's wires present there in the line's
    wire order; the components one after the other (ordered by where their first contact wire starts, components
    without a contact wire last), each over its nodes in order. Returns the blocks' offsets (nblock + 1), the w slot
    of every wire at every node (-1 absent), each wire's node range [i0, i1] and each component's block range
    (ncomp x 2, [first, end)). A line of one component (a tension section) has a block per node, the node-by-node
    order [w_cw, theta_cw, w_mw, theta_mw, ...]; a route's sections are contiguous and uncoupled, so its step
    matrix is block diagonal, one banded block per section (`native/catenary.c` steps only the sections in play)."""
    at = node_index(x)
    nw, nn = len(line.wires), x.size
    present = np.zeros((nw, nn), bool)
    ranges = []
    for k, w in enumerate(line.wires):
        i0, i1 = at(w.x0), at(w.x1)
        present[k, i0:i1 + 1] = True
        ranges.append((i0, i1))
    comp = np.asarray(line.wire_components())
    first_contact = {}
    for k, w in enumerate(line.wires):
        if w.role == "contact":
            first_contact.setdefault(int(comp[k]), w.x0)
    order = sorted(range(int(comp.max()) + 1), key=lambda c: (c not in first_contact, first_contact.get(c, 0.0), c))
    slot = -np.ones((nw, nn), dtype=np.int64)
    sizes, cblocks = [], []
    start = 0
    for c in order:
        mine = np.nonzero(comp == c)[0]
        here = present[mine]
        nodes = np.nonzero(here.any(axis=0))[0]
        counts = 2 * here[:, nodes].sum(axis=0)
        offs = start + np.concatenate([[0], np.cumsum(counts)])
        rank = np.cumsum(here[:, nodes], axis=0) - 1
        slot[mine[:, None], nodes[None, :]] = np.where(here[:, nodes], offs[:-1][None, :] + 2 * rank, -1)
        b0 = len(sizes)
        sizes.extend(counts.tolist())
        cblocks.append((b0, len(sizes)))
        start = int(offs[-1])
    offset = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    return offset, slot, ranges, np.array(cblocks, dtype=np.int64).reshape(-1, 2)
