"""The `reference` path (label "kinematic") of the double-coupler run, beside the hand-derived kinematics it solves
(`double`): the rigid mechanism driven along the ramped input angle, every coordinate from the FPP and the input torque
from the power balance; and the kinematic pose at the recorded samples of a run, which the MuJoCo path compares its
output against (`kinematic_pose`).
"""

from __future__ import annotations

import math

import numpy as np

from ... import results
from ...errors import GeometryError, SolverError
from ...results import SimResult
from .double import (
    DOUBLE_TURN,
    double_residual_batch,
    double_revolution,
    solve_double,
    solve_double_wrapped_batch,
)
from .geometry import EY, rot_x, rot_y, rot_z
from .params import CouplerParams
from .scenario import closure_figure, ramp, scene_inputs, time_mean

#: largest distance (rad for angles, R for lengths) between the simulated pose and the kinematic pose of a sample that
#: still counts as the same assembly branch; the soft closures keep them ~1e-4 apart (1e-3 in the start-up ramp)
BRANCH_TOL = 0.1


def kinematic_pose(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, guess: np.ndarray,
                   times: np.ndarray | None = None, what: str = "coupler") -> np.ndarray:
    """The FPP pose (N, 8) at every sampled phi_a, all samples at once (`double.solve_double_wrapped_batch`),
    Gauss-Newton started from `guess` (the simulated pose). Same solutions as the per-sample continuation
    `kinematic_output` (tested to 1e-12); a sample that does not converge, or converges to a pose farther than
    BRANCH_TOL from its guess (another assembly branch), raises SolverError naming its time."""
    rest = np.array([inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]])
    try:
        U = solve_double_wrapped_batch(p, phi_a, rest, guess, times=times)
    except (SolverError, GeometryError) as exc:
        raise type(exc)(f"{what}: kinematic reference: {exc}") from exc
    dev = np.max(np.abs(U - guess) / np.array([1, p.R, p.R, p.R, p.R, 1, 1, 1]), axis=1)
    far = np.flatnonzero(~(dev <= BRANCH_TOL))
    if far.size:
        i = int(far[0])
        at = f"t = {times[i]:.6g} s" if times is not None else f"sample {i}"
        raise SolverError(f"{what}: the kinematic pose at {at} (phi_a = {phi_a[i]:.6g} rad) is {dev[i]:.3g} away from "
                          f"the simulated one (more than {BRANCH_TOL:g}: another assembly branch, or closures torn "
                          f"open; {far.size} of {dev.size} samples)")
    return U


def kinematic_output(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, u0: np.ndarray) -> np.ndarray:
    """phi_c from the double-coupler FPP at each sampled phi_a, one sample after the other by continuation from the
    initial pose u0 (the readable reference of `kinematic_pose`)."""
    out = np.empty_like(phi_a)
    u = u0
    rest = [inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]]
    turn = np.zeros(8)
    turn[[0, 5]] = 2 * math.pi  # phi_c and phi_b advance with phi_a
    for i, pa in enumerate(phi_a):
        guess = u.copy()
        if i:
            guess[0] += pa - phi_a[i - 1]
            guess[5] += pa - phi_a[i - 1]
        # solve at phi_a wrapped to one turn: the FPP's absolute tolerance cannot be met by sin/cos of an angle of
        # 1000 rad (long runs), and the pose is 2 pi-periodic in phi_a, phi_b, phi_c
        k = round(pa / (2 * math.pi))
        u = solve_double(p, np.array([pa - 2 * math.pi * k, *rest]), guess - k * turn) + k * turn
        out[i] = u[0]
    return out


