"""One passage of a pantograph under the FE catenary on the readable Python path: the step object `Passage` (the
coupled state and its `step()`: predict with the banded solve, locate the contact point, couple the pantograph,
advance the momenta, check; the scheme is `sim.py`'s) and its per-step records (`CoupledResult`, `Recorder`).

The compiled core (`native_core.py`) is this passage's twin; `CoupledSimulation` (`sim.py`) holds the method a passage
steps with (step matrix, factorisation, influence columns, the local contact/dropper solver).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import SolverError
from ...stepping import Stepping

#: steps between the plausibility checks of a passage (and the progress calls of `CoupledSimulation.run`)
CHECK_EVERY = 200


def steps_to_cover(distance: float, V: float, dt: float) -> int:
    """Steps of dt at speed V to cover `distance` (the last one may overshoot). A distance that is a whole number of
    steps in exact arithmetic (420 m at 250 km/h and 2e-4 s: 30240) is that number whatever its last bits: the count
    is taken to a relative 1e-8, so a 1e-12 change of V, dt or the positions cannot add a step."""
    r = distance / (V * dt)
    return int(math.ceil(r - 1e-8 * max(1.0, abs(r))))


def irregularity_at(irr, x: float) -> tuple[float, float]:
    """The contact wire's height irregularity r(x) (m) and its slope dr/dx at position x (m): `irr` (`fe.irregularity`:
    heights `r` on the uniform grid x0 + i dx) interpolated linearly, 0 outside the grid and for None; the slope is
    the right-hand one at a grid point. The compiled core evaluates r in the same operations (native/catenary.c)."""
    if irr is None:
        return 0.0, 0.0
    r = irr.r
    m = len(r)
    t = (x - irr.x0) / irr.dx
    if not t >= 0.0 or t > m - 1:
        return 0.0, 0.0
    i = int(t)
    if i >= m - 1:
        return float(r[m - 1]), 0.0
    return float(r[i] + (t - i) * (r[i + 1] - r[i])), float((r[i + 1] - r[i]) / irr.dx)


def dropper_energy(sim: Any, u: np.ndarray) -> float:
    """The droppers' stored energy at the displacement u from the static state, beyond the static tensions' linear
    term (J): the potential of T(delta) = T0 + k delta, or max(T0 + k delta, 0) for a tension-only dropper
    (`sim.slackable`), less T0 delta (that term cancels against the static reactions' work: the static state is an
    equilibrium)."""
    delta = u[sim.up] - u[sim.lo]
    kd, T0 = sim.kd, sim.fe.T0
    Vd = np.where(sim.slackable & (delta < -T0 / kd), -0.5 * T0**2 / kd, T0 * delta + 0.5 * kd * delta**2)
    return float(np.sum(Vd - T0 * delta))


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
    #: a line of several contact wires (a route): per contact wire (its name) its own contact force `force` (N), its
    #: height under the head `wire` (m, static state included; 0 off the wire) and `on` (the head on its x-range)
    wires: dict[str, dict[str, np.ndarray]] | None = None
    #: the name of each uplift column (`fe.arm_names`; None: the support's x, "%g")
    support_names: list[str] | None = None


class Passage(Stepping):
    """One passage of the pantograph under the catenary in progress, in the spirit of scipy's `OdeSolver`: the coupled
    state after `n` steps and `step()`, which advances it by one time step of the scheme in `sim.py`'s docstring, with
    the method of `sim` (a `sim.CoupledSimulation`); a `mbsuite.stepping.StepObject`.

    State: time `t` = n dt (s) of `nsteps`, pantograph position `x` (m), contact force `force` (N) and head height
    `head` (m) at the end of the last step, the catenary's displacement `u` from its static state and momenta `q`, `p`
    (q_n = M v_n - h K u_n and its partner recursion), the slack droppers `slack` with their tension-cancelling
    corrections `s_slack`, `in_contact`; `status` is "running" until x reaches x_end, then "finished" ("failed"
    after a step raised).
    `static_force` is the coupled static contact force at the start; `n_local` counts the pantograph's trial steps."""

    def __init__(self, sim: Any, x_start: float, x_end: float):
        self.sim, self.panto = sim, sim.panto
        self.x_start, self.x_end = x_start, x_end
        self.nsteps = steps_to_cover(x_end - x_start, sim.V, sim.dt)
        self.n, self.t, self.x = 0, 0.0, x_start
        self.n_local = 0
        self._gp = None  # slope of a nonlinear pantograph's head map, kept between steps by the secant iteration
        h = sim.h
        # constants of the momentum recursions (sim.py)
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
        contact stiffness in series with the wire's static compliance at x_start (its point-load defect included,
        `sim.contact_stiffness`), the wire's static response to that force."""
        sim, panto = self.sim, self.panto
        fe, h = sim.fe, sim.h
        n = fe.n
        u = np.zeros(n)
        q = np.zeros(n)
        pv = np.zeros(n)
        e, _ = sim.locate(x_start, 0)
        self._set_contactelement(e, x_start)
        Nl, dofs, valid = self.Nl, self._dofs, self._valid
        w0 = float(Nl @ self._w0d) + self.r_irr
        c_static = sim.static_compliance(Nl, dofs)
        f = panto.static(w0, 1.0 / (1.0 / self.kce + c_static))
        if sim.unilateral and f < 0:
            f = panto.static(w0, 0.0)
        if f != 0.0 and c_static > 0:
            rhs = np.zeros(n)
            rhs[dofs[valid]] += (Nl * f)[valid]
            u = sim.static_solve(rhs)
            if sim.slack and np.any((fe.T0 + sim.kd * (u[sim.up] - u[sim.lo]) < 0) & sim.slackable):
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

    def _set_contactelement(self, e: int, xp: float) -> None:
        """The contact point at xp (m) in CW element e: its element data, shape functions, the contact wire's
        point-load defect there (`cb`), the contact spring in series with it (`kce`) and the contact wire's height
        irregularity there (`r_irr`, m, and its slope `r_slope`)."""
        x_e, he, dofs, valid, w0d, cols = self.sim.element(e)
        dx = xp - self.sim.fe.x[e]
        self.e, self._dofs, self._valid, self._w0d, self._cols = e, dofs, valid, w0d, cols
        self.Nl = self.sim.shape(dx / he, he, valid)
        self.cb, self.kce = self.sim.contact_stiffness(e, dx / he)
        self.r_irr, self.r_slope = irregularity_at(self.sim.fe.irregularity, xp)

    # --- one step ---------------------------------------------------------------------------------------------
    def _one_step(self) -> None:
        """Advance the coupled state by one time step dt (raises SolverError on a failure)."""
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
            R[sim.up[S]] -= hh2 * sS
            R[sim.lo[S]] += hh2 * sS
        return R, sim.lu.solve(R)

    def _contact_point(self, xp: float, vbs: np.ndarray) -> tuple:
        """The contact point at xp at the end of the step: G N (zc), the wire's height without new local forces (a)
        and its compliance (c) there, and for slack droppers their elongations (dstar) and the contact force's
        influence on them (bz)."""
        sim, u, h2 = self.sim, self.u, 2 * self.sim.h
        e, _ = sim.locate(xp, self.e)
        self._set_contactelement(e, xp)
        Nl, dofs = self.Nl, self._dofs
        zc = self._cols @ Nl  # G N
        c = float(Nl @ zc[dofs])
        a = (float(Nl @ (u[dofs] + h2 * vbs[dofs])) + float(Nl @ self._w0d)) + self.r_irr
        if sim.slack:
            up, lo = sim.up, sim.lo
            bz = zc[up] - zc[lo]
            dstar = (u[up] - u[lo]) + h2 * (vbs[up] - vbs[lo])
        else:
            bz = dstar = None
        return zc, a, c, bz, dstar

    def _couple_affine(self, t: float, a: float, c: float, bz, dstar) -> tuple:
        """An affine pantograph: its exact head map P - g f1 into the local problem, one trial to advance it."""
        sim, panto, f_prev = self.sim, self.panto, self.force
        P, gp = panto.affine_map(sim.dt, f_prev)
        f, S, sS, active = sim.solve_local(P, gp, a, c, bz, dstar, self.in_contact, self.slack, self.kce)
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
            f, S, sS, active = sim.solve_local(P, gp, a, c, bz, dstar, active, S, self.kce)
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
        up, lo = sim.up, sim.lo
        if S:
            vb = vbs + (zc * f - sim.Zg[:, S] @ sS) * (1.0 / (2 * h))
        else:
            vb = vbs + zc * (f / (2 * h))
        self.u += (2 * h) * vb
        valid = self._valid
        self._g_dofs, self._g_vals = self._dofs[valid], (self.Nl * f)[valid]
        R[self._g_dofs] += hh2 * self._g_vals
        if S:
            R[up[S]] -= hh2 * sS
            R[lo[S]] += hh2 * sS
        Kvb = sim.K @ vb
        Mvb = (R - self._c_ab * Kvb) * self._inv_1ha
        dv = (sim.kd * self._c_kd) * (vb[up] - vb[lo])
        Mvb[up] += dv
        Mvb[lo] -= dv
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
        """CW height at the contact point, static sag, the point-load defect's deflection d f and the height
        irregularity r(x) included (m): the height the contact spring meets, f = k_c max(head - wire, 0)."""
        Nl = self.Nl
        return float(Nl @ self._w0d) + float(Nl @ self.u[self._dofs]) + self.cb * self.force + self.r_irr

    def dropper_tension(self) -> np.ndarray:
        """Elastic dropper tensions T0 + k delta (N); negative on a slack dropper."""
        sim = self.sim
        return sim.fe.T0 + sim.kd * (self.u[sim.up] - self.u[sim.lo])

    def velocity(self) -> np.ndarray:
        """Catenary velocity, from M v = (q + p) / 2."""
        return self.sim.mass().solve(0.5 * (self.q + self.p))

    def energy_terms(self) -> dict[str, float]:
        """The catenary energy relative to the static state (kinetic + wires + support springs + droppers with their
        exact law), the pantograph's energy (if it offers `energy()`, else NaN), the contact spring energy (the
        wire's point-load defect under it included: f^2 (1/k_c + d) / 2) and the power -f V d(w + r)/dx that the
        imposed horizontal motion feeds in through the sloping wire, its height irregularity r included (its time
        integral closes the balance of an undamped system)."""
        sim, fe, u, f = self.sim, self.sim.fe, self.u, self.force
        v = self.velocity()
        E_c = 0.5 * v @ (fe.M @ v) + 0.5 * u @ (fe.K0 @ u) + dropper_energy(sim, u)
        en = getattr(self.panto, "energy", None)
        x_e, he, dofs, valid, w0d, cols = sim.element(self.e)
        xi = (self.x - x_e) / he
        dN = np.array([(-6 * xi + 6 * xi * xi) / he, 1 - 4 * xi + 3 * xi * xi, (6 * xi - 6 * xi * xi) / he,
                       3 * xi * xi - 2 * xi])
        dN = np.where(valid, dN, 0.0)
        slope = float(dN @ (u[dofs] + w0d)) + self.r_slope
        return {"catenary": E_c, "pantograph": en() if en is not None else np.nan,
                "contact": 0.5 * f * f * (1.0 / fe.params.k_contact + self.cb), "drive_power": -f * sim.V * slope}


class Recorder:
    """The per-step records of a passage (CoupledResult), one row per recorded step from the start."""

    def __init__(self, passage: Passage, every: int, droppers: bool, energy: bool):
        sim = passage.sim
        fe = sim.fe
        nrec = passage.nsteps // every + 1
        sup_dofs = fe.support_cw
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
        """Store the passage's current state as the next row."""
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
        """The recorded rows as a `CoupledResult` with `stats`."""
        sl = slice(0, self.rows)
        return CoupledResult(t=self.T[sl], x=self.X[sl], force=self.F[sl], head=self.H[sl], wire=self.W[sl],
                             uplift=self.U[sl], n_slack=self.NS[sl], panto={k: v[sl] for k, v in self.psig.items()},
                             support_x=self.fe.x[self.fe.supports], stats=stats,
                             energy=None if self.EN is None else {k: v[sl] for k, v in self.EN.items()},
                             dropper_elastic=None if self.DE is None else self.DE[sl],
                             dropper_slack=None if self.DS is None else self.DS[sl])
