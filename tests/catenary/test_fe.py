"""Finite-element catenary: element matrices against closed-form wire frequencies, mesh, static state."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sla

from mbsuite.errors import ParameterError
from mbsuite.models.catenary.fe import CW_W, NDOF_NODE, assemble, beam_mass, beam_stiffness, build_nodes, hermite
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
