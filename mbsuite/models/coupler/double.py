"""Hand-derived kinematics of the double 4-link coupler (plain numpy; Maniowski & Czauderna, Sect. 2, Eqs 2-7).

Conventions (README, "Conventions and geometry"; the platforms' points and rotations: `geometry`):
- shaft b carries BA (local points p_k) and BC (local points R_y(phi_bc) p_k + (0, l_b, 0));
  shaft c (points p_k) sits at o^c = (x_c, 2 e_y + l_b + y_c, z_c), R^c = R_z(a_cz) R_x(a_cx) R_y(phi_c).
- coupler 1: a_k -- ba_{k+1}; coupler 2 (mirror image of coupler 1 in shaft b's mid-plane): c_k -- bc_{k+1}.
- nominal: phi_b = phi_a - pi/2, phi_c = phi_a + phi_bc.
- batched FPP (`solve_double_batch`, `solve_double_wrapped_batch`): the same equations and tolerance for N poses at
  once (numpy, batched 8 x 8 solves), for the samples of a run; `solve_double` stays the readable reference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import GeometryError, SolverError
from .fpp import ADMISSIBLE, check_physical, continuation, gauss_newton, no_physical
from .geometry import (
    EY,
    NEXT,
    SKEW_Y,
    bc_points,
    platform_points,
    rot_y,
    shaft_rotation,
    shaft_rotation_derivs,
)
from .params import CouplerParams

DOUBLE_UNKNOWNS = ("phi_c", "y_c", "x_b", "y_b", "z_b", "phi_b", "alpha_bx", "alpha_bz")  # Table 1 (README erratum 2)
DOUBLE_INPUTS = ("phi_a", "alpha_cx", "alpha_cz", "x_c", "z_c")


def double_points(p: CouplerParams, inp: np.ndarray, u: np.ndarray):
    """(a, ba, bc, c, o_b, R_b, o_c, R_c) in the base frame (Eqs 2, 3, 6); inp = (phi_a, a_cx, a_cz, x_c, z_c)."""
    phi_a, acx, acz, xc, zc = inp
    phi_c, yc, xb, yb, zb, phi_b, abx, abz = u
    loc = platform_points(p.gamma, p.R)
    a = loc @ rot_y(phi_a).T
    Rb = shaft_rotation(abx, abz, phi_b)
    ob = np.array([xb, p.e_y + yb, zb])
    ba = loc @ Rb.T + ob
    bc = bc_points(p) @ Rb.T + ob
    Rc = shaft_rotation(acx, acz, phi_c)
    oc = np.array([xc, 2 * p.e_y + p.l_b + yc, zc])
    c = loc @ Rc.T + oc
    return a, ba, bc, c, ob, Rb, oc, Rc


def double_residual(p: CouplerParams, inp: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Eq (4) with Eq (7): 8 residuals |ba_{k+1} - a_k|^2 - l^2 and |bc_{k+1} - c_k|^2 - l^2."""
    a, ba, bc, c, *_ = double_points(p, inp, u)
    l1, l2 = ba[NEXT] - a, bc[NEXT] - c
    return np.concatenate([np.einsum("ij,ij->i", l1, l1), np.einsum("ij,ij->i", l2, l2)]) - p.link_length**2


