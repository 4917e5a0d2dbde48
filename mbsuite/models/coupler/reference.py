"""Hand-derived kinematics of the single and double 4-link coupler (plain numpy; Maniowski & Czauderna, Sect. 2,
Eqs 2-7, 12-13).

Conventions (README, "Conventions and geometry"):
- base frame: y is the input-shaft axis; platforms lie in y = const planes; A's centre is the origin.
- local S-joint centres of every platform: p_k = R (cos psi_k, 0, sin psi_k), psi_k = pi/2+g, pi/2-g, -pi/2+g, -pi/2-g.
- R^a = R_y(phi_a) (Eq 2); R^b = R_z(alpha_bz) R_x(alpha_bx) R_y(phi_b) (inclination fixed in space, then spin).
- single coupler: link k joins a_k to b_{k+1} (k mod 4); nominal phi_b = phi_a - pi/2; o^b = (x_b, e_y + y_b, z_b).
- double coupler: shaft b carries BA (local points p_k) and BC (local points R_y(phi_bc) p_k + (0, l_b, 0));
  shaft c (points p_k) sits at o^c = (x_c, 2 e_y + l_b + y_c, z_c), R^c = R_z(a_cz) R_x(a_cx) R_y(phi_c).
  Coupler 1: a_k -- ba_{k+1}; coupler 2 (mirror image of coupler 1 in shaft b's mid-plane): c_k -- bc_{k+1}.
  Nominal: phi_b = phi_a - pi/2, phi_c = phi_a + phi_bc.
- mechanism Jacobian (Eqs 12-13, physical sign): l_dot = J w, w = (v_o, omega) of platform B at o^b in base axes,
  row k = [l_k^T, ((b_k - o^b) x l_k)^T] with l_k the unit link vector. The paper's printed Eq (15) is the transposed
  matrix with the moment rows negated ((o - b) x l, Eq 13) and the rows ordered (x, z, -y | m_x, m_z, -m_y):
  see `paper_eq15_layout`.
- batched double-coupler FPP (`solve_double_batch`, `solve_double_wrapped_batch`): the same equations and tolerance for
  N poses at once (numpy, batched 8 x 8 solves), for the samples of a run; `solve_double` stays the readable reference.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...errors import GeometryError, ParameterError, SolverError
from .params import CouplerParams

EY = np.array([0.0, 1.0, 0.0])


# ----------------------------------------------------------------------------------------------------------- rotations
def rot_x(a: float) -> np.ndarray:
    """Rotation about x by a [rad]."""
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a: float) -> np.ndarray:
    """R_y as printed for R^a in Eq (2)."""
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a: float) -> np.ndarray:
    """Rotation about z by a [rad]."""
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrix: skew(v) @ u = v x u."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


_SX, _SY, _SZ = skew(np.array([1.0, 0, 0])), skew(EY), skew(np.array([0, 0, 1.0]))


def shaft_rotation(alpha_x: float, alpha_z: float, phi: float) -> np.ndarray:
    """R = R_z(alpha_z) R_x(alpha_x) R_y(phi)."""
    return rot_z(alpha_z) @ rot_x(alpha_x) @ rot_y(phi)


def shaft_rotation_derivs(alpha_x: float, alpha_z: float, phi: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(dR/dalpha_x, dR/dalpha_z, dR/dphi) of `shaft_rotation`."""
    Rz, Rx, Ry = rot_z(alpha_z), rot_x(alpha_x), rot_y(phi)
    return Rz @ _SX @ Rx @ Ry, _SZ @ Rz @ Rx @ Ry, Rz @ Rx @ Ry @ _SY


# ------------------------------------------------------------------------------------------------------------ geometry
def platform_points(gamma: float, R: float = 1.0) -> np.ndarray:
    """Local S-joint centres (4, 3): R (cos psi, 0, sin psi), psi = pi/2+g, pi/2-g, -pi/2+g, -pi/2-g
    (README, "Conventions and geometry")."""
    s, c = math.sin(gamma), math.cos(gamma)
    return R * np.array([[-s, 0.0, c], [s, 0.0, c], [s, 0.0, -c], [-s, 0.0, -c]])


