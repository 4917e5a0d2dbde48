"""The coupler's MuJoCo path on the native core and its batched kinematic reference: the recorded signals against a
plain Python replay of the same steps, batched FPP against the per-sample continuation, the servo bound, failures
named by their sample time, and runs in concurrent threads."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

import mbsuite
from mbsuite.errors import GeometryError, SolverError
from mbsuite.models.coupler import mujoco as cm
from mbsuite.models.coupler import reference
from mbsuite.models.coupler.double import (
    DOUBLE_TURN,
    double_residual,
    double_residual_batch,
    double_residual_jac,
    double_residual_jac_batch,
    ramp_double,
    solve_double,
)
from mbsuite.models.coupler.geometry import phi_c_offset
from mbsuite.models.coupler.params import CouplerParams
from mbsuite.models.coupler.reference import (
    kinematic_derivatives,
    kinematic_output,
    kinematic_pose,
    kinematic_rates,
    revolution_guess,
    shaft_b_energy,
    shaft_b_energy_batch,
)
from mbsuite.models.coupler.scenario import ramp, scene_inputs
from mbsuite.scenes import load_scene


def continuation_poses(p: CouplerParams, inp: dict, phi_a: np.ndarray) -> np.ndarray:
    """Full FPP poses (N, 8) one sample after the other (the readable path of `kinematic_output`, all 8 unknowns)."""
    rest = [inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]]
    k0 = round(phi_a[0] / (2 * math.pi))
    u = ramp_double(p, np.array([phi_a[0] - 2 * math.pi * k0, *rest])) + k0 * DOUBLE_TURN
    out = np.empty((phi_a.size, 8))
    for i, pa in enumerate(phi_a):
        g = u.copy()
        if i:
            g[[0, 5]] += pa - phi_a[i - 1]
        k = round(pa / (2 * math.pi))
        u = solve_double(p, np.array([pa - 2 * math.pi * k, *rest]), g - k * DOUBLE_TURN) + k * DOUBLE_TURN
        out[i] = u
    return out


def _inp(**kw) -> dict:
    return {**{k: 0.0 for k in ("alpha_cx", "alpha_cz", "x_c", "z_c")}, **kw}


# ------------------------------------------------------------------------------------------------ batched FPP
def test_batched_equations_equal_the_readable_ones():
    rng = np.random.default_rng(7)
    for p in (CouplerParams(), CouplerParams(phi_bc=math.pi / 2, l_b=1.0, gamma=0.2)):
        n = 40
        inp = np.column_stack([rng.uniform(-700, 700, n), rng.uniform(-0.04, 0.04, (n, 2)),
                               rng.uniform(-0.06, 0.06, (n, 2))])
        u = rng.normal(size=(n, 8)) * 0.2
        r = np.array([double_residual(p, x, v) for x, v in zip(inp, u, strict=True)])
        J = np.array([double_residual_jac(p, x, v) for x, v in zip(inp, u, strict=True)])
        np.testing.assert_allclose(double_residual_batch(p, inp, u), r, rtol=0, atol=1e-12)
        np.testing.assert_allclose(double_residual_jac_batch(p, inp, u), J, rtol=0, atol=1e-12)


@pytest.mark.parametrize("params, inp, phi", [
    ({}, _inp(z_c=0.05), (0.0, 2 * math.pi, 361)),  # homokinetic, one revolution
    ({"phi_bc": math.pi / 2}, _inp(z_c=0.08), (0.0, 4 * math.pi, 721)),  # the fluctuations add
    ({}, _inp(alpha_cx=0.03, z_c=0.03), (0.0, 2 * math.pi, 181)),  # inclined output shaft
    ({"phi_bc": math.pi / 2}, _inp(alpha_cz=-0.02, x_c=0.04, z_c=0.02), (600.0, 600.0 + 4 * math.pi, 401)),  # long
    ({}, _inp(z_c=0.05), (1250.0, 1250.0 + 2 * math.pi, 101)),  # 100 s at 2 rev/s: phi_a ~ 1250 rad
])
def test_batched_fpp_equals_per_sample_continuation(params, inp, phi):
    """Every sample of the batched FPP is the continuation's pose to 1e-12, over full revolutions, with phi_a wrapped
    for the solve when it is hundreds of rad; started from a perturbed pose (like a simulated one, ~1e-3 off)."""
    p = CouplerParams(**params)
    phi_a = np.linspace(*phi)
    U_ref = continuation_poses(p, inp, phi_a)
    guess = U_ref + np.random.default_rng(3).normal(scale=1e-3, size=U_ref.shape)
    U = kinematic_pose(p, inp, phi_a, guess)
    assert np.max(np.abs(U - U_ref)) < 1e-12
    assert U[-1, 0] - U[0, 0] - (phi_a[-1] - phi_a[0]) == pytest.approx(0.0, abs=1e-10)  # whole turns: closes
    if phi[0] == 0.0:  # the model's readable reference, continuation from the initial pose
        assert np.max(np.abs(kinematic_output(p, inp, phi_a, U_ref[0]) - U[:, 0])) < 1e-12


def test_batched_fpp_on_a_simulated_run_equals_continuation():
    """On the samples of a MuJoCo run (phi_bc = pi/2, start-up ramp included), started from the simulated poses."""
    sc = load_scene("coupler/double_phibc90").replace(solver={"duration": 0.6})
    res = mbsuite.run(sc)
    p, inp = sc.build_params(), scene_inputs(sc)
    u0 = ramp_double(p, np.array([0.0, inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]]))
    np.testing.assert_allclose(res["phi_c_kin"], kinematic_output(p, inp, res["phi_a"], u0), rtol=0, atol=1e-12)


def test_non_converging_sample_is_named_by_its_time():
    p = CouplerParams()
    inp = _inp(z_c=0.05)
    phi_a = np.linspace(0.0, 1.0, 5)
    guess = continuation_poses(p, inp, phi_a)
    t = np.array([0.0, 0.01, 0.02, 0.03, 0.04])
    bad = guess.copy()
    bad[2, 0] = np.nan
    with pytest.raises(SolverError, match=r"non-finite residual at t = 0\.02 s"):
        kinematic_pose(p, inp, phi_a, bad, times=t)
    bad = guess.copy()
    bad[3, [0, 5]] += 1.0  # far off: Gauss-Newton diverges
    with pytest.raises(SolverError, match=r"did not converge in 50 iterations at t = 0\.03 s"):
        kinematic_pose(p, inp, phi_a, bad, times=t)
    bad = guess.copy()
    bad[1, 3], bad[1, 1] = -2 * p.e_y, -4 * p.e_y  # shaft b pushed through platform A: converges to a crossed pose
    with pytest.raises(GeometryError, match=r"at t = 0\.01 s .*cross platform A"):
        kinematic_pose(p, inp, phi_a, bad, times=t)


def test_pose_far_from_the_simulated_one_is_an_error(monkeypatch):
    """The batched FPP must land on the simulated pose's branch: a pose farther than BRANCH_TOL is reported."""
    p = CouplerParams()
    inp = _inp(z_c=0.05)
    phi_a = np.linspace(0.0, 1.0, 5)
    guess = continuation_poses(p, inp, phi_a)
    guess[4, 2] += 1e-6
    kinematic_pose(p, inp, phi_a, guess)  # 1e-6 is the same branch
    monkeypatch.setattr(reference, "BRANCH_TOL", 1e-7)
    with pytest.raises(SolverError, match=r"t = 0\.4 s .*another assembly branch"):
        kinematic_pose(p, inp, phi_a, guess, times=np.arange(5) / 10)


