"""The catenary's compiled step core (`native/catenary.c`), driven through ctypes with numpy arrays.

`NativeCore(sim, contacts)` mirrors a `CoupledSimulation`: the banded Cholesky factor of the step matrix S (computed in
C, once), K in CSR, the droppers' influence columns, and the state of a passage (u, q, p, the slack set, per contact
its element, shape functions and cached influence columns). `run(n0, n1)` steps a passage entirely in C, every
pantograph through its one-port (`attach`; `engines/native/mbsuite.h`): the 2-mass pantograph's (in the C file), the
linear pantographs' and a MuJoCo model's (`engines/native/oneport.c`), a registry model's own (the Eppinger
pantograph's hand-derived ODE), an affine one by its head map, a nonlinear one by a secant iteration in C. The stages
`predict`, `local`, `advance` are exposed for the Python-driven twin (`train._Secant`, the test oracle). The readable
twin is `passage.Passage`; tests hold all three equal to rounding.
`NativeFactor(S, node_offset, free)` is the core's factorisation and sweeps alone, for any SPD matrix.

Why a hand-written banded Cholesky rather than LAPACK: S is factorised once per passage and the per-step solve is the
core of the step, fused with the mat-vec and the recursions in one C loop; LAPACK's dpbtrs (column-oriented dtbsv)
costs about 120 us per solve at half-bandwidth 5 and 4 800 DOFs (the EN 50318 line), the block sweeps here (nodes of
2 to 8 DOFs, `build_blocks` in the C file) about 35 us (`scripts/catenary_benchmark.py`), and no binding to scipy's
private LAPACK capsules is needed.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from typing import Any

import numpy as np

from ...engines import native
from ...errors import SolverError

_P = ctypes.c_void_p
_I = ctypes.c_int
_D = ctypes.c_double
ABI = 7


class _Job(ctypes.Structure):
    _fields_ = [
        ("n", _I), ("bw", _I), ("nd", _I), ("nsup", _I), ("ncon", _I), ("nnode", _I), ("nnz", _I),
        ("slack", _I), ("unilateral", _I), ("max_iter", _I),
        ("h", _D), ("hh2", _D), ("c_ab", _D), ("inv_1ha", _D), ("c_kd", _D), ("two_hh", _D), ("kc", _D),
        ("V", _D), ("dt", _D), ("max_disp", _D),
        ("L", _P), ("invd", _P), ("Kp", _P), ("Ki", _P), ("Kx", _P), ("up", _P), ("lo", _P), ("dslack", _P),
        ("T0", _P), ("kdj", _P), ("Zg", _P), ("D", _P), ("xnode", _P), ("cwdof", _P), ("w0cw", _P), ("supidx", _P),
        ("esig", _P), ("pq", _P), ("pref", _P), ("ptk", _P), ("nirr", _I), ("irr_x0", _D), ("irr_dx", _D), ("irr", _P),
        ("u", _P), ("q", _P), ("p", _P), ("R", _P), ("vbs", _P), ("vb", _P),
        ("slk", _P), ("nslack", _I), ("sS", _P),
        ("present", _P), ("active", _P), ("elem", _P), ("xc", _P), ("xs", _P), ("xend", _P), ("Nl", _P),
        ("dofs", _P), ("w0d", _P), ("cols", _P), ("crng", _P), ("zrng", _P), ("f", _P), ("kce", _P), ("cbc", _P),
        ("rirr", _P), ("gv", _P), ("a", _P), ("Cm", _P), ("bz", _P),
        ("dstar", _P), ("P", _P), ("gp", _P), ("head", _P), ("work", _P), ("iwork", _P),
        ("ports", _P), ("gs", _P), ("cw", _P), ("nl", _P),
        ("rec_t", _P), ("rec_x", _P), ("rec_f", _P), ("rec_head", _P), ("rec_wire", _P), ("rec_out", _P),
        ("rec_up", _P), ("rec_ns", _P), ("ooff", _P), ("nout", _I),
        ("blocked", _I), ("fidx", _P), ("noff", _P), ("boff", _P), ("blk", _P), ("pw", _P), ("seg", _P),
        ("nseg_f", _I), ("nseg_b", _I),
        ("n_local", ctypes.c_long), ("err", _I), ("err_con", _I), ("err_port", _I), ("err_value", _D),
        ("ncw", _I), ("own", _P), ("cwk", _P), ("erng", _P), ("onw", _P), ("xrng", _P), ("cwEI", _P), ("Nf", _P),
        ("nblk", _I), ("ncomp", _I), ("cmpb", _P), ("cmpd", _P), ("cmpx", _P), ("retire", _I), ("cmpt", _P),
        ("lb0", _I), ("lb1", _I), ("ld0", _I), ("ld1", _I),
    ]


_L = ctypes.c_long
#: the catenary's C file as Python binds it (`engines.native.bind`: ABI and `_Job` layout checked)
DECLARATION = native.Declaration(
    "models/catenary/native/catenary.c", "mbs_cat_abi", ABI,
    functions=tuple(native.CFunction(name, res, args) for name, res, args in (
        ("mbs_cat_factor", _I, (_P,)), ("mbs_cat_solve", None, (_P, _P)), ("mbs_cat_place", None, (_P, _I, _D)),
        ("mbs_cat_wire", _D, (_P, _I)), ("mbs_cat_predict", None, (_P, _D)), ("mbs_cat_local", _I, (_P,)),
        ("mbs_cat_advance", None, (_P,)), ("mbs_cat_check", _I, (_P,)), ("mbs_cat_run", _I, (_P, _L, _L, _I)),
        ("mbs_cat_record", None, (_P, _L, _D)), ("mbs_cat_dropper_ranges", None, (_P,)),
        ("mbs_cat_twomass_port", None, (_P, _P)), ("mbs_cat_twomass_size", _I, ()),
    )),
    structs=(native.CStruct(_Job, "mbs_cat_job_size"),),
)


def library() -> native.Binding:
    """The catenary's entry points on the native library (loaded once, thread-safe; ABI and `_Job` layout
    checked)."""
    return native.bind(DECLARATION)


def _ptr(a: np.ndarray | None) -> int | None:
    return None if a is None else a.ctypes.data


def _band_arrays(S, bw: int, node_offset: np.ndarray, free: np.ndarray) -> dict[str, np.ndarray]:
    """The arrays of the factorisation of the SPD step matrix `S` (sparse, on the free DOFs, half-bandwidth `bw`):
    its lower band and the storage of the factor's block form, node I's DOFs at `node_offset[I] ..
    node_offset[I+1] - 1` of the padded vector, `free` the padded index of each free DOF (per node of size s between
    nodes of sizes p and q: s^2 + s p + s^2 + s q doubles, `native/catenary.c`, build_blocks)."""
    S = S.tocsr()
    n = S.shape[0]
    L = np.zeros((n, bw + 1))
    for k in range(bw + 1):
        L[k:, k] = S.diagonal(-k)
    noff = np.asarray(node_offset, dtype=np.int64)
    s = np.diff(noff)
    sp = np.concatenate([[0], s[:-1]])
    sq = np.concatenate([s[1:], [0]])
    boff = np.concatenate([[0], np.cumsum(2 * s * s + s * (sp + sq))])
    if boff[-1] >= 2**31 or noff[-1] >= 2**31:
        raise SolverError(f"the catenary's padded DOF vector ({noff[-1]}) is too large for the native core")
    return {"L": L, "invd": np.zeros(n), "fidx": np.asarray(free).astype(np.int32), "noff": noff.astype(np.int32),
            "boff": boff.astype(np.int32), "blk": np.zeros(max(int(boff[-1]), 1)),
            "pw": np.zeros(max(int(noff[-1]), 1)), "seg": np.zeros(6 * max(s.size, 1), np.int32)}


class NativeFactor:
    """The core's factorisation of an SPD matrix `S` on its own (no passage): node I's DOFs at `node_offset[I] ..
    node_offset[I+1] - 1` of the padded vector, `free` the padded index of each row of S. `solve` runs the sweeps
    the core steps with (block form when `blocked`, else the band)."""

    def __init__(self, S, node_offset: np.ndarray, free: np.ndarray):
        lib = self.lib = library()
        S = S.tocsr()
        r, c = S.nonzero()
        j = self.job = _Job()
        j.n, j.nnode = S.shape[0], np.size(node_offset) - 1
        j.nblk = j.nnode
        j.bw = int(np.max(np.abs(r - c))) if r.size else 0
        self._arrays = _band_arrays(S, j.bw, node_offset, free)
        for name, arr in self._arrays.items():
            setattr(j, name, arr.ctypes.data)
        if lib.mbs_cat_factor(ctypes.byref(j)):
            raise SolverError(f"the matrix is not positive definite (native Cholesky, row {int(j.err_value)})")
        self.blocked = bool(j.blocked)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """x = S^-1 b."""
        x = np.ascontiguousarray(b, dtype=float).copy()
        self.lib.mbs_cat_solve(ctypes.byref(self.job), x.ctypes.data)
        return x


#: which sections (mechanical components) of a line the core steps: "in play" (from the step a contact point first
#: reaches one to the step every contact point has passed it; exact for the pantographs), "reached" (from the first
#: reach on: every record exact) or "all"
SECTIONS = ("in play", "reached", "all")


def section_ranges(fe) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per mechanical component of `fe` (`mesh.layout`, in DOF order): its block range, its free-DOF range (both
    [first, end)) and the x-range of its contact wires ([inf, -inf]: none)."""
    cb = np.asarray(fe.component_blocks, dtype=np.int64).reshape(-1, 2)
    start = np.asarray(fe.node_offset)[cb]  # full index of each range's ends
    cd = np.searchsorted(np.asarray(fe.free), start)
    cx = np.tile([np.inf, -np.inf], (cb.shape[0], 1))
    slots = np.asarray(fe.slot)
    for k, w in enumerate(fe.line.wires):
        if w.role != "contact":
            continue
        first = int(slots[k][slots[k] >= 0].min())  # the component's DOFs are contiguous: its range holds this one
        c = int(np.searchsorted(start[:, 0], first, side="right") - 1)
        cx[c] = (min(cx[c, 0], w.x0), max(cx[c, 1], w.x1))
    return cb, cd, cx


