"""Hand-derived kinematics of the 4-link coupler against the paper (Maniowski & Czauderna) and closed forms.

The e_y -> 0 limit (rank, condition number and singular values against their closed forms, the coplanar free
motions, the singularity warnings) is asserted once, by the hard case `coupler_ey_to_zero`."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from mbsuite.errors import GeometryError, ParameterError, SolverError
from mbsuite.models.coupler import analysis, criteria
from mbsuite.models.coupler.double import (
    double_quasi_static,
    double_residual,
    double_revolution,
    ramp_double,
    solve_double,
)
from mbsuite.models.coupler.fpp import gauss_newton
from mbsuite.models.coupler.geometry import NEXT
from mbsuite.models.coupler.jacobian import (
    EQ15,
    analyse_jacobian,
    cond_asymptotic,
    paper_eq15_layout,
    pitch_of_mixed_basis,
    single_jacobian,
)
from mbsuite.models.coupler.params import GAMMA_17DEG, CouplerParams, geometry_params
from mbsuite.models.coupler.single import single_points, single_residual, single_revolution

G = GAMMA_17DEG


def test_eq1_link_length_is_the_chord_of_the_assembled_points():
    """Eq (1): the distance between a_k and b_{k+1} at the coplanar pose equals sqrt(2(1 - sin 2g)) R."""
    for g in (0.11, 0.297, 0.391):
        p = CouplerParams(gamma=g, e_y=0.0, R=1.7)
        a, b, _, _ = single_points(p, 0.0, 0.0, 0.0, np.array([-math.pi / 2, 0, 0, 0]))
        d = np.linalg.norm(b[NEXT] - a, axis=1)
        np.testing.assert_allclose(d, 1.7 * math.sqrt(2 * (1 - math.sin(2 * g))), rtol=0, atol=1e-14)


def test_eq15_reproduced_with_documented_layout():
    """Eq (15) digit for digit: transpose, Eq 13 moment sign, rows (x, z, -y | m_x, m_z, -m_y). Every entry
    rounded to the paper's 4 decimals is the printed one (the largest gap, 4.76e-5, is 0.88295 printed as 0.8829)."""
    J = single_jacobian(CouplerParams(e_y=0.0))
    assert np.array_equal(np.round(paper_eq15_layout(J), 4), EQ15)
    # with gamma = 0.297 exactly the moment entry is 0.8831, not 0.8829 (README erratum 7): the paper used 17 deg
    J297 = single_jacobian(CouplerParams(gamma=0.297, e_y=0.0))
    assert np.max(np.abs(paper_eq15_layout(J297) - EQ15)) > 1e-4


@pytest.mark.parametrize("ey", [0.05, 0.1])
def test_condition_number_against_closed_form_not_table2(ey):
    """Table 2's e_y rows, R = 1: the SVD of J against the closed form of the aligned pose (README, "Condition number
    - derivation"): sigma_min = 2 e_y / l, sigma_max = 2R cos(pi/4 - gamma) l0 / l, chi = R^2 cos(2 gamma) / e_y =
    16.5808 / 8.29038. Measured <= 2.5e-15 relative; bound 2e-14 (8x). The paper prints chi = 87 / 85 (Table 2), not
    reproducible with the geometry that reproduces Eq (15) and Table 2's axes: chi is proportional to 1/e_y, while the
    printed values (`analysis.TABLE2`, reported beside ours) stay near-constant as e_y doubles."""
    s = np.linalg.svd(single_jacobian(CouplerParams(e_y=ey)), compute_uv=False)
    l0 = 2 * math.sin(math.pi / 4 - G)
    l = math.hypot(l0, ey)
    assert s[-1] == pytest.approx(2 * ey / l, rel=2e-14)
    assert s[0] == pytest.approx(2 * math.cos(math.pi / 4 - G) * l0 / l, rel=2e-14)
    assert s[0] / s[-1] == pytest.approx(math.cos(2 * G) / ey, rel=2e-14)


@pytest.mark.parametrize("R", [1.0, 1.5, 2.0, 3.0])
def test_condition_number_closed_form_scales_with_R_squared(R):
    """J mixes force and moment rows: chi = R^2 cos(2 gamma)/e_y (length units matter); below R ~ 0.85 a translational
    singular value dominates and there is no closed form (clear error, not a wrong number)."""
    p = CouplerParams(R=R, e_y=0.1)
    s = np.linalg.svd(single_jacobian(p), compute_uv=False)  # the numerical side: the SVD of J
    # the derived closed form against the SVD, and cond_asymptotic against the SVD (measured <= 2.5e-15; bound 8x)
    assert s[0] / s[-1] == pytest.approx(R**2 * math.cos(2 * G) / 0.1, rel=2e-14)
    assert cond_asymptotic(p) == pytest.approx(s[0] / s[-1], rel=2e-14)
    with pytest.raises(ParameterError, match="too small"):
        cond_asymptotic(CouplerParams(R=0.5, e_y=0.1))


