"""Pinocchio path (URDF spanning trees + closures; MJCF read by Pinocchio) against the hand-derived kinematics."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from mbsuite.models.coupler.double import (
    DOUBLE_INPUTS,
    DOUBLE_UNKNOWNS,
    double_residual_jac,
    double_revolution,
    ramp_double,
)
from mbsuite.models.coupler.jacobian import single_jacobian
from mbsuite.models.coupler.params import CouplerParams
from mbsuite.models.coupler.pinocchio import (
    PinCoupler,
    PinMjcfCoupler,
    pin_to_mujoco_qpos,
    single_revolution_pin,
)
from mbsuite.models.coupler.single import ramp_single, single_residual_jac, single_revolution
from mbsuite.paths import mjcf_path

# largest measured difference 3.5e-13 (the double FPP pose, which stops at |r| <= 1e-13 R^2); bound 8.5x
TOL = 3e-12


@pytest.fixture(scope="module")
def single():
    return PinCoupler.build("single")


@pytest.fixture(scope="module")
def double():
    return PinCoupler.build("double")


def test_single_fpp_over_revolution_matches(single):
    p = CouplerParams()
    rev = single_revolution(p, 0.06, -0.02, n=49)
    pr = single_revolution_pin(single, 0.06, -0.02, rev.phi_a, rev.u[0])
    assert np.max(np.abs(pr - rev.u)) < TOL


@pytest.mark.parametrize("pose", [(0.0, 0.0, 0.0), (0.7, 0.05, 0.0), (2.9, -0.03, 0.04)])
def test_single_jacobians_match(single, pose):
    p = CouplerParams()
    phi_a, ax, az = pose
    sp = ramp_single(p, phi_a, ax, az)
    q = single.q_of({"phi_a": phi_a, "alpha_bx": ax, "alpha_bz": az,
                     **dict(zip(("phi_b", "x_b", "y_b", "z_b"), sp.u, strict=True))})
    assert np.max(np.abs(single.residual(q))) < 1e-12
    # mechanism Jacobian (4 x 6) and the FPP Jacobian (each row l_hat^T (J_b - J_a))
    assert np.max(np.abs(single.mechanism_jacobian(q) - single_jacobian(p, sp))) < TOL
    single.update(q)
    K = single.constraint_jacobian()[:, [single.iv[n] for n in single.unknowns]]
    Kh = single_residual_jac(p, phi_a, ax, az, sp.u) / (2 * p.link_length)
    assert np.max(np.abs(K - Kh)) < TOL


def test_double_fpp_and_jacobian_match(double):
    p = CouplerParams()
    rev = double_revolution(p, 0.02, 0.01, -0.02, 0.05, n=13)
    q = double.q_of({"phi_a": 0.0, **dict(zip(DOUBLE_INPUTS[1:], rev.inputs, strict=True)),
                     **dict(zip(DOUBLE_UNKNOWNS, rev.u[0], strict=True))})
    prev = 0.0
    for phi, u in zip(rev.phi_a, rev.u, strict=True):
        for name in ("phi_b", "phi_c"):  # predictor: both shafts follow the input
            q[double.iq[name]] += phi - prev
        prev = phi
        q = double.fpp({"phi_a": phi, **dict(zip(DOUBLE_INPUTS[1:], rev.inputs, strict=True))}, q)
        assert np.max(np.abs(double.coords(q) - u)) < TOL
        double.update(q)
        K = double.constraint_jacobian()[:, [double.iv[n] for n in double.unknowns]]
        Kh = double_residual_jac(p, np.r_[phi, rev.inputs], u) / (2 * p.link_length)
        assert np.max(np.abs(K - Kh)) < TOL


def test_pinocchio_fpp_rejects_unphysical_branch(single):
    """Started on the mirror branch (B pushed through A), the Pinocchio FPP reports the crossing instead of a pose."""
    from mbsuite.errors import GeometryError

    p = CouplerParams()
    q = single.q_of({"phi_a": 0.0, "phi_b": -math.pi / 2, "y_b": -2 * p.e_y})
    with pytest.raises(GeometryError, match="cross"):
        single.fpp({"phi_a": 0.0, "alpha_bx": 0.0, "alpha_bz": 0.0}, q)


@pytest.mark.parametrize("kind", ["single", "double"])
def test_mjcf_in_pinocchio_and_mujoco_same_kinematics(kind):
    """The MJCF (link bodies, ball joints, connects) solved in Pinocchio gives the URDF/hand-derived pose, and MuJoCo
    sees zero connect residual at that configuration."""
    p = CouplerParams()
    pm = PinMjcfCoupler(kind, mjcf_path(f"coupler_{kind}"))
    if kind == "single":
        inp = {"phi_a": 0.8, "alpha_bx": 0.04, "alpha_bz": -0.02}
        qm = pm.fpp_ramp(inp)
        u = ramp_single(p, 0.8, 0.04, -0.02).u
        c = pm.shaft_coords(qm, "b")
        got = np.array([c[5] - math.pi / 2, c[0], c[1], c[2]])
        np.testing.assert_allclose(c[3:5], [-0.02, 0.04], atol=1e-14)
        # directly against the URDF spanning tree + closures
        pc = PinCoupler.build("single")
        qu = pc.fpp(inp, pc.q_of(dict(zip(("phi_b", "x_b", "y_b", "z_b"), u, strict=True))))
        assert np.max(np.abs(pc.coords(qu) - got)) < TOL
    else:
        x = np.array([0.8, 0.02, 0.01, -0.02, 0.05])
        qm = pm.fpp_ramp(dict(zip(DOUBLE_INPUTS, x, strict=True)))
        u = ramp_double(p, x)
        b, c = pm.shaft_coords(qm, "b"), pm.shaft_coords(qm, "c")
        got = np.array([c[5] + p.phi_bc, c[1], b[0], b[1], b[2], b[5] - math.pi / 2, b[4], b[3]])
    assert np.max(np.abs(got - u)) < TOL
    mm = mujoco.MjModel.from_xml_path(str(mjcf_path(f"coupler_{kind}")))
    dd = mujoco.MjData(mm)
    dd.qpos[:] = pin_to_mujoco_qpos(pm.model, qm, mm)
    mujoco.mj_forward(mm, dd)
    assert dd.nefc == 3 * (4 if kind == "single" else 8)
    assert np.max(np.abs(dd.efc_pos)) < 1e-12