def test_batched_rates_and_energy_equal_the_readable_ones():
    p = CouplerParams(phi_bc=math.pi / 2)
    inp = _inp(alpha_cx=0.02, z_c=0.06)
    phi_a = np.linspace(0.0, 2 * math.pi, 61)
    u0 = ramp_double(p, np.array([0.0, 0.02, 0.0, 0.0, 0.06]))
    U0, D0, _ = kinematic_derivatives(p, inp, phi_a, u0)
    U, D = kinematic_rates(p, inp, phi_a, revolution_guess(p, inp, phi_a))
    # measured 3.1e-15 (poses) and 1.7e-11 (du/dphi_a by central differences of poses solved to 1e-13); bounds ~6x
    assert np.max(np.abs(U - U0)) < 2e-14 and np.max(np.abs(D - D0)) < 1e-10
    rates = D * 4.0
    e0 = np.array([shaft_b_energy(p, u, du) for u, du in zip(U, rates, strict=True)])
    np.testing.assert_allclose(shaft_b_energy_batch(p, U, rates), e0, rtol=1e-13)


# ------------------------------------------------------------------------------------------------ the MuJoCo path
def test_recorded_signals_equal_a_python_replay():
    """The native run, replayed step by step in Python (ctrl row k written before step k, every recorded quantity
    taken from a forward at the recorded state): same trajectory and the same closure residuals, link tensions
    (from the body axes) and drive torque, over the start-up ramp and after it."""
    sc = load_scene("coupler/double_lateral").replace(effects={"friction": True},
                                                     solver={"duration": 0.3, "t_settle": 0.1})
    res = mbsuite.run(sc)
    p, inp, sv = sc.build_params(), scene_inputs(sc), sc.solver
    m, d, _ = cm.build(p, dict(sc.effects), inp, sv.timestep, sv.integrator)
    n, every = int(round(sv.duration / sv.timestep)), int(round(sv.sample_dt / sv.timestep))
    ctrl = np.array([[inp["omega"] * ramp(k * sv.timestep, inp["t_ramp"]),
                      -inp["load_torque"] * ramp(k * sv.timestep, inp["t_ramp"])] for k in range(n)])
    J, E, B = mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_EQUALITY, mujoco.mjtObj.mjOBJ_BODY
    eqs = [mujoco.mj_name2id(m, E, f"link{k + 1}") for k in range(8)]
    links = [mujoco.mj_name2id(m, B, f"link{k + 1}") for k in range(8)]
    ic = m.jnt_qposadr[mujoco.mj_name2id(m, J, "phi_c")]
    rows = []
    for k in range(n + 1):
        if k < n:
            d.ctrl[:] = ctrl[k]
        if k % every == 0:
            mujoco.mj_forward(m, d)
            eq = np.flatnonzero(d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
            res_k, f_k = 0.0, []
            for e, b in zip(eqs, links, strict=True):
                r = eq[d.efc_id[eq] == e]
                res_k = max(res_k, float(np.linalg.norm(d.efc_pos[r])))
                f_k.append(float(d.xmat[b].reshape(3, 3)[:, 2] @ d.efc_force[r]))
            rows.append([d.time, d.qpos[0], d.qpos[ic] + phi_c_offset(p), d.actuator_force[0], res_k, *f_k])
        if k < n:
            mujoco.mj_step(m, d)
    want = np.array(rows)
    got = np.column_stack([res.t, res["phi_a"], res["phi_c"], res["torque_in"], res["closure_residual"],
                           *(res[f"link_force_{k + 1}"] for k in range(8))])
    assert got.shape == want.shape
    # the same MuJoCo steps: measured 2.2e-16 rad, 0 N m, 0 m and 3.2e-12 N (of 1.8e3 N, the tension's summation
    # order); bounds about 10x these, a few ulps
    np.testing.assert_allclose(got[:, :3], want[:, :3], rtol=0, atol=2e-15)  # s, rad (the phi_c offset adds an ulp)
    np.testing.assert_allclose(got[:, 3], want[:, 3], rtol=1e-14, atol=0)  # N m, of ~1e3
    np.testing.assert_allclose(got[:, 4], want[:, 4], rtol=1e-14, atol=0)  # m, of ~1e-4
    np.testing.assert_allclose(got[:, 5:], want[:, 5:], rtol=0, atol=3e-11)  # N, of ~1e3
    assert res.stats["steps"] == n and res.stats["integrator"] == "implicitfast"


def test_result_keeps_the_scene_outputs_with_declared_units():
    sc = load_scene("coupler/double_lateral").replace(outputs=["phi_c", "torque_in"],
                                                     solver={"duration": 0.3, "t_settle": 0.1})
    for engine in ("mujoco", "reference"):
        res = mbsuite.run(sc, engine=engine)
        assert set(res.signals) == {"phi_c", "torque_in", "phi_c_err"}
        assert res.units == {"phi_c": "rad", "torque_in": "N m", "phi_c_err": "rad"}
        assert res.engine == engine and res.scene["outputs"]["signals"] == ["phi_c", "torque_in"]


@pytest.mark.parametrize("integrator, timestep", [("rk4", 1e-3), ("euler", 1e-3)])
def test_unstable_servo_is_a_solver_error(integrator, timestep):
    """An explicit integrator at a step too long for the stiff velocity servo: the drive torque leaves its bound
    kv x servo_tol within the start-up ramp and the run stops with the servo's advice."""
    sc = load_scene("coupler/double_lateral").replace(solver={"integrator": integrator, "timestep": timestep,
                                                              "duration": 1.0})
    with pytest.raises(SolverError) as ei:
        mbsuite.run(sc)
    msg = str(ei.value)
    assert "torque_in =" in msg and "outside its plausible range [-200000, 200000]" in msg
    assert f"integrator {integrator}, timestep {timestep:g} s" in msg
    assert "input velocity servo (kv = 200000 N m s/rad" in msg
    assert "reduce solver.timestep or use implicitfast/implicit" in msg
    t_fail = float(msg.split("at t = ")[1].split(" s")[0])
    assert t_fail < 0.05  # caught as soon as it leaves the bound, not after seconds of garbage


def test_servo_too_weak_for_the_load_is_named():
    """The bound is the servo's speed error: a servo that cannot hold the load trips it as well, and the advice
    names kv_drive."""
    sc = load_scene("coupler/double_lateral").replace(params={"kv_drive": 500.0},
                                                     solver={"duration": 0.5, "t_settle": 0.3})
    with pytest.raises(SolverError, match=r"torque_in = .* outside its plausible range \[-500, 500\].*kv_drive"):
        mbsuite.run(sc)
    assert cm.servo_bound(sc.build_params(), scene_inputs(sc)) == 500.0