@pytest.mark.parametrize("ey", [0.05, 0.1])
def test_table2_axes_are_the_zero_pitch_screws(ey):
    p = CouplerParams(e_y=ey)
    an = analyse_jacobian(single_jacobian(p), np.array([0.0, ey, 0.0]))
    assert an.rank == 4 - 0 and an.null_space.shape[1] == 2
    zp = analysis.zero_pitch_pair(an.principal_screws)
    y1, y2, h_paper, _ = analysis.TABLE2[ey]
    assert abs(abs(zp[0].axis[0]) - 1) < 1e-12 and abs(abs(zp[1].axis[2]) - 1) < 1e-12
    # Table 2 prints 4 decimals (rounding 5e-5). e_y = 0.05: ours 0.07202 / -0.02202, within the rounding. e_y = 0.1:
    # ours 0.14404 / -0.04404 against 0.1439 / -0.0439, 1.36e-4 apart - beyond the rounding and not explained by
    # gamma = 0.297 (0.14410) nor by links kept at l0 (0.14404); the paper's printed value is asserted with that gap.
    tol = 5e-5 if ey == 0.05 else 1.5e-4
    assert zp[0].point[1] == pytest.approx(y1, abs=tol)
    assert zp[1].point[1] == pytest.approx(y2, abs=tol)
    # principal screws: axes at +-45 deg through (0, e_y/2, 0), pitches +-d/2 with d = distance of Table 2's axes
    d = zp[0].point[1] - zp[1].point[1]
    pit = sorted(s.pitch for s in an.principal_screws)
    np.testing.assert_allclose(pit, [-d / 2, d / 2], rtol=1e-10)
    for s in an.principal_screws:
        assert s.point[1] == pytest.approx(ey / 2, abs=1e-12)
        assert abs(abs(s.axis[0]) - math.sqrt(0.5)) < 1e-12
    # Table 2's +-pitches come from a basis turned by theta away from the zero-pitch pair
    th = 0.5 * math.asin(h_paper / (d / 2))
    h1, h2 = pitch_of_mixed_basis(zp[0], zp[1], th)
    assert abs(h1) == pytest.approx(h_paper, rel=1e-9) and h1 == pytest.approx(-h2, rel=1e-9)
    # null vectors really are free motions: J t = 0
    assert np.max(np.abs(an.J @ an.null_space)) < 1e-12


def test_single_fpp_full_revolution_continuation_largest_misalignment():
    p = CouplerParams(e_y=0.1)
    rev = single_revolution(p, 0.07, 0.02, n=91)
    for phi, u in zip(rev.phi_a, rev.u, strict=True):
        assert np.max(np.abs(single_residual(p, phi, 0.07, 0.02, u))) < 1e-12
    # no branch jump: the pose after a full turn is the starting pose with phi_b advanced by exactly 2 pi
    assert rev.u[-1, 0] - rev.u[0, 0] == pytest.approx(2 * math.pi, abs=1e-10)
    np.testing.assert_allclose(rev.u[-1, 1:], rev.u[0, 1:], atol=1e-10)
    assert np.all(np.diff(rev.u[:, 0]) > 0)


def test_c1_quadratic_in_alpha_period_pi_independent_of_ey():
    p = CouplerParams(e_y=0.1)
    c = [criteria.single_criteria(p, a, 121) for a in (0.02, 0.04)]
    # parabolic in alpha (Sect. 3.4): ratio 4 (1 + O(alpha^2)), measured 4.0008; bound 5x the deviation
    assert c[1]["c1"] / c[0]["c1"] == pytest.approx(4.0, rel=1e-3)
    d = c[1]["rev"].phi_a[:-1] - c[1]["rev"].u[:-1, 0]
    spec = np.abs(np.fft.rfft(d - d.mean()))
    assert int(np.argmax(spec)) == 2  # two oscillations per revolution (not one, as Sect. 3.4 says of Fig 6)
    c3 = criteria.single_criteria(CouplerParams(e_y=0.3), 0.04, 121)
    assert c3["c1"] == pytest.approx(c[1]["c1"], rel=1e-9)  # "virtually not influenced by e_y" (Sect. 3.4): measured 0
    # c2 "proportional to" alpha (Sect. 3.4): measured ratio 1.9655 for doubling alpha (1.7 % below 2); bound 3x
    assert c[1]["c2"] / c[0]["c2"] == pytest.approx(2.0, rel=0.05)
    # "c4 achieves 10 times greater values than c3" (Sect. 3.4, read off Fig 9): measured 9.12 and 9.21. The
    # paper's beta angles are defined in its Fig 3c, not in the text (ours: README): a 15 % reading tolerance.
    for ci in c:
        assert ci["c4"] / ci["c3"] == pytest.approx(10.0, rel=0.15)


