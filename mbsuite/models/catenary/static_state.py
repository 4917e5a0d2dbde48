"""The static state of a line (catenary.md, "Choices mbsuite fixes"): no pre-sag; the CW is held level (w = 0) at
every dropper and support and sags under its own weight between them. The constraint reactions at the droppers are
the droppers' static tensions; those at the supports are the steady arms' static pre-loads (constant, they cancel in
the dynamics). `check_compression` refuses a slack dropper in compression in it.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from ...errors import ParameterError
from .line import Line, joined


def check_compression(line: Line, T0: np.ndarray, slack: np.ndarray) -> None:
    """A `ParameterError` naming the first dropper of mask `slack` whose static tension is negative."""
    bad = np.nonzero(slack & (T0 < 0))[0]
    if bad.size:
        d = line.droppers[int(bad[0])]
        raise ParameterError(
            f"line {line.name!r}: the dropper at x = {d.x} m ({d.upper} -> {d.lower}) is in compression in the static "
            f"state (T0 = {T0[int(bad[0])]:.4g} N): a slack dropper cannot hold the wire there (give it law = "
            "'linear' if it is a strut, or change the line)")


def static_state(line: Line, x: np.ndarray, slot: np.ndarray, supports: np.ndarray, up: np.ndarray,
                 low: np.ndarray, K: sp.csr_matrix, f: np.ndarray, pinned: list[int]
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The static state of every wire (catenary.md, "Choices mbsuite fixes", generalised): each dropper holds its
    lower wire at its design height (the contact wire: `Line.design_height`, the presag; another wire: 0), the contact
    wire is held at its design height at every support, and the droppers' tensions and the steady arms' pre-loads are
    the holds' reactions r = K w - f. Wires joined by clamps form a group (`wire_groups`); a group is solved once every
    dropper hanging from it has its tension (the contact wire's group first), those tensions loading it where they
    hang: the simple line's contact wire is solved alone, exactly as before, and the messenger then carries its
    droppers. K holds the beams, the clamps and the ground springs of the wires other than the contact wire. Returns
    the full static state, the dropper tensions and the support reactions."""
    nd = up.size
    wi = {w.name: k for k, w in enumerate(line.wires)}
    group = wire_groups(line)
    d_up = np.array([group[wi[d.upper]] for d in line.droppers], dtype=int)
    d_low = np.array([group[wi[d.lower]] for d in line.droppers], dtype=int)
    if np.any(d_up == d_low):
        j = int(np.nonzero(d_up == d_low)[0][0])
        raise ParameterError(f"line {line.name!r}: the dropper at x = {line.droppers[j].x} m joins wires that clamps "
                             "already join (a loop: it would hang a wire from itself)")
    ncw = len(line.contacts)
    xd = np.array([d.x for d in line.droppers], dtype=float)
    z = line.design_height(xd)
    z = np.where(d_low == group[0], z, 0.0)
    for c in range(1, ncw):  # a route's further contact wires: each dropper on its group at that wire's heights
        z = np.where(d_low == group[c], line.design_height(xd, line.wires[c]), z)
    u = np.zeros(K.shape[0])
    T0 = np.full(nd, np.nan)
    preload = np.zeros(supports.size)
    f = f.copy()
    todo = sorted(set(group))
    while todo:
        ready = [g for g in todo if not np.any(np.isnan(T0[d_up == g]))]
        if not ready:
            raise ParameterError(_loop_text(line, d_up, d_low, np.isnan(T0)))
        g = ready[0]
        todo.remove(g)
        ks = [k for k in range(len(line.wires)) if group[k] == g]
        sl = slot[ks]
        idx = np.sort(np.concatenate([sl[sl >= 0], sl[sl >= 0] + 1]))
        pos = -np.ones(K.shape[0], dtype=int)
        pos[idx] = np.arange(idx.size)
        mine = np.nonzero(d_low == g)[0]
        held = _holds(line, x, slot, supports, pinned, pos, low, z, mine,
                      [c for c in range(ncw) if group[c] == g])
        Kg = K[idx][:, idx].tocsr()
        Kg.eliminate_zeros()
        fg = f[idx]
        w = _solve_held(Kg, fg, held)
        if not np.all(np.isfinite(w)):
            names = [line.wires[k].name for k in ks]
            raise ParameterError(f"line {line.name!r}: the static state of wire(s) {names} is singular: a part is held "
                                 "by nothing (no pinned end, ground spring, clamp or dropper carries it)")
        r = Kg @ w - fg
        u[idx] = w
        T0[mine] = r[pos[low[mine]]]
        for j in mine:  # the dropper now loads the wire it hangs from
            f[up[j]] -= T0[j]
        for c in range(ncw):
            if group[c] != g:
                continue
            cw = line.wires[c]
            arm = np.array([line.steady_arm(sp_, cw) and slot[c, i] >= 0
                            for sp_, i in zip(line.supports, supports, strict=True)], dtype=bool)
            here = np.where(arm, r[pos[np.maximum(slot[c, supports], 0)]], 0.0)
            preload = here if c == 0 else preload + here
    return u, T0, preload


