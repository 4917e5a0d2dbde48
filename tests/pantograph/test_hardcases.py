"""Hard cases stay numerically stable; bad input gives clear errors."""

import math

import numpy as np
import pytest

from mbsuite import AccuracyError, ModelFileError, SceneError, SolverError, load_scene, run
from mbsuite.analysis.harmonic import fundamental
from mbsuite.engines.mujoco_engine import load_model
from mbsuite.engines.pinocchio_engine import load_mjcf, load_urdf
from mbsuite.health import InaccurateResultWarning
from mbsuite.models.pantograph.modelfiles import E_THETA_Q, q_to_theta, theta_to_q
from mbsuite.models.pantograph.mujoco import MujocoPantograph
from mbsuite.models.pantograph.reference import PantographConfig, PantographODE, simulate


def test_stick_slip_2hz_bounded_work_both_paths(lab_scene):
    """Coulomb friction at 2 Hz (the head joint sticks and slips every half cycle): exact sign() stalls DOP853/LSODA;
    the event-driven reference finishes with a bounded number of RHS calls and events, and MuJoCo agrees."""
    sc = lab_scene.replace(input={"frequency": 2.0})
    ref = run(sc.replace(solver={"engine": "reference", "sample_dt": 1e-3}))
    sticks = [e for e in ref.events if e["kind"] == "stick"]
    assert len(sticks) >= 20  # real stick-slip happens (head joint, twice per cycle)
    assert ref.stats["nfev"] < 100_000 and ref.stats["segments"] < 1000
    mj = run(sc)
    assert mj.stats["warnings"] == {}
    for s in ("F1", "HD"):
        a, b = fundamental(mj.t, mj[s], 2.0, 5.0), fundamental(ref.t, ref[s], 2.0, 5.0)
        assert abs(a) / abs(b) == pytest.approx(1.0, abs=0.01)


def test_nonlinear_cylinder_from_supply_pressure_no_stall(lab_scene):
    """P = Ps at the start: the uncorrected law has an unbounded slope there; the laminar band keeps the RHS Lipschitz.
    No stall, no NaN, the pressure stays positive (that the band width does not change the result:
    test_orifice_band.py)."""
    sc = load_scene("pantograph/nonlinear_cylinder").replace(solver={"engine": "reference", "duration": 4.0,
                                                                     "t_settle": 2.0})
    r = run(sc)
    assert r.stats["nfev"] < 100_000
    assert all(np.all(np.isfinite(v)) for v in r.signals.values())
    assert np.min(r["cylinder_state"]) > 0.0


def test_orifice_law_branches():
    """Corrected 3.17: inflow below Ps, outflow above (erratum 12), choked flow independent of Pd below 0.528."""
    ode = PantographODE(cylinder="nonlinear")
    p = ode.p
    assert ode.orifice_mass_flow(0.9 * p.Ps) > 0 > ode.orifice_mass_flow(1.1 * p.Ps)
    assert ode.orifice_mass_flow(p.Ps) == 0.0
    choked = ode.orifice_mass_flow(0.3 * p.Ps)
    assert ode.orifice_mass_flow(0.2 * p.Ps) == pytest.approx(choked, rel=1e-14)
    r = 0.528
    expect = p.cd * p.Ao * math.sqrt(2 * p.gamma / (p.R_gas * (p.gamma - 1))) * p.Ps / math.sqrt(p.T) \
        * r ** (1 / p.gamma) * math.sqrt(1 - r ** ((p.gamma - 1) / p.gamma))
    assert choked == pytest.approx(expect, rel=1e-12)
    # the laminar band joins the turbulent law continuously at r_laminar
    P_edge = p.r_laminar * p.Ps
    assert ode.orifice_mass_flow(P_edge * (1 - 1e-12)) == pytest.approx(ode.orifice_mass_flow(P_edge * (1 + 1e-12)),
                                                                         rel=1e-6)


