"""MuJoCo double-coupler dynamics against the kinematics, the power balance, the virtual-work link forces and the
rigid-shaft reference; effects; bad input. (Stepping every shipped scene without NaN or warning is
tests/suite/test_menagerie.py's job; here each shipped scene carries a physical invariant.)"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

import mbsuite
from mbsuite.errors import ParameterError, SceneError
from mbsuite.models.coupler import SPEC
from mbsuite.models.coupler import mujoco as cm
from mbsuite.models.coupler.double import double_quasi_static, ramp_double
from mbsuite.models.coupler.params import CouplerParams
from mbsuite.models.coupler.scenario import scene_inputs
from mbsuite.scenes import load_scene


@pytest.mark.parametrize("name", sorted(SPEC.scene_files()))
def test_shipped_scenes_power_balance(name, request):
    """Power balance over the settled revolution (0.5-1 s at 2 rev/s): T_in w_a = T_load w_c + losses, with w_c = w_a
    on average. Without friction the only losses are the S joints' viscous damping and the closures' damping: mean
    T_in = T_load, measured |error| <= 7.0e-6 T_load (bound 7x). With friction (double_friction, F = 2 N m) the
    prediction from the rigid mechanism's link motion (conftest.py's `swing`, as test_dissipation.py): the output
    bearing dissipates F w_c, each S joint F (|w_x| + |w_y|), the S joints' damping c w_a^2 sum |dd/dphi|^2, so mean
    T_in - T_load = F (1 + ab) + c w_a sq = 2.2808 N m; measured 2.2802 N m (-0.029 %);
    bound 0.3 % (10x). Without the output bearing's friction the excess drops by F."""
    sc = load_scene(f"coupler/{name}").replace(solver={"duration": 1.0})
    res = mbsuite.run(sc)
    load, excess = sc.input["load_torque"], res.statistics["torque_in_mean"] - sc.input["load_torque"]
    if sc.effects["friction"]:
        p = sc.build_params()
        # `swing` is the default design's revolution at z_c = 0.05, input shaft turning about its own axis
        inp = scene_inputs(sc)
        assert p.geometry() == CouplerParams().geometry() and inp["z_c"] == 0.05
        assert inp["x_c"] == inp["alpha_cx"] == inp["alpha_cz"] == 0.0
        sq, ab = request.getfixturevalue("swing")
        expected = p.joint_friction * (1.0 + ab) + p.joint_damping * inp["omega"] * sq
        assert excess == pytest.approx(expected, rel=3e-3)
    else:
        assert abs(excess) <= 5e-5 * load


def test_lateral_offset_agreement_and_torque_balance():
    """Baseline scene, 2 s: phi_c(t) within 1e-4 rad of the FPP (measured 3.5e-5), closure residual < 1e-4 R
    (3.75e-5), mean input torque = load (power balance over 3 whole revolutions), and the homokinetic phi_bc = 0
    coupler has a small ripple (0.70 %: the links' own inertia)."""
    sc = load_scene("coupler/double_lateral")
    r = mbsuite.run(sc)
    s = r.statistics
    assert s["revolutions"] > 2.9
    assert s["phi_c_kin_fluctuation_pp"] < 1e-12  # kinematically homokinetic
    assert s["phi_c_err_max"] < 1e-4
    assert s["closure_residual_max"] < 1e-4
    assert s["torque_in_mean"] == pytest.approx(1000.0, rel=5e-5)  # power balance, 3 revolutions: 6.4e-6 measured
    assert s["torque_in_ripple_rel"] < 0.02


def test_massless_limit_forces_match_quasi_static():
    """Massless-link limit, no gravity: the mean link forces equal the virtual-work link forces (+-284.7 N) within 2 %
    (measured 0.74 %: the links' 5 % mass and the soft closures)."""
    sc = load_scene("coupler/double_massless")
    r = mbsuite.run(sc)
    p = sc.build_params()
    inp = np.array([0.0, 0.0, 0.0, 0.0, sc.input["z_c"]])
    f, _ = double_quasi_static(p, inp, ramp_double(p, inp), sc.input["load_torque"])
    np.testing.assert_allclose(r.statistics["link_force_mean"], f, rtol=0.02)