def kinematic_derivatives(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, u0: np.ndarray,
                          h: float = 1e-4) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """FPP solution u (n, 8) along phi_a and its first and second derivatives du/dphi_a, d2u/dphi_a2 (central
    differences of converged FPP solutions, step h), one sample after the other by continuation from u0 (the readable
    reference of `kinematic_rates`)."""
    rest = [inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]]
    U, D1, D2 = (np.empty((phi_a.size, 8)) for _ in range(3))
    u = u0
    for i, pa in enumerate(phi_a):
        g = u.copy()
        if i:
            g[[0, 5]] += pa - phi_a[i - 1]
        u = solve_double(p, np.array([pa, *rest]), g)
        up = solve_double(p, np.array([pa + h, *rest]), u)
        um = solve_double(p, np.array([pa - h, *rest]), u)
        U[i], D1[i], D2[i] = u, (up - um) / (2 * h), (up - 2 * u + um) / h**2
    return U, D1, D2


def shaft_b_energy(p: CouplerParams, u: np.ndarray, du: np.ndarray) -> float:
    """Kinetic energy of shaft b (mass m_shaft_b at (0, l_b/2, 0), inertia diag(I_t, I_a, I_t) in its frame) for
    coordinates u and rates du (DOUBLE_UNKNOWNS order)."""
    _, _, xd, yd, zd, phd, axd, azd = du
    _, _, _, _, _, ph, ax, az = u
    Rz, Rx = rot_z(az), rot_x(ax)
    R = Rz @ Rx @ rot_y(ph)
    w = azd * np.array([0.0, 0.0, 1.0]) + axd * (Rz @ np.array([1.0, 0.0, 0.0])) + phd * (Rz @ Rx @ EY)
    v = np.array([xd, yd, zd]) + np.cross(w, R @ np.array([0.0, p.l_b / 2, 0.0]))
    Ib = R @ np.diag([p.i_shaft_b_trans, p.i_shaft_b_axial, p.i_shaft_b_trans]) @ R.T
    return 0.5 * p.m_shaft_b * float(v @ v) + 0.5 * float(w @ Ib @ w)


def shaft_b_energy_batch(p: CouplerParams, U: np.ndarray, dU: np.ndarray) -> np.ndarray:
    """`shaft_b_energy` for N samples (U, dU (N, 8)), vectorised: with b = R e_y the shaft axis,
    w = alpha_bz' e_z + alpha_bx' R_z e_x + phi_b' b, v = (x_b', y_b', z_b') + w x (l_b/2) b and
    E = m |v|^2 / 2 + (I_t |w|^2 + (I_a - I_t) (w . b)^2) / 2."""
    cx, sx, cz, sz = np.cos(U[:, 6]), np.sin(U[:, 6]), np.cos(U[:, 7]), np.sin(U[:, 7])
    b = np.column_stack([-sz * cx, cz * cx, sx])
    w = (dU[:, 7, None] * np.array([0.0, 0.0, 1.0]) + dU[:, 6, None] * np.column_stack([cz, sz, np.zeros_like(cz)])
         + dU[:, 5, None] * b)
    v = dU[:, 2:5] + np.cross(w, 0.5 * p.l_b * b)
    It, Ia = p.i_shaft_b_trans, p.i_shaft_b_axial
    wb = np.einsum("ni,ni->n", w, b)
    rot = It * np.einsum("ni,ni->n", w, w) + (Ia - It) * wb**2
    return 0.5 * p.m_shaft_b * np.einsum("ni,ni->n", v, v) + 0.5 * rot