def test_unilateral_contact_losses_detected_in_both_paths():
    """Push-only contact at 2.5 mm, 4.25 Hz: both paths detect the same losses (count, start times, durations)."""
    sc = load_scene("pantograph/unilateral")
    mj = run(sc)
    ref = run(sc.replace(solver={"engine": "reference", "sample_dt": 1e-3}))
    lm = [e for e in mj.events if e["kind"] == "contact_loss" and e["t_start"] >= 3.0 and e["duration"]]
    lr = [e for e in ref.events if e["kind"] == "contact_loss" and e["t_start"] >= 3.0 and e["duration"]]
    assert len(lr) >= 20 and abs(len(lm) - len(lr)) <= 1
    for b in lr[1:-1]:  # pair each reference loss with the MuJoCo loss that starts nearest (1 ms sampling)
        a = min(lm, key=lambda e: abs(e["t_start"] - b["t_start"]))
        assert a["t_start"] == pytest.approx(b["t_start"], abs=2.5e-3)
        assert a["duration"] == pytest.approx(b["duration"], abs=2.5e-3)
    assert sum(e["duration"] for e in lm) == pytest.approx(sum(e["duration"] for e in lr), rel=0.05)
    assert min(mj["contact_force"]) == 0.0 and min(ref["contact_force"]) == 0.0


def test_energy_drift_without_damping_and_friction():
    """Damping and friction off, constant cylinder, fixed ram: the reference conserves energy to 1e-8 J over 10 s;
    MuJoCo RK4 at 5e-4 s to 1e-5 J and implicitfast (semi-implicit Euler) to 1e-2 J (bounded, not growing)."""
    cfg = PantographConfig(cylinder="constant", viscous=False, coulomb=False)
    ode = PantographODE(config=cfg)
    x0 = ode.equilibrium()
    x0[3:6] = [0.05, -0.03, 0.1]
    E0 = ode.energy(x0, 1.58)
    sol = simulate(ode, lambda t: 1.58, 10.0, x0, method="DOP853", rtol=1e-11, atol=1e-13)
    drift = max(abs(ode.energy(sol.x[:, k], 1.58) - E0) for k in range(0, sol.t.size, 10))
    assert drift < 1e-8
    for integ, bound in (("rk4", 1e-5), ("implicitfast", 1e-2)):
        mp = MujocoPantograph(config=cfg, integrator=integ, timestep=5e-4)
        mp.set_static(theta_to_q(x0[:3]), 1.58)
        mp.data.qvel[:] = np.linalg.solve(E_THETA_Q, x0[3:6])
        tr = mp.stepper(every=200).run(20000)
        es = [ode.energy(np.r_[q_to_theta(q), E_THETA_Q @ v], 1.58) - E0 for q, v in zip(tr["qpos"], tr["qvel"],
                                                                                        strict=True)]
        assert max(abs(e) for e in es) < bound, integ


@pytest.mark.parametrize("integrator", ["euler", "implicitfast"])
def test_over_large_timestep_is_a_clear_error(lab_scene, integrator):
    """h = 0.02 s: refused before stepping (AccuracyError, stability_margin); with inaccuracy allowed the run diverges
    and the core stops it with a SolverError telling to reduce the step (never garbage)."""
    sc = lab_scene.replace(solver={"timestep": 0.02, "integrator": integrator, "duration": 2.0, "t_settle": 1.0})
    with pytest.raises(AccuracyError, match="stability_margin"):
        run(sc)
    with pytest.raises(SolverError, match="reduce solver.timestep"):
        run(sc.replace(solver={"allow_inaccurate": True}))


def test_over_large_timestep_rk4_stays_finite(lab_scene):
    sc = lab_scene.replace(solver={"timestep": 0.02, "integrator": "rk4", "duration": 2.0, "t_settle": 1.0,
                                   "allow_inaccurate": True})
    with pytest.warns(InaccurateResultWarning):
        res = run(sc)
    assert all(np.all(np.isfinite(v)) for v in res.signals.values())


def test_malformed_model_files(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody><body><joint type='hinge'/></body></worldbody>")  # not closed
    with pytest.raises(ModelFileError, match="bad.xml"):
        load_model(bad)
    with pytest.raises(ModelFileError, match="bad.xml"):
        load_mjcf(bad)
    badu = tmp_path / "bad.urdf"
    badu.write_text("<robot name='x'><link name='a'/><joint name='j' type='revolute'>"
                    "<parent link='a'/></joint></robot>")
    with pytest.raises(ModelFileError, match="bad.urdf"):
        load_urdf(badu)
    with pytest.raises(ModelFileError, match="not found"):
        load_model(tmp_path / "missing.xml")


def test_unknown_effect_value_and_unreachable_height(lab_scene):
    with pytest.raises(SceneError, match="valid"):
        lab_scene.replace(effects={"contact": "magnetic"})
    from mbsuite import ParameterError

    with pytest.raises(ParameterError, match="cannot be reached"):
        lab_scene.replace(params={"y_op": 5.0})