def _loop_text(line: Line, d_up: np.ndarray, d_low: np.ndarray, pending: np.ndarray) -> str:
    """Why the static state cannot order the wires: droppers hanging two wires from each other (the fewer of the two
    directions named: a dropper upside down), else the droppers that hang in the loop."""
    dr = line.droppers
    for j in np.nonzero(pending)[0]:
        back = np.nonzero(pending & (d_up == d_low[j]) & (d_low == d_up[j]))[0]
        if back.size:
            same = np.nonzero(pending & (d_up == d_up[j]) & (d_low == d_low[j]))[0]
            few, many = (same, back) if same.size <= back.size else (back, same)
            d, e = dr[few[0]], dr[many[0]]
            xs = ", ".join(f"{dr[k].x:g}" for k in few[:4]) + (" ..." if few.size > 4 else "")
            return (f"line {line.name!r}: the dropper(s) at x = {xs} m hang wire {d.lower!r} from {d.upper!r}, while "
                    f"{many.size} other(s) (e.g. at x = {e.x:g} m) hang {e.lower!r} from {e.upper!r}: a dropper upside "
                    "down? (upper = the wire it hangs from, lower = the wire it holds)")
    xs = ", ".join(f"{dr[k].x:g} m ({dr[k].upper} -> {dr[k].lower})" for k in np.nonzero(pending)[0][:4])
    return f"line {line.name!r}: its droppers form a loop (a wire hangs from a wire that hangs from it): {xs}"


def wire_groups(line: Line) -> list[int]:
    """The group of each wire: wires joined by clamps share one (its representative wire's index)."""
    wi = {w.name: k for k, w in enumerate(line.wires)}
    return joined(len(line.wires), [(wi[c.a], wi[c.b]) for c in line.clamps])


def _holds(line: Line, x: np.ndarray, slot: np.ndarray, supports: np.ndarray, pinned: list[int], pos: np.ndarray,
           low: np.ndarray, z: np.ndarray, mine: np.ndarray, contacts: list[int]) -> dict[int, float]:
    """The held DOFs of one group (its local index -> height): pinned ends at 0, the lower end of each of its droppers
    `mine` at its design height, and each contact wire of the group (`contacts`, indices of `line.wires`) at each
    support with a steady arm on it (or its pinned end) at its design height."""
    held = {}
    for p in pinned:
        if pos[p] >= 0:
            held[int(pos[p])] = 0.0
    for j in mine:
        held[int(pos[low[j]])] = float(z[j])
    for c in contacts:  # the contact wire at each support with a steady arm (a ground spring on it)
        cw = line.wires[c]
        zs = line.design_height(x[supports], cw if c else None)
        for i, s in enumerate(slot[c, supports]):
            if s >= 0 and line.steady_arm(line.supports[i], cw):
                held[int(pos[s])] = float(zs[i])
    return held


def _solve_held(Kg: sp.csr_matrix, fg: np.ndarray, held: dict[int, float]) -> np.ndarray:
    """The group's static state with the `held` DOFs at their heights (NaN where its matrix is singular)."""
    hk = np.array(sorted(held), dtype=int)
    w = np.zeros(fg.size)
    w[hk] = [held[k] for k in hk]
    mask = np.ones(fg.size, bool)
    mask[hk] = False
    fr = np.nonzero(mask)[0]
    with warnings.catch_warnings():
        warnings.simplefilter("error", category=sp.linalg.MatrixRankWarning)
        try:
            w[fr] = spsolve(Kg[fr][:, fr].tocsc(), fg[fr] - Kg[fr][:, hk] @ w[hk]) if np.any(w[hk]) else \
                spsolve(Kg[fr][:, fr].tocsc(), fg[fr])
        except (sp.linalg.MatrixRankWarning, RuntimeError):
            w[fr] = np.nan
    return w