NEXT = np.array([1, 2, 3, 0])  # link k joins point k of the driving side to point k+1 of the driven side


def bc_points(p: CouplerParams) -> np.ndarray:
    """Local points of platform BC in shaft-b coordinates: R_y(phi_bc) p_k + (0, l_b, 0)."""
    return platform_points(p.gamma, p.R) @ rot_y(p.phi_bc).T + np.array([0.0, p.l_b, 0.0])


# --------------------------------------------------------------------------------------------------- Gauss-Newton FPP
def gauss_newton(
    fun: Callable[[np.ndarray], np.ndarray],
    jac: Callable[[np.ndarray], np.ndarray],
    u0: np.ndarray,
    *,
    tol: float = 1e-13,
    max_iter: int = 50,
    what: str = "FPP",
) -> tuple[np.ndarray, int]:
    """Gauss-Newton u <- u - lstsq(J, r) until |r|_inf <= tol (Sect. 2.2). Raises SolverError with the residual."""
    u = np.array(u0, dtype=float)
    r = fun(u)
    for it in range(max_iter):
        if not np.all(np.isfinite(r)):
            break
        if np.max(np.abs(r)) <= tol:
            return u, it
        du = np.linalg.lstsq(jac(u), r, rcond=None)[0]
        u = u - du
        r = fun(u)
    res = float(np.max(np.abs(r))) if np.all(np.isfinite(r)) else float("nan")
    raise SolverError(f"{what}: Gauss-Newton did not converge in {max_iter} iterations (residual |r|_inf = {res:.3e}, "
                      f"tolerance {tol:.1e})")


# ------------------------------------------------------------------------------------------------------ single coupler
@dataclass(frozen=True)
class SinglePose:
    """Solved pose of the single coupler: inputs (phi_a, alpha_bx, alpha_bz) and unknowns u = (phi_b, x_b, y_b, z_b)."""

    phi_a: float
    alpha_bx: float
    alpha_bz: float
    u: np.ndarray

    @property
    def phi_b(self) -> float:
        """Output angle phi_b [rad] (first FPP unknown)."""
        return float(self.u[0])


def single_points(p: CouplerParams, phi_a: float, alpha_bx: float, alpha_bz: float, u: np.ndarray):
    """(a, b, o_b, R_b): base-frame joint centres of A (Eq 2) and B (Eq 3), B's centre and rotation."""
    loc = platform_points(p.gamma, p.R)
    a = loc @ rot_y(phi_a).T
    Rb = shaft_rotation(alpha_bx, alpha_bz, u[0])
    ob = np.array([u[1], p.e_y + u[2], u[3]])
    b = loc @ Rb.T + ob
    return a, b, ob, Rb


def single_residual(p: CouplerParams, phi_a: float, alpha_bx: float, alpha_bz: float, u: np.ndarray) -> np.ndarray:
    """Eq (4): l_k^T l_k - l^2 with l_k = b_{k+1} - a_k (Eq 5)."""
    a, b, _, _ = single_points(p, phi_a, alpha_bx, alpha_bz, u)
    lv = b[NEXT] - a
    return np.einsum("ij,ij->i", lv, lv) - p.link_length**2


def single_residual_jac(p: CouplerParams, phi_a: float, alpha_bx: float, alpha_bz: float, u: np.ndarray) -> np.ndarray:
    """d(Eq 4)/du, u = (phi_b, x_b, y_b, z_b): 2 l_k^T [dR^b/dphi_b b_loc, I]."""
    a, b, _, _ = single_points(p, phi_a, alpha_bx, alpha_bz, u)
    lv = b[NEXT] - a
    loc = platform_points(p.gamma, p.R)[NEXT]
    dphi = loc @ shaft_rotation_derivs(alpha_bx, alpha_bz, u[0])[2].T
    return 2.0 * np.column_stack([np.einsum("ij,ij->i", lv, dphi), lv])


