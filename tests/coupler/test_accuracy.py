"""The coupler's declared accuracy (`mbsuite/models/coupler/accuracy.py`): the declaration, its values against an
independent computation, the error estimate on the command line, and (slow) every shipped scene's headlines at their
default settings within their tolerances of a much refined run of another method, with the estimate bracketing the
true error."""

from __future__ import annotations

import json

import numpy as np
import pytest

import mbsuite
from mbsuite.cli import main
from mbsuite.models.coupler import accuracy as acc
from mbsuite.models.coupler.criteria import double_c5
from mbsuite.trust.estimate import declared
from mbsuite.trust.health import InaccurateResultWarning

SCENES = ("double_lateral", "double_massless", "double_inclined", "double_phibc90", "double_friction")


def _scene(name: str, **solver):
    return mbsuite.load_scene(f"coupler/{name}").replace(solver=solver) if solver else \
        mbsuite.load_scene(f"coupler/{name}")


def test_declaration_names_units_tolerances_and_refinement():
    """Each path's headlines, units and tolerances; the MuJoCo refinement halves step and samples and holds the
    friction time constant at the unrefined run's 2 timesteps (every level solves one model); the reference halves its
    sample spacing (10 timesteps where sample_dt is 0)."""
    mj = _scene("double_friction")
    assert [(h.name, h.unit, h.tol) for h in declared(mj)] == [
        ("phi_c_err_max", "rad", 5e-6), ("torque_in_mean", "N m", 0.01), ("closure_residual_max", "m", 1e-5),
        ("torque_in_ripple_pp", "N m", 0.3), ("link_force_max_abs", "N", 5.0)]
    ref = mj.replace(solver={"engine": "reference"})
    assert [(h.name, h.unit, h.tol) for h in declared(ref)] == [
        ("torque_in_mean", "N m", 1e-5), ("torque_in_ripple_pp", "N m", 0.3), ("closure_residual_max", "m", 1e-12),
        ("phi_c_kin_fluctuation_pp", "rad", 5e-6)]
    r = acc.refinement(mj)
    assert (r.setting, r.factor, r.order) == ("solver.timestep + solver.sample_dt", 2.0, 1.0)
    lv2 = r.refine(mj, 2)
    assert (lv2.solver.timestep, lv2.solver.sample_dt) == (5e-4 / 4, 2e-3 / 4)
    assert lv2.build_params().solref_friction_timeconst == 2 * 5e-4 and r.refine(mj, 0) is mj
    assert acc.refinement(mj.replace(solver={"integrator": "rk4"})).order == 4.0
    fine = acc.much_refined(mj)
    assert (fine.solver.integrator, fine.solver.timestep, fine.solver.sample_dt) == ("rk4", 5e-4 / 8, 2e-3 / 16)
    rr = acc.refinement(ref)
    assert (rr.setting, rr.order, rr.refine(ref, 1).solver.sample_dt) == ("solver.sample_dt", 2.0, 1e-3)
    assert rr.refine(ref.replace(solver={"sample_dt": 0.0}), 1).solver.sample_dt == 10 * 5e-4 / 2
    # a scene's [accuracy] table overrides a tolerance by its headline name
    assert {h.name: h.tol for h in declared(mj.replace(accuracy={"link_force_max_abs": 20.0}))}[
        "link_force_max_abs"] == 20.0


def test_values_against_the_signals_and_closed_forms():
    """The headline values of a short run against numpy on its signals over the window t >= max(t_settle, t_ramp)
    (computed here; the mean is the time average), and on the kinematic reference against two independent numbers:
    the mean input torque over whole revolutions is the load, 1000 N m, by the power balance (the kinetic energy is
    periodic; measured 7.0e-7 N m off at 2 ms samples, bound 1e-5, 14x); c5 as a peak-to-peak read off the 2 ms
    samples against c5's extrema located by Brent on the FPP (`criteria.double_c5`), which the sampled one may only
    under-read, by less than its declared tolerance 5e-6 rad (measured 1.6e-7 rad)."""
    sc = _scene("double_phibc90", duration=0.75, t_settle=0.25)
    res = mbsuite.run(sc)
    w = res.t >= max(sc.solver.t_settle, sc.input["t_ramp"])
    forces = np.array([res[f"link_force_{k}"][w] for k in range(1, 9)])
    mine = {"phi_c_err_max": np.max(np.abs(res["phi_c"][w] - res["phi_c_kin"][w])),
            "torque_in_mean": np.trapezoid(res["torque_in"][w], res.t[w]) / np.ptp(res.t[w]),  # time average
            "closure_residual_max": np.max(res["closure_residual"][w]),
            "torque_in_ripple_pp": np.ptp(res["torque_in"][w]), "link_force_max_abs": np.max(np.abs(forces))}
    assert acc.values(sc, res) == pytest.approx(mine, rel=1e-14, abs=0.0)

    ref = sc.replace(solver={"engine": "reference", "duration": 1.5, "t_settle": 0.5})  # 2 revolutions in the window
    v = acc.values(ref, mbsuite.run(ref))
    assert abs(v["torque_in_mean"] - 1000.0) <= 1e-5  # measured 7.0e-7 N m
    c5 = double_c5(ref.build_params(), ref.input["z_c"])["c5_pp"]
    assert 0.0 <= c5 - v["phi_c_kin_fluctuation_pp"] <= 5e-6


