"""Lines as data (`line.Line`, `lines.py`, `linefile.py`, `irregularity.py`) assembled by `fe.assemble`, checked
against sources that are not the FE: a finite-difference solve of the same tensioned-beam equations written here,
each wire's closed-form frequencies, reductions of the stitched and compound lines to the simple line, the presag
and the dropper tensions by hand, irregularity profiles against their files and their requested rms, and the line
file's errors."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from mbsuite.models.catenary import lines
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.line import Line
from mbsuite.models.catenary.params import CatenaryParams

#: three EN 50318:2002 spans (180 m): the shortest line with an interior span between two interior supports
THREE = dict(n_spans=3, x_end=180.0, window_start=60.0, window_end=120.0)


# --- an independent static solve: finite differences on a fine uniform grid per wire ---------------------------------
class FiniteDifferenceLine:
    """The static equations of a line solved by finite differences, independently of the FE: each wire on a uniform
    grid of spacing h over [x0, x1] (every key point a grid point), EI w'''' - T w'' = q in the energy form of the
    central differences (tension T(x) on every interval, curvature (w[i-1] - 2 w[i] + w[i+1]) / h^2 at every interior
    grid point: the moment EI w'' vanishes at both ends, a pinned end also has w = 0, a free end's shear balances the
    springs there); ground springs, droppers (all linear) and clamps are point springs k between grid points, with
    their stiffness as given (no point-load correction: the continuous beam needs none). Second-order accurate."""

    def __init__(self, line: Line, h: float) -> None:
        self.line, self.h = line, h
        self.offset, n0 = {}, 0
        for w in line.wires:
            n = int(round((w.x1 - w.x0) / h))
            assert abs(n * h - (w.x1 - w.x0)) < 1e-9, w.name
            self.offset[w.name] = n0
            n0 += n + 1
        R, C, V = [], [], []

        def spring(idx: np.ndarray, vec: list[float], k: np.ndarray) -> None:  # sum_r k_r (vec . w[idx_r])^2 / 2
            idx, vec = np.atleast_2d(idx), np.asarray(vec, float)
            m = vec.size
            R.append(np.repeat(idx, m, axis=1).ravel())
            C.append(np.tile(idx, (1, m)).ravel())
            V.append((np.asarray(k, float)[:, None] * np.outer(vec, vec).ravel()[None, :]).ravel())

        pinned = []
        for w in line.wires:
            o, n = self.offset[w.name], int(round((w.x1 - w.x0) / h))
            i = o + np.arange(n)
            xm = w.x0 + h * (np.arange(n) + 0.5)
            spring(np.stack([i, i + 1], 1), [1.0, -1.0], w.tension_at(xm) / h)
            if w.EI > 0:
                j = o + np.arange(n - 1)
                spring(np.stack([j, j + 1, j + 2], 1), [1.0, -2.0, 1.0], np.full(n - 1, w.EI / h**3))
            pinned += [o + (0 if e == 0 else n) for e, end in enumerate(w.ends) if end == "pinned"]
        for s in line.supports:
            for name, k in s.k.items():
                spring(np.array([[self.at(name, s.x)]]), [1.0], np.array([k]))
        for d in line.droppers:
            spring(np.array([[self.at(d.upper, d.x), self.at(d.lower, d.x)]]), [1.0, -1.0], np.array([d.k]))
        for c in line.clamps:
            spring(np.array([[self.at(c.a, c.x), self.at(c.b, c.x)]]), [1.0, -1.0], np.array([c.k]))
        K = sp.coo_matrix((np.concatenate(V), (np.concatenate(R), np.concatenate(C))), shape=(n0, n0)).tocsc()
        self.n = n0
        self.keep = np.setdiff1d(np.arange(n0), pinned)
        self.lu = splu(K[self.keep][:, self.keep].tocsc())

    def at(self, wire: str, x: float) -> int:
        """Grid index of `wire` at x."""
        w = self.line.wire(wire)
        i = int(round((x - w.x0) / self.h))
        assert abs(w.x0 + i * self.h - x) < 1e-9, (wire, x)
        return self.offset[wire] + i

    def point_load(self, x: float) -> np.ndarray:
        """Every grid displacement (m) under a unit upward force on the contact wire at x."""
        f = np.zeros(self.n)
        f[self.at(self.line.contact.name, x)] = 1.0
        u = np.zeros(self.n)
        u[self.keep] = self.lu.solve(f[self.keep])
        return u

    def dropper_forces(self, u: np.ndarray) -> np.ndarray:
        """Each dropper's tension change (N) in the state u."""
        return np.array([d.k * (u[self.at(d.upper, d.x)] - u[self.at(d.lower, d.x)]) for d in self.line.droppers])


def _fe_point_load(fe, x: float) -> tuple[float, np.ndarray]:
    """The FE under a unit upward force on the contact wire's node at x, u = (K0 + Kd)^-1 F: the contact wire's
    height under the load as the contact law reads it (the node's w plus the contact wire's point-load defect there,
    `fe.contact`; 0 without the correction) and each dropper's tension change k_drop (w_upper - w_lower)."""
    i = int(np.argmin(np.abs(fe.x - x)))
    assert abs(fe.x[i] - x) < 1e-9
    f = np.zeros(fe.n)
    f[fe.full_to_free[fe.slot[0, i]]] = 1.0
    u = splu((fe.K0 + fe.Kd).tocsc()).solve(f)
    d = fe.contact.nodal()[i] if fe.contact.active else 0.0
    return float(u[fe.full_to_free[fe.slot[0, i]]] + d), fe.k_drop * (u[fe.dropper_upper] - u[fe.dropper_lower])


#: (line, load position, what is there, bound on the corrected FE's driving-point error relative to the FD's)
POINT_LOADS = [
    ("simple", 90.0, "dropper", 1.5e-3),  # the mid-span dropper
    ("simple", 60.0, "support", 5e-4),
    ("simple", 87.5, "between droppers", 1e-5),
    ("stitched", 60.0, "support", 5e-4),
    ("stitched", 65.0, "dropper", 6e-4),  # a stitch dropper
    ("compound", 60.0, "support", 5e-4),
    ("compound", 92.5, "dropper", 2.5e-3),  # a contact dropper
    ("compound", 90.0, "between droppers", 1.5e-5),  # mid-span, between contact droppers
]


@pytest.fixture(scope="module")
def three_lines() -> dict[str, tuple]:
    """The three shipped line kinds on three spans: (line, corrected FE, plain FE, FD solve)."""
    p = CatenaryParams(**THREE)
    out = {}
    for kind, build in (("simple", lines.simple), ("stitched", lines.stitched), ("compound", lines.compound)):
        line = build(p)
        q = dataclasses.replace(p, line=line)
        out[kind] = (line, assemble(q), assemble(q, point_correction=False), FiniteDifferenceLine(line, 0.005))
    return out


def test_static_point_load_against_finite_differences(three_lines):
    """The FE's static response to a unit force on the contact wire (u = (K0 + Kd)^-1 F on the free DOFs) on the
    simple, stitched (`lines.stitched`) and compound (`lines.compound`) lines of three EN 50318 spans against the
    finite-difference solve of the same equations (`FiniteDifferenceLine`, h = 0.005 m: within 1.1e-5 relative and
    5.2e-6 N per N of h = 0.0025 m). Two measures: the contact wire's height under the load (the node's w plus the
    contact defect, as the contact law reads it) and the tension change of every dropper.

    Driving point, relative error (corrected / plain FE, measured): simple 5.5e-4 / 8.3e-4 at the mid-span dropper,
    1.7e-4 / 3.0e-3 at a support, 3.1e-6 / 1.2e-3 between droppers; stitched 1.5e-4 / 1.3e-3 at a support,
    2.2e-4 / 1.5e-3 at a stitch dropper; compound 1.6e-4 / 6.2e-3 at a support, 8.8e-4 / 1.1e-3 at a contact
    dropper, 4.3e-6 / 1.6e-3 between contact droppers. Bounds 2.5x to 3.5x the measured error (`POINT_LOADS`). The
    corrected FE is closer everywhere: by 9x to 38x at the supports, ~380x between droppers, only 1.2x to 6.7x at a
    dropper (asserted: closer everywhere, by >= 5x at supports and between droppers).

    Dropper forces, load at a support or between droppers: corrected <= 3.9e-5 N per N (bound 1.5e-4), plain
    2.4e-4 to 8.1e-4 N per N (asserted > 1.5e-4). Load at a dropper: the load and the dropper share the wire's
    bending boundary layer, a cross term the correction leaves out (`fe` docstring): the dropper under the load is
    off by 2.7e-4 to 1.05e-3 N per N corrected against 2.0e-5 to 2.6e-4 plain, its neighbours by up to 5.0e-4
    (plain 3.1e-4); bound 3e-3."""
    for kind, x, what, bound in POINT_LOADS:
        line, fe, plain, fd = three_lines[kind]
        u = fd.point_load(x)
        exact, t_exact = u[fd.at(line.contact.name, x)], fd.dropper_forces(u)
        w_fe, t_fe = _fe_point_load(fe, x)
        w_pl, t_pl = _fe_point_load(plain, x)
        err, err_plain = abs(w_fe / exact - 1), abs(w_pl / exact - 1)
        assert err < bound, (kind, x, err)
        assert err < err_plain / (1.0 if what == "dropper" else 5.0), (kind, x, err, err_plain)
        if what == "dropper":
            assert np.max(np.abs(t_fe - t_exact)) < 3e-3, (kind, x)
        else:
            assert np.max(np.abs(t_fe - t_exact)) < 1.5e-4, (kind, x)
            assert np.max(np.abs(t_pl - t_exact)) > 1.5e-4, (kind, x)