@pytest.mark.parametrize("name, extra", [("double_phibc90", {}), ("double_lateral", {"gravity": False}),
                                         ("double_inclined", {"gravity": False})])
def test_torque_ripple_matches_rigid_reference(name, extra):
    """Light links (5 % mass), no gravity: the MuJoCo input torque follows the rigid-shaft power balance
    T_in w_a = d/dt(E_b + I_c w_c^2/2) + T_load w_c within 5 % of its ripple + 0.2 N m (the 5 % link inertia left;
    measured 0.70 of 2.42 N m allowed (phi_bc = pi/2), 0.099 of 0.39 (lateral), 0.030 of 0.23 (inclined))."""
    sc = load_scene(f"coupler/{name}").replace(effects={"link_inertia": "massless", **extra},
                                               params={"massless_factor": 0.05, "solref_timeconst": 1e-3},
                                               solver={"duration": 1.5})
    rm = mbsuite.run(sc)
    rr = mbsuite.run(sc, engine="reference")
    w = rm.t >= 0.5
    t_ref = np.interp(rm["phi_a"][w], rr["phi_a"], rr["torque_in"])
    ripple = np.ptp(t_ref)
    assert np.max(np.abs(rm["torque_in"][w] - t_ref)) < 0.05 * ripple + 0.2
    assert np.mean(rm["torque_in"][w]) == pytest.approx(np.mean(t_ref), abs=0.03)  # measured <= 7.7e-3 N m
    if name == "double_phibc90":  # inertial ripple of the output shaft dominates the quasi-static one
        assert ripple > 5 * rr.statistics["torque_in_ripple_quasi_static_pp"]


def test_effects_switch_model_content():
    sc = load_scene("coupler/double_lateral")
    p = sc.build_params()
    inp = scene_inputs(sc)
    m1, _, _ = cm.build(p, {"gravity": True, "link_inertia": "real", "friction": False}, inp, 5e-4, "implicitfast")
    m2, _, _ = cm.build(p, {"gravity": False, "link_inertia": "massless", "friction": True}, inp, 5e-4, "implicitfast")
    b = mujoco.mj_name2id(m1, mujoco.mjtObj.mjOBJ_BODY, "link1")
    assert m1.opt.gravity[2] == pytest.approx(-9.81) and m2.opt.gravity[2] == 0.0
    assert m2.body_mass[b] == pytest.approx(p.massless_factor * m1.body_mass[b])
    assert np.all(m1.dof_frictionloss == 0.0) and np.max(m2.dof_frictionloss) == pytest.approx(p.joint_friction)
    # shaft c keeps only its axial slide and spin; the imposed misalignment is in its body pose
    names = [mujoco.mj_id2name(m1, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m1.njnt)]
    assert "y_c" in names and "phi_c" in names and "x_c" not in names and "alpha_cx" not in names


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
    with pytest.raises(mbsuite.GeometryError, match="no physical pose"):  # shaft b would tilt more than e_y allows
        mbsuite.run(sc.replace(input={"z_c": 0.4}, solver={"duration": 0.01, "t_settle": 0.0}))


def test_friction_time_constant_default_follows_timestep_and_a_set_one_is_held():
    """solref_friction_timeconst: unset, MuJoCo's dry-friction constraints (8 S joints, output bearing) get 2
    timesteps; set, the same value at every timestep; below 2 timesteps (MuJoCo would silently raise it) a SceneError
    naming it; outside (0, 1] s a ParameterError."""
    sc = load_scene("coupler/double_friction")
    inp = scene_inputs(sc)
    fx = {"gravity": True, "link_inertia": "real", "friction": True}
    for h in (1e-3, 5e-4):
        m, _, _ = cm.build(sc.build_params(), fx, inp, h, "implicitfast")
        held, _, _ = cm.build(sc.replace(params={"solref_friction_timeconst": 3e-3}).build_params(), fx, inp, h,
                              "implicitfast")
        rub = m.dof_frictionloss > 0
        assert rub.sum() == 3 * 8 + 1  # 8 balls (3 dofs each) and the output bearing
        assert np.all(m.dof_solref[rub, 0] == 2 * h) and np.all(held.dof_solref[rub, 0] == 3e-3)
    p = sc.replace(params={"solref_friction_timeconst": 1.5e-3}).build_params()
    with pytest.raises(SceneError, match="solref_friction_timeconst"):
        cm.build(p, fx, inp, 1e-3, "implicitfast")
    cm.build(p, {**fx, "friction": False}, inp, 1e-3, "implicitfast")  # no friction constraint: nothing to refuse
    for bad in (0.0, -1e-3, 2.0):
        with pytest.raises(ParameterError, match="solref_friction_timeconst"):
            sc.replace(params={"solref_friction_timeconst": bad})