def test_c1_improves_with_slimmer_platform():
    c = [criteria.single_criteria(CouplerParams(gamma=g), 0.05, 61)["c1"] for g in (0.11, 0.297, 0.391)]
    assert c[0] < c[1] < c[2]


def test_double_homokinetic_at_phibc_0_not_at_pi_2():
    c0 = criteria.double_c5(CouplerParams(), 0.08, n=37)
    c90 = criteria.double_c5(CouplerParams(phi_bc=math.pi / 2), 0.08, n=37)
    # phi_bc = 0: full homokineticity (Sect. 4.3) although the intermediate shaft fluctuates (measured 1.7e-16
    # vs 5.0e-4)
    assert c0["c5"] < 1e-12 < 1e-4 < c0["c1_intermediate"]
    # phi_bc = pi/2: the two couplers' fluctuations add, c5 = 2 c1 of shaft b (measured ratio 1.0154; bound 3x)
    assert c90["c5"] == pytest.approx(2 * c90["c1_intermediate"], rel=0.05)
    # inclined output shaft: shaft b barely tilts, coupler 2 takes the whole angle, so c5 is the single coupler's c1 at
    # alpha = 0.03 (a different FPP, 4 unknowns): measured 2.2 % below it; bound 4.5x
    ci = criteria.double_c5(CouplerParams(), 0.0, alpha_cx=0.03, n=37)
    assert ci["c5"] == pytest.approx(criteria.single_criteria(CouplerParams(), 0.03, 121)["c1"], rel=0.1)


def test_double_fpp_revolution_phibc_90_no_jump():
    p = CouplerParams(phi_bc=math.pi / 2)
    rev = double_revolution(p, 0.02, -0.01, 0.03, 0.05, n=61)
    for phi, u in zip(rev.phi_a, rev.u, strict=True):
        assert np.max(np.abs(double_residual(p, np.r_[phi, rev.inputs], u))) < 1e-12
    assert rev.u[-1, 0] - rev.u[0, 0] == pytest.approx(2 * math.pi, abs=1e-10)
    np.testing.assert_allclose(rev.u[-1, 1:5], rev.u[0, 1:5], atol=1e-10)


def test_quasi_static_forces_balance_the_load():
    """Virtual work: T_in = T_load dphi_c/dphi_a; links of each coupler alternate tension/compression."""
    p = CouplerParams(phi_bc=math.pi / 2)
    inp = np.array([0.3, 0.0, 0.0, 0.0, 0.06])
    u = ramp_double(p, inp)
    f, t_in = double_quasi_static(p, inp, u, 1000.0)
    h = 1e-6
    up = solve_double(p, inp + [h, 0, 0, 0, 0], u)
    um = solve_double(p, inp - [h, 0, 0, 0, 0], u)
    assert t_in == pytest.approx(1000.0 * (up[0] - um[0]) / (2 * h), rel=1e-7)
    assert np.all(np.sign(f[:4]) == [1, -1, 1, -1])


def test_bad_input_errors():
    with pytest.raises(ParameterError, match="gamma"):
        CouplerParams(gamma=0.0)
    with pytest.raises(ParameterError, match="gamma"):
        CouplerParams(gamma=math.pi / 4)
    with pytest.raises(ParameterError, match="e_y"):
        CouplerParams(e_y=-0.01)
    with pytest.raises(ParameterError, match="R"):
        CouplerParams(R=-1.0)
    with pytest.raises(ParameterError, match="l_b"):
        CouplerParams(l_b=0.0)
    with pytest.raises(ParameterError, match="unknown"):
        geometry_params(gama=0.3)
    # e_y smaller than ~R alpha (no physical pose): the hard case coupler_ey_below_R_alpha and, at the boundary,
    # tests/coupler/test_checks.py::test_admissibility_boundary
    # e_y = 0.03 with alpha = 0.05: the inclination ramp reaches the boundary at alpha_bx = 0.03125 rad
    with pytest.raises(GeometryError, match=r"alpha_bx = 0\.03125 rad.*link 1's axial component -0\.00518 l <= 0"):
        single_revolution(CouplerParams(e_y=0.03), 0.05, 0.0, n=31)
    # Gauss-Newton non-convergence reported with the residual
    with pytest.raises(SolverError, match=r"residual \|r\|_inf = [0-9.e+-]+"):
        gauss_newton(lambda u: np.array([u[0] ** 2 + 1.0]), lambda u: np.array([[2 * u[0]]]), np.array([0.3]))