def test_dynamics_command_error_estimate(tmp_path, capsys):
    """`mbsuite coupler dynamics --error-estimate`: the estimate's table and JSON rows (the reference path, one
    revolution in the window); an estimate above a tightened tolerance keeps the result, printed and flagged, with exit
    status 3 and a line naming the headline and the setting to refine; accepted as a warning with --allow-inaccurate."""
    scene = tmp_path / "short.toml"
    scene.write_text('model = "coupler"\n[input]\ntype = "constant_speed"\nz_c = 0.05\n'
                     '[solver]\nengine = "reference"\nduration = 0.85\nt_settle = 0.35\nsample_dt = 2e-3\n')
    assert main(["coupler", "dynamics", str(scene), "--error-estimate", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    est = data["summary"]["error_estimate"]
    assert est["setting"] == "solver.sample_dt"
    assert est["levels"] == ["solver.sample_dt = 0.002", "solver.sample_dt = 0.001", "solver.sample_dt = 0.0005"]
    assert [r["name"] for r in est["rows"]] == list(acc.REFERENCE) and all(r["ok"] for r in est["rows"])
    scene.write_text(scene.read_text() + "[accuracy]\ntorque_in_ripple_pp = 1e-9\n")
    assert main(["coupler", "dynamics", str(scene), "--error-estimate"]) == 3
    cap = capsys.readouterr()
    assert "error_estimate[torque_in_ripple_pp]" in cap.err and cap.err.startswith("mbsuite: inaccurate:")
    assert "EXCEEDED" in cap.out and "INACCURATE RESULT, kept" in cap.out
    with pytest.warns(InaccurateResultWarning, match="refine solver.sample_dt"):
        assert main(["coupler", "dynamics", str(scene), "--error-estimate", "--allow-inaccurate"]) == 0
    assert "EXCEEDED" in capsys.readouterr().out


#: scenes on which the estimate must bracket the true error of every MuJoCo headline (estimate / true error measured
#: 1.25-5.8; the other two scenes have headlines whose estimate sits just below or at rounding, see README)
BRACKET = ("double_lateral", "double_inclined", "double_friction")


@pytest.mark.slow
@pytest.mark.parametrize("engine", ["mujoco", "reference"])
@pytest.mark.parametrize("name", SCENES)
def test_declared_tolerances_hold_against_a_much_refined_run(name, engine):
    """Every headline at the scene's default settings within its declared tolerance of a much refined run of another
    method (MuJoCo: RK4 at h/8 sampled at sample_dt/16, the friction model held; reference: sample_dt/16), and on the
    reference the mean input torque within its tolerance of the power balance's 1000 N m. On three scenes the error
    estimate brackets the true error: estimate >= true and <= 10x true (measured 1.25-5.8x)."""
    sc = _scene(name, engine=engine)
    res = mbsuite.run(sc, error_estimate=True, workers=2)
    fine_sc = acc.much_refined(sc)
    fine = acc.values(fine_sc, mbsuite.run(fine_sc))
    for row in res.error_estimate.rows:
        true = abs(row.value - fine[row.name])
        assert true <= row.tol, (row.name, true, row.tol)
        assert row.error <= row.tol, (row.name, row.error, row.tol)
        if engine == "mujoco" and name in BRACKET:
            assert true <= row.error <= 10 * true, (row.name, row.error, true)
    if engine == "reference":
        row = res.error_estimate["torque_in_mean"]
        assert abs(row.value - sc.input["load_torque"]) <= row.tol