#: the admissibility rule in words, used by every error that refuses a pose (README "Physical pose")
ADMISSIBLE = ("admissible poses keep every link's axial component positive along both shaft axes it joins "
              "(l_k . s > 0): at l_k . s <= 0 a joint centre of one platform lies on or behind the other platform's "
              "plane, i.e. the platform discs would interpenetrate; roughly e_y > R*alpha")


def _no_physical(p: CouplerParams, tilt: float, exc: SolverError, inputs: str = "") -> None:
    """Re-raise a Gauss-Newton failure as GeometryError when the inclination makes the pose unphysical
    (e_y < ~1.5 R tilt: platform B would reach platform A's plane), else re-raise the SolverError."""
    if p.e_y < 1.5 * p.R * tilt:
        at = f" at {inputs}" if inputs else ""
        raise GeometryError(f"no physical pose{at}: e_y = {p.e_y:g} m is too small for a relative inclination of "
                            f"{tilt:.4g} rad (need e_y > ~R*alpha = {p.R * tilt:.4g} m); platform B would cross "
                            f"platform A ({ADMISSIBLE}) [{exc}]") from exc
    raise exc


def check_physical(p: CouplerParams, links: np.ndarray, axes: list[np.ndarray], what: str, inputs: str = "") -> None:
    """The admissibility rule: every link must leave the driving platform and reach the driven one from the same side,
    l_k . s > 0 for both shaft axes s. Otherwise a joint centre lies on or behind the other platform's plane: the
    platform discs would interpenetrate (platform B crossed A; e_y too small for the inclination). The FPP equations
    (4) still have a solution there (an independent solver converges to it); it is refused as GeometryError naming
    the inputs, the link and its axial component."""
    for s in axes:
        ax = links @ s / p.link_length
        k = int(np.argmin(ax))
        if ax[k] <= 0.0:
            at = f" at {inputs}" if inputs else ""
            raise GeometryError(
                f"{what}{at}: no physical pose - platform B would cross platform A (link {k + 1}'s axial component "
                f"{ax[k]:+.3g} l <= 0); e_y = {p.e_y:g} m is too small for this misalignment ({ADMISSIBLE})")


def _single_inputs(phi_a: float, alpha_bx: float, alpha_bz: float) -> str:
    return f"phi_a = {phi_a:.6g} rad, alpha_bx = {alpha_bx:.6g} rad, alpha_bz = {alpha_bz:.6g} rad"


def _double_inputs(inp: np.ndarray) -> str:
    return ", ".join(f"{k} = {v:.6g} {u}" for k, v, u in zip(DOUBLE_INPUTS, inp, ("rad", "rad", "rad", "m", "m"),
                                                                 strict=True))


def solve_single(p: CouplerParams, phi_a: float, alpha_bx: float = 0.0, alpha_bz: float = 0.0,
                 guess: np.ndarray | None = None, *, tol: float = 1e-13) -> SinglePose:
    """Forward position problem of the single coupler (Gauss-Newton on Eq 4). Physical pose or GeometryError."""
    if p.e_y == 0.0 and (alpha_bx or alpha_bz):
        raise GeometryError(f"single coupler FPP at {_single_inputs(phi_a, alpha_bx, alpha_bz)}: e_y = 0 (coplanar "
                            f"platforms) admits no inclined physical pose; platform B would cross platform A "
                            f"({ADMISSIBLE})")
    u0 = np.array([phi_a - math.pi / 2, 0.0, 0.0, 0.0]) if guess is None else np.asarray(guess, float)
    try:
        u, _ = gauss_newton(lambda u: single_residual(p, phi_a, alpha_bx, alpha_bz, u),
                            lambda u: single_residual_jac(p, phi_a, alpha_bx, alpha_bz, u), u0,
                            tol=tol * p.R**2, what=f"single coupler FPP at phi_a = {phi_a:.6g}")
    except SolverError as exc:
        _no_physical(p, math.hypot(alpha_bx, alpha_bz), exc, _single_inputs(phi_a, alpha_bx, alpha_bz))
    a, b, _, Rb = single_points(p, phi_a, alpha_bx, alpha_bz, u)
    if p.e_y > 0.0:
        check_physical(p, b[NEXT] - a, [EY, Rb @ EY], "single coupler FPP", _single_inputs(phi_a, alpha_bx, alpha_bz))
    return SinglePose(phi_a, alpha_bx, alpha_bz, u)


