"""Coupled time integration of the FE catenary and a moving pantograph.

Scheme: the trapezoidal rule (Newmark average acceleration, beta = 1/4, gamma = 1/2; unconditionally stable, second
order, no numerical damping) in its midpoint form. With h = dt/2 and the mean velocity vb = (v_n + v_{n+1})/2,

    S vb = q_n + h (g_n + g_{n+1}) / 2,      S = M + h C + h^2 K,      u_{n+1} = u_n + 2 h vb,
    q_n = M v_n - h K u_n   (kept by the recursions q_{n+1} = 2(M - h^2 K) vb - p_n, p_{n+1} = 2(M + h^2 K) vb - q_n)

so one step costs one banded solve (S is symmetric positive definite and narrow-banded in the node-by-node DOF
ordering, `fe.node_offset`: half-bandwidth 5 on the simple line, 7 on the stitched and compound lines; LAPACK banded
Cholesky dpbtrf once, dpbtrs per step) and one sparse mat-vec. C = alpha M + beta K0
(Rayleigh on the wires and support springs; droppers are massless undamped springs). K = K0 + Kd holds the
droppers as linear springs; g are the local forces: the contact force f N(x) (Hermite shape functions at the
contact point) and, for slack droppers, a correction -s B_i that cancels the dropper's tension. Every point spring
carries its wires' point-load defect in series (`fe.PointCorrection`): the droppers and support springs in K, the
contact spring through its effective stiffness k_c,eff = 1 / (1/k_c + d(x)) at the contact point x.

Consistency (no lag): with G = h^2 S^-1, the end-of-step displacement is affine in the unknown local forces,
u_{n+1} = u* + f G N - G B s, where u* comes from the single solve and G B (all droppers) is precomputed; G N is
combined from cached columns G e_j of the contact element's four CW DOFs (two new solves per element crossed). The
contact force f_{n+1} >= 0 (penalty k_c on the overlap, zero when separated) and the slack set of the droppers
(tension T0 + k delta >= 0, else zero) are solved exactly each step by an active-set (semi-smooth Newton) iteration on
this piecewise-linear problem; an affine pantograph enters through its exact affine head map, a nonlinear one through
a secant iteration on f_{n+1}.

Code: `CoupledSimulation` (here) holds the method for a catenary, a pantograph, a speed and a time step (matrices, the
factorisation, cached influence columns, the local solver); `CoupledSimulation.start` gives a `passage.Passage`, the
state of one passage with `step()` (in the spirit of scipy's `OdeSolver.step`); `CoupledSimulation.run` steps a passage
to its end on the Python path or in the compiled core (`native_core.py`) and records it (`CoupledResult`). Several
pantographs on one train: `train.py`.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.linalg import lapack

from ...errors import SolverError
from .fe import CatenaryFE
from .native_core import NativeCore
from .pantographs import Pantograph
from .passage import CHECK_EVERY, CoupledResult, Passage, Recorder

#: displacement (m) beyond which the small-displacement catenary model is declared invalid (SolverError)
MAX_DISPLACEMENT = 1.0


class BandedSPD:
    """Banded Cholesky factorisation of a sparse SPD matrix (LAPACK dpbtrf), reused for every solve (dpbtrs)."""

    def __init__(self, A):
        A = A.tocsr()
        r, c = A.nonzero()
        bw = int(np.max(np.abs(r - c))) if r.size else 0
        n = A.shape[0]
        ab = np.zeros((bw + 1, n))
        for k in range(bw + 1):
            ab[bw - k, k:] = A.diagonal(k)
        self.c, info = lapack.dpbtrf(ab, lower=0)
        if info != 0:
            raise SolverError(f"the step matrix is not positive definite (dpbtrf info = {info})")
        self.bandwidth = bw

    def solve(self, b: np.ndarray) -> np.ndarray:
        """x = S^-1 b with the stored banded Cholesky factor (LAPACK dpbtrs)."""
        x, info = lapack.dpbtrs(self.c, b, lower=0)
        if info != 0:
            raise SolverError(f"banded solve failed (dpbtrs info = {info})")
        return x


class CoupledSimulation:
    """Catenary `fe` + `pantograph` moving at `speed` (m/s) with time step `dt` (s): the method (step matrix and its
    factorisation, influence columns, the local contact/dropper solver). `start` gives a `Passage` to step; `run`
    steps one to its end and records it.

    `dropper_law`: the scene's `droppers` effect, "slack" (tension-only) or "linear" (bilateral), for the droppers
    without a law of their own (`fe.slack_mask`). `contact`: "unilateral" or "bilateral"."""

    def __init__(self, fe: CatenaryFE, pantograph: Pantograph, speed: float, dt: float, dropper_law: str = "slack",
                 contact: str = "unilateral", max_active_iter: int = 100):
        if dropper_law not in ("slack", "linear"):
            raise SolverError(f"dropper_law must be 'slack' or 'linear', got {dropper_law!r}")
        if contact not in ("unilateral", "bilateral"):
            raise SolverError(f"contact must be 'unilateral' or 'bilateral', got {contact!r}")
        self.fe, self.panto, self.V, self.dt = fe, pantograph, float(speed), float(dt)
        #: the sections of a route the compiled core steps (`CatenaryParams.step_sections`; one section: all of it)
        self.sections = fe.params.step_sections
        #: per dropper: tension-only (may go slack; `fe.slack_mask`); `slack`: any of them is
        self.slackable = np.asarray(fe.slack_mask(dropper_law), dtype=bool)
        self.slack = bool(np.any(self.slackable))
        self.unilateral = contact == "unilateral"
        self.max_active_iter = max_active_iter
        p = fe.params
        h = self.h = dt / 2
        self.alpha, self.beta = p.rayleigh()
        self.K = (fe.K0 + fe.Kd).tocsr()
        S = self.S = ((1 + h * self.alpha) * fe.M + (h * self.beta + h * h) * fe.K0 + h * h * fe.Kd).tocsr()
        self.lu = BandedSPD(S)
        self.max_displacement = MAX_DISPLACEMENT
        self.up, self.lo = fe.dropper_upper, fe.dropper_lower  # free index of each dropper's upper / lower w DOF
        self.cw_dof, self.cw_w0 = fe.cw_dof, fe.cw_w0  # the contact wire's free DOFs and static state per node
        self.kd = fe.k_drop  # per dropper (the wires' point-load defects in series)
        nd = fe.T0.size
        if self.slack:
            # G B with G = h^2 S^-1: response of u_{n+1} to unit slack corrections; D = B^T G B
            self.Zg = h * h * self.lu.solve(fe.B.toarray())
            self.D = self.Zg[self.up] - self.Zg[self.lo]
        else:
            self.Zg = np.zeros((fe.n, 0))
            self.D = np.zeros((0, 0))
        self._nd = nd if self.slack else 0
        self._cols: dict[int, np.ndarray] = {}
        self._elem: dict[int, tuple] = {}

    # --- contact geometry ------------------------------------------------------------------------------------------
    def _node_cols(self, i: int) -> np.ndarray:
        """G e_w, G e_theta for the CW DOFs of node i, shape (n, 2) (zero column for a pinned DOF)."""
        c = self._cols.get(i)
        if c is None:
            fe = self.fe
            rhs = np.zeros((fe.n, 2))
            for j, d in enumerate(self.cw_dof[i]):
                if d >= 0:
                    rhs[d, j] = 1.0
            c = self.h * self.h * self.lu.solve(rhs)
            self._cols[i] = c
        return c

    def element(self, e: int) -> tuple:
        """Cached data of CW element e: (x_left, length, free dofs (4, pinned -> 0), valid mask, static dofs (4),
        G columns (n, 4))."""
        d = self._elem.get(e)
        if d is None:
            fe = self.fe
            dofs = np.concatenate([self.cw_dof[e], self.cw_dof[e + 1]]).astype(int)
            valid = dofs >= 0
            w0d = np.concatenate([self.cw_w0[e], self.cw_w0[e + 1]]).astype(float)
            cols = np.ascontiguousarray(np.hstack([self._node_cols(e), self._node_cols(e + 1)]))
            if len(self._elem) > 4:
                for k in sorted(self._elem)[:-2]:
                    del self._elem[k]
                for k in sorted(self._cols)[:-4]:
                    del self._cols[k]
            d = (float(fe.x[e]), float(fe.x[e + 1] - fe.x[e]), np.where(valid, dofs, 0), valid, w0d, cols)
            self._elem[e] = d
        return d

    def contact_stiffness(self, e: int, xi: float) -> tuple[float, float]:
        """The contact wire's point-load defect d (m/N) at local coordinate xi of element e and the contact spring in
        series with it, k_c,eff = 1 / (1/k_c + d) (k_c itself where d = 0)."""
        d = self.fe.contact_defect(e, xi)
        kc = self.fe.params.k_contact
        return d, (kc / (1.0 + kc * d) if d != 0.0 else kc)

    @staticmethod
    def shape(xi: float, he: float, valid: np.ndarray) -> np.ndarray:
        """Hermite shape functions of a beam element at local coordinate `xi` (length `he`); 0 where not `valid`."""
        x2 = xi * xi
        x3 = x2 * xi
        N = np.array([1 - 3 * x2 + 2 * x3, he * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, he * (x3 - x2)])
        return np.where(valid, N, 0.0)

    # --- the local nonlinear problem of one step ---------------------------------------------------------------
    def solve_local(self, P, gp, a, c, bz, dstar, active, S, kc):
        """Contact force f and slack corrections s (on the set S) for the pantograph map y_h = P - gp f and the wire
        map y_w = a + c f - bz_S . s_S, dropper elongations delta = dstar + bz f - D[:, S] s_S, contact stiffness kc
        (the effective one at the contact point, `contact_stiffness`).

        Returns f, S, s_S, active. Semi-smooth Newton (primal-dual active set) on the piecewise-linear conditions
        f = k_c max(y_h - y_w, 0) and T0 + k delta + s = 0 with s >= 0 on slack droppers (only the tension-only
        ones, `slackable`, enter the slack set)."""
        kd, T0, slackable = self.kd, self.fe.T0, self.slackable
        if not S:  # fast path: no slack dropper
            f = kc * (P - a) / (1 + kc * (gp + c))
            if self.unilateral and f < 0:
                f, active = 0.0, False
            else:
                active = True
            if not self.slack or not np.any((T0 + kd * (dstar + bz * f) < 0) & slackable):
                return f, S, np.zeros(0), active
        for _ in range(self.max_active_iter):
            m = len(S)
            n_un = m + (1 if active else 0)
            if n_un:
                A = np.zeros((n_un, n_un))
                r = np.zeros(n_un)
                o = 0
                if active:
                    A[0, 0] = 1 + kc * (gp + c)
                    r[0] = kc * (P - a)
                    if m:
                        A[0, 1:] = -kc * bz[S]
                        A[1:, 0] = kd[S] * bz[S]
                    o = 1
                if m:
                    A[o:, o:] = np.eye(m) - kd[S][:, None] * self.D[np.ix_(S, S)]
                    r[o:] = -T0[S] - kd[S] * dstar[S]
                sol = np.linalg.solve(A, r)
                f = float(sol[0]) if active else 0.0
                sS = sol[o:]
            else:
                f, sS = 0.0, np.zeros(0)
            changed = False
            if self.unilateral:
                if active and f < 0:
                    active, changed = False, True
                elif not active:
                    gap = P - a + (float(bz[S] @ sS) if m else 0.0)
                    if gap > 0:
                        active, changed = True, True
            if self.slack:
                delta = dstar + bz * f
                if m:
                    delta = delta - self.D[:, S] @ sS
                tension = T0 + kd * delta
                inS = np.zeros(T0.size, bool)
                inS[S] = True
                add = np.nonzero((tension < 0) & ~inS & slackable)[0]
                drop = [i for j, i in enumerate(S) if sS[j] < 0]
                if add.size or drop:
                    S = sorted((set(S) - set(drop)) | {int(i) for i in add})
                    changed = True
            if not changed:
                return f, S, sS, active
        raise SolverError(f"contact/dropper active set did not settle in {self.max_active_iter} iterations "
                          f"(time step {self.dt} s); reduce solver.timestep")

    # --- passages ------------------------------------------------------------------------------------------------
    def start(self, x_start: float, x_end: float) -> Passage:
        """A passage from x_start to x_end, at its coupled static equilibrium, ready to `step()`."""
        return Passage(self, x_start, x_end)

    def native_ok(self, record_every: int = 1, record_droppers: bool = False, record_energy: bool = False) -> bool:
        """Whether `run` can step this passage in the compiled core: a pantograph with a one-port (`native`), every
        step recorded, no dropper or energy diagnostics (those stay on the readable Python path)."""
        return record_every == 1 and not record_droppers and not record_energy and hasattr(self.panto, "native")

    def run(self, x_start: float, x_end: float, progress=None, record_every: int = 1,
            record_droppers: bool = False, record_energy: bool = False, native: bool | None = None) -> CoupledResult:
        """Integrate the passage from x_start to x_end (`start`, then `Passage.step()` until it is finished),
        recording every `record_every` steps. `record_droppers` adds the droppers' elastic tensions and slack status;
        `record_energy` adds, at every recorded step, the energy terms of `Passage.energy_terms()`. `progress(n,
        nsteps)` is called every CHECK_EVERY steps and at the end. `native`: step in the compiled core
        (`native_core`, same scheme, equal to rounding); None = whenever `native_ok`, False = the Python path."""
        if self.fe.n_contact_wires > 1:
            raise SolverError(f"line {self.fe.line.name!r} has {self.fe.n_contact_wires} contact wires (a route): its "
                              "passages run through train.run_passage (a head on several contact wires)")
        use_native = self.native_ok(record_every, record_droppers, record_energy) if native is None else native
        if use_native:
            if not self.native_ok(record_every, record_droppers, record_energy):
                raise SolverError("the native core steps a pantograph with a one-port (`native`) and records every "
                                  "step without dropper/energy diagnostics; use native=False for this run")
            return self._run_native(x_start, x_end, progress)
        passage = self.start(x_start, x_end)
        rec = Recorder(passage, record_every, record_droppers, record_energy)
        t0 = time.perf_counter()
        while passage.status == "running":
            passage.step()
            if passage.n % record_every == 0:
                rec.record(passage)
            if progress is not None and (passage.n % CHECK_EVERY == 0 or passage.status == "finished"):
                progress(passage.n, passage.nsteps)
        wall = time.perf_counter() - t0
        return rec.result({"steps": passage.nsteps, "wall_time_loop_s": wall, "dofs": self.fe.n,
                           "half_bandwidth": self.lu.bandwidth, "local_solves": passage.n_local})

    def _run_native(self, x_start: float, x_end: float, progress=None) -> CoupledResult:
        """`run` in the compiled core: the static start from `start` (Python), then C steps in chunks (progress
        between chunks); records as `Recorder`."""
        passage = self.start(x_start, x_end)
        fe, panto = self.fe, self.panto
        core = NativeCore(self, 1, np.array([x_start]), np.array([x_end]))
        core.u[:], core.q[:], core.p[:] = passage.u, passage.q, passage.p
        core.present[0], core.active[0] = 1, int(passage.in_contact)
        core.place(0, x_start)
        core.set_force(0, passage.force)
        core.head[0] = passage.head
        port = panto.native(self.dt)
        nsteps = passage.nsteps
        nrec = nsteps + 1
        T, X, F, H, W = (np.zeros(nrec) for _ in range(5))
        OUT = np.zeros((nrec, core.attach([port])))
        U = np.zeros((nrec, fe.arm_cw.size))
        NS = np.zeros(nrec, dtype=np.int32)
        core.set_records(t=T, x=X, f=F, head=H, wire=W, out=OUT, up=U, ns=NS)
        core.record(0, 0.0)
        t0 = time.perf_counter()
        core.run_chunks(0, nsteps, CHECK_EVERY, CHECK_EVERY * 25, passage.static_force,
                        None if progress is None else lambda n: progress(n, nsteps))
        wall = time.perf_counter() - t0
        port.pull()
        return CoupledResult(t=T, x=X, force=F, head=H, wire=W, uplift=U, n_slack=NS, panto=port.signals(OUT),
                             support_x=fe.arm_x,
                             stats={"steps": nsteps, "wall_time_loop_s": wall, "dofs": fe.n,
                                    "half_bandwidth": self.lu.bandwidth, "local_solves": core.n_local,
                                    "native": True})

    def locate(self, xp: float, e: int) -> tuple[int, float]:
        """The element holding position `xp` (searched from element `e`) and the position of its left node."""
        x = self.fe.x
        last = x.size - 2
        while e < last and xp > x[e + 1]:
            e += 1
        while e > 0 and xp < x[e]:
            e -= 1
        return e, x[e]

    def static_solve(self, rhs: np.ndarray) -> np.ndarray:
        """The static displacement K^-1 rhs of the catenary."""
        from scipy.sparse.linalg import spsolve
        return spsolve(self.K.tocsc(), rhs)

    def static_compliance(self, Nl: np.ndarray, dofs: np.ndarray) -> float:
        """The static compliance at a point load with shape values `Nl` on `dofs` (m/N)."""
        if not np.any(Nl != 0):
            return 0.0
        rhs = np.zeros(self.fe.n)
        np.add.at(rhs, dofs, Nl)
        return float(Nl @ self.static_solve(rhs)[dofs])

    def mass(self) -> BandedSPD:
        """The factorised mass matrix (for velocities), built on first use."""
        if getattr(self, "_Mfac", None) is None:
            self._Mfac = BandedSPD(self.fe.M)
        return self._Mfac
