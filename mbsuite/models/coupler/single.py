"""Hand-derived kinematics of the single 4-link coupler (plain numpy; Maniowski & Czauderna, Sect. 2, Eqs 2-5):
platform B on shaft b, o^b = (x_b, e_y + y_b, z_b), nominal phi_b = phi_a - pi/2 (conventions: `geometry`). The FPP
unknowns u = (phi_b, x_b, y_b, z_b) follow from the input phi_a and the inclination (alpha_bx, alpha_bz)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import GeometryError, SolverError
from .fpp import ADMISSIBLE, check_physical, continuation, gauss_newton, no_physical
from .geometry import EY, NEXT, platform_points, rot_y, shaft_rotation, shaft_rotation_derivs
from .params import CouplerParams

SINGLE_UNKNOWNS = ("phi_b", "x_b", "y_b", "z_b")  # single-coupler FPP unknowns (Eqs 4-5)


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


def _single_inputs(phi_a: float, alpha_bx: float, alpha_bz: float) -> str:
    return f"phi_a = {phi_a:.6g} rad, alpha_bx = {alpha_bx:.6g} rad, alpha_bz = {alpha_bz:.6g} rad"


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
        no_physical(p, math.hypot(alpha_bx, alpha_bz), exc, _single_inputs(phi_a, alpha_bx, alpha_bz))
    a, b, _, Rb = single_points(p, phi_a, alpha_bx, alpha_bz, u)
    if p.e_y > 0.0:
        check_physical(p, b[NEXT] - a, [EY, Rb @ EY], "single coupler FPP", _single_inputs(phi_a, alpha_bx, alpha_bz))
    return SinglePose(phi_a, alpha_bx, alpha_bz, u)


def ramp_single(p: CouplerParams, phi_a: float, alpha_bx: float, alpha_bz: float, n: int = 8) -> SinglePose:
    """Continuation in the inclination from the aligned pose (exact there) to (alpha_bx, alpha_bz)."""
    pose = solve_single(p, phi_a)
    for s in np.linspace(0.0, 1.0, n + 1)[1:]:
        pose = solve_single(p, phi_a, s * alpha_bx, s * alpha_bz, pose.u)
    return pose


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
    u0 = ramp_single(p, phis[0], alpha_bx, alpha_bz).u

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
        no_physical(p, math.hypot(alpha_bx, alpha_bz), exc, f"alpha_bx = {alpha_bx:.6g} rad, alpha_bz = "
                     f"{alpha_bz:.6g} rad over a revolution of phi_a")
    return SingleRevolution(phis, u, alpha_bx, alpha_bz)