def _ramp_single(p: CouplerParams, phi_a: float, alpha_bx: float, alpha_bz: float, n: int = 8) -> SinglePose:
    """Continuation in the inclination from the aligned pose (exact there) to (alpha_bx, alpha_bz)."""
    pose = solve_single(p, phi_a)
    for s in np.linspace(0.0, 1.0, n + 1)[1:]:
        pose = solve_single(p, phi_a, s * alpha_bx, s * alpha_bz, pose.u)
    return pose


def continuation(step: Callable[[float, np.ndarray], np.ndarray], u0: np.ndarray, phis: np.ndarray,
                 jump: Callable[[np.ndarray, np.ndarray, float], float], what: str,
                 max_halvings: int = 8) -> np.ndarray:
    """Follow a solution branch along phis (first entry solved already as u0), predicting with the last increment and
    halving the step whenever the corrector jumps (jump(u_prev, u_new, dphi) > 1). Raises SolverError on failure."""
    out = np.empty((phis.size, u0.size))
    out[0] = u0
    u_prev, du_prev, phi_prev = u0.copy(), np.zeros_like(u0), phis[0]
    for i in range(1, phis.size):
        target = phis[i]
        h = target - phi_prev
        while phi_prev < target - 1e-15 or phi_prev > target + 1e-15:
            for _ in range(max_halvings + 1):
                hh = min(h, target - phi_prev) if h > 0 else max(h, target - phi_prev)
                frac = hh / (phis[i] - phis[i - 1])
                try:
                    u_new = step(phi_prev + hh, u_prev + du_prev * frac)
                    ok = jump(u_prev, u_new, hh) <= 1.0
                except (SolverError, GeometryError):
                    ok = False
                    err = True
                else:
                    err = False
                if ok:
                    break
                h = hh / 2
            else:
                kind = "did not converge" if err else "jumped to another branch"
                raise SolverError(f"{what}: continuation {kind} at phi_a = {phi_prev:.6g} after {max_halvings} "
                                  "step halvings")
            du_prev = (u_new - u_prev) * ((phis[i] - phis[i - 1]) / hh)
            u_prev, phi_prev = u_new, phi_prev + hh
        out[i] = u_prev
    return out


@dataclass
class SingleRevolution:
    """Single-coupler FPP over one revolution: phi_a (n,) and u (n, 4) = (phi_b, x_b, y_b, z_b)."""
    phi_a: np.ndarray
    u: np.ndarray  # (n, 4): phi_b, x_b, y_b, z_b
    alpha_bx: float
    alpha_bz: float


def single_revolution(p: CouplerParams, alpha_bx: float = 0.0, alpha_bz: float = 0.0, n: int = 181,
                      phi_start: float = 0.0) -> SingleRevolution:
    """FPP over one revolution of phi_a (n samples including both ends) by continuation; no branch jumps (checked)."""
    phis = phi_start + np.linspace(0.0, 2 * math.pi, n)
    u0 = _ramp_single(p, phis[0], alpha_bx, alpha_bz).u

    def step(phi: float, guess: np.ndarray) -> np.ndarray:
        return solve_single(p, phi, alpha_bx, alpha_bz, guess).u

    def jump(u_prev: np.ndarray, u_new: np.ndarray, dphi: float) -> float:
        # output angle must follow the input within 0.5 dphi + 0.05 rad; centre within 0.1 R per step
        dang = abs((u_new[0] - u_prev[0]) - dphi) / (0.5 * abs(dphi) + 0.05)
        dpos = np.max(np.abs(u_new[1:] - u_prev[1:])) / (0.1 * p.R)
        return max(dang, dpos)

    try:
        u = continuation(step, u0, phis, jump, "single coupler FPP")
    except SolverError as exc:
        _no_physical(p, math.hypot(alpha_bx, alpha_bz), exc, f"alpha_bx = {alpha_bx:.6g} rad, alpha_bz = "
                     f"{alpha_bz:.6g} rad over a revolution of phi_a")
    return SingleRevolution(phis, u, alpha_bx, alpha_bz)