def revolution_guess(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, n: int = 37) -> np.ndarray:
    """A guess (N, 8) of the FPP pose at any phi_a: one revolution by continuation (`double.double_revolution`,
    n samples, branch jumps detected), whose 2 pi-periodic part (phi_b and phi_c less phi_a) is interpolated linearly
    at phi_a mod 2 pi (within ~1e-5 of the pose for n = 37)."""
    rev = double_revolution(p, inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"], n=n)
    slope = DOUBLE_TURN / (2 * math.pi)
    per = rev.u[:-1] - rev.phi_a[:-1, None] * slope
    G = np.column_stack([np.interp(phi_a, rev.phi_a[:-1], per[:, j], period=2 * math.pi) for j in range(8)])
    return G + phi_a[:, None] * slope


def kinematic_rates(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, guess: np.ndarray, h: float = 1e-4,
                    times: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """FPP pose U (N, 8) along phi_a and du/dphi_a by central differences of converged poses (step h), all samples at
    once (the batched twin of `kinematic_derivatives`)."""
    rest = np.array([inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]])
    U = solve_double_wrapped_batch(p, phi_a, rest, guess, times=times)
    up = solve_double_wrapped_batch(p, phi_a + h, rest, U, times=times)
    um = solve_double_wrapped_batch(p, phi_a - h, rest, U, times=times)
    return U, (up - um) / (2 * h)


def run_reference(scene) -> SimResult:
    """Rigid-shaft reference: phi_a(t) from the ramped speed, all coordinates from the FPP, and the input torque from
    the power balance with massless links and no gravity or friction:
    T_in phi_a' = d/dt (E_b + I_c phi_c'^2 / 2) + T_load phi_c' (+ I_a phi_a'' phi_a'), E_b shaft b's kinetic energy.
    The FPP is solved for all samples at once, started from one revolution of continuation (`revolution_guess`)."""
    p: CouplerParams = scene.build_params()
    inp = scene_inputs(scene)
    sv = scene.solver
    dt = sv.sample_dt or 10 * sv.timestep
    t = np.arange(0.0, sv.duration + 0.5 * dt, dt)
    s = ramp(t, inp["t_ramp"])
    om = inp["omega"] * s
    al = np.gradient(om, t, edge_order=2)
    phi_a = np.concatenate([[0.0], np.cumsum(0.5 * (om[1:] + om[:-1]) * np.diff(t))])
    U, D1 = kinematic_rates(p, inp, phi_a, revolution_guess(p, inp, phi_a), times=t)
    rates = D1 * om[:, None]
    energy = shaft_b_energy_batch(p, U, rates) + 0.5 * p.i_shaft_c * rates[:, 0] ** 2
    tl = inp["load_torque"] * s
    power = np.gradient(energy, t, edge_order=2) + tl * rates[:, 0]  # second order at the ends too
    with np.errstate(divide="ignore", invalid="ignore"):
        t_in = np.where(om > 0, power / np.where(om > 0, om, 1.0), tl * D1[:, 0]) + p.i_shaft_a * al
    # closure gap of the rigid reference: |r_k| = ||l_k|^2 - l^2| at the solved poses, as a length |r_k| / (2 l)
    gap = np.max(np.abs(double_residual_batch(p, np.column_stack(
        [phi_a - 2 * math.pi * np.round(phi_a / (2 * math.pi)), np.broadcast_to(
            [inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]], (t.size, 4))]),
        U - np.round(phi_a / (2 * math.pi))[:, None] * DOUBLE_TURN)), axis=1) / (2 * p.link_length)
    signals = {"phi_a": phi_a, "phi_c": U[:, 0], "phi_c_kin": U[:, 0], "phi_c_err": np.zeros_like(t),
               "omega_c": rates[:, 0], "torque_in": t_in, "torque_out": tl, "closure_residual": gap}
    w = t >= max(sv.t_settle, inp["t_ramp"])
    st = {"torque_in_mean": time_mean(t[w], t_in[w]), "torque_in_ripple_pp": float(np.ptp(t_in[w])),
          "torque_in_ripple_quasi_static_pp": float(np.ptp(tl[w] * D1[w, 0])),
          "speed_ratio_min": float(np.min(D1[w, 0])), "speed_ratio_max": float(np.max(D1[w, 0])),
          "phi_c_kin_fluctuation_pp": float(np.ptp(phi_a[w] - U[w, 0])), "closure_residual_max": float(gap[w].max()),
          "closure_residual_max_all": float(gap.max())}
    return results.assemble(scene, t, signals, engine="reference", statistics=st, always=("phi_c_err",),
                            health=[closure_figure(st["closure_residual_max_all"], p, reference=True)])

