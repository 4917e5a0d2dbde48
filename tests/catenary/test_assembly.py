"""The assembled catenary against sources that do not use its assembly: each wire's frequencies from the tensioned
beam's closed form, the static response of the whole catenary (both wires, droppers, steady arms, messenger supports)
against a string network solved by hand in numpy, the coupled static contact force in closed form, and the Rayleigh
damping the step matrix carries. Every value below is a non-default one."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.sparse.linalg import spsolve

from mbsuite.models.catenary.fe import CW_W, MW_W, NDOF_NODE, assemble
from mbsuite.models.catenary.pantographs import TwoMassPantograph, build
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.sim import CoupledSimulation

#: one 12 m span, droppers at non-default positions (uneven elements), supports free: each wire is a pinned-pinned
#: tensioned beam over 12 m; every wire datum differs from the specification's and between the wires
WIRES = dict(n_spans=1, span_length=12.0, dropper_positions=[2.5, 6.0, 9.0], element_length=0.3, x_end=12.0,
             window_start=2.0, window_end=10.0, k_steady_arm=0.0, k_messenger_support=0.0,
             cw_mass=1.1, cw_tension=15000.0, cw_EI=300.0, mw_mass=0.8, mw_tension=11000.0, mw_EI=250.0)


def _wire_block(fe, wire: int) -> np.ndarray:
    """Free indices of one wire's DOFs (w, theta)."""
    local = fe.free % NDOF_NODE
    return np.nonzero((local == wire) | (local == wire + 1))[0]


@pytest.mark.parametrize("wire", ["cw", "mw"])
def test_each_wire_has_its_own_mass_tension_and_bending_stiffness(wire):
    """Each wire's block of the assembled M and K0 (no support springs): the first eight frequencies against the
    pinned-pinned tensioned beam, f_n = n/(2L) sqrt(T/rho) sqrt(1 + (n pi/L)^2 EI/T), with that wire's own data.
    EI carries 9 % of f_8 here, so a wire built with the other wire's EI, T or rho is off by >= 1 %. Measured
    8.6e-6 relative at f_8 (CW; both wires <= 8.7e-6: the cubic elements at 14 per wavelength); bound 1e-4 (11x).
    The wires share no mass or stiffness term."""
    p = CatenaryParams(**WIRES)
    fe = assemble(p)
    rho, T, EI = {"cw": (p.cw_mass, p.cw_tension, p.cw_EI), "mw": (p.mw_mass, p.mw_tension, p.mw_EI)}[wire]
    idx = _wire_block(fe, {"cw": CW_W, "mw": MW_W}[wire])
    K, M = fe.K0.toarray(), fe.M.toarray()
    other = np.setdiff1d(np.arange(fe.n), idx)
    assert not np.any(K[np.ix_(idx, other)]) and not np.any(M[np.ix_(idx, other)])
    f = np.sqrt(sla.eigh(K[np.ix_(idx, idx)], M[np.ix_(idx, idx)], eigvals_only=True)[:8]) / (2 * math.pi)
    L = p.span_length
    n = np.arange(1, 9)
    exact = n / (2 * L) * math.sqrt(T / rho) * np.sqrt(1 + (n * math.pi / L) ** 2 * EI / T)
    assert np.max(np.abs(f / exact - 1)) < 1e-4


#: two 40 m spans of strings (EI = 0), droppers at non-default positions and stiffness, soft supports
NET = dict(n_spans=2, span_length=40.0, dropper_positions=[8.0, 20.0, 32.0], element_length=0.25, x_end=80.0,
           window_start=10.0, window_end=70.0, cw_EI=0.0, mw_EI=0.0, cw_tension=15000.0, mw_tension=11000.0,
           k_dropper=5000.0, k_steady_arm=2000.0, k_messenger_support=3000.0)