class NativeCore:
    """The C twin of a passage of `sim` with `ncon` pantograph heads (see the module docstring). Arrays are owned here
    (numpy) and the C job points into them; the state arrays (`u`, `q`, `p`, `f`, `head`, ...) are views the
    Python driver reads and writes between calls. Each head's pantograph is stepped through its one-port
    (`attach`).

    On a line of several contact wires (a route, `line.Line`) each head has one contact point per contact wire
    (`ncw`), contiguous: head k's are contacts k ncw .. k ncw + ncw - 1 (`contacts_of`), the first its owner (the
    one-port, the head height); a contact exists only while the head is on its wire's x-range. With one contact wire
    a contact is its head."""

    def __init__(self, sim, ncon: int, x_start: np.ndarray, x_end: np.ndarray, sections: str | None = None):
        sections = getattr(sim, "sections", "in play") if sections is None else sections
        if sections not in SECTIONS:
            raise SolverError(f"sections = {sections!r} is invalid; valid: {', '.join(map(repr, SECTIONS))}")
        lib = self.lib = library()
        fe, p = sim.fe, sim.fe.params
        ncw = self.ncw = fe.n_contact_wires
        self.nheads = int(ncon)
        self.sim_fe = fe
        n, nd, nc = fe.n, fe.T0.size, int(ncon) * ncw
        if nd and (np.min(fe.dropper_upper) < 0 or np.min(fe.dropper_lower) < 0):
            raise SolverError("a dropper hangs from a pinned DOF (fe.dropper_upper / dropper_lower hold -1)")
        self._keep: list[np.ndarray] = []
        K = sim.K.tocsr()
        K.sort_indices()
        arm = fe.arm_cw
        j = self.job = _Job()
        j.n, j.bw, j.nd, j.nsup, j.ncon, j.nnode = n, sim.lu.bandwidth, nd, arm.size, nc, fe.x.size
        j.nnz = K.nnz
        j.nblk = np.size(fe.node_offset) - 1
        cb, cd, cx = section_ranges(fe)
        j.ncomp = 0 if sections == "all" else cb.shape[0]
        j.retire = int(sections == "in play")
        j.slack, j.unilateral, j.max_iter = int(sim.slack), int(sim.unilateral), int(sim.max_active_iter)
        h = sim.h
        c_ab = h * sim.beta + h * h
        inv_1ha = 1.0 / (1 + h * sim.alpha)
        j.h, j.hh2, j.c_ab, j.inv_1ha = h, 0.5 * h, c_ab, inv_1ha
        j.c_kd, j.two_hh, j.kc = (c_ab - h * h) * inv_1ha, 2 * h * h, p.k_contact
        j.V, j.dt, j.max_disp = sim.V, sim.dt, sim.max_displacement
        irr = fe.irregularity
        j.nirr = 0 if irr is None else int(np.size(irr.r))
        j.irr_x0, j.irr_dx = (0.0, 1.0) if irr is None else (float(irr.x0), float(irr.dx))
        zg = np.ascontiguousarray(sim.Zg.T) if sim.slack else np.zeros((max(nd, 1), n))
        dd = np.ascontiguousarray(sim.D) if sim.slack else np.zeros((max(nd, 1), max(nd, 1)))
        m = nc + nd
        j.ncw = ncw
        pcs = fe.contacts or (fe.contact,)
        ranges = fe.contact_ranges or ((0, fe.x.size - 1),)
        esig, pq, pref, ptk, base = [], [], [], [], 0
        for pc, (i0, i1) in zip(pcs, ranges, strict=True):
            sig = np.zeros(fe.x.size - 1, np.int32)
            sig[i0:i1] = pc.sig + base
            esig.append(sig)
            pq.append(pc.Q.reshape(-1))
            pref.append(pc.ref.reshape(-1))
            ptk.append(np.full(pc.ref.shape[0], pc.T) if pc.Tk is None else np.asarray(pc.Tk, float))
            base += pc.ref.shape[0]
        wires = fe.line.contacts
        cwk = np.tile(np.arange(ncw), int(ncon))
        arrays = {
            **_band_arrays(sim.S, j.bw, fe.node_offset, fe.free),
            "Kp": K.indptr.astype(np.int32), "Ki": K.indices.astype(np.int32),
            "Kx": K.data.astype(float), "up": fe.dropper_upper.astype(np.int32),
            "lo": fe.dropper_lower.astype(np.int32), "dslack": np.asarray(sim.slackable, np.int32),
            "T0": fe.T0.astype(float), "kdj": np.asarray(sim.kd, float) if nd else np.zeros(1), "Zg": zg, "D": dd,
            "xnode": fe.x.astype(float),
            "cwdof": np.concatenate([fe.cw_dof_of(c).reshape(-1) for c in range(ncw)]).astype(np.int32),
            "w0cw": np.concatenate([fe.cw_w0_of(c).reshape(-1) for c in range(ncw)]).astype(float),
            "supidx": arm.astype(np.int32), "esig": np.concatenate(esig).astype(np.int32),
            "pq": np.concatenate(pq).astype(float), "pref": np.concatenate(pref).astype(float),
            "ptk": np.concatenate(ptk).astype(float), "cwEI": np.array([pc.EI for pc in pcs], dtype=float),
            "irr": np.zeros(1) if irr is None else np.asarray(irr.r, float).reshape(-1),
            "u": np.zeros(n), "q": np.zeros(n), "p": np.zeros(n), "R": np.zeros(n), "vbs": np.zeros(n),
            "vb": np.zeros(n), "slk": np.zeros(max(nd, 1), np.int32), "sS": np.zeros(max(nd, 1)),
            "present": np.zeros(nc, np.int32), "active": np.zeros(nc, np.int32), "elem": -np.ones(nc, np.int32),
            "xc": np.zeros(nc), "xs": np.repeat(np.asarray(x_start, float), ncw),
            "xend": np.repeat(np.asarray(x_end, float), ncw),
            "own": np.repeat(np.arange(int(ncon)) * ncw, ncw).astype(np.int32), "cwk": cwk.astype(np.int32),
            "erng": np.array([[ranges[c][0], ranges[c][1] - 1] for c in cwk], np.int32).reshape(-1),
            "xrng": np.array([[wires[c].x0, wires[c].x1] for c in cwk], float).reshape(-1),
            "onw": np.zeros(nc, np.int32),
            "Nl": np.zeros(4 * nc), "Nf": np.zeros(4 * nc), "dofs": np.zeros(4 * nc, np.int32), "w0d": np.zeros(4 * nc),
            "cols": np.zeros((nc, 4, n)), "crng": np.zeros(2 * nc, np.int32),
            "zrng": np.zeros(2 * max(nd, 1), np.int32), "f": np.zeros(nc), "kce": np.full(nc, float(p.k_contact)),
            "cbc": np.zeros(nc), "rirr": np.zeros(nc), "gv": np.zeros(4 * nc), "a": np.zeros(nc),
            "Cm": np.zeros(nc * nc), "bz": np.zeros(max(nc * nd, 1)), "dstar": np.zeros(max(nd, 1)),
            "P": np.zeros(nc), "gp": np.zeros(nc), "head": np.zeros(nc),
            "work": np.zeros(m * (m + 1) + m + 1), "iwork": np.zeros(2 * m + 2, np.int32),
            "ports": np.zeros(nc, np.uintp), "gs": np.full(nc, np.nan), "cw": np.zeros(4 * nc),
            "nl": np.zeros(nc, np.int32), "ooff": np.zeros(nc, np.int32),
            "cmpb": cb.astype(np.int32).reshape(-1), "cmpd": cd.astype(np.int32).reshape(-1),
            "cmpx": cx.astype(float).reshape(-1), "cmpt": np.full(max(cb.shape[0], 1), np.nan),
        }
        self.native_ports: list[Any] = [None] * nc
        self._bind(arrays)
        if lib.mbs_cat_factor(ctypes.byref(j)):
            raise SolverError(f"the step matrix is not positive definite (native Cholesky, row {int(j.err_value)})")
        if sim.slack:
            lib.mbs_cat_dropper_ranges(ctypes.byref(j))
        self.blocked = bool(j.blocked)

    def left_at(self) -> np.ndarray:
        """Per uplift point (`fe.arms`): the time (s) from which its section was no longer stepped, every pantograph
        having passed it (`CatenaryParams.step_sections` "in play"; inf: stepped to the end)."""
        fe = self.sim_fe
        d = fe.arm_cw
        cd = self.cmpd.reshape(-1, 2)
        out = np.full(d.size, np.inf)
        for c, t in enumerate(self.cmpt[:cd.shape[0]]):
            if np.isfinite(t):
                out[(d >= cd[c, 0]) & (d < cd[c, 1])] = t
        return out

    def contacts_of(self, head: int) -> range:
        """The contact indices of pantograph head `head` (one per contact wire; the first owns the head)."""
        return range(head * self.ncw, (head + 1) * self.ncw)

    def head_force(self, head: int) -> float:
        """The contact force on head `head`: its contacts' forces summed (N)."""
        ks = self.contacts_of(head)
        s = float(self.f[ks[0]])
        for k in ks[1:]:
            s += float(self.f[k])
        return s

    def _bind(self, arrays: dict[str, np.ndarray]) -> None:
        """Point the job's fields at `arrays` (kept here, contiguous) and expose each as an attribute."""
        for name, arr in arrays.items():
            arr = np.ascontiguousarray(arr)
            arrays[name] = arr
            setattr(self.job, name, arr.ctypes.data)
            setattr(self, name, arr)
        self._arrays = arrays

    # --- state exchange ---------------------------------------------------------------------------------------
    @property
    def nslack(self) -> int:
        """Number of slack droppers in the core's current slack set."""
        return int(self.job.nslack)

    def place(self, k: int, x: float) -> None:
        """Place contact k at position x (m): its element, Hermite shape functions N(x), the contact wire's
        point-load defect there (`cbc`) and the contact spring in series with it (`kce`); off its wire's x-range
        (or not present) it has none (`onw` 0)."""
        self.lib.mbs_cat_place(ctypes.byref(self.job), k, float(x))

    def wire(self, k: int) -> float:
        """Contact-wire height (m, from the undisturbed level) at contact k, from the current state (the nodes';
        without the defect's deflection under a force)."""
        return float(self.lib.mbs_cat_wire(ctypes.byref(self.job), k))

    def set_force(self, k: int, f: float) -> None:
        """Contact k pressing with f at its current place: f and its local force g = N f (for the next predict)."""
        self.f[k] = f
        self.gv[4 * k:4 * k + 4] = self.Nl[4 * k:4 * k + 4] * f

    def solve(self, b: np.ndarray) -> np.ndarray:
        """x = S^-1 b by the block-bidiagonal forward and back sweeps (S = M + hC + h^2 K)."""
        x = np.ascontiguousarray(b, dtype=float).copy()
        self.lib.mbs_cat_solve(ctypes.byref(self.job), x.ctypes.data)
        return x

    def attach(self, ports: list[Any]) -> int:
        """Couple each head's pantograph through its one-port: `ports[k]` a `NativePort` (`pantographs.py`) whose
        `.port` is a filled `mbs_port`, held by the head's owner contact; returns the width of a row of port outputs
        (each head's at its owner's offset)."""
        if len(ports) != self.nheads:
            raise SolverError(f"{len(ports)} one-ports for {self.nheads} pantographs")
        off = 0
        for h, np_ in enumerate(ports):
            k = h * self.ncw
            self.native_ports[k] = np_
            self.ports[k] = ctypes.addressof(np_.port)
            self.ooff[k] = off
            off += int(np_.port.nout)
        self.job.nout = off
        return off

    def set_records(self, **arrays: np.ndarray | None) -> None:
        """Record arrays (row = step): t, x, f, head, wire (nrec x ncon), out (nrec x the `attach` width: each
        pantograph's port outputs), up (nrec x nsup), ns (int32)."""
        for name, arr in arrays.items():
            if arr is not None:
                self._keep.append(arr)
            setattr(self.job, f"rec_{name}", _ptr(arr))

    # --- stages and the loop ----------------------------------------------------------------------------------
    def predict(self, t_new: float) -> None:
        """Predict stage: the banded solve for u* of the step ending at `t_new` (no local forces)."""
        self.lib.mbs_cat_predict(ctypes.byref(self.job), float(t_new))

    def local(self) -> None:
        """Local stage: contact forces and slack set by the active-set iteration (SolverError if it fails)."""
        if self.lib.mbs_cat_local(ctypes.byref(self.job)):
            raise SolverError(self._error_text(4, 0.0))

    def advance(self) -> None:
        """Advance stage: end-of-step displacement and momentum recursions with the local forces."""
        self.lib.mbs_cat_advance(ctypes.byref(self.job))

    def record(self, row: int, t: float) -> None:
        """Write the current state into record row `row` at time `t` (s)."""
        self.lib.mbs_cat_record(ctypes.byref(self.job), int(row), float(t))

    def check(self) -> int:
        """Finite-state and small-displacement check: 0, or an error code (`_error_text`)."""
        return int(self.lib.mbs_cat_check(ctypes.byref(self.job)))

    def run(self, n0: int, n1: int, check_every: int) -> int:
        """Steps n0+1 .. n1, every present pantograph through its one-port (`attach`); 0 or an error code
        (`failure`)."""
        return int(self.lib.mbs_cat_run(ctypes.byref(self.job), int(n0), int(n1), int(check_every)))

    def run_chunks(self, n0: int, n1: int, check_every: int, chunk: int, static_force: float,
                   progress: Callable[[int], None] | None = None) -> None:
        """`run` from step n0 to n1 in chunks of `chunk` steps, `progress(n)` after each; a failed step is a
        SolverError in the words of the Python path (`failure`)."""
        n = n0
        while n < n1:
            m = min(n + chunk, n1)
            code = self.run(n, m, check_every)
            if code:
                raise SolverError(self.failure(code, static_force))
            n = m
            if progress is not None:
                progress(n)

    @property
    def n_local(self) -> int:
        """Total number of local-problem iterations so far."""
        return int(self.job.n_local)

    def _error_text(self, code: int, t: float) -> str:
        return f"native catenary step failed (code {code}) at t = {t:.6f} s"

    def failure(self, code: int, static_force: float) -> str:
        """The message of a failed step (`run`, `check`), in the words of `passage.Passage._check`."""
        j = self.job
        k = max(int(j.err_con), 0)
        xp, yh = float(self.xc[k]), float(self.head[k])
        pan = k // self.ncw + 1  # the pantograph (head) of contact k
        if code == 4:
            t = float(j.err_value)
            return (f"contact/dropper active set did not settle in {int(j.max_iter)} iterations at t = {t:.6f} s "
                    f"(time step {float(j.dt)} s); reduce solver.timestep")
        if code == 1:
            return f"non-finite state at x = {xp:.2f} m"
        if code == 6:
            port = self.native_ports[k]
            return (f"pantograph {pan} failed at t = {float(j.err_value):.6f} s (x = {xp:.2f} m): "
                    + port.failure(int(j.err_port)))
        if code == 7:
            return (f"pantograph-catenary coupling did not converge at t = {float(j.err_value):.6f} s (time step "
                    f"{float(j.dt)} s); reduce solver.timestep")
        if code == 8:
            return f"pantograph {pan} is on the line without a one-port (internal error of the compiled loop)"
        if code == 3:
            return (f"the pantograph lost the wire and moved {yh:+.3g} m away from it (x = {xp:.2f} m; static "
                    f"contact force {static_force:.4g} N): it cannot hold the wire")
        return (f"catenary/pantograph displacement {abs(float(j.err_value)):.3g} m exceeds {float(j.max_disp):g} m "
                f"at x = {xp:.2f} m: outside the small-displacement model (speed too close to the wave speed, or a "
                "diverging pantograph)")


