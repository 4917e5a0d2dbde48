"""Coupled time integration of the FE catenary and a moving pantograph.

Scheme: the trapezoidal rule (Newmark average acceleration, beta = 1/4, gamma = 1/2; unconditionally stable, second
order, no numerical damping) in its midpoint form. With h = dt/2 and the mean velocity vb = (v_n + v_{n+1})/2,

    S vb = q_n + h (g_n + g_{n+1}) / 2,      S = M + h C + h^2 K,      u_{n+1} = u_n + 2 h vb,
    q_n = M v_n - h K u_n   (kept by the recursions q_{n+1} = 2(M - h^2 K) vb - p_n, p_{n+1} = 2(M + h^2 K) vb - q_n)

so one step costs one banded solve (S is symmetric positive definite with half-bandwidth 5 in the node-by-node DOF
ordering: LAPACK banded Cholesky dpbtrf once, dpbtrs per step) and one sparse mat-vec. C = alpha M + beta K0
(Rayleigh on the wires and support springs; droppers are massless undamped springs). K = K0 + Kd holds the
droppers as linear springs; g are the local forces: the contact force f N(x) (Hermite shape functions at the
contact point) and, for slack droppers, a correction -s B_i that cancels the dropper's tension.

Consistency (no lag): with G = h^2 S^-1, the end-of-step displacement is affine in the unknown local forces,
u_{n+1} = u* + f G N - G B s, where u* comes from the single solve and G B (all droppers) is precomputed; G N is
combined from cached columns G e_j of the contact element's four CW DOFs (two new solves per element crossed). The
contact force f_{n+1} >= 0 (penalty k_c on the overlap, zero when separated) and the slack set of the droppers
(tension T0 + k delta >= 0, else zero) are solved exactly each step by an active-set (semi-smooth Newton) iteration on
this piecewise-linear problem; an affine pantograph enters through its exact affine head map, a nonlinear one through
a secant iteration on f_{n+1}.

Code: `CoupledSimulation` holds the method for a catenary, a pantograph, a speed and a time step (matrices, the
factorisation, cached influence columns, the local solver); `CoupledSimulation.start` gives a `Passage`, the state of
one passage with `step()` (predict with the banded solve, locate the contact point, couple the pantograph, advance the
momenta, check), in the spirit of scipy's `OdeSolver.step`; `CoupledSimulation.run` steps a passage to its end and
records it (`CoupledResult`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import lapack

from ...errors import SolverError
from .fe import CW_T, CW_W, NDOF_NODE, CatenaryFE
from .pantographs import Pantograph

#: displacement (m) beyond which the small-displacement catenary model is declared invalid (SolverError)
MAX_DISPLACEMENT = 1.0
#: steps between the plausibility checks of a passage (and the progress calls of `CoupledSimulation.run`)
CHECK_EVERY = 200


def steps_to_cover(distance: float, V: float, dt: float) -> int:
    """Steps of dt at speed V to cover `distance` (the last one may overshoot). A distance that is a whole number of
    steps in exact arithmetic (420 m at 250 km/h and 2e-4 s: 30240) is that number whatever its last bits: the count
    is taken to a relative 1e-8, so a 1e-12 change of V, dt or the positions cannot add a step."""
    r = distance / (V * dt)
    return int(math.ceil(r - 1e-8 * max(1.0, abs(r))))


#: the energy terms recorded with `record_energy` (`Passage.energy_terms`)
ENERGY_TERMS = ("catenary", "pantograph", "contact", "drive_power")


@dataclass
class CoupledResult:
    """Per-step records of a coupled run (SI units)."""

    t: np.ndarray
    x: np.ndarray  # pantograph position (m)
    force: np.ndarray  # unfiltered contact force (N)
    head: np.ndarray  # contact-point height of the pantograph (m, from the undisturbed CW level)
    wire: np.ndarray  # CW height at the contact point, static sag included (m)
    uplift: np.ndarray  # (n_steps, n_supports) CW displacement from static at every support (m)
    n_slack: np.ndarray  # number of slack droppers
    panto: dict[str, np.ndarray]
    support_x: np.ndarray
    stats: dict = field(default_factory=dict)
    dropper_elastic: np.ndarray | None = None  # (n, nd) T0 + k delta from the end-of-step state (diagnostics)
    dropper_slack: np.ndarray | None = None  # (n, nd) slack status of each dropper (diagnostics)
    energy: dict[str, np.ndarray] | None = None  # energy diagnostics (record_energy=True), see Passage.energy_terms


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

    `dropper_law`: "slack" (tension-only) or "linear" (bilateral). `contact`: "unilateral" or "bilateral"."""

    def __init__(self, fe: CatenaryFE, pantograph: Pantograph, speed: float, dt: float, dropper_law: str = "slack",
                 contact: str = "unilateral", max_active_iter: int = 100):
        if dropper_law not in ("slack", "linear"):
            raise SolverError(f"dropper_law must be 'slack' or 'linear', got {dropper_law!r}")
        if contact not in ("unilateral", "bilateral"):
            raise SolverError(f"contact must be 'unilateral' or 'bilateral', got {contact!r}")
        self.fe, self.panto, self.V, self.dt = fe, pantograph, float(speed), float(dt)
        self.slack = dropper_law == "slack"
        self.unilateral = contact == "unilateral"
        self.max_active_iter = max_active_iter
        p = fe.params
        h = self.h = dt / 2
        self.alpha, self.beta = p.rayleigh()
        self.K = (fe.K0 + fe.Kd).tocsr()
        S = self.S = ((1 + h * self.alpha) * fe.M + (h * self.beta + h * h) * fe.K0 + h * h * fe.Kd).tocsr()
        self.lu = BandedSPD(S)
        self.max_displacement = MAX_DISPLACEMENT
        self.mw, self.cw = fe.dropper_mw, fe.dropper_cw
        self.kd = p.k_dropper
        nd = fe.T0.size
        if self.slack:
            # G B with G = h^2 S^-1: response of u_{n+1} to unit slack corrections; D = B^T G B
            self.Zg = h * h * self.lu.solve(fe.B.toarray())
            self.D = self.Zg[self.mw] - self.Zg[self.cw]
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
            for j, d in enumerate(fe.cw_dofs_of_node(i)):
                if d >= 0:
                    rhs[d, j] = 1.0
            c = self.h * self.h * self.lu.solve(rhs)
            self._cols[i] = c
        return c

    def _element(self, e: int) -> tuple:
        """Cached data of CW element e: (x_left, length, free dofs (4, pinned -> 0), valid mask, static dofs (4),
        G columns (n, 4))."""
        d = self._elem.get(e)
        if d is None:
            fe = self.fe
            dofs = np.array(fe.cw_dofs_of_node(e) + fe.cw_dofs_of_node(e + 1))
            valid = dofs >= 0
            w0d = fe.w0_full[[NDOF_NODE * e + CW_W, NDOF_NODE * e + CW_T, NDOF_NODE * (e + 1) + CW_W,
                              NDOF_NODE * (e + 1) + CW_T]]
            cols = np.ascontiguousarray(np.hstack([self._node_cols(e), self._node_cols(e + 1)]))
            if len(self._elem) > 4:
                for k in sorted(self._elem)[:-2]:
                    del self._elem[k]
                for k in sorted(self._cols)[:-4]:
                    del self._cols[k]
            d = (float(fe.x[e]), float(fe.x[e + 1] - fe.x[e]), np.where(valid, dofs, 0), valid, w0d, cols)
            self._elem[e] = d
        return d

    @staticmethod
    def _shape(xi: float, he: float, valid: np.ndarray) -> np.ndarray:
        x2 = xi * xi
        x3 = x2 * xi
        N = np.array([1 - 3 * x2 + 2 * x3, he * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, he * (x3 - x2)])
        return np.where(valid, N, 0.0)

    # --- the local nonlinear problem of one step ---------------------------------------------------------------
    def _solve_local(self, P, gp, a, c, bz, dstar, active, S):
        """Contact force f and slack corrections s (on the set S) for the pantograph map y_h = P - gp f and the wire
        map y_w = a + c f - bz_S . s_S, dropper elongations delta = dstar + bz f - D[:, S] s_S.

        Returns f, S, s_S, active. Semi-smooth Newton (primal-dual active set) on the piecewise-linear conditions
        f = k_c max(y_h - y_w, 0) and T0 + k delta + s = 0 with s >= 0 on slack droppers."""
        kc, kd, T0 = self.fe.params.k_contact, self.kd, self.fe.T0
        if not S:  # fast path: no slack dropper
            f = kc * (P - a) / (1 + kc * (gp + c))
            if self.unilateral and f < 0:
                f, active = 0.0, False
            else:
                active = True
            if not self.slack or np.min(T0 + kd * (dstar + bz * f)) >= 0:
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
                        A[1:, 0] = kd * bz[S]
                    o = 1
                if m:
                    A[o:, o:] = np.eye(m) - kd * self.D[np.ix_(S, S)]
                    r[o:] = -T0[S] - kd * dstar[S]
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
                add = np.nonzero((tension < 0) & ~inS)[0]
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
        """Whether `run` can step this passage in the compiled core: an affine 2-mass pantograph, every step
        recorded, no dropper or energy diagnostics (those stay on the readable Python path)."""
        return (record_every == 1 and not record_droppers and not record_energy
                and hasattr(self.panto, "pack") and hasattr(self.panto, "unpack"))

    def run(self, x_start: float, x_end: float, progress=None, record_every: int = 1,
            record_droppers: bool = False, record_energy: bool = False, native: bool | None = None) -> CoupledResult:
        """Integrate the passage from x_start to x_end (`start`, then `Passage.step()` until it is finished),
        recording every `record_every` steps. `record_droppers` adds the droppers' elastic tensions and slack status;
        `record_energy` adds, at every recorded step, the energy terms of `Passage.energy_terms()`. `progress(n,
        nsteps)` is called every CHECK_EVERY steps and at the end. `native`: step in the compiled core
        (`native_core`, same scheme, equal to rounding); None = whenever `native_ok`, False = the Python path."""
        use_native = self.native_ok(record_every, record_droppers, record_energy) if native is None else native
        if use_native:
            if not self.native_ok(record_every, record_droppers, record_energy):
                raise SolverError("the native core steps an affine 2-mass pantograph and records every step without "
                                  "dropper/energy diagnostics; use native=False for this run")
            return self._run_native(x_start, x_end, progress)
        passage = self.start(x_start, x_end)
        rec = _Recorder(passage, record_every, record_droppers, record_energy)
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
        between chunks); records as `_Recorder`."""
        from .native_core import NativeCore

        passage = self.start(x_start, x_end)
        fe, panto = self.fe, self.panto
        core = NativeCore(self, 1, np.array([x_start]), np.array([x_end]))
        core.u[:], core.q[:], core.p[:] = passage.u, passage.q, passage.p
        core.present[0], core.active[0] = 1, int(passage.in_contact)
        core.place(0, x_start)
        core.set_force(0, passage.force)
        core.head[0] = passage.head
        panto.pack(core.pm[0:16], self.dt)
        nsteps = passage.nsteps
        nrec = nsteps + 1
        T, X, F, H, W, FR = (np.zeros(nrec) for _ in range(6))
        U = np.zeros((nrec, fe.supports.size))
        NS = np.zeros(nrec, dtype=np.int32)
        core.set_records(t=T, x=X, f=F, head=H, wire=W, frame=FR, up=U, ns=NS)
        core.record(0, 0.0)
        t0 = time.perf_counter()
        chunk = CHECK_EVERY * 25
        n = 0
        while n < nsteps:
            n1 = min(n + chunk, nsteps)
            code = core.run(n, n1, CHECK_EVERY)
            if code:
                raise SolverError(_native_error(core, code, passage.static_force))
            n = n1
            if progress is not None:
                progress(n, nsteps)
        wall = time.perf_counter() - t0
        panto.unpack(core.pm[0:16])
        return CoupledResult(t=T, x=X, force=F, head=H, wire=W, uplift=U, n_slack=NS,
                             panto={"head_displacement": H.copy(), "frame_displacement": FR},
                             support_x=fe.x[fe.supports],
                             stats={"steps": nsteps, "wall_time_loop_s": wall, "dofs": fe.n,
                                    "half_bandwidth": self.lu.bandwidth, "local_solves": core.n_local,
                                    "native": True})

    def _locate(self, xp: float, e: int) -> tuple[int, float]:
        x = self.fe.x
        last = x.size - 2
        while e < last and xp > x[e + 1]:
            e += 1
        while e > 0 and xp < x[e]:
            e -= 1
        return e, x[e]

    def _static_solve(self, rhs: np.ndarray) -> np.ndarray:
        from scipy.sparse.linalg import spsolve
        return spsolve(self.K.tocsc(), rhs)

    def _static_compliance(self, Nl: np.ndarray, dofs: np.ndarray) -> float:
        if not np.any(Nl != 0):
            return 0.0
        rhs = np.zeros(self.fe.n)
        np.add.at(rhs, dofs, Nl)
        return float(Nl @ self._static_solve(rhs)[dofs])

    def _mass(self) -> BandedSPD:
        """The factorised mass matrix (for velocities), built on first use."""
        if getattr(self, "_Mfac", None) is None:
            self._Mfac = BandedSPD(self.fe.M)
        return self._Mfac


def _native_error(core, code: int, static_force: float) -> str:
    """The message of a failed native step, in the words of `Passage._check`."""
    j = core.job
    k = max(int(j.err_con), 0)
    xp, yh = float(core.xc[k]), float(core.head[k])
    if code == 4:
        t = float(j.err_value)
        return (f"contact/dropper active set did not settle in {int(j.max_iter)} iterations at t = {t:.6f} s "
                f"(time step {float(j.dt)} s); reduce solver.timestep")
    if code == 1:
        return f"non-finite state at x = {xp:.2f} m"
    if code == 3:
        return (f"the pantograph lost the wire and moved {yh:+.3g} m away from it (x = {xp:.2f} m; static contact "
                f"force {static_force:.4g} N): it cannot hold the wire")
    return (f"catenary/pantograph displacement {abs(float(j.err_value)):.3g} m exceeds {float(j.max_disp):g} m at "
            f"x = {xp:.2f} m: outside the small-displacement model (speed too close to the wave speed, or a "
            "diverging pantograph)")


class Passage:
    """One passage of the pantograph under the catenary in progress, in the spirit of scipy's `OdeSolver`: the coupled
    state after `n` steps and `step()`, which advances it by one time step (module docstring).

    State: time `t` = n dt (s) of `nsteps`, pantograph position `x` (m), contact force `force` (N) and head height
    `head` (m) at the end of the last step, the catenary's displacement `u` from its static state and momenta `q`, `p`
    (q_n = M v_n - h K u_n and its partner recursion), the slack droppers `slack` with their tension-cancelling
    corrections `s_slack`, `in_contact`; `status` is "running" until x reaches x_end, then "finished".
    `static_force` is the coupled static contact force at the start; `n_local` counts the pantograph's trial steps."""

    def __init__(self, sim: CoupledSimulation, x_start: float, x_end: float):
        self.sim, self.panto = sim, sim.panto
        self.x_start, self.x_end = x_start, x_end
        self.nsteps = steps_to_cover(x_end - x_start, sim.V, sim.dt)
        self.n, self.t, self.x = 0, 0.0, x_start
        self.n_local = 0
        self._gp = None  # slope of a nonlinear pantograph's head map, kept between steps by the secant iteration
        h = sim.h
        # constants of the momentum recursions (module docstring)
        self._c_ab = h * sim.beta + h * h
        self._inv_1ha = 1.0 / (1 + h * sim.alpha)
        self._c_kd = (self._c_ab - h * h) * self._inv_1ha
        self._two_hh = 2 * h * h
        self._hh2 = 0.5 * h
        self._static(x_start)
        self.status = "running" if self.nsteps > 0 else "finished"

    # --- the start: coupled static equilibrium ----------------------------------------------------------------
    def _static(self, x_start: float) -> None:
        """Catenary and pantograph at rest, pressing on each other: the pantograph's static state on a spring of the
        contact stiffness in series with the wire's static compliance at x_start, the wire's static response to that
        force."""
        sim, panto = self.sim, self.panto
        fe, h = sim.fe, sim.h
        n = fe.n
        kc = fe.params.k_contact
        u = np.zeros(n)
        q = np.zeros(n)
        pv = np.zeros(n)
        e, _ = sim._locate(x_start, 0)
        self._set_contact_element(e, (x_start - fe.x[e]))
        Nl, dofs, valid = self.Nl, self._dofs, self._valid
        w0 = float(Nl @ self._w0d)
        c_static = sim._static_compliance(Nl, dofs)
        f = panto.static(w0, 1.0 / (1.0 / kc + c_static))
        if sim.unilateral and f < 0:
            f = panto.static(w0, 0.0)
        if f != 0.0 and c_static > 0:
            rhs = np.zeros(n)
            rhs[dofs[valid]] += (Nl * f)[valid]
            u = sim._static_solve(rhs)
            if sim.slack and np.any(fe.T0 + sim.kd * (u[sim.mw] - u[sim.cw]) < 0):
                raise SolverError(f"the static contact force at x_start = {x_start} m slackens a dropper; "
                                  "start at a support")
            q = -h * (sim.K @ u)
            pv = -q
        self.u, self.q, self.p = u, q, pv
        self.force = self.static_force = f
        self.in_contact = (f > 0) or not sim.unilateral
        self.slack: list[int] = []
        self.s_slack = np.zeros(0)
        self._g_dofs, self._g_vals = dofs[valid], (Nl * f)[valid]
        self.head = panto.head()

    def _set_contact_element(self, e: int, dx: float) -> None:
        """The contact point at distance dx into CW element e: its element data and shape functions."""
        x_e, he, dofs, valid, w0d, cols = self.sim._element(e)
        self.e, self._dofs, self._valid, self._w0d, self._cols = e, dofs, valid, w0d, cols
        self.Nl = self.sim._shape(dx / he, he, valid)

    # --- one step ---------------------------------------------------------------------------------------------
    def step(self) -> None:
        """Advance the coupled state by one time step dt (raises SolverError on a failure)."""
        if self.status != "running":
            raise RuntimeError(f"the passage is {self.status}; start a new one")
        sim = self.sim
        n = self.n + 1
        t_new = n * sim.dt
        xp = min(self.x_start + sim.V * t_new, self.x_end)
        R, vbs = self._predict()
        zc, a, c, bz, dstar = self._contact_point(xp, vbs)
        if sim.panto.affine and hasattr(self.panto, "affine_map"):
            f, S, sS, active, yh = self._couple_affine(t_new - sim.dt, a, c, bz, dstar)
        else:
            f, S, sS, active, yh = self._couple_secant(t_new - sim.dt, a, c, bz, dstar)
        self.panto.commit()
        self._advance(R, vbs, zc, f, S, sS)
        self.n, self.t, self.x, self.force, self.head = n, t_new, xp, f, yh
        self.slack, self.s_slack, self.in_contact = S, sS, active
        if n % CHECK_EVERY == 0 or n == self.nsteps:
            self._check()
        if n == self.nsteps:
            self.status = "finished"

    def _predict(self) -> tuple[np.ndarray, np.ndarray]:
        """R = q_n + h/2 g_n and the mean velocity vb* = S^-1 R of the step without the new local forces (g_{n+1} =
        0): the single banded solve of the step."""
        sim, S, sS = self.sim, self.slack, self.s_slack
        hh2 = self._hh2
        R = self.q.copy()
        R[self._g_dofs] += hh2 * self._g_vals
        if S:
            R[sim.mw[S]] -= hh2 * sS
            R[sim.cw[S]] += hh2 * sS
        return R, sim.lu.solve(R)

    def _contact_point(self, xp: float, vbs: np.ndarray) -> tuple:
        """The contact point at xp at the end of the step: G N (zc), the wire's height without new local forces (a)
        and its compliance (c) there, and for slack droppers their elongations (dstar) and the contact force's
        influence on them (bz)."""
        sim, u, h2 = self.sim, self.u, 2 * self.sim.h
        e, _ = sim._locate(xp, self.e)
        self._set_contact_element(e, xp - sim.fe.x[e])
        Nl, dofs = self.Nl, self._dofs
        zc = self._cols @ Nl  # G N
        c = float(Nl @ zc[dofs])
        a = float(Nl @ (u[dofs] + h2 * vbs[dofs])) + float(Nl @ self._w0d)
        if sim.slack:
            mw, cw = sim.mw, sim.cw
            bz = zc[mw] - zc[cw]
            dstar = (u[mw] - u[cw]) + h2 * (vbs[mw] - vbs[cw])
        else:
            bz = dstar = None
        return zc, a, c, bz, dstar

    def _couple_affine(self, t: float, a: float, c: float, bz, dstar) -> tuple:
        """An affine pantograph: its exact head map P - g f1 into the local problem, one trial to advance it."""
        sim, panto, f_prev = self.sim, self.panto, self.force
        P, gp = panto.affine_map(sim.dt, f_prev)
        f, S, sS, active = sim._solve_local(P, gp, a, c, bz, dstar, self.in_contact, self.slack)
        yh = panto.trial(t, sim.dt, f_prev, f)
        self.n_local += 1
        return f, S, sS, active, yh

    def _couple_secant(self, t: float, a: float, c: float, bz, dstar) -> tuple:
        """A nonlinear pantograph: secant iteration on f_{n+1} between its head map and the local problem; the slope
        of the head map is kept between steps."""
        sim, panto, f_prev, dt = self.sim, self.panto, self.force, self.sim.dt
        active, S = self.in_contact, self.slack
        y0 = panto.trial(t, dt, f_prev, f_prev)
        self.n_local += 1
        if self._gp is None:
            self._gp = y0 - panto.trial(t, dt, f_prev, f_prev + 1.0)
        gp = self._gp
        P = y0 + gp * f_prev
        fa, ya = f_prev, y0
        for _it in range(30):
            f, S, sS, active = sim._solve_local(P, gp, a, c, bz, dstar, active, S)
            if f == fa:
                yh = ya
                panto.trial(t, dt, f_prev, f)
                break
            yh = panto.trial(t, dt, f_prev, f)
            self.n_local += 1
            err = yh - (P - gp * f)
            if abs(err) < 1e-13 + 1e-11 * abs(yh):
                break
            if abs(f - fa) > 1e-9:
                g_new = (ya - yh) / (f - fa)
                if g_new > 0:
                    gp = self._gp = g_new
            P = yh + gp * f
            fa, ya = f, yh
        else:
            raise SolverError(f"pantograph-catenary coupling did not converge at t = {(self.n + 1) * dt:.6f} s")
        return f, S, sS, active, yh

    def _advance(self, R: np.ndarray, vbs: np.ndarray, zc: np.ndarray, f: float, S: list[int],
                 sS: np.ndarray) -> None:
        """End-of-step state: vb = vb* + (f G N - G B_S s_S) / (2h), u_{n+1} = u_n + 2h vb, and the momentum
        recursions with the full R (g_{n+1} included)."""
        sim, h, hh2 = self.sim, self.sim.h, self._hh2
        mw, cw = sim.mw, sim.cw
        if S:
            vb = vbs + (zc * f - sim.Zg[:, S] @ sS) * (1.0 / (2 * h))
        else:
            vb = vbs + zc * (f / (2 * h))
        self.u += (2 * h) * vb
        valid = self._valid
        self._g_dofs, self._g_vals = self._dofs[valid], (self.Nl * f)[valid]
        R[self._g_dofs] += hh2 * self._g_vals
        if S:
            R[mw[S]] -= hh2 * sS
            R[cw[S]] += hh2 * sS
        Kvb = sim.K @ vb
        Mvb = (R - self._c_ab * Kvb) * self._inv_1ha
        dv = (sim.kd * self._c_kd) * (vb[mw] - vb[cw])
        Mvb[mw] += dv
        Mvb[cw] -= dv
        A2 = 2 * Mvb
        B2 = self._two_hh * Kvb
        q_new = A2 - B2 - self.p
        self.p = A2 + B2 - self.q
        self.q = q_new

    def _check(self) -> None:
        """Finite state, the pantograph still near the wire, displacements inside the small-displacement model."""
        lim = self.sim.max_displacement
        umax = float(np.max(np.abs(self.u)))
        f, yh, t, xp = self.force, self.head, self.t, self.x
        if not (math.isfinite(umax) and math.isfinite(f) and math.isfinite(yh)):
            raise SolverError(f"non-finite state at t = {t:.4f} s (x = {xp:.2f} m)")
        if abs(yh) > lim and f == 0.0:
            raise SolverError(
                f"the pantograph lost the wire and moved {yh:+.3g} m away from it at t = {t:.4f} s "
                f"(x = {xp:.2f} m; static contact force {self.static_force:.4g} N): it cannot hold the wire")
        if umax > lim or abs(yh) > lim:
            raise SolverError(
                f"catenary/pantograph displacement {max(umax, abs(yh)):.3g} m exceeds {lim} m at "
                f"t = {t:.4f} s (x = {xp:.2f} m): outside the small-displacement model (speed too close "
                "to the wave speed, or a diverging pantograph)")

    # --- what the state shows ---------------------------------------------------------------------------------
    def wire_height(self) -> float:
        """CW height at the contact point, static sag included (m)."""
        Nl = self.Nl
        return float(Nl @ self._w0d) + float(Nl @ self.u[self._dofs])

    def dropper_tension(self) -> np.ndarray:
        """Elastic dropper tensions T0 + k delta (N); negative on a slack dropper."""
        sim = self.sim
        return sim.fe.T0 + sim.kd * (self.u[sim.mw] - self.u[sim.cw])

    def velocity(self) -> np.ndarray:
        """Catenary velocity, from M v = (q + p) / 2."""
        return self.sim._mass().solve(0.5 * (self.q + self.p))

    def energy_terms(self) -> dict[str, float]:
        """The catenary energy relative to the static state (kinetic + wires + support springs + droppers with their
        exact law), the pantograph's energy (if it offers `energy()`, else NaN), the contact spring energy and the
        power -f V dw/dx that the imposed horizontal motion feeds in through the sloping wire (its time integral
        closes the balance of an undamped system)."""
        sim, fe, u, f = self.sim, self.sim.fe, self.u, self.force
        v = self.velocity()
        delta = u[sim.mw] - u[sim.cw]
        kd, T0 = sim.kd, fe.T0
        if sim.slack:  # potential of T(delta) = max(T0 + k delta, 0) relative to delta = 0
            dmin = -T0 / kd
            Vd = np.where(delta >= dmin, T0 * delta + 0.5 * kd * delta**2, -0.5 * T0**2 / kd)
        else:
            Vd = T0 * delta + 0.5 * kd * delta**2
        # T0 delta terms cancel against the gravity/static reactions' work: the static state is an equilibrium, so
        # only the part beyond the linear one is stored energy; keep it consistent with K0 (wires + supports)
        E_c = 0.5 * v @ (fe.M @ v) + 0.5 * u @ (fe.K0 @ u) + float(np.sum(Vd - T0 * delta))
        en = getattr(self.panto, "energy", None)
        x_e, he, dofs, valid, w0d, cols = sim._element(self.e)
        xi = (self.x - x_e) / he
        dN = np.array([(-6 * xi + 6 * xi * xi) / he, 1 - 4 * xi + 3 * xi * xi, (6 * xi - 6 * xi * xi) / he,
                       3 * xi * xi - 2 * xi])
        dN = np.where(valid, dN, 0.0)
        slope = float(dN @ (u[dofs] + w0d))
        return {"catenary": E_c, "pantograph": en() if en is not None else np.nan,
                "contact": f * f / (2 * fe.params.k_contact), "drive_power": -f * sim.V * slope}


