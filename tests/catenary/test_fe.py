"""Finite-element catenary: element matrices against closed-form wire frequencies, mesh, static state, the point-load
correction against the continuous catenary solved by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.sparse.linalg import spsolve

from mbsuite.errors import ParameterError
from mbsuite.models.catenary.fe import (
    CW_T,
    CW_W,
    NDOF_NODE,
    PointCorrection,
    assemble,
    beam_mass,
    beam_stiffness,
    build_nodes,
    hermite,
)
from mbsuite.models.catenary.params import EN50318_DROPPERS, CatenaryParams


def _pinned_wire(rho, T, EI, L, ne):
    h = L / ne
    n = 2 * (ne + 1)
    K = np.zeros((n, n))
    M = np.zeros((n, n))
    for e in range(ne):
        d = slice(2 * e, 2 * e + 4)
        K[d, d] += beam_stiffness(EI, T, h)
        M[d, d] += beam_mass(rho, h)
    keep = [i for i in range(n) if i not in (0, n - 2)]  # w = 0 at both ends
    return K[np.ix_(keep, keep)], M[np.ix_(keep, keep)]


def test_tensioned_beam_frequencies_match_closed_form():
    """Pinned-pinned tensioned Euler-Bernoulli beam: f_n = n/(2L) sqrt(T/rho) sqrt(1 + (n pi/L)^2 EI/T)."""
    rho, T, EI, L = 1.35, 20000.0, 195.0, 12.0
    K, M = _pinned_wire(rho, T, EI, L, 48)
    f = np.sqrt(sla.eigh(K, M, eigvals_only=True)[:6]) / (2 * math.pi)
    for k in range(1, 7):
        exact = k / (2 * L) * math.sqrt(T / rho) * math.sqrt(1 + (k * math.pi / L) ** 2 * EI / T)
        assert f[k - 1] == pytest.approx(exact, rel=1e-6)


def test_hermite_shape_functions_interpolate_cubics_exactly():
    h = 0.37
    for xi in (0.0, 0.2, 0.5, 0.9, 1.0):
        # w = x^3 - 2x^2 + 0.5 on [0, h]: nodal values and slopes
        w = lambda x: x**3 - 2 * x**2 + 0.5  # noqa: E731
        dw = lambda x: 3 * x**2 - 4 * x  # noqa: E731
        d = np.array([w(0), dw(0), w(h), dw(h)])
        assert hermite(xi, h) @ d == pytest.approx(w(xi * h), abs=1e-14)


def test_mesh_has_supports_and_droppers_as_nodes():
    p = CatenaryParams(element_length=0.5)
    x, sup, drop = build_nodes(p)
    assert np.allclose(x[sup], np.arange(11) * 60.0)
    expect = np.array([s * 60 + d for s in range(10) for d in EN50318_DROPPERS])
    assert np.allclose(x[drop], expect)
    assert np.max(np.diff(x)) <= 0.5 + 1e-12
    # non-aligned target length: key points still nodes, elements never longer than asked
    p2 = CatenaryParams(element_length=0.7)
    x2, sup2, drop2 = build_nodes(p2)
    assert np.allclose(x2[drop2], expect) and np.max(np.diff(x2)) <= 0.7 + 1e-12


@pytest.mark.parametrize("g", [9.81, 5.0])
def test_static_state_level_at_droppers_and_weight_balance(g):
    """The specification's static state, and the same at a non-default g and CW mass (and CW tension and EI, which
    set the sag): level at every dropper and support, the reactions carrying the wire's weight, tributary loads and
    the tensioned-beam sag, all from the parameters."""
    p = CatenaryParams(element_length=0.25) if g == 9.81 else CatenaryParams(element_length=0.25, g=g, cw_mass=1.8,
                                                                             cw_tension=17000.0, cw_EI=250.0)
    fe = assemble(p)
    w_cw = fe.w0_full[CW_W::NDOF_NODE]
    assert np.all(np.abs(w_cw[fe.droppers]) < 1e-15) and np.all(np.abs(w_cw[fe.supports]) < 1e-15)
    # reactions carry the whole CW weight
    # measured 3.6e-15 and 1.1e-15 relative (rounding over 10 spans of reactions); bound 4e-14 (11x)
    assert fe.T0.sum() + fe.support_preload.sum() == pytest.approx(p.cw_mass * p.g * p.length, rel=4e-14)
    # all droppers in tension; an interior dropper carries about its tributary length of wire
    assert np.all(fe.T0 > 0)
    trib = (36.5 - 23.5) / 2  # dropper at 30 m: half of each neighbouring 6.5 m bay
    # measured 7.4e-8 and 1.35e-7 (the unequal bays beyond the neighbours bend the wire a little); bound 1.5e-6 (11x)
    assert fe.T0[4] == pytest.approx(p.cw_mass * p.g * trib, rel=1.5e-6)
    # sag between droppers 23.5 and 30 m (equal 6.5 m bays on both sides: zero slope at the droppers by symmetry).
    # Tensioned beam EI w'''' - T w'' = q clamped over L: mid sag = qL^2/(8T) - (qL/(2T lam)) (cosh(lam L/2) - 1) /
    # sinh(lam L/2), lam = sqrt(T/EI); the string value qL^2/(8T) is 6 % larger.
    mid = int(np.argmin(np.abs(fe.x - 26.75)))
    q, L, lam = p.cw_mass * p.g, 6.5, math.sqrt(p.cw_tension / p.cw_EI)
    beam = q * L**2 / (8 * p.cw_tension) - q * L / (2 * p.cw_tension * lam) * math.tanh(lam * L / 4)
    # measured 1.1e-3 and 7.1e-4 relative (the neighbouring bays' slopes are not exactly zero); bound 2e-3 (1.8x)
    assert -w_cw[mid] == pytest.approx(beam, rel=2e-3)


def test_banded_structure():
    fe = assemble(CatenaryParams(element_length=0.5))
    K = (fe.K0 + fe.Kd).tocoo()
    assert np.max(np.abs(K.row - K.col)) == 5
    assert abs(fe.M - fe.M.T).max() < 1e-14 and abs(K.tocsr() - K.tocsr().T).max() < 1e-9


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"dropper_positions": [5.0, 70.0]}, "outside its span"),
        ({"dropper_positions": [5.0, -1.0]}, "outside its span"),
        ({"dropper_positions": [5.0, 17.0, 10.5]}, "strictly increasing"),
        ({"dropper_positions": [5.0, 5.0]}, "strictly increasing"),
        ({"cw_tension": -20000.0}, "cw_tension"),
        ({"mw_tension": 0.0}, "mw_tension"),
        ({"cw_mass": float("nan")}, "cw_mass"),
        ({"k_dropper": -1.0}, "k_dropper"),
        ({"n_spans": 0}, "n_spans"),
        ({"x_end": 700.0}, "x_end"),
        ({"window_start": 400.0, "window_end": 380.0}, "window"),
        ({"f_damp1": 30.0}, "f_damp2"),
    ],
)
def test_malformed_catenary_data_raise_parameter_error(kw, match):
    with pytest.raises(ParameterError, match=match):
        CatenaryParams(**kw)


#: two 30 m spans, four droppers per span at non-default places (bays of 4, 7.25, 7.25, 7.5, 4 m: elements of 0.5 and
#: 0.483 m), every wire and spring value away from the specification's
POINT = dict(n_spans=2, span_length=30.0, dropper_positions=[4.0, 11.25, 18.5, 26.0], element_length=0.5, x_end=60.0,
             window_start=10.0, window_end=50.0, cw_tension=18000.0, cw_EI=170.0, mw_tension=14000.0, mw_EI=110.0,
             k_dropper=8.0e4, k_steady_arm=500.0, k_messenger_support=4.0e4)


def _beam_green(x: float, a: float, T: float, EI: float, L: float) -> float:
    """Deflection at x under a unit force at a of the pinned-pinned tensioned beam (EI w'''' - T w'' = delta(x - a)):
    [x (L - a) / L - sinh(lam x) sinh(lam (L - a)) / (lam sinh(lam L))] / T for x <= a (lam = sqrt(T/EI); the other
    side by symmetry), the sinh quotient written with decaying exponentials."""
    if x > a:
        x, a = L - x, L - a
    lam = math.sqrt(T / EI)
    layer = (math.exp(lam * (x - a)) * -math.expm1(-2 * lam * x) * -math.expm1(-2 * lam * (L - a))
             / (2 * lam * -math.expm1(-2 * lam * L)))
    return (x * (L - a) / L - layer) / T


def _continuous_compliance(p: CatenaryParams, xp: float) -> float:
    """Static compliance at xp of the continuous catenary: two pinned-pinned tensioned beams joined by the droppers and
    held by the steady arm and messenger support at the interior supports, solved by superposition of the beams' Green
    functions. Unknowns: both wires' deflections z at the spring points; the springs' forces are -Ks z, so
    (I + G Ks) z = g (G the flexibility between the spring points, g the response there to the unit load at xp)."""
    L = p.length
    drops = [s * p.span_length + d for s in range(p.n_spans) for d in p.dropper_positions]
    pts = drops + [s * p.span_length for s in range(1, p.n_spans)]
    nd, m = len(drops), len(pts)
    G = np.zeros((2 * m, 2 * m))
    for i, a in enumerate(pts):
        for j, b in enumerate(pts):
            G[i, j] = _beam_green(a, b, p.cw_tension, p.cw_EI, L)
            G[m + i, m + j] = _beam_green(a, b, p.mw_tension, p.mw_EI, L)
    Ks = np.zeros((2 * m, 2 * m))
    for j in range(nd):
        Ks[np.ix_([j, m + j], [j, m + j])] += p.k_dropper * np.array([[1.0, -1.0], [-1.0, 1.0]])
    for s in range(nd, m):
        Ks[s, s] += p.k_steady_arm
        Ks[m + s, m + s] += p.k_messenger_support
    g = np.concatenate([[_beam_green(a, xp, p.cw_tension, p.cw_EI, L) for a in pts], np.zeros(m)])
    F = -Ks @ np.linalg.solve(np.eye(2 * m) + G @ Ks, g)
    return _beam_green(xp, xp, p.cw_tension, p.cw_EI, L) + sum(
        _beam_green(xp, a, p.cw_tension, p.cw_EI, L) * F[i] for i, a in enumerate(pts))


def _fe_compliance(fe, xp: float) -> float:
    """The FE's static compliance at xp on the contact wire, the contact point's defect included (as the coupled
    static start and the contact spring see it)."""
    e, xi, he = fe.element_at(xp)
    full = [NDOF_NODE * e + CW_W, NDOF_NODE * e + CW_T, NDOF_NODE * (e + 1) + CW_W, NDOF_NODE * (e + 1) + CW_T]
    d = fe.full_to_free[full]
    N = np.where(d >= 0, hermite(xi, he), 0.0)
    d = np.maximum(d, 0)
    rhs = np.zeros(fe.n)
    np.add.at(rhs, d, N)
    u = spsolve((fe.K0 + fe.Kd).tocsc(), rhs)
    return float(N @ u[d]) + fe.contact_defect(e, xi)


def test_point_load_compliance_against_the_continuous_catenary():
    """The point-load correction (`fe.PointCorrection`: every point spring with its wires' point-load defect in series,
    the contact point with the contact wire's) against the continuous model solved by hand: the static compliance at
    points of the contact wire, from the tensioned beams' closed-form Green functions joined by the springs
    (`_continuous_compliance`). At points more than an element from any spring (mid-element, at a third, next to the
    pinned end): measured 1.2e-11 relative (rounding of the closed forms), bound 1e-9; the plain Hermite wires are off
    there by 1.3e-3 to 6.3e-2 (mostly the droppers, 7 % too stiff), which the test also asserts (> 1e-3). Within an
    element of a spring the contact point and the spring share the wire's bending boundary layer, whose cross term is
    not corrected: at a dropper and at a support measured 1.1e-3 and 3.4e-4 (the plain wires' 1.0e-3 and 3.4e-3),
    bound 2e-3."""
    p = CatenaryParams(**POINT)
    fe, plain = assemble(p), assemble(p, point_correction=False)
    away = [7.6, 7.75, 7.8833, 15.0, 45.25, 45.4, 0.25, 59.5]  # m: mid-element, thirds, beside the pinned ends
    near = [11.25, 41.25, 30.0, 30.25]  # m: two droppers, a support, half an element beside it
    for xp in away:
        exact = _continuous_compliance(p, xp)
        assert abs(_fe_compliance(fe, xp) / exact - 1) < 1e-9, xp
        assert abs(_fe_compliance(plain, xp) / exact - 1) > 1e-3, xp
    for xp in near:
        assert abs(_fe_compliance(fe, xp) / _continuous_compliance(p, xp) - 1) < 2e-3, xp


def test_point_load_defect_falls_with_the_element_length():
    """The defect d of the contact wire at a node and mid-element (the correction's size) for 0.5, 0.25, 0.125 m: the
    closed form of the continuous tensioned beam minus the Hermite elements on the wire alone, computed here on a 12 m
    uniform pinned wire with numpy (not `PointCorrection`'s 17-element reference beam): measured 2.98e-7 / 5.89e-7,
    4.26e-8 / 1.52e-7, 3.79e-9 / 3.06e-8 m/N. The tables agree to 1.7e-16 m/N (the rounding of the 12 m wire's
    compliance, 1.5e-4 m/N; bound 2e-15 m/N), and d falls with h at both places."""
    T, EI = 20000.0, 195.0
    last = {0.0: math.inf, 0.5: math.inf}
    for h in (0.5, 0.25, 0.125):
        ne = int(round(12.0 / h))
        n = 2 * (ne + 1)
        K = np.zeros((n, n))
        for i in range(ne):
            K[2 * i:2 * i + 4, 2 * i:2 * i + 4] += beam_stiffness(EI, T, h)
        keep = [i for i in range(n) if i not in (0, n - 2)]
        C = np.zeros((n, n))
        C[np.ix_(keep, keep)] = np.linalg.inv(K[np.ix_(keep, keep)])
        e = ne // 2
        table = PointCorrection.build(np.arange(ne + 1) * h, T, EI)
        for xi in (0.0, 0.5):
            N = hermite(xi, h)
            a = (e + xi) * h
            d = _beam_green(a, a, T, EI, ne * h) - N @ C[2 * e:2 * e + 4, 2 * e:2 * e + 4] @ N
            assert abs(table.defect(e, xi) - d) < 2e-15, (h, xi)
            assert 0 < d < last[xi], (h, xi)
            last[xi] = d