def double_residual_jac(p: CouplerParams, inp: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Analytic d(residual)/du (8 x 8), u ordered as DOUBLE_UNKNOWNS."""
    phi_a, acx, acz, xc, zc = inp
    phi_c, yc, xb, yb, zb, phi_b, abx, abz = u
    a, ba, bc, c, ob, Rb, oc, Rc = double_points(p, inp, u)
    l1, l2 = ba[NEXT] - a, bc[NEXT] - c
    loc = platform_points(p.gamma, p.R)
    dbx, dbz, dbp = shaft_rotation_derivs(abx, abz, phi_b)
    dcp = shaft_rotation_derivs(acx, acz, phi_c)[2]
    J = np.zeros((8, 8))
    pa, pc = loc[NEXT], bc_points(p)[NEXT]
    # coupler 1 depends on shaft b only
    J[:4, 2:5] = l1
    J[:4, 5] = np.einsum("ij,ij->i", l1, pa @ dbp.T)
    J[:4, 6] = np.einsum("ij,ij->i", l1, pa @ dbx.T)
    J[:4, 7] = np.einsum("ij,ij->i", l1, pa @ dbz.T)
    # coupler 2: l = bc_{k+1} - c_k
    J[4:, 2:5] = l2
    J[4:, 5] = np.einsum("ij,ij->i", l2, pc @ dbp.T)
    J[4:, 6] = np.einsum("ij,ij->i", l2, pc @ dbx.T)
    J[4:, 7] = np.einsum("ij,ij->i", l2, pc @ dbz.T)
    J[4:, 0] = -np.einsum("ij,ij->i", l2, loc @ dcp.T)
    J[4:, 1] = -l2[:, 1]
    return 2.0 * J


def double_nominal(p: CouplerParams, inp: np.ndarray) -> np.ndarray:
    """Exact solution for zero misalignment (a_cx = a_cz = x_c = z_c = 0)."""
    return np.array([inp[0] + p.phi_bc, 0.0, 0.0, 0.0, 0.0, inp[0] - math.pi / 2, 0.0, 0.0])


def _double_inputs(inp: np.ndarray) -> str:
    return ", ".join(f"{k} = {v:.6g} {u}" for k, v, u in zip(DOUBLE_INPUTS, inp, ("rad", "rad", "rad", "m", "m"),
                                                                 strict=True))


def solve_double(p: CouplerParams, inp, guess: np.ndarray | None = None, *, tol: float = 1e-13) -> np.ndarray:
    """FPP of the double coupler: 8 unknowns (DOUBLE_UNKNOWNS) from 5 inputs (DOUBLE_INPUTS), Gauss-Newton on Eq 4."""
    inp = np.asarray(inp, float)
    if p.e_y == 0.0 and np.any(inp[1:] != 0.0):
        raise GeometryError("double coupler FPP: e_y = 0 (coplanar platforms) admits no misaligned physical pose")
    u0 = double_nominal(p, inp) if guess is None else np.asarray(guess, float)
    try:
        u, _ = gauss_newton(lambda u: double_residual(p, inp, u), lambda u: double_residual_jac(p, inp, u), u0,
                            tol=tol * p.R**2, what=f"double coupler FPP at phi_a = {inp[0]:.6g}")
    except SolverError as exc:
        no_physical(p, _double_tilt(p, inp), exc, _double_inputs(inp))
    if p.e_y > 0.0:
        a, ba, bc, c, _, Rb, _, Rc = double_points(p, inp, u)
        check_physical(p, ba[NEXT] - a, [EY, Rb @ EY], "double coupler FPP (coupler A-BA)", _double_inputs(inp))
        check_physical(p, c - bc[NEXT], [Rb @ EY, Rc @ EY], "double coupler FPP (coupler BC-C)", _double_inputs(inp))
    return u


def _double_tilt(p: CouplerParams, inp: np.ndarray) -> float:
    """Rough relative inclination of shaft b against a or c: output inclination plus lateral offset over the span."""
    return float(math.hypot(inp[1], inp[2]) + math.hypot(inp[3], inp[4]) / (p.l_b + 2 * p.e_y))


def ramp_double(p: CouplerParams, inp: np.ndarray, n: int = 8) -> np.ndarray:
    """The double coupler's FPP solution at input `inp`: from the nominal pose at its first component, the other
    components ramped in over `n` continuation steps."""
    base = inp.copy()
    base[1:] = 0.0
    u = double_nominal(p, base)
    for s in np.linspace(0.0, 1.0, n + 1)[1:]:
        x = inp.copy()
        x[1:] *= s
        u = solve_double(p, x, u)
    return u


@dataclass
class DoubleRevolution:
    """Double-coupler FPP over one revolution: phi_a (n,), u (n, 8) in DOUBLE_UNKNOWNS order, the inputs."""
    phi_a: np.ndarray
    u: np.ndarray  # (n, 8) ordered as DOUBLE_UNKNOWNS
    inputs: np.ndarray  # (alpha_cx, alpha_cz, x_c, z_c)


def double_revolution(p: CouplerParams, alpha_cx: float = 0.0, alpha_cz: float = 0.0, x_c: float = 0.0,
                      z_c: float = 0.0, n: int = 181, phi_start: float = 0.0) -> DoubleRevolution:
    """FPP of the double coupler over one revolution of phi_a by continuation (branch jumps detected)."""
    rest = np.array([alpha_cx, alpha_cz, x_c, z_c], float)
    phis = phi_start + np.linspace(0.0, 2 * math.pi, n)
    u0 = ramp_double(p, np.concatenate([[phis[0]], rest]))

    def step(phi: float, guess: np.ndarray) -> np.ndarray:
        return solve_double(p, np.concatenate([[phi], rest]), guess)

    def jump(u_prev: np.ndarray, u_new: np.ndarray, dphi: float) -> float:
        dang = max(abs((u_new[0] - u_prev[0]) - dphi), abs((u_new[5] - u_prev[5]) - dphi)) / (0.5 * abs(dphi) + 0.05)
        dpos = np.max(np.abs(np.r_[u_new[1:5], u_new[6:]] - np.r_[u_prev[1:5], u_prev[6:]])) / 0.1
        return max(dang, dpos)

    try:
        u = continuation(step, u0, phis, jump, "double coupler FPP")
    except SolverError as exc:
        no_physical(p, _double_tilt(p, np.r_[0.0, rest]), exc, _double_inputs(np.r_[phi_start, rest]))
    return DoubleRevolution(phis, u, rest)


# ---------------------------------------------------------------------------------------- double coupler, batched
# The same equations for N poses at once (numpy, no Python loop over samples): used where the FPP is solved for every
# recorded sample of a run. `double_residual` / `double_residual_jac` / `solve_double` above stay the readable
# reference; a test holds the batched functions equal to them.
def _rx(x, y, z, c, s):
    return x, c * y - s * z, s * y + c * z


def _ry(x, y, z, c, s):
    return c * x + s * z, y, -s * x + c * z


def _rz(x, y, z, c, s):
    return c * x - s * y, s * x + c * y, z


def _trig(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.cos(a)[:, None], np.sin(a)[:, None]


def _link_points_b(p: CouplerParams) -> np.ndarray:
    """Local points (8, 3) on shaft b where links 1..8 end: BA_{k+1} for coupler 1, BC_{k+1} for coupler 2."""
    return np.vstack([platform_points(p.gamma, p.R)[NEXT], bc_points(p)[NEXT]])


def _double_links_n(p: CouplerParams, inp: np.ndarray, u: np.ndarray, jac: bool):
    """For N poses (inp (N, 5), u (N, 8)): the link vectors L = (driven point - driving point) as components
    (Lx, Ly, Lz), each (N, 8) (links 1-4: ba_{k+1} - a_k; links 5-8: bc_{k+1} - c_k), shaft b's and c's axes
    R_b e_y, R_c e_y (N, 3), and, if `jac`, d(|L|^2 / 2)/du (N, 8, 8). Rotations are applied to point components one
    factor at a time (R = R_z R_x R_y), so everything is elementwise on (N, 8) arrays."""
    n = inp.shape[0]
    loc = platform_points(p.gamma, p.R)
    qb = _link_points_b(p)
    ca, sa = _trig(inp[:, 0])
    ccx, scx = _trig(inp[:, 1])
    ccz, scz = _trig(inp[:, 2])
    cpc, spc = _trig(u[:, 0])
    cpb, spb = _trig(u[:, 5])
    cbx, sbx = _trig(u[:, 6])
    cbz, sbz = _trig(u[:, 7])
    zero = np.zeros((n, 1))
    # shaft b: P = R_b q (q the 8 link points), W = R_x R_y q (for d/dalpha_bx)
    v = _ry(qb[:, 0], qb[:, 1] + zero, qb[:, 2], cpb, spb)
    w = _rx(*v, cbx, sbx)
    P = _rz(*w, cbz, sbz)
    ob = (u[:, 2:3], p.e_y + u[:, 3:4], u[:, 4:5])
    # driving points: a_k on shaft a (links 1-4), c_k on shaft c (links 5-8)
    a = _ry(loc[:, 0], loc[:, 1] + zero, loc[:, 2], ca, sa)
    vc = _ry(loc[:, 0], loc[:, 1] + zero, loc[:, 2], cpc, spc)
    C = _rz(*_rx(*vc, ccx, scx), ccz, scz)
    oc = (inp[:, 3:4], 2 * p.e_y + p.l_b + u[:, 1:2], inp[:, 4:5])
    L = tuple(np.hstack([P[i][:, :4] + ob[i] - a[i], P[i][:, 4:] + ob[i] - C[i] - oc[i]]) for i in range(3))
    yb = np.column_stack([-sbz * cbx, cbz * cbx, sbx])  # R_b e_y
    yc = np.column_stack([-scz * ccx, ccz * ccx, scx])  # R_c e_y
    if not jac:
        return L, yb, yc, None
    J = np.zeros((n, 8, 8))
    J[:, :, 2], J[:, :, 3], J[:, :, 4] = L

    def dot(D) -> np.ndarray:
        return L[0] * D[0] + L[1] * D[1] + L[2] * D[2]

    # d/dphi_b: R_b (e_y x q);  d/dalpha_bx: R_z (e_x x W);  d/dalpha_bz: e_z x P
    sy = (qb[:, 2], qb[:, 1] * 0.0, -qb[:, 0])
    J[:, :, 5] = dot(_rz(*_rx(*_ry(*sy, cpb, spb), cbx, sbx), cbz, sbz))
    J[:, :, 6] = dot(_rz(zero, -w[2], w[1], cbz, sbz))
    J[:, :, 7] = dot((-P[1], P[0], zero))
    # coupler 2 also depends on shaft c: d/dphi_c of c_k is R_c (e_y x p_k); d/dy_c of c_k is e_y
    syc = (loc[:, 2], loc[:, 1] * 0.0, -loc[:, 0])
    dC = _rz(*_rx(*_ry(*syc, cpc, spc), ccx, scx), ccz, scz)
    J[:, 4:, 0] = -(L[0][:, 4:] * dC[0] + L[1][:, 4:] * dC[1] + L[2][:, 4:] * dC[2])
    J[:, 4:, 1] = -L[1][:, 4:]
    return L, yb, yc, J


def double_residual_batch(p: CouplerParams, inp: np.ndarray, u: np.ndarray) -> np.ndarray:
    """`double_residual` for N poses: inp (N, 5), u (N, 8) -> (N, 8)."""
    L, *_ = _double_links_n(p, np.atleast_2d(inp), np.atleast_2d(u), False)
    return L[0] ** 2 + L[1] ** 2 + L[2] ** 2 - p.link_length**2


def double_residual_jac_batch(p: CouplerParams, inp: np.ndarray, u: np.ndarray) -> np.ndarray:
    """`double_residual_jac` for N poses: (N, 8, 8)."""
    return 2.0 * _double_links_n(p, np.atleast_2d(inp), np.atleast_2d(u), True)[3]


def _sample(i: int, inp: np.ndarray, times: np.ndarray | None) -> str:
    where = f"t = {times[i]:.6g} s" if times is not None else f"sample {i}"
    return f"{where} (phi_a = {inp[i, 0]:.6g} rad)"


def _check_physical_batch(p: CouplerParams, links: np.ndarray, axes: list[np.ndarray], what: str,
                          inp: np.ndarray, times: np.ndarray | None) -> None:
    """`check_physical` for N poses: links (3 components, each (N, 4)), axes [(N, 3)]; GeometryError naming the first
    bad sample."""
    for s in axes:
        worst = np.min(links[0] * s[:, :1] + links[1] * s[:, 1:2] + links[2] * s[:, 2:], axis=1) / p.link_length
        bad = np.flatnonzero(~(worst > 0.0))
        if bad.size:
            i = int(bad[0])
            raise GeometryError(
                f"{what} at {_sample(i, inp, times)}, {_double_inputs(inp[i])}: no physical pose - platform B would "
                f"cross platform A (a link's axial component {worst[i]:+.3g} l <= 0; {bad.size} of {worst.size} "
                f"samples); e_y = {p.e_y:g} m is too small for this misalignment ({ADMISSIBLE})")


def solve_double_batch(p: CouplerParams, inp: np.ndarray, guess: np.ndarray, *, tol: float = 1e-13,
                       max_iter: int = 50, times: np.ndarray | None = None) -> np.ndarray:
    """`solve_double` for N poses at once: Gauss-Newton on Eq (4) for every sample (batched 8 x 8 solves), each sample
    iterated until |r|_inf <= tol R^2 (the tolerance of `solve_double`), then the same physical-pose check. inp (N, 5)
    as DOUBLE_INPUTS, guess (N, 8) as DOUBLE_UNKNOWNS, one guess per sample (it must be near the wanted branch: a
    continuation's predictor, or the state of a simulation of the mechanism). A sample that does not converge is a
    SolverError naming it (its time if `times` is given), never a silent number."""
    inp = np.atleast_2d(np.asarray(inp, float))
    u = np.array(np.atleast_2d(guess), dtype=float)
    if inp.ndim != 2 or inp.shape[1] != 5 or u.shape != (inp.shape[0], 8):
        raise ValueError(f"inp must be (N, 5) and guess (N, 8); got {inp.shape} and {u.shape}")
    if p.e_y == 0.0 and np.any(inp[:, 1:] != 0.0):
        raise GeometryError("double coupler FPP: e_y = 0 (coplanar platforms) admits no misaligned physical pose")
    tol_abs = tol * p.R**2
    l2 = p.link_length**2
    rmax = np.full(inp.shape[0], np.inf)
    active = np.ones(inp.shape[0], bool)
    with np.errstate(over="ignore", invalid="ignore"):  # a diverging sample is reported below, by name
        for it in range(max_iter + 1):
            idx = np.flatnonzero(active)
            if not idx.size:
                break
            L, _, _, J = _double_links_n(p, inp[idx], u[idx], True)
            r = L[0] ** 2 + L[1] ** 2 + L[2] ** 2 - l2
            rmax[idx] = np.max(np.abs(r), axis=1)  # NaN for a non-finite residual
            go = ~(rmax[idx] <= tol_abs) & np.isfinite(rmax[idx])  # converged or non-finite: stop iterating it
            active[idx] = go
            if it == max_iter or not go.any():
                break
            idx, J, r = idx[go], 2.0 * J[go], r[go]
            try:
                du = np.linalg.solve(J, r[:, :, None])[..., 0]
            except np.linalg.LinAlgError:  # an exactly singular J somewhere: least squares for these samples
                du = (np.linalg.pinv(J) @ r[:, :, None])[..., 0]
            u[idx] -= du
    bad = np.flatnonzero(~(rmax <= tol_abs))
    if bad.size:
        i = int(bad[0])
        fin = bool(np.isfinite(rmax[i]))
        why = f"did not converge in {max_iter} iterations" if fin else "met a non-finite residual"
        res = f"residual |r|_inf = {rmax[i]:.3e}, " if fin else ""
        exc = SolverError(f"double coupler FPP: Gauss-Newton {why} at {_sample(i, inp, times)} ({res}tolerance "
                          f"{tol_abs:.1e}; {bad.size} of {rmax.size} samples)")
        no_physical(p, _double_tilt(p, inp[i]), exc, _double_inputs(inp[i]))
    if p.e_y > 0.0:
        L, yb, yc, _ = _double_links_n(p, inp, u, False)
        ey = np.broadcast_to(EY, yb.shape)
        _check_physical_batch(p, [x[:, :4] for x in L], [ey, yb], "double coupler FPP (coupler A-BA)", inp, times)
        _check_physical_batch(p, [-x[:, 4:] for x in L], [yb, yc], "double coupler FPP (coupler BC-C)", inp, times)
    return u


#: the unknowns that turn with phi_a (phi_c and phi_b): the pose is 2 pi-periodic in phi_a with these advanced by 2 pi
DOUBLE_TURN = np.array([2 * math.pi, 0.0, 0.0, 0.0, 0.0, 2 * math.pi, 0.0, 0.0])


def solve_double_wrapped_batch(p: CouplerParams, phi_a: np.ndarray, rest: np.ndarray, guess: np.ndarray, *,
                               tol: float = 1e-13, times: np.ndarray | None = None) -> np.ndarray:
    """FPP poses (N, 8) at input angles phi_a (N,) and fixed misalignment rest = (alpha_cx, alpha_cz, x_c, z_c), solved
    at phi_a wrapped to within pi of 0 and turned back: the absolute tolerance cannot be met by sin/cos of an angle of
    1000 rad (long runs), and the pose is 2 pi-periodic in phi_a (phi_b, phi_c advanced by 2 pi, `DOUBLE_TURN`)."""
    phi_a = np.asarray(phi_a, float)
    k = np.round(phi_a / (2 * math.pi))
    inp = np.column_stack([phi_a - 2 * math.pi * k, np.broadcast_to(np.asarray(rest, float), (phi_a.size, 4))])
    turn = k[:, None] * DOUBLE_TURN
    return solve_double_batch(p, inp, np.asarray(guess, float) - turn, tol=tol, times=times) + turn


def double_quasi_static(p: CouplerParams, inp, u: np.ndarray, load_torque: float) -> tuple[np.ndarray, float]:
    """Quasi-static link tensions f (8, tension > 0) and input torque of the double coupler with massless links, no
    gravity and a load torque opposing phi_c, by virtual work: K_u^T f = Q with K_u = d|l|/du (square, 8 x 8) and
    Q = (-T_load, 0, ..., 0) on (phi_c, ...); T_in = f . d|l|/dphi_a (= T_load dphi_c/dphi_a)."""
    inp = np.asarray(inp, float)
    K = double_residual_jac(p, inp, u) / (2.0 * p.link_length)
    Q = np.zeros(8)
    Q[0] = -load_torque
    f = np.linalg.solve(K.T, Q)
    a, ba, *_ = double_points(p, inp, u)
    l1 = ba[NEXT] - a
    lh = l1 / np.linalg.norm(l1, axis=1)[:, None]
    loc = platform_points(p.gamma, p.R)
    da = loc @ (rot_y(inp[0]) @ SKEW_Y).T  # d a_k / d phi_a
    dl = np.concatenate([-np.einsum("ij,ij->i", lh, da), np.zeros(4)])
    return f, float(f @ dl)