class _Recorder:
    """The per-step records of a passage (CoupledResult), one row per recorded step from the start."""

    def __init__(self, passage: Passage, every: int, droppers: bool, energy: bool):
        sim = passage.sim
        fe = sim.fe
        nrec = passage.nsteps // every + 1
        sup_dofs = fe.full_to_free[NDOF_NODE * fe.supports + CW_W]
        self.sup_sel = np.nonzero(sup_dofs >= 0)[0]
        self.sup_idx = sup_dofs[self.sup_sel]
        self.fe = fe
        self.T, self.X, self.F, self.H, self.W = (np.empty(nrec) for _ in range(5))
        self.U = np.zeros((nrec, fe.supports.size))
        self.NS = np.zeros(nrec, dtype=np.int32)
        self.psig = {k: np.empty(nrec) for k in passage.panto.signals()}
        nd = fe.T0.size
        self.DE = np.zeros((nrec, nd)) if droppers else None
        self.DS = np.zeros((nrec, nd), bool) if droppers else None
        self.EN = {k: np.zeros(nrec) for k in ENERGY_TERMS} if energy else None
        self.rows = 0
        self.record(passage)

    def record(self, ps: Passage) -> None:
        r = self.rows
        self.T[r], self.X[r], self.F[r], self.H[r] = ps.t, ps.x, ps.force, ps.head
        self.W[r] = ps.wire_height()
        self.U[r, self.sup_sel] = ps.u[self.sup_idx]
        self.NS[r] = len(ps.slack)
        if self.DE is not None:
            self.DE[r] = ps.dropper_tension()
            self.DS[r, ps.slack] = True
        if self.EN is not None:
            for k, v in ps.energy_terms().items():
                self.EN[k][r] = v
        for k, v in ps.panto.signals().items():
            self.psig[k][r] = v
        self.rows += 1

    def result(self, stats: dict) -> CoupledResult:
        sl = slice(0, self.rows)
        return CoupledResult(t=self.T[sl], x=self.X[sl], force=self.F[sl], head=self.H[sl], wire=self.W[sl],
                             uplift=self.U[sl], n_slack=self.NS[sl], panto={k: v[sl] for k, v in self.psig.items()},
                             support_x=self.fe.x[self.fe.supports], stats=stats,
                             energy=None if self.EN is None else {k: v[sl] for k, v in self.EN.items()},
                             dropper_elastic=None if self.DE is None else self.DE[sl],
                             dropper_slack=None if self.DS is None else self.DS[sl])
