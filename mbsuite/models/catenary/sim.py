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
    energy: dict[str, np.ndarray] | None = None  # energy diagnostics (record_energy=True), see CoupledSimulation.run


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
        x, info = lapack.dpbtrs(self.c, b, lower=0)
        if info != 0:
            raise SolverError(f"banded solve failed (dpbtrs info = {info})")
        return x


class CoupledSimulation:
    """Catenary `fe` + `pantograph` moving at `speed` (m/s) with time step `dt` (s).

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
        S = (1 + h * self.alpha) * fe.M + (h * self.beta + h * h) * fe.K0 + h * h * fe.Kd
        self.lu = BandedSPD(S)
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

    # --- run -------------------------------------------------------------------------------------------------
    def run(self, x_start: float, x_end: float, progress=None, record_every: int = 1,
            record_droppers: bool = False, record_energy: bool = False) -> CoupledResult:
        """Integrate the passage from x_start to x_end. `record_energy` adds, at every recorded step, the catenary
        energy relative to the static state (kinetic + wires + support springs + droppers with their exact law),
        the pantograph's energy (if it offers `energy()`), the contact spring energy and the power -f V dw/dx that
        the imposed horizontal motion feeds in through the sloping wire (its time integral closes the balance of an
        undamped system)."""
        fe, p, V, dt, h = self.fe, self.fe.params, self.V, self.dt, self.h
        n = fe.n
        panto = self.panto
        nsteps = int(math.ceil((x_end - x_start) / (V * dt) - 1e-9))
        kc = p.k_contact
        u = np.zeros(n)
        q = np.zeros(n)
        pv = np.zeros(n)
        # coupled static equilibrium at the start (catenary static, its compliance at x_start)
        e, _ = self._locate(x_start, 0)
        x_e, he, dofs, valid, w0d, cols = self._element(e)
        Nl = self._shape((x_start - x_e) / he, he, valid)
        w0 = float(Nl @ w0d)
        c_static = self._static_compliance(Nl, dofs)
        f = panto.static(w0, 1.0 / (1.0 / kc + c_static))
        if self.unilateral and f < 0:
            f = panto.static(w0, 0.0)
        if f != 0.0 and c_static > 0:
            rhs = np.zeros(n)
            rhs[dofs[valid]] += (Nl * f)[valid]
            u = self._static_solve(rhs)
            if self.slack and np.any(fe.T0 + self.kd * (u[self.mw] - u[self.cw]) < 0):
                raise SolverError(f"the static contact force at x_start = {x_start} m slackens a dropper; "
                                  "start at a support")
            q = -h * (self.K @ u)
            pv = -q
        active = (f > 0) or not self.unilateral
        S: list[int] = []
        sS = np.zeros(0)
        g_dofs, g_vals = dofs[valid], (Nl * f)[valid]

        sup_dofs = fe.full_to_free[NDOF_NODE * fe.supports + CW_W]
        sup_sel = np.nonzero(sup_dofs >= 0)[0]
        sup_idx = sup_dofs[sup_sel]
        nrec = nsteps // record_every + 1
        T = np.empty(nrec)
        X = np.empty(nrec)
        F = np.empty(nrec)
        H = np.empty(nrec)
        W = np.empty(nrec)
        U = np.zeros((nrec, fe.supports.size))
        NS = np.zeros(nrec, dtype=np.int32)
        psig = {k: np.empty(nrec) for k in panto.signals()}
        nd = fe.T0.size
        DE = np.zeros((nrec, nd)) if record_droppers else None
        DS = np.zeros((nrec, nd), bool) if record_droppers else None
        if record_droppers:
            DE[0] = fe.T0 + self.kd * (u[self.mw] - u[self.cw])
        EN = None
        if record_energy:
            EN = {k: np.zeros(nrec) for k in ("catenary", "pantograph", "contact", "drive_power")}
            self.q, self.p, self.u = q, pv, u
            self._energy_record(EN, 0, x_start, f, e, Nl)
        T[0], X[0], F[0], H[0], W[0] = 0.0, x_start, f, panto.head(), w0 + float(Nl @ u[dofs])
        for k, val in panto.signals().items():
            psig[k][0] = val
        c_ab = h * self.beta + h * h
        inv_1ha = 1.0 / (1 + h * self.alpha)
        c_kd = (c_ab - h * h) * inv_1ha
        two_hh = 2 * h * h
        hh2 = 0.5 * h
        mw, cw, kd = self.mw, self.cw, self.kd
        affine_map = getattr(panto, "affine_map", None) if panto.affine else None
        Kmat = self.K
        solve = self.lu.solve
        t0 = time.perf_counter()
        n_local = 0
        gp_nl = None
        e_cur = e
        rec = 0
        for step in range(1, nsteps + 1):
            t_new = step * dt
            xp = min(x_start + V * t_new, x_end)
            # R = q_n + h/2 g_n  (then the single banded solve gives vb* with g_{n+1} = 0)
            R = q.copy()
            R[g_dofs] += hh2 * g_vals
            if S:
                R[mw[S]] -= hh2 * sS
                R[cw[S]] += hh2 * sS
            vbs = solve(R)
            e_cur, _ = self._locate(xp, e_cur)
            x_e, he, dofs, valid, w0d, cols = self._element(e_cur)
            Nl = self._shape((xp - x_e) / he, he, valid)
            zc = cols @ Nl  # G N
            c = float(Nl @ zc[dofs])
            a = float(Nl @ (u[dofs] + (2 * h) * vbs[dofs])) + float(Nl @ w0d)
            if self.slack:
                bz = zc[mw] - zc[cw]
                dstar = (u[mw] - u[cw]) + (2 * h) * (vbs[mw] - vbs[cw])
            else:
                bz = dstar = None
            f_prev = f
            if affine_map is not None:
                P, gp = affine_map(dt, f_prev)
                f, S, sS, active = self._solve_local(P, gp, a, c, bz, dstar, active, S)
                yh = panto.trial(t_new - dt, dt, f_prev, f)
                n_local += 1
            else:
                # nonlinear pantograph: secant iteration on f_{n+1}; the slope g of the head map is kept between steps
                y0 = panto.trial(t_new - dt, dt, f_prev, f_prev)
                n_local += 1
                if gp_nl is None:
                    gp_nl = y0 - panto.trial(t_new - dt, dt, f_prev, f_prev + 1.0)
                gp = gp_nl
                P = y0 + gp * f_prev
                fa, ya = f_prev, y0
                for _it in range(30):
                    f, S, sS, active = self._solve_local(P, gp, a, c, bz, dstar, active, S)
                    if f == fa:
                        yh = ya
                        panto.trial(t_new - dt, dt, f_prev, f)
                        break
                    yh = panto.trial(t_new - dt, dt, f_prev, f)
                    n_local += 1
                    err = yh - (P - gp * f)
                    if abs(err) < 1e-13 + 1e-11 * abs(yh):
                        break
                    if abs(f - fa) > 1e-9:
                        g_new = (ya - yh) / (f - fa)
                        if g_new > 0:
                            gp = gp_nl = g_new
                    P = yh + gp * f
                    fa, ya = f, yh
                else:
                    raise SolverError(f"pantograph-catenary coupling did not converge at t = {t_new:.6f} s")
            panto.commit()
            # vb = vb* + (f G N - G B_S s_S) / (2h)
            if S:
                vb = vbs + (zc * f - self.Zg[:, S] @ sS) * (1.0 / (2 * h))
            else:
                vb = vbs + zc * (f / (2 * h))
            u += (2 * h) * vb
            # momentum recursions with the full R (g_{n+1} included)
            g_dofs, g_vals = dofs[valid], (Nl * f)[valid]
            R[g_dofs] += hh2 * g_vals
            if S:
                R[mw[S]] -= hh2 * sS
                R[cw[S]] += hh2 * sS
            Kvb = Kmat @ vb
            Mvb = (R - c_ab * Kvb) * inv_1ha
            dv = (kd * c_kd) * (vb[mw] - vb[cw])
            Mvb[mw] += dv
            Mvb[cw] -= dv
            A2 = 2 * Mvb
            B2 = two_hh * Kvb
            q_new = A2 - B2 - pv
            pv = A2 + B2 - q
            q = q_new
            if step % record_every == 0:
                rec += 1
                T[rec], X[rec], F[rec], H[rec] = t_new, xp, f, yh
                W[rec] = float(Nl @ w0d) + float(Nl @ u[dofs])
                U[rec, sup_sel] = u[sup_idx]
                NS[rec] = len(S)
                if record_droppers:
                    DE[rec] = fe.T0 + kd * (u[mw] - u[cw])
                    DS[rec, S] = True
                if record_energy:
                    self.q, self.p, self.u = q, pv, u
                    self._energy_record(EN, rec, xp, f, e_cur, Nl)
                for k, val in panto.signals().items():
                    psig[k][rec] = val
            if step % 200 == 0 or step == nsteps:
                umax = float(np.max(np.abs(u)))
                if not (math.isfinite(umax) and math.isfinite(f) and math.isfinite(yh)):
                    raise SolverError(f"non-finite state at t = {t_new:.4f} s (x = {xp:.2f} m)")
                if abs(yh) > MAX_DISPLACEMENT and f == 0.0:
                    raise SolverError(
                        f"the pantograph lost the wire and moved {yh:+.3g} m away from it at t = {t_new:.4f} s "
                        f"(x = {xp:.2f} m; static contact force {F[0]:.4g} N): it cannot hold the wire")
                if umax > MAX_DISPLACEMENT or abs(yh) > MAX_DISPLACEMENT:
                    raise SolverError(
                        f"catenary/pantograph displacement {max(umax, abs(yh)):.3g} m exceeds {MAX_DISPLACEMENT} m at "
                        f"t = {t_new:.4f} s (x = {xp:.2f} m): outside the small-displacement model (speed too close "
                        "to the wave speed, or a diverging pantograph)")
                if progress is not None:
                    progress(step, nsteps)
        self.u, self.q, self.p = u, q, pv
        self.slack_set = list(S)
        wall = time.perf_counter() - t0
        sl = slice(0, rec + 1)
        return CoupledResult(t=T[sl], x=X[sl], force=F[sl], head=H[sl], wire=W[sl], uplift=U[sl], n_slack=NS[sl],
                             panto={k: v[sl] for k, v in psig.items()}, support_x=fe.x[fe.supports],
                             stats={"steps": nsteps, "wall_time_loop_s": wall, "dofs": n,
                                    "half_bandwidth": self.lu.bandwidth, "local_solves": n_local},
                             energy=None if EN is None else {k: v[sl] for k, v in EN.items()},
                             dropper_elastic=None if DE is None else DE[sl],
                             dropper_slack=None if DS is None else DS[sl])

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

    def _energy_record(self, EN: dict, rec: int, xp: float, f: float, e: int, Nl: np.ndarray) -> None:
        fe = self.fe
        u = self.u
        v = self.velocity()
        delta = u[self.mw] - u[self.cw]
        kd, T0 = self.kd, fe.T0
        if self.slack:  # potential of T(delta) = max(T0 + k delta, 0) relative to delta = 0
            dmin = -T0 / kd
            Vd = np.where(delta >= dmin, T0 * delta + 0.5 * kd * delta**2, -0.5 * T0**2 / kd)
        else:
            Vd = T0 * delta + 0.5 * kd * delta**2
        # T0 delta terms cancel against the gravity/static reactions' work: the static state is an equilibrium, so
        # only the part beyond the linear one is stored energy; keep it consistent with K0 (wires + supports)
        E_c = 0.5 * v @ (fe.M @ v) + 0.5 * u @ (fe.K0 @ u) + float(np.sum(Vd - T0 * delta))
        EN["catenary"][rec] = E_c
        en = getattr(self.panto, "energy", None)
        EN["pantograph"][rec] = en() if en is not None else np.nan
        EN["contact"][rec] = f * f / (2 * fe.params.k_contact)
        x_e, he, dofs, valid, w0d, cols = self._element(e)
        xi = (xp - x_e) / he
        dN = np.array([(-6 * xi + 6 * xi * xi) / he, 1 - 4 * xi + 3 * xi * xi, (6 * xi - 6 * xi * xi) / he,
                       3 * xi * xi - 2 * xi])
        dN = np.where(valid, dN, 0.0)
        slope = float(dN @ (u[dofs] + w0d))
        EN["drive_power"][rec] = -f * self.V * slope

    def velocity(self) -> np.ndarray:
        """Catenary velocity at the end of the run, from M v = (q + p) / 2."""
        if getattr(self, "_Mfac", None) is None:
            self._Mfac = BandedSPD(self.fe.M)
        return self._Mfac.solve(0.5 * (self.q + self.p))

    def energy(self) -> float:
        """Catenary energy (J) relative to the static state, droppers as linear springs (kinetic + strain)."""
        v = self.velocity()
        return float(0.5 * v @ (self.fe.M @ v) + 0.5 * self.u @ (self.K @ self.u))