def _string_network(p: CatenaryParams) -> tuple[np.ndarray, np.ndarray]:
    """Hand-built stiffness of the catenary as two strings through its key points (supports and droppers): a string
    segment of length l under tension T is a spring T/l between its end points; droppers join CW and MW, steady arms
    tie the CW and messenger supports the MW to the ground; both wires pinned at the two ends. Returns the key
    points' positions and the (2 n_key) x (2 n_key) stiffness (CW rows first), pinned rows kept as identity."""
    L = p.span_length
    keys = sorted({s * L for s in range(p.n_spans + 1)} | {s * L + d for s in range(p.n_spans)
                                                           for d in p.dropper_positions})
    xk = np.array(keys)
    m = xk.size
    K = np.zeros((2 * m, 2 * m))
    for off, T in ((0, p.cw_tension), (m, p.mw_tension)):
        for i in range(m - 1):
            k = T / (xk[i + 1] - xk[i])
            a, b = off + i, off + i + 1
            K[a, a] += k
            K[b, b] += k
            K[a, b] -= k
            K[b, a] -= k
    for i, x in enumerate(xk):
        if abs(x / L - round(x / L)) < 1e-12:  # a support
            K[i, i] += p.k_steady_arm
            K[m + i, m + i] += p.k_messenger_support
        else:  # a dropper
            K[i, i] += p.k_dropper
            K[m + i, m + i] += p.k_dropper
            K[i, m + i] -= p.k_dropper
            K[m + i, i] -= p.k_dropper
    for j in (0, m - 1, m, 2 * m - 1):
        K[j, :] = 0.0
        K[:, j] = 0.0
        K[j, j] = 1.0
    return xk, K


def _fe_key_dofs(fe, xk: np.ndarray) -> np.ndarray:
    """Free indices of the CW w then MW w at the key points (-1 where pinned)."""
    nodes = np.array([int(np.argmin(np.abs(fe.x - x))) for x in xk])
    assert np.allclose(fe.x[nodes], xk, atol=1e-12)
    return np.concatenate([fe.full_to_free[NDOF_NODE * nodes + CW_W], fe.full_to_free[NDOF_NODE * nodes + MW_W]])


@pytest.mark.parametrize("wire", ["cw", "mw"])
def test_static_point_load_against_a_hand_built_string_network(wire):
    """A 1 kN point load at a dropper (on the CW, or on the MW) of the assembled catenary with linear droppers
    (K0 + Kd, EI = 0) against the hand-built network (`_string_network`) solved with numpy: the displacements of both
    wires at every support and dropper. Exercises both tensions, the dropper stiffness and its CW-MW connection, the
    steady arms and the messenger supports at non-default values (any one of them taken from its neighbour in the
    table, e.g. the steady arm at the messenger support's 3 kN/m, moves the answer by >= 4 %). The strings kink at
    the key points, which the FE's C1 cubics round off: first order in the element length (measured 2.96e-3,
    1.48e-3, 7.4e-4 of the largest displacement at 0.5, 0.25, 0.125 m); at 0.25 m the bound is 5e-3 (3.4x)."""
    p = CatenaryParams(**NET)
    fe = assemble(p)
    xk, Kn = _string_network(p)
    m = xk.size
    j = int(np.argmin(np.abs(xk - 60.0))) + (m if wire == "mw" else 0)  # the dropper at 20 m into the second span
    fn = np.zeros(2 * m)
    fn[j] = 1000.0
    wn = np.linalg.solve(Kn, fn)
    dofs = _fe_key_dofs(fe, xk)
    f = np.zeros(fe.n)
    f[dofs[j]] = 1000.0
    w = spsolve((fe.K0 + fe.Kd).tocsc(), f)
    w_fe = np.where(dofs >= 0, w[np.maximum(dofs, 0)], 0.0)
    assert np.max(np.abs(w_fe - wn)) < 5e-3 * np.max(np.abs(wn))
    assert np.max(np.abs(wn)) > 0.05  # the load moves the wires (m)