def test_shaft_inertias_on_both_paths():
    """Non-default shaft inertias on both paths, each against the other path.

    Output shaft, i_shaft_c = 90 kg m^2 (3x), phi_bc = pi/2 (its speed fluctuates twice per revolution), shaft b
    heavier (m_shaft_b = 120 kg, inertias 30 / 60 kg m^2), omega = 3 pi rad/s, load 1.5 kN m, light links, no
    gravity, a velocity servo half as stiff (kv_drive = 1e5): the MuJoCo input torque follows the rigid reference's
    power balance within 5 % of its ripple + 0.2 N m (measured 1.19 of 3.48 N m allowed, 2.9x, ripple 65.7 N m; 0.82
    at the default kv; the reference with i_shaft_c at the file's 30 differs by 18.7 N m).
    Input shaft, start-up ramp t_ramp = 0.2 s (non-default): raising i_shaft_a by 30 kg m^2 adds 30 alpha_a(t) to the
    torque during the ramp on both paths, alpha_a = omega s'(t) in closed form (MuJoCo: the difference of two runs,
    so the servo's lag and its implicit damping, which records kv h alpha_a more than it applies, cancel): measured
    139.8 N m of a 2827 N m peak (MuJoCo), 28.1 (reference); bound 10 % of the peak (2x)."""
    sc = load_scene("coupler/double_phibc90").replace(
        effects={"link_inertia": "massless"},
        params={"massless_factor": 0.05, "solref_timeconst": 1e-3, "i_shaft_c": 90.0, "m_shaft_b": 120.0,
                "i_shaft_b_axial": 30.0, "i_shaft_b_trans": 60.0, "kv_drive": 1e5},
        input={"omega": 3 * math.pi, "load_torque": 1500.0}, solver={"duration": 1.0})
    rm, rr = mbsuite.run(sc), mbsuite.run(sc, engine="reference")
    w = rm.t >= 0.5
    t_ref = np.interp(rm["phi_a"][w], rr["phi_a"], rr["torque_in"])
    assert np.ptp(t_ref) > 50.0
    assert np.max(np.abs(rm["torque_in"][w] - t_ref)) < 0.05 * np.ptp(t_ref) + 0.2
    base = load_scene("coupler/double_lateral").replace(
        effects={"link_inertia": "massless", "gravity": False}, params={"massless_factor": 0.05,
                                                                        "solref_timeconst": 1e-3},
        input={"t_ramp": 0.2}, solver={"duration": 0.3, "t_settle": 0.25})
    runs = {(eng, ia): mbsuite.run(base.replace(params={"i_shaft_a": ia}), engine=eng)
            for eng in ("mujoco", "reference") for ia in (10.0, 40.0)}
    t = runs["mujoco", 10.0].t
    x = np.clip(t / base.input["t_ramp"], 0.0, 1.0)
    alpha = base.input["omega"] * 6 * x * (1 - x) / base.input["t_ramp"]  # the ramp's s'(t) omega
    peak = 30.0 * alpha.max()
    for eng in ("mujoco", "reference"):
        r40, r10 = runs[eng, 40.0], runs[eng, 10.0]
        d = np.interp(t, r40.t, r40["torque_in"]) - np.interp(t, r10.t, r10["torque_in"])
        inner = t > 0.02  # the servo's first few ms (it starts from rest against a jerk-free ramp)
        assert np.max(np.abs(d[inner] - 30.0 * alpha[inner])) < 0.1 * peak, eng
