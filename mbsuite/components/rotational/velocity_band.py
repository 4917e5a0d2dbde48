"""The thesis' numerical treatment of stick/slip (Sec. 3.2, App. C/D): a velocity band instead of events, for
comparison with the event-exact hand path (`event_exact.py`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.integrate import solve_ivp

from ...errors import ParameterError, SolverError
from .commands import CommandQueue, Controller
from .interfaces import BWD, FREE, FWD, STUCK, RefResult, RotorSystem
from .projection import StuckProjection


def simulate_velocity_band(
    sys: RotorSystem,
    q0: Sequence[float],
    w0: Sequence[float],
    t_end: float,
    *,
    controller: Controller | None = None,
    u0: dict[str, int] | None = None,
    sample_dt: float = 1e-3,
    velocity_tol: float = 0.01,
    rtol: float = 1e-3,
    atol: float = 1e-6,
    max_step: float = 0.0019,
) -> RefResult:
    """The thesis' numerical treatment (Sec. 3.2, App. C/D): no events; inside |w_rel| < velocity_tol an element is
    held (zero relative acceleration) while the torque it must carry is within its capacity; RK23 with the App. J
    settings (tol 1e-3, max step 1.9 ms). The velocity stays wherever it was inside the band, so positions creep.
    Held torques use the same capacity-weighted constraint solution as the event-exact path (the App. D two-body test
    evaluated jointly rather than clutch by clutch).
    One function (about 110 lines), as the thesis' App. C/D loop it reproduces reads: the band's modes, the
    controller's samples and the integration step stay in one place."""
    if sys.dampers() or any(f.g is not None or f.one_way_hold is not None for f in sys.frictions):
        raise ParameterError("the velocity-band scheme takes two-rotor friction elements without one-way logic and "
                             "springs without dampers (the thesis' systems); use simulate_reference")
    n, ne = sys.n, len(sys.frictions)
    part_owner = [e for e, f in enumerate(sys.frictions) for _ in f.parts]
    peaks = np.array([f.peak for f in sys.frictions])
    labels = sys.part_labels()
    u = {c: 0 for c in sys.commands()}
    u.update(u0 or {})
    queue = CommandQueue(sys.delays, controller.dt if controller else 1.0, u) if controller else None
    cache: dict[tuple, StuckProjection] = {}
    ne_tot = 1 + n + len(part_owner)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        q, w = y[:n], y[n:2 * n]
        lv = sys.levels(t, u)
        el = np.zeros(ne)
        np.add.at(el, part_owner, lv)
        wr = sys.w_rel(w)
        mode = np.where(el <= 0, FREE, np.where(np.abs(wr) < velocity_tol, STUCK, np.sign(wr))).astype(int)
        f0, p_src = sys.free_torque(t, q, w)
        for _ in range(2 * ne + 2):
            stuck = [e for e in range(ne) if mode[e] == STUCK]
            caps = peaks[stuck] * el[stuck]
            key = (tuple(stuck), tuple(np.round(caps, 12)) if len(stuck) > 1 else ())
            cfg = cache.get(key) or cache.setdefault(key, StuckProjection(sys, stuck, caps))
            f = f0.copy()
            for e in range(ne):
                if mode[e] in (FWD, BWD):
                    fr = sys.frictions[e]
                    f[fr.a] += mode[e] * el[e]
                    if fr.b >= 0:
                        f[fr.b] -= mode[e] * el[e]
            if not stuck:
                break
            lam = cfg.lam(f)
            ratio = np.abs(lam) / caps
            r = int(np.argmax(ratio))
            if ratio[r] <= 1.0:
                break
            mode[stuck[r]] = FWD if lam[r] > 0 else BWD
        dy = np.zeros(2 * n + ne_tot)
        dy[:n] = w
        dy[n:2 * n] = cfg.Pa @ f
        dy[2 * n] = p_src
        dy[2 * n + 1:2 * n + 1 + n] = sys.B * w * w
        for i, e in enumerate(part_owner):
            if mode[e] in (FWD, BWD):
                dy[2 * n + 1 + n + i] = lv[i] * abs(wr[e])
        return dy

    y = np.concatenate([np.asarray(q0, float), np.asarray(w0, float), np.zeros(ne_tot)])
    t_samples = np.arange(0.0, t_end + 0.5 * sample_dt, sample_dt)
    Y = np.empty((t_samples.size, y.size))
    U = {c: np.empty(t_samples.size) for c in u}
    Y[0] = y
    for c in u:
        U[c][0] = u[c]
    k_out = 1
    t = 0.0
    dt_c = controller.dt if controller else t_end
    k = 0
    nfev = 0
    while t < t_end - 1e-12:
        if controller is not None:
            queue.issue(k, controller(k, t, y[:n], y[n:2 * n]))
            while queue.pending and queue.pending[0][0] <= t + 1e-12:
                _, c, v = queue.pending.pop(0)
                u[c] = v
        t_next = min((k + 1) * dt_c, t_end)
        for b in sys.breaks:
            if t < b < t_next:
                t_next = b
        ts = t_samples[(t_samples > t + 1e-12) & (t_samples <= t_next + 1e-12)]
        sol = solve_ivp(rhs, (t, t_next), y, method="RK23", rtol=rtol, atol=atol, max_step=max_step,
                        t_eval=ts if ts.size else None)
        if not sol.success:
            raise SolverError(f"velocity-band integration failed at t = {t:.6g} s: {sol.message}")
        nfev += sol.nfev
        for j in range(ts.size):
            Y[k_out] = sol.y[:, j]
            for c in u:
                U[c][k_out] = u[c]
            k_out += 1
        y = sol.y[:, -1] if not ts.size or abs(sol.t[-1] - t_next) < 1e-12 else \
            solve_ivp(rhs, (sol.t[-1], t_next), sol.y[:, -1], method="RK23", rtol=rtol, atol=atol).y[:, -1]
        if abs(t_next - (k + 1) * dt_c) < 1e-12:
            k += 1
        t = t_next
    Y = Y[:k_out]
    e_names = ["source"] + [f"viscous_{nm}" for nm in sys.names] + labels
    return RefResult(t=t_samples[:k_out], q=Y[:, :n].T, w=Y[:, n:2 * n].T, modes=np.zeros((ne, k_out), int),
                     energy={nm: Y[:, 2 * n + i] for i, nm in enumerate(e_names)}, events=[],
                     u={c: v[:k_out] for c, v in U.items()}, stats={"nfev": nfev, "reset_energy": 0.0})
