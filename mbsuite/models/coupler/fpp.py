"""Numerics of the coupler's forward position problem (FPP), shared by the single and the double coupler:
Gauss-Newton on the closure equations (Maniowski & Czauderna, Sect. 2.2), continuation along the input angle, and the
admissibility rule that refuses a pose with platform B through platform A (README, "Physical pose")."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...errors import GeometryError, SolverError
from .params import CouplerParams


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


#: the admissibility rule in words, used by every error that refuses a pose (README "Physical pose")
ADMISSIBLE = ("admissible poses keep every link's axial component positive along both shaft axes it joins "
              "(l_k . s > 0): at l_k . s <= 0 a joint centre of one platform lies on or behind the other platform's "
              "plane, i.e. the platform discs would interpenetrate; roughly e_y > R*alpha")


def no_physical(p: CouplerParams, tilt: float, exc: SolverError, inputs: str = "") -> None:
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