@pytest.mark.parametrize("x_start", [0.0, 40.0])
def test_static_contact_force_in_closed_form(x_start):
    """The coupled static state of the 2-mass pantograph against the wire: the frame spring k2 (referenced to the
    undisturbed CW level) in series with the head spring k1, the contact spring k_c and the wire's static compliance
    c at the contact point, pushed by F0: f = F0 / (1 + k2 (1/k1 + 1/k_c + c)). At the pinned end c = 0; at the
    interior support (CW level there, w0 = 0) c is the string network's (strings, EI = 0). Non-default F0, k1, k2,
    k_c. Measured: 0 at the pinned end (bound 1e-12 relative); 9.1e-5 relative at the support, the FE's rounding of
    the strings' kinks (`test_static_point_load_against_a_hand_built_string_network`; bound 5e-4, 5.5x), where the
    wire's compliance is 11 % of the force's (dropping it is off by 8 %)."""
    p = CatenaryParams(**{**NET, "x_start": x_start, "window_start": 50.0}, F0=95.0, k1=3000.0, k2=400.0,
                       k_contact=2000.0)
    fe = assemble(p)
    pan = TwoMassPantograph(p.m1, p.k1, p.c1, p.m2, p.k2, p.c2, p.F0)
    ps = CoupledSimulation(fe, pan, 200 / 3.6, 2e-4, "linear").start(x_start, 80.0)
    c = 0.0
    if x_start > 0:
        xk, Kn = _string_network(p)
        j = int(np.argmin(np.abs(xk - x_start)))
        c = float(np.linalg.solve(Kn, np.eye(xk.size * 2)[j])[j])
        assert c > 1e-4  # m/N: the wire gives noticeably
    expect = p.F0 / (1 + p.k2 * (1 / p.k1 + 1 / p.k_contact + c))
    assert ps.static_force == pytest.approx(expect, rel=1e-12 if x_start == 0 else 5e-4)


def test_rayleigh_damping_ratio_at_both_matching_frequencies_and_on_the_wires_only():
    """C = alpha M + beta K0 has the modal damping ratio zeta(w) = alpha/(2w) + beta w/2 (Rayleigh). With non-default
    zeta, f_damp1, f_damp2: zeta(w) equals zeta at both matching frequencies (closed form; measured 1e-16, bound
    1e-14: a few roundings of two products), and the damping the step matrix S = M + hC + h^2 K carries,
    (S - M - h^2 (K0 + Kd)) / h, is alpha M + beta K0 with alpha, beta from solving those two conditions here (numpy):
    the droppers undamped (measured 1.8e-15 relative; bound 2e-14, 11x; a Rayleigh term on the droppers' stiffness too
    is 5e-2 off)."""
    p = CatenaryParams(**WIRES, zeta=0.02, f_damp1=2.0, f_damp2=35.0)
    a, b = p.rayleigh()
    for f in (p.f_damp1, p.f_damp2):
        w = 2 * math.pi * f
        assert a / (2 * w) + b * w / 2 == pytest.approx(p.zeta, rel=1e-14)
    w1, w2 = 2 * math.pi * p.f_damp1, 2 * math.pi * p.f_damp2
    a_ref, b_ref = np.linalg.solve([[1 / (2 * w1), w1 / 2], [1 / (2 * w2), w2 / 2]], [p.zeta, p.zeta])
    fe = assemble(p)
    dt = 1e-3
    sim = CoupledSimulation(fe, TwoMassPantograph(p.m1, p.k1, p.c1, p.m2, p.k2, p.c2, p.F0), 100 / 3.6, dt, "linear")
    h = dt / 2
    C = ((sim.S - fe.M - h * h * (fe.K0 + fe.Kd)) / h).toarray()
    C_ref = a_ref * fe.M.toarray() + b_ref * fe.K0.toarray()
    assert np.max(np.abs(C - C_ref)) < 2e-14 * np.max(np.abs(C_ref))


def test_eppinger_section_parameters_reach_the_pantograph_under_the_wire():
    """The scene's [pantograph] params reach the Eppinger pantograph the catenary builds: at the supply pressure the
    pantograph model solves for a 120 N static force (its own root finder on its own linkage), the catenary-built
    pantograph presses the wire with 120 N (measured 9.5e-9 N off; bound 1e-7 N, 10x), on both engine paths."""
    from mbsuite.models.pantograph.under_wire import pressure_for_static_force

    p = CatenaryParams(element_length=0.5, x_end=30.0, window_start=10.0, window_end=28.0)
    pg = pressure_for_static_force(120.0)
    for engine in ("reference", "mujoco"):
        pan = build("eppinger", p, engine, 1e-4, section={"params": {"Pg": pg}}, contact="unilateral")
        assert pan.static(0.0, p.k_contact) == pytest.approx(120.0, abs=1e-7), engine