def test_jacobian_report_no_warning_when_regular():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rep = analysis.jacobian_report(CouplerParams(e_y=0.1), 0.4, 0.03, 0.01)
    assert rep.data["rank"] == 4


def test_inclination_about_z_equals_about_x_up_to_phase():
    """alpha_b may be applied about x or z: same c1, x- and z-ranges of O_b swap (the platform turns through both)."""
    p = CouplerParams()
    rx = single_revolution(p, 0.05, 0.0, 121)
    rz = single_revolution(p, 0.0, 0.05, 121)
    assert np.ptp(rx.phi_a - rx.u[:, 0]) == pytest.approx(np.ptp(rz.phi_a - rz.u[:, 0]), rel=1e-9)
    assert np.ptp(rx.u[:, 1]) == pytest.approx(np.ptp(rz.u[:, 3]), rel=1e-9)


@pytest.mark.parametrize("gamma, ey, R", [(0.2, 0.07, 1.3), (0.35, 0.12, 2.0)])
def test_analysed_condition_number_at_non_default_design(gamma, ey, R):
    """`analyse_jacobian`'s chi and rank against the closed form chi = R^2 cos(2 gamma)/e_y of the aligned pose
    (README derivation), at non-default gamma, e_y and R: measured <= 4e-15 relative; bound 2e-14 (5x)."""
    p = CouplerParams(gamma=gamma, e_y=ey, R=R)
    an = analyse_jacobian(single_jacobian(p), np.array([0.0, ey, 0.0]))
    assert an.rank == 4
    assert an.cond == pytest.approx(R**2 * math.cos(2 * gamma) / ey, rel=2e-14)
    assert cond_asymptotic(p) == pytest.approx(R**2 * math.cos(2 * gamma) / ey, rel=2e-14)


@pytest.mark.parametrize("ey", [0.05, 0.1])
def test_screws_are_free_motions_with_their_pitch(ey):
    """Every screw reported (principal and SVD basis) is a free motion: the twist of a screw of unit axis s through the
    point r with pitch h, written by hand at B's centre o (v_o = s x (o - r) + h s, omega = s), has zero link-length
    rates, J (v_o, s) = 0. A wrong pitch sign or point gives |J t| ~ h or ~ |r - r_true| (h ~ 0.05). Measured
    |J t| <= 1.7e-16; bound 2e-15 (12x; the entries are O(1), |J| <= 0.88 and |t| <= 1, so the floor is a few ulps of
    1 = 2.2e-16 from the SVD and the screw conversion on another platform). A pure rotation about a hand-chosen axis
    (pitch 0.3 added) comes back as that axis, point and pitch: measured exact (pitch, magnitude, axis) and 1.1e-16 m
    (the point, one ulp of its coordinates); bounds 1e-14 relative to each value (45 ulps: the floor on another
    platform's arithmetic is a few ulps, not 0)."""
    from mbsuite.models.coupler.jacobian import twist_to_screw

    p = CouplerParams(e_y=ey)
    o = np.array([0.0, ey, 0.0])
    an = analyse_jacobian(single_jacobian(p), o)
    for sc in [*an.principal_screws, *an.svd_screws]:
        s = sc.axis
        t = np.concatenate([np.cross(s, o - sc.point) + sc.pitch * s, s])
        assert np.max(np.abs(an.J @ t)) < 2e-15
    assert sorted(sc.pitch for sc in an.principal_screws)[1] > 0.04
    s, r, h = np.array([0.6, 0.0, 0.8]), np.array([0.2, 0.5, -0.15]), 0.3
    sc2 = twist_to_screw(np.concatenate([2.0 * (np.cross(s, o - r) + h * s), 2.0 * s]), o)
    assert sc2.pitch == pytest.approx(h, rel=1e-14) and sc2.magnitude == pytest.approx(2.0, rel=1e-14)
    np.testing.assert_allclose(sc2.axis, s, rtol=0, atol=1e-14)  # a unit vector: absolute = relative
    # the reported point is the axis point nearest to o: r moved along s to the foot of the perpendicular from o
    foot = r + s * float(s @ (o - r))
    np.testing.assert_allclose(sc2.point, foot, rtol=0, atol=1e-14 * np.linalg.norm(foot))
