"""MuJoCo double-coupler dynamics against the kinematics; shipped scenes; effects; bad input."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

import mbsuite
from mbsuite.errors import ParameterError, SceneError
from mbsuite.models.coupler import SPEC
from mbsuite.models.coupler import mujoco as cm
from mbsuite.models.coupler import reference as ref
from mbsuite.scenes import load_scene


@pytest.mark.parametrize("name", sorted(SPEC.scene_files()))
def test_shipped_scenes_step_one_second_without_warnings(name):
    sc = load_scene(f"coupler/{name}").replace(solver={"duration": 1.0})
    res = mbsuite.run(sc)
    assert res.stats["warnings"] == {}
    assert res.t[-1] == pytest.approx(1.0)
    # output follows the kinematic solution; closures stay closed (bounds justified in README)
    assert res.stats["phi_c_err_max"] < 5e-4
    assert res.stats["closure_residual_max"] < 2e-4 * SPEC.params_cls().R


def test_lateral_offset_agreement_and_torque_balance():
    """Baseline scene: phi_c(t) within 1e-4 rad of the FPP, closure residual < 1e-4 R, mean input torque = load
    (energy balance over whole revolutions), and the homokinetic phi_bc = 0 coupler has a small ripple."""
    sc = load_scene("coupler/double_lateral")
    r = mbsuite.run(sc)
    s = r.stats
    assert s["revolutions"] > 2.9
    assert s["phi_c_kin_fluctuation_pp"] < 1e-12  # kinematically homokinetic
    assert s["phi_c_err_max"] < 1e-4
    assert s["closure_residual_max"] < 1e-4
    assert s["torque_in_mean"] == pytest.approx(1000.0, rel=1e-3)
    assert s["torque_in_ripple_rel"] < 0.02


def test_massless_limit_forces_match_quasi_static():
    """Massless-link limit, no gravity: the mean link forces equal the virtual-work link forces within 2 %."""
    sc = load_scene("coupler/double_massless")
    r = mbsuite.run(sc)
    p = sc.build_params()
    inp = np.array([0.0, 0.0, 0.0, 0.0, sc.input["z_c"]])
    f, _ = ref.double_quasi_static(p, inp, ref._ramp_double(p, inp), sc.input["load_torque"])
    np.testing.assert_allclose(r.stats["link_force_mean"], f, rtol=0.02)


@pytest.mark.parametrize("name, extra", [("double_phibc90", {}), ("double_lateral", {"gravity": False}),
                                         ("double_inclined", {"gravity": False})])
def test_torque_ripple_matches_rigid_reference(name, extra):
    """Light links (5 % mass), no gravity: the MuJoCo input torque follows the rigid-shaft power balance
    T_in w_a = d/dt(E_b + I_c w_c^2/2) + T_load w_c within 5 % of its ripple + 0.2 N m (the 5 % link inertia left)."""
    sc = load_scene(f"coupler/{name}").replace(effects={"link_inertia": "massless", **extra},
                                               params={"massless_factor": 0.05, "solref_timeconst": 1e-3},
                                               solver={"duration": 1.5})
    rm = mbsuite.run(sc)
    rr = mbsuite.run(sc, engine="reference")
    w = rm.t >= 0.5
    t_ref = np.interp(rm["phi_a"][w], rr["phi_a"], rr["torque_in"])
    ripple = np.ptp(t_ref)
    assert np.max(np.abs(rm["torque_in"][w] - t_ref)) < 0.05 * ripple + 0.2
    assert np.mean(rm["torque_in"][w]) == pytest.approx(np.mean(t_ref), abs=0.1)
    if name == "double_phibc90":  # inertial ripple of the output shaft dominates the quasi-static one
        assert ripple > 5 * rr.stats["torque_in_ripple_quasi_static_pp"]


def test_effects_switch_model_content():
    sc = load_scene("coupler/double_lateral")
    p = sc.build_params()
    inp = cm._inputs(sc)
    m1, _, _ = cm.build(p, {"gravity": True, "link_inertia": "real", "friction": False}, inp, 5e-4, "implicitfast")
    m2, _, _ = cm.build(p, {"gravity": False, "link_inertia": "massless", "friction": True}, inp, 5e-4, "implicitfast")
    b = mujoco.mj_name2id(m1, mujoco.mjtObj.mjOBJ_BODY, "link1")
    assert m1.opt.gravity[2] == pytest.approx(-9.81) and m2.opt.gravity[2] == 0.0
    assert m2.body_mass[b] == pytest.approx(p.massless_factor * m1.body_mass[b])
    assert np.all(m1.dof_frictionloss == 0.0) and np.max(m2.dof_frictionloss) == pytest.approx(p.joint_friction)
    # shaft c keeps only its axial slide and spin; the imposed misalignment is in its body pose
    names = [mujoco.mj_id2name(m1, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m1.njnt)]
    assert "y_c" in names and "phi_c" in names and "x_c" not in names and "alpha_cx" not in names


def test_friction_costs_input_torque():
    base = load_scene("coupler/double_lateral").replace(solver={"duration": 1.0})
    r0 = mbsuite.run(base)
    r1 = mbsuite.run(base.replace(effects={"friction": True}))
    assert r1.stats["torque_in_mean"] > r0.stats["torque_in_mean"] + 0.5


def test_bad_scene_input():
    sc = load_scene("coupler/double_lateral")
    with pytest.raises(SceneError, match="omega"):
        mbsuite.run(sc.replace(input={"omega": -1.0}))
    with pytest.raises(SceneError, match="unknown input"):
        sc.replace(input={"speed": 3.0})
    with pytest.raises(SceneError, match="effect"):
        sc.replace(effects={"gravity": "yes"})
    with pytest.raises(ParameterError, match="e_y"):
        sc.replace(params={"e_y": -0.1})
    with pytest.raises(mbsuite.GeometryError):  # shaft b would have to tilt more than e_y allows
        mbsuite.run(sc.replace(input={"z_c": 0.4}, solver={"duration": 0.01, "t_settle": 0.0}))
    assert math.isfinite(sc.build_params().link_length)
