"""The mechanism Jacobian of the single coupler, its rank, condition number and free motions as screws (Maniowski &
Czauderna, Sect. 2.3, Eqs 12-15, Table 2).

Mechanism Jacobian (Eqs 12-13, physical sign): l_dot = J w, w = (v_o, omega) of platform B at o^b in base axes,
row k = [l_k^T, ((b_k - o^b) x l_k)^T] with l_k the unit link vector. The paper's printed Eq (15) is the transposed
matrix with the moment rows negated ((o - b) x l, Eq 13) and the rows ordered (x, z, -y | m_x, m_z, -m_y):
see `paper_eq15_layout`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from .geometry import NEXT
from .params import CouplerParams
from .single import SinglePose, single_points


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
