"""Geometry of the single and double 4-link coupler shared by every path: rotations, the S-joint centres on the
platforms (Maniowski & Czauderna, Sect. 2, Eqs 1-3), the model files' mounted frames and the SS links as closures.

Conventions (README, "Conventions and geometry"):
- base frame: y is the input-shaft axis; platforms lie in y = const planes; A's centre is the origin.
- local S-joint centres of every platform: p_k = R (cos psi_k, 0, sin psi_k), psi_k = pi/2+g, pi/2-g, -pi/2+g, -pi/2-g.
- R^a = R_y(phi_a) (Eq 2); R^b = R_z(alpha_bz) R_x(alpha_bx) R_y(phi_b) (inclination fixed in space, then spin).
- link k joins point k of the driving platform to point k+1 of the driven one (`NEXT`).

Joint coordinates of the model files vs the paper's: every joint is the paper's coordinate with zero at the
assembled, aligned pose. Platform frames in the files are the *mounted* frames (`mounted_points`), so
    phi_b = q[phi_b] - pi/2 (`PHI_B_OFFSET`),   phi_c = q[phi_c] + phi_bc (`phi_c_offset`),
every other joint q = paper coordinate (x_b, y_b, z_b are deviations of o^b from (0, e_y, 0); y_c of o^c from
(0, 2 e_y + l_b, 0)). Each SS link is a closure |p(frame_b) - p(frame_a)| = length (`Closure`, `closures`); a model
file whose closures do not assemble at q = 0 is refused (`raise_on_gaps`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import ModelFileError
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


#: cross-product matrices of the base axes x, y, z
SKEW_X, SKEW_Y, SKEW_Z = skew(np.array([1.0, 0, 0])), skew(EY), skew(np.array([0, 0, 1.0]))


def shaft_rotation(alpha_x: float, alpha_z: float, phi: float) -> np.ndarray:
    """R = R_z(alpha_z) R_x(alpha_x) R_y(phi)."""
    return rot_z(alpha_z) @ rot_x(alpha_x) @ rot_y(phi)


def shaft_rotation_derivs(alpha_x: float, alpha_z: float, phi: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(dR/dalpha_x, dR/dalpha_z, dR/dphi) of `shaft_rotation`."""
    Rz, Rx, Ry = rot_z(alpha_z), rot_x(alpha_x), rot_y(phi)
    return Rz @ SKEW_X @ Rx @ Ry, SKEW_Z @ Rz @ Rx @ Ry, Rz @ Rx @ Ry @ SKEW_Y


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


# ------------------------------------------------------------------------------------- mounted frames, closures
PHI_B_OFFSET = -math.pi / 2  # phi_b = q_phi_b + PHI_B_OFFSET


def phi_c_offset(p: CouplerParams) -> float:
    """phi_c - q(phi_c) [rad]: the mounted frame of shaft c is turned by phi_bc."""
    return p.phi_bc  # phi_c = q_phi_c + phi_bc


@dataclass(frozen=True)
class Closure:
    """One SS link of a model file's spanning tree: |p(frame_b) - p(frame_a)| = length."""

    name: str
    frame_a: str
    frame_b: str
    length: float


def mounted_points(p: CouplerParams, kind: str) -> dict[str, np.ndarray]:
    """Local joint-point coordinates on each platform in the files' mounted frames."""
    loc = platform_points(p.gamma, p.R)
    out = {"A": loc, "B": loc @ rot_y(PHI_B_OFFSET).T}
    if kind == "double":
        out["BA"] = out.pop("B")
        out["BC"] = loc @ rot_y(PHI_B_OFFSET + p.phi_bc).T + np.array([0.0, p.l_b, 0.0])
        out["C"] = loc @ rot_y(phi_c_offset(p)).T
    return out


def closures(p: CouplerParams, kind: str) -> list[Closure]:
    """The SS links as closures between named joint-point frames (link k joins driving point k to driven k+1)."""
    l = p.link_length
    if kind == "single":
        return [Closure(f"link{k + 1}", f"A_S{k + 1}", f"B_S{NEXT[k] + 1}", l) for k in range(4)]
    if kind == "double":
        return ([Closure(f"link{k + 1}", f"A_S{k + 1}", f"BA_S{NEXT[k] + 1}", l) for k in range(4)]
                + [Closure(f"link{k + 5}", f"C_S{k + 1}", f"BC_S{NEXT[k] + 1}", l) for k in range(4)])
    raise ModelFileError(f"unknown coupler kind {kind!r}; valid: ['single', 'double']")


def check_kind(kind: str) -> None:
    """ModelFileError unless `kind` is a coupler kind ('single' or 'double')."""
    if kind not in ("single", "double"):
        raise ModelFileError(f"unknown coupler kind {kind!r}; valid: ['single', 'double']")


#: largest gap (relative to the link length) between a link's stated geometry and the model file at its assembled pose
#: q = 0: the files are written to 15 digits (gaps ~1e-16 l); a file rounded to 6 digits still passes, a changed link
#: length or a moved joint point fails by orders of magnitude
CLOSURE_RTOL = 1e-6


def raise_on_gaps(path: str | Path, gaps: list[tuple[str, str, float]], length: float, engine: str) -> None:
    """ModelFileError naming the file, the worst closure/body and its residual if any gap exceeds CLOSURE_RTOL x the
    link length. gaps: (closure, body, residual in m)."""
    bad = [g for g in gaps if not g[2] <= CLOSURE_RTOL * length]
    if bad:
        name, body, r = max(bad, key=lambda g: g[2] if math.isfinite(g[2]) else math.inf)
        raise ModelFileError(
            f"{path}: loop closure {name!r} (body {body!r}) does not assemble at the initial pose q = 0 ({engine}): "
            f"residual {r:.4g} m > {CLOSURE_RTOL:g} x link length {length:.6g} m ({len(bad)} of {len(gaps)} "
            "closures); the file's joint points and link lengths must match the stated geometry")