class TwoMassPort:
    """The 2-mass pantograph `panto` (`pantographs.TwoMassPantograph`) as the C file's one-port: its state and step
    constants at time step `dt` packed into `mbs_cat_twomass_size()` doubles (`TwoMassPantograph.pack`)."""

    names = ("head_displacement", "frame_displacement")

    def __init__(self, panto: Any, dt: float):
        from ...engines.native.oneport import Port

        lib = library()
        self.panto, self.dt = panto, dt
        self.state = np.zeros(int(lib.mbs_cat_twomass_size()))
        self.port = Port()
        lib.mbs_cat_twomass_port(ctypes.byref(self.port), self.state.ctypes.data)
        self.load()

    def load(self) -> None:
        """The pantograph's committed state into the port."""
        self.panto.pack(self.state, self.dt)

    def pull(self) -> None:
        """The port's committed state back into the pantograph."""
        self.panto.unpack(self.state)

    def signals(self, rows: np.ndarray) -> dict[str, np.ndarray]:
        """Recorded output rows (x1, x2) as the pantograph's signals."""
        return {k: rows[:, i].copy() for i, k in enumerate(self.names)}

    def failure(self, code: int) -> str:
        """The words of a failed trial (code `code` of the C step)."""
        return f"the 2-mass pantograph's step failed (code {code})"