# -------------------------------------------------------------------------------------------------- mechanism Jacobian
def mechanism_jacobian(links_from: np.ndarray, links_to: np.ndarray, o: np.ndarray) -> np.ndarray:
    """Eqs (12)-(13), physical sign: row k = [l_k^T, ((b_k - o) x l_k)^T], l_k unit vector from a_k to b_k, so that
    l_dot = J (v_o, omega) for a rigid motion of the platform carrying b_k."""
    lv = links_to - links_from
    lh = lv / np.linalg.norm(lv, axis=1)[:, None]
    return np.hstack([lh, np.cross(links_to - o, lh)])


def single_jacobian(p: CouplerParams, pose: SinglePose | None = None) -> np.ndarray:
    """Mechanism Jacobian (4 x 6) of the single coupler at a solved pose (default: phi_a = 0, aligned, i.e. the
    coplanar pose of Eq 15 when e_y = 0)."""
    if pose is None:
        pose = SinglePose(0.0, 0.0, 0.0, np.array([-math.pi / 2, 0.0, 0.0, 0.0]))
    a, b, ob, _ = single_points(p, pose.phi_a, pose.alpha_bx, pose.alpha_bz, pose.u)
    return mechanism_jacobian(a, b[NEXT], ob)


EQ15 = np.array([
    [-0.7071, 0.7071, 0.7071, -0.7071],
    [-0.7071, -0.7071, 0.7071, 0.7071],
    [0, 0, 0, 0],
    [0, 0, 0, 0],
    [0, 0, 0, 0],
    [-0.8829, 0.8829, -0.8829, 0.8829],
])  # Eq (15), printed 6 x 4 (one column per link)


def paper_eq15_layout(J: np.ndarray) -> np.ndarray:
    """Our 4 x 6 J (columns v_x, v_y, v_z, w_x, w_y, w_z; rows = links 1..4) in the paper's printed layout: the 6 x 4
    transpose with Eq (13)'s moment sign ((o - b) x l = -our moment) and rows (x, z, -y | m_x, m_z, -m_y), i.e. a proper
    frame (x, z, -y) whose third axis is the shaft (README, "Conventions and geometry")."""
    Jp = np.vstack([J[:, :3].T, -J[:, 3:].T])  # 6 x 4, Eq (13) sign
    rows = [0, 2, 1, 3, 5, 4]
    sign = np.array([1, 1, -1, 1, 1, -1])[:, None]
    return sign * Jp[rows]


# ---------------------------------------------------------------------------------------------- rank, SVD and screws
RANK_RTOL = 1e-9  # singular values below RANK_RTOL * sigma_max count as zero (documented relative tolerance)


@dataclass
class Screw:
    """Instantaneous screw of a twist (v at o, omega): unit axis, the point of the axis nearest to o, pitch
    h = omega.v / |omega|^2 (inf for a pure translation, whose axis is v/|v| through o), magnitude |omega| (or |v|)."""

    axis: np.ndarray
    point: np.ndarray
    pitch: float
    magnitude: float

    def as_dict(self) -> dict:
        """The screw as a dict (axis, point, pitch, magnitude)."""
        return {"axis": self.axis, "point": self.point, "pitch": self.pitch, "magnitude": self.magnitude}


def screw_to_twist(sc: Screw) -> np.ndarray:
    """Unit-omega twist (v at the origin, omega) of a finite-pitch screw: v = point x axis + pitch axis (inverse of
    `twist_to_screw` for |omega| = 1)."""
    return np.concatenate([np.cross(sc.point, sc.axis) + sc.pitch * sc.axis, sc.axis])


SINGLE_UNKNOWNS = ("phi_b", "x_b", "y_b", "z_b")  # single-coupler FPP unknowns (Eqs 4-5)


