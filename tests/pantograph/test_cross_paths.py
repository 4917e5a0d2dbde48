"""Hand-derived vs Pinocchio vs MuJoCo: mass matrix, gravity, contact kinematics, full dynamics, equilibrium."""

import math

import mujoco
import numpy as np
import pytest

from mbsuite.engines.mujoco_engine import callbacks, full_inertia
from mbsuite.models.pantograph.equations import PantographConfig, PantographODE
from mbsuite.models.pantograph.modelfiles import E_THETA_Q, q_to_theta, theta_to_q
from mbsuite.models.pantograph.mujoco import MujocoPantograph
from mbsuite.models.pantograph.pinocchio import PinocchioPantograph, reference_in_q
from mbsuite.models.pantograph.python_effects import PythonEffects

REL = 1e-10


def rel_err(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(np.max(np.abs(b)), 1e-300))


@pytest.mark.parametrize("source", ["urdf", "mjcf"])
def test_pinocchio_matches_hand_derived(ode, random_thetas, source):
    pp = PinocchioPantograph(source=source)
    for th in random_thetas:
        q = theta_to_q(th)
        ref = reference_in_q(ode, q)
        assert rel_err(pp.mass_matrix(q), ref["M"]) <= REL
        assert rel_err(-pp.gravity(q), ref["gravity_force"]) <= REL
        assert pp.contact_height(q) == pytest.approx(ref["contact_height"], rel=REL)
        assert rel_err(pp.frame_jacobian(q, pp.f_contact)[2], ref["contact_jacobian"]) <= REL


def test_mujoco_mass_matrix_matches_hand_derived(ode, random_thetas):
    mp = MujocoPantograph()
    m, d = mp.model, mp.data
    for th in random_thetas:
        d.qpos[:] = theta_to_q(th)
        mujoco.mj_forward(m, d)
        assert rel_err(full_inertia(m, d), E_THETA_Q.T @ ode.mass_matrix_theta(th) @ E_THETA_Q) <= REL
        assert d.actuator_length[mp.i_cat] == pytest.approx(ode.contact_height(np.r_[th, 0, 0, 0]), rel=REL)


@pytest.mark.parametrize("impl", ["native", "python"])
@pytest.mark.parametrize("cylinder", ["constant", "linear", "nonlinear"])
@pytest.mark.parametrize("elbow_kinematics", ["B6", "exact"])
def test_mujoco_accelerations_match_hand_derived(random_thetas, cylinder, elbow_kinematics, impl):
    """Full right-hand side at random states (q, q', P, y_w): every force term of both paths (gravity, contact spring,
    head spring, elbow spring, cylinder force and its dynamics, joint damping), with the effects as the engine
    plugins (native) and as their Python twins (callbacks). Coulomb friction off, since MuJoCo's frictionloss is a
    constraint, not a force law."""
    cfg = PantographConfig(cylinder=cylinder, coulomb=False, elbow_kinematics=elbow_kinematics)
    ode = PantographODE(config=cfg)
    mp = MujocoPantograph(config=cfg, plugins=impl == "native")
    m, d = mp.model, mp.data
    rng = np.random.default_rng(7)
    cbs = PythonEffects(ode.p, cfg).callbacks() if impl == "python" else {}
    with callbacks(**cbs):
        for th in random_thetas[:40]:
            thd = rng.normal(0.0, 0.3, 3)
            y_w = 1.58 + rng.uniform(-0.05, 0.05)
            x = np.r_[th, thd]
            if cylinder == "linear":
                x = np.r_[x, ode.cylinder_lever(th[0])[0] + rng.uniform(-1e-3, 1e-3)]
            elif cylinder == "nonlinear":
                x = np.r_[x, ode.p.Ps * rng.uniform(0.5, 1.3)]
            dx = ode.rhs(0.0, x, y_w)
            d.qpos[:] = theta_to_q(th)
            d.qvel[:] = np.linalg.solve(E_THETA_Q, thd)
            d.ctrl[mp.i_cat] = y_w
            if m.na:
                d.act[0] = x[-1]
            mujoco.mj_forward(m, d)
            assert rel_err(E_THETA_Q @ d.qacc, dx[3:6]) <= 1e-9
            if m.na:
                mujoco.mj_forward(m, d)
                assert d.act_dot[0] == pytest.approx(dx[6], rel=1e-9, abs=1e-9 * abs(x[-1]))


@pytest.mark.parametrize("cylinder", ["linear", "nonlinear", "constant"])
def test_equilibrium_same_in_three_paths(lab_scene, cylinder):
    """Operating height 1.58 m, supply pressure of Table 3-I: theta agree to 1e-8 rad."""
    from mbsuite.models.pantograph.reports import equilibrium_all_paths

    paths = equilibrium_all_paths(lab_scene.replace(effects={"cylinder": cylinder}))
    assert set(paths) == {"reference", "mujoco", "pinocchio"}
    for name in ("mujoco", "pinocchio"):
        assert np.max(np.abs(paths[name] - paths["reference"])) <= 1e-8, name


def test_equilibrium_physics(ode, params):
    """At equilibrium the static force balance holds with a positive contact force, the cylinder supplies Pg Ap and
    the thesis' FORTRAN initial condition (erratum 18) is NOT an equilibrium."""
    x0 = ode.equilibrium()
    y_d = ode.contact_height(x0)
    f_contact = params.ks * (y_d - params.y_op)
    # the same force from MuJoCo: the catenary actuator's force at MuJoCo's own equilibrium (Newton on MuJoCo's
    # residual, its own site kinematics). Measured 88.7345 N in both, difference 2.6e-11 N; bound 2e-10 N (8x).
    mp = MujocoPantograph()
    mp.set_static(mp.equilibrium(), params.y_op)
    assert f_contact == pytest.approx(-mp.data.actuator_force[mp.i_cat], abs=2e-10)
    assert np.max(np.abs(ode.rhs(0.0, x0, params.y_op)[3:])) < 1e-9
    t1 = math.asin((params.y_op + 1.85e-3) / (2 * params.l1))
    assert np.max(np.abs(ode.static_residual(np.array([t1, t1, 0.0]), params.y_op))) > 100.0


def test_rigid_elbow_equilibrium_mujoco_vs_reference():
    """Rigid elbow: MuJoCo's quartic joint equality vs the exact reduced coordinates: within the fit error."""
    from mbsuite.models.pantograph.modelfiles import rigid_elbow_fit

    cfg = PantographConfig(elbow="rigid")
    ode = PantographODE(config=cfg)
    th_ref = ode.theta(ode.equilibrium()[:2])
    mp = MujocoPantograph(config=cfg)
    th_mj = q_to_theta(mp.equilibrium())
    _, fit = rigid_elbow_fit(ode.p)
    assert fit < 1e-5
    assert np.max(np.abs(th_mj - th_ref)) < 10 * fit