def twist_to_screw(t: np.ndarray, o: np.ndarray, eps: float = 1e-12) -> Screw:
    """Screw of the twist t = (v at o, omega): axis omega/|omega|, point o + omega x v/|omega|^2, pitch
    omega.v/|omega|^2; a pure translation (|omega| ~ 0) has infinite pitch and axis v/|v| through o."""
    v, w = t[:3], t[3:]
    nw = float(np.linalg.norm(w))
    if nw <= eps * max(1.0, float(np.linalg.norm(v))):
        nv = float(np.linalg.norm(v))
        return Screw(v / nv, o.copy(), math.inf, nv)
    return Screw(w / nw, o + np.cross(w, v) / nw**2, float(w @ v) / nw**2, nw)


@dataclass
class JacobianAnalysis:
    """SVD analysis of a mechanism Jacobian: singular values, rank, condition number, null space as screws."""
    J: np.ndarray
    singular_values: np.ndarray
    rank: int
    cond: float
    null_space: np.ndarray  # (6, 6 - rank): orthonormal basis from the SVD
    svd_screws: list[Screw]  # screws of the SVD basis vectors (basis-dependent pitches)
    principal_screws: list[Screw]  # basis-independent principal screws of the null space


def principal_twists(N: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Principal basis of a screw system spanned by the columns of N (6 x k): pure translations (omega = 0) first, then
    the remaining twists diagonalising the pitch form omega.v against omega.omega (generalised eigenproblem)."""
    k = N.shape[1]
    W = N[3:]
    _, s, Vt = np.linalg.svd(W)
    r = int(np.sum(s > tol * max(1.0, s[0] if s.size else 0.0)))
    trans = N @ Vt[r:].T  # omega = 0
    rot = N @ Vt[:r].T
    out = []
    if trans.shape[1]:
        out.append(trans)
    if r:
        Wr, Vr = rot[3:], rot[:3]
        Qw = Wr.T @ Wr
        Qh = 0.5 * (Wr.T @ Vr + Vr.T @ Wr)
        # generalised symmetric eigenproblem via Cholesky of Qw (positive definite on the rotational part)
        Lc = np.linalg.cholesky(Qw)
        Li = np.linalg.inv(Lc)
        _, vecs = np.linalg.eigh(Li @ Qh @ Li.T)
        out.append(rot @ (Li.T @ vecs))
    T = np.hstack(out) if out else np.zeros((6, 0))
    assert T.shape[1] == k
    return T


def analyse_jacobian(J: np.ndarray, o: np.ndarray, rtol: float = RANK_RTOL) -> JacobianAnalysis:
    """Rank (SVD, relative tolerance rtol), condition number sigma_max/sigma_min of the 4 singular values (Eq 14;
    inf when sigma_min == 0), null space -> free motions of the platform as screws (Sect. 2.3)."""
    _, s, Vt = np.linalg.svd(J)
    rank = int(np.sum(s > rtol * s[0]))
    smin = s[min(J.shape) - 1]
    cond = math.inf if smin <= rtol * s[0] * 1e-6 else float(s[0] / smin)
    N = Vt[rank:].T
    svd_screws = [twist_to_screw(N[:, i], o) for i in range(N.shape[1])]
    P = principal_twists(N)
    principal = [twist_to_screw(P[:, i], o) for i in range(P.shape[1])]
    # order: translations first, then by the dominant axis component x, y, z
    principal.sort(key=lambda sc: (math.isfinite(sc.pitch), int(np.argmax(np.abs(sc.axis)))))
    return JacobianAnalysis(J, s, rank, cond, N, svd_screws, principal)


def cond_asymptotic(p: CouplerParams) -> float:
    """Condition number of the single coupler's J at the aligned pose, in closed form (README):
    sigma_min = 2 e_y / l and, while the moment singular value is the largest, sigma_max = 2 R cos(pi/4 - g) l0 / l
    with l0 = 2 R sin(pi/4 - g)  =>  chi = R^2 cos(2 g) / e_y.

    J mixes force (unit) and moment (length) rows, so chi depends on the length unit: the paper's R = 1 gives
    cos(2 g)/e_y. Below R ~ 0.85 (gamma = 17 deg) a translational singular value (~ sqrt 2) is the largest and there is
    no such closed form: ParameterError."""
    if p.e_y == 0:
        return math.inf
    l0 = 2 * p.R * math.sin(math.pi / 4 - p.gamma)
    l = math.hypot(l0, p.e_y)
    s_moment = 2 * p.R * math.cos(math.pi / 4 - p.gamma) * l0 / l
    if s_moment < math.sqrt(2.0) * 1.001:  # the in-plane translational singular values are sqrt 2 (l0/l) + O(e_y)
        raise ParameterError(
            f"closed-form condition number needs the moment singular value to dominate (R = {p.R} is too small "
            f"for gamma = {p.gamma}: 2 R cos(pi/4 - gamma) l0/l = {s_moment:.4g} < sqrt 2)")
    return p.R**2 * math.cos(2 * p.gamma) / p.e_y


def pitch_of_mixed_basis(s1: Screw, s2: Screw, theta: float) -> tuple[float, float]:
    """Pitches of the orthonormal basis rotated by theta from two zero-pitch principal rotations (unit omegas):
    t1' = cos t1 + sin t2, t2' = -sin t1 + cos t2 (used to show Table 2's pitches are basis artefacts)."""
    t1, t2 = screw_to_twist(s1), screw_to_twist(s2)
    c, s = math.cos(theta), math.sin(theta)
    return twist_to_screw(c * t1 + s * t2, np.zeros(3)).pitch, twist_to_screw(-s * t1 + c * t2, np.zeros(3)).pitch


# ------------------------------------------------------------------------------------------------------ double coupler
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
        _no_physical(p, _double_tilt(p, inp), exc, _double_inputs(inp))
    if p.e_y > 0.0:
        a, ba, bc, c, _, Rb, _, Rc = double_points(p, inp, u)
        check_physical(p, ba[NEXT] - a, [EY, Rb @ EY], "double coupler FPP (coupler A-BA)", _double_inputs(inp))
        check_physical(p, c - bc[NEXT], [Rb @ EY, Rc @ EY], "double coupler FPP (coupler BC-C)", _double_inputs(inp))
    return u


def _double_tilt(p: CouplerParams, inp: np.ndarray) -> float:
    """Rough relative inclination of shaft b against a or c: output inclination plus lateral offset over the span."""
    return float(math.hypot(inp[1], inp[2]) + math.hypot(inp[3], inp[4]) / (p.l_b + 2 * p.e_y))


def _ramp_double(p: CouplerParams, inp: np.ndarray, n: int = 8) -> np.ndarray:
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
    u0 = _ramp_double(p, np.concatenate([[phis[0]], rest]))

    def step(phi: float, guess: np.ndarray) -> np.ndarray:
        return solve_double(p, np.concatenate([[phi], rest]), guess)

    def jump(u_prev: np.ndarray, u_new: np.ndarray, dphi: float) -> float:
        dang = max(abs((u_new[0] - u_prev[0]) - dphi), abs((u_new[5] - u_prev[5]) - dphi)) / (0.5 * abs(dphi) + 0.05)
        dpos = np.max(np.abs(np.r_[u_new[1:5], u_new[6:]] - np.r_[u_prev[1:5], u_prev[6:]])) / 0.1
        return max(dang, dpos)

    try:
        u = continuation(step, u0, phis, jump, "double coupler FPP")
    except SolverError as exc:
        _no_physical(p, _double_tilt(p, np.r_[0.0, rest]), exc, _double_inputs(np.r_[phi_start, rest]))
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
        _no_physical(p, _double_tilt(p, inp[i]), exc, _double_inputs(inp[i]))
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


def double_output_angle(p: CouplerParams, inp: np.ndarray, guess: np.ndarray | None = None) -> float:
    """Output angle phi_c [rad] of the double coupler at inputs (phi_a, alpha_cx, alpha_cz, x_c, z_c)."""
    return float(solve_double(p, inp, guess)[0])


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
    da = loc @ (rot_y(inp[0]) @ _SY).T  # d a_k / d phi_a
    dl = np.concatenate([-np.einsum("ij,ij->i", lh, da), np.zeros(4)])
    return f, float(f @ dl)
