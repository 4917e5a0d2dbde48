"""Declared accuracy and the error estimate (`mbsuite.trust.estimate`, `mbsuite.analysis.errorestimate`).

The estimator against sequences with a known limit (the grid-convergence index must bracket the true error without
inflating it more than its safety factor allows), against a closed form through a real run (the IFToMM four-bar on its
parallelogram branch, psi'' = -(6/5) g cos psi), and against a much finer run of the same model on MuJoCo; the
`[accuracy]` section and the health verdict of an estimate above its tolerance."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbsuite
from mbsuite.analysis.errorestimate import error_estimate
from mbsuite.errors import SceneError
from mbsuite.trust.estimate import declared, estimate_one
from mbsuite.trust.health import AccuracyError


@pytest.mark.parametrize("factor,order", [(2.0, 1.0), (2.0, 2.0), (2.0, 4.0), (10.0, 1.0), (10.0, 2.0)])
@pytest.mark.parametrize("c,a", [(1.0, 0.0), (-3.0, 0.3), (0.5, -0.4)])
def test_estimate_brackets_a_sequence_with_a_known_limit(order, factor, c, a):
    """q(h) = q* + c h^p (1 + a h): the estimate of |q(h) - q*| lies in [1, 2] times the true error (safety 1.25
    times the Richardson factor at the observed order; the higher-order term moves it by up to 1.5x here)."""
    q_star, h = 3.7, 0.1 if factor == 2.0 else 0.05

    def q(hh: float) -> float:
        return q_star + c * hh**order * (1 + a * hh)

    err, p_obs, asym = estimate_one(q(h), q(h / factor), q(h / factor**2), factor, order)
    true = abs(q(h) - q_star)
    assert asym
    assert p_obs == pytest.approx(order, abs=0.25)
    assert 1.0 <= err / true <= 2.0


def test_estimate_of_an_oscillating_sequence_still_brackets():
    """Values that overshoot and come back (not in the asymptotic range): the two-level factor 3 on the larger
    difference; the true error is |q0 - q*| = 1."""
    err, _, asym = estimate_one(1.0, -0.5, 0.125, 2.0, 2.0)
    assert not asym
    assert err >= 1.0
    assert err == pytest.approx(3.0 * 1.5)


def test_values_equal_to_round_off_give_no_order_and_no_error():
    err, p_obs, asym = estimate_one(2.0, 2.0, 2.0, 2.0, 4.0)
    assert (err, p_obs, asym) == (0.0, None, True)
    # converged refined values: the error of q0 is its distance to them
    err, p_obs, _ = estimate_one(2.5, 2.0, 2.0, 2.0, 4.0)
    assert err == 0.5 and p_obs is None
    assert estimate_one(1.0, math.nan, 1.0, 2.0, 1.0)[0] == math.inf


def _fourbar(**solver):
    return mbsuite.load_scene("iftomm/fourbar").replace(solver={"duration": 2.0, "allow_inaccurate": True, **solver})


def _closed_form_angle(scene) -> float:
    g = scene.build_params().gravity
    sol = solve_ivp(lambda _, x: [x[1], -1.2 * g * math.cos(x[0])], (0.0, scene.solver.duration),
                    [math.pi / 2, float(scene.input["rate"])], method="DOP853", rtol=1e-13, atol=1e-13)
    return float(sol.y[0][-1] - math.pi / 2)


def test_estimate_brackets_the_true_error_against_a_closed_form():
    """Pinocchio path at rtol 1e-5 (the closures exact on the branch to 5e-8 rad): the estimate of the final crank
    angle against the closed form. Measured: estimate 1.33e-4 rad, true 1.05e-4 rad (1.26x), observed order 0.86."""
    sc = _fourbar(engine="reference", rtol=1e-5, atol=1e-7)
    est = error_estimate(sc, workers=2)
    row = est["final_angle"]
    true = abs(row.value - _closed_form_angle(sc))
    assert true > 1e-5  # a real error to bracket
    assert true <= row.error <= 3.0 * true
    assert est.setting == "solver.rtol" and est.factor == 10.0


def test_estimate_brackets_the_true_error_against_a_finer_run_on_mujoco():
    """MuJoCo Euler at 1 ms against RK4 at 0.1 ms of the same model (the soft closures are part of it; against the
    rigid closed form MuJoCo's error is the closures' own 7e-3 rad, which no step refinement removes: docs/accuracy.md).
    Measured: estimate 3.67e-4 rad, observed order 1.12."""
    sc = _fourbar(integrator="euler", timestep=1e-3)
    res = mbsuite.run(sc, error_estimate=True, workers=2)
    fine = mbsuite.run(sc.replace(solver={"integrator": "rk4", "timestep": 1e-4}))
    row = res.error_estimate["final_angle"]
    true = abs(row.value - float(fine["input_angle"][-1]))
    assert true <= row.error <= 3.0 * true
    assert row.order == pytest.approx(1.0, abs=0.3)
    # it is in the result's summary (JSON) with the levels that ran
    d = json.loads(json.dumps(res.summary()["error_estimate"]))
    assert d["levels"] == ["solver.timestep = 0.001, solver.sample_dt = 0.01",
                           "solver.timestep = 0.0005, solver.sample_dt = 0.005",
                           "solver.timestep = 0.00025, solver.sample_dt = 0.0025"]
    assert {r["name"] for r in d["rows"]} == {"final_angle", "closure_residual_max", "energy_drift_max"}


def test_an_estimate_above_its_tolerance_is_an_accuracy_error_naming_headline_and_setting():
    sc = mbsuite.load_scene("iftomm/fourbar").replace(
        solver={"duration": 1.0, "integrator": "euler"}, accuracy={"final_angle": 1e-9})
    with pytest.raises(AccuracyError, match=r"error_estimate\[final_angle\].*refine solver.timestep"):
        mbsuite.run(sc, error_estimate=True, workers=2)
    res = mbsuite.run(sc.replace(solver={"allow_inaccurate": True}), error_estimate=True, workers=2)
    assert any("error_estimate[final_angle]" in w for w in res.warnings)
    assert res.error_estimate["final_angle"].tol == 1e-9
    assert not res.error_estimate["final_angle"].ok


def test_accuracy_section_is_checked():
    sc = mbsuite.load_scene("iftomm/fourbar")
    assert {h.name for h in declared(sc)} == {"final_angle", "closure_residual_max", "energy_drift_max"}
    assert {h.name: h.tol for h in declared(sc.replace(accuracy={"final_angle": 0.5}))}["final_angle"] == 0.5
    with pytest.raises(SceneError, match=r"unknown headline\(s\) \['F1'\].*final_angle"):
        sc.replace(accuracy={"F1": 1.0})
    for bad in (0.0, -1.0, math.inf, True, "1"):
        with pytest.raises(SceneError, match="accuracy.final_angle"):
            sc.replace(accuracy={"final_angle": bad})
    assert sc.replace(accuracy={"final_angle": np.float64(0.5)}).accuracy["final_angle"] == 0.5


def test_sweep_and_run_error_estimates_agree_point_by_point(tmp_path, capsys):
    """`mbsuite sweep --error-estimate` runs every grid point at three levels; each point's estimate equals the one
    `mbsuite run --error-estimate` gives for that point's scene (the same runs, another route)."""
    from mbsuite.cli import main

    scene = tmp_path / "fourbar_short.toml"
    scene.write_text('model = "iftomm"\n[input]\ntype = "initial"\nrate = 6.0\n'
                     '[solver]\nintegrator = "euler"\nduration = 1.0\nsample_dt = 1e-2\nallow_inaccurate = true\n')
    assert main(["sweep", str(scene), "--vary", "input.rate=4,6", "--error-estimate", "--workers", "2",
                 "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    for pt in data["points"]:
        rate = pt["values"]["input.rate"]
        one = mbsuite.run(mbsuite.load_scene(str(scene)).replace(input={"rate": rate}), error_estimate=True,
                          workers=1).error_estimate
        for row in pt["error_estimate"]["rows"]:
            assert row["value"] == one[row["name"]].value
            assert row["error"] == pytest.approx(one[row["name"]].error, rel=1e-12, abs=1e-300)


def test_a_relative_tolerance_scales_with_the_value():
    """`Headline(tol, rtol)`: the bound is tol + rtol |value| of the run (level 0). A second-order sequence with a
    known limit (hand values: q_k = 2 + 0.4 / 4^k, true error of q0 0.4, estimate 1.25 * 0.3 * 4/3 = 0.5) is within
    0.05 + 0.3 * 2.4 = 0.77 and outside 0.05 + 0.1 * 2.4 = 0.29; an [accuracy] override is absolute."""
    from mbsuite.trust.estimate import Headline, estimate, timestep_refinement

    ref = timestep_refinement(2.0)
    levels = [{"q": 2.0 + 0.4 / 4**k} for k in range(3)]
    ok = estimate(levels, (Headline("q", "1", 0.05, rtol=0.3),), ref)["q"]
    bad = estimate(levels, (Headline("q", "1", 0.05, rtol=0.1),), ref)["q"]
    assert ok.error == pytest.approx(0.5) and ok.tol == pytest.approx(0.77) and ok.ok
    assert bad.tol == pytest.approx(0.29) and not bad.ok
    assert Headline("q", "1", 0.05, rtol=0.1).bound(-3.0) == pytest.approx(0.35)


# ------------------------------------------------------------------------------------ coarse companions, by hand
def _coarse_levels(a: float, b: float, c: float = 10.0, h: float = 0.1) -> list[dict[str, float]]:
    """v = c + a h^2 + b h^3 at the run's h and at 2h, 4h (the companions coarsened once and twice)."""
    return [{"q": c + a * x**2 + b * x**3} for x in (h, 2 * h, 4 * h)]


@pytest.mark.parametrize("a,b,d0,d1,order,error", [
    # d0 = v(2h) - v(h), d1 = v(4h) - v(2h); order log2(d1 / d0); error 1.25 |d0| / (2^p' - 1), p' = min(order, 2)
    (0.5, 0.2, 0.0164, 0.0712, 2.1181814263484, 1.25 * 0.0164 / 3.0),             # p' = the nominal 2
    (0.5, -0.3, 0.0129, 0.0432, 1.7436602467404, 1.25 * 0.0129 / (0.0432 / 0.0129 - 1.0)),  # p' = observed
])
def test_coarse_companions_estimate_by_hand(a, b, d0, d1, order, error):
    """Hand-made level values v = 10 + a h^2 + b h^3 at h = 0.1, 0.2, 0.4: the differences, the observed order, the
    estimated error (hand numbers: case 1 error 0.0068333, true 0.0052; case 2 error 0.0068651, true 0.0047), the
    settings and the check in the row, `to_dict` and the table."""
    from mbsuite.trust.estimate import Headline, estimate, timestep_refinement

    ref = timestep_refinement(2.0)
    settings = ["solver.timestep = 0.1", "solver.timestep = 0.2", "solver.timestep = 0.4"]
    est = estimate(_coarse_levels(a, b), (Headline("q", "m", 0.05),), ref, settings, companions="coarse")
    r = est["q"]
    assert est.companions == "coarse" and est.passed and not est.fallback
    assert r.differences == pytest.approx((d0, d1), rel=1e-9)
    assert r.order == pytest.approx(order, rel=1e-9)
    assert r.error == pytest.approx(error, rel=1e-9)
    assert r.error >= abs(r.value - 10.0)  # it brackets the true error (1.31x, 1.46x)
    assert (r.check, r.passed, r.asymptotic, r.ok) == ("asymptotic", True, True, True)
    d = est.to_dict()
    assert (d["companions"], d["levels"], d["order_band"]) == ("coarse", settings, [1.5, 2.5, 4.0])
    row = d["rows"][0]
    assert row["coarse"] == pytest.approx([10.0 + 0.04 * a + 0.008 * b, 10.0 + 0.16 * a + 0.064 * b], rel=1e-12)
    assert "refined" not in row
    assert row["differences"] == pytest.approx([d0, d1], rel=1e-9)
    assert (row["order"], row["error"], row["check"], row["passed"]) == (r.order, r.error, "asymptotic", True)
    table = est.table()
    assert "solver.timestep coarsened by 2 and 4 (coarse companions; nominal order 2, observed orders accepted in " \
           "[1.5, 4], safety factor 1.25 up to 2.5, 3 above; levels: solver.timestep = 0.1; solver.timestep = 0.2; " \
           "solver.timestep = 0.4)" in table
    assert f"{r.error:.4g}" in table and f"{d0:.4g}" in table and f"{d1:.4g}" in table and f"{order:.2f}" in table


def test_coarse_check_by_hand():
    """`check_coarse`: which level values pass (converged, asymptotic, faster than the nominal order, small against
    the tolerance) and why the others fail: not monotone, differences not shrinking towards the run, an order
    outside [0.75 p, 2 p]."""
    from mbsuite.trust.estimate import check_coarse

    assert check_coarse(0.0, 0.0, 0.0, 2.0, 2.0, 0.05) == (0.0, None, True, "converged")  # contact loss 0 %
    # d1 / d0 = 8: order 3, above 1.25 x 2: Roy's factor 3 at the nominal order, 3 x 0.01 / (2^2 - 1) = 0.01
    err, p, ok, how = check_coarse(1.0, 1.01, 1.09, 2.0, 2.0)
    assert ok and p == pytest.approx(3.0) and err == pytest.approx(0.01)
    assert how == "faster: observed order 3.00 above 2.5, safety factor 3 at the nominal order"
    # d1 / d0 = 2.5: order 1.32, below 0.75 x 2
    assert check_coarse(1.0, 1.1, 1.35, 2.0, 2.0)[2:] == (False, "observed order 1.32 below 1.5 (d0 = 0.1, d1 = 0.25)")
    err, p, ok, how = check_coarse(1.0, 1.2, 0.9, 2.0, 2.0, 0.05)
    assert not ok and how.startswith("not monotone: d0 = 0.2, d1 = -0.3")
    assert err == pytest.approx(3.0 * 0.2) and p == pytest.approx(math.log2(1.5))
    assert check_coarse(1.0, 1.4, 1.6, 2.0, 2.0)[2:] == (False, "the differences do not shrink towards the run: "
                                                          "|d1| = 0.2 <= |d0| = 0.4")
    err, p, ok, how = check_coarse(1.0, 1.01, 1.33, 2.0, 2.0)  # d1 / d0 = 32: order 5
    assert not ok and p == pytest.approx(5.0) and how.startswith("observed order 5.00 above 4")
    # the same values with a tolerance 12 times their spread of 0.33 or more: small, the error 3 x the spread
    err, p, ok, how = check_coarse(1.0, 1.01, 1.33, 2.0, 2.0, 4.0)
    assert ok and err == pytest.approx(3.0 * 0.33) and how.startswith("small: observed order 5.00")
    assert not check_coarse(1.0, 1.01, 1.33, 2.0, 2.0, 3.9)[2]
    assert check_coarse(1.0, 1.0, 1.5, 2.0, 2.0)[2:] == (
        False, "the first coarse value equals the run's, the second differs by 0.5: no order to observe")
    assert check_coarse(1.0, math.nan, 1.0, 2.0, 2.0)[:3] == (math.inf, None, False)


def test_a_non_monotone_coarse_estimate_fails_its_check_and_names_the_headline():
    from mbsuite.trust.estimate import Headline, Refinement, estimate, timestep_refinement

    heads = (Headline("good", "m", 1.0), Headline("bad", "N", 1e-3), Headline("zero", "%", 0.05))
    levels = [{**a, "bad": b, "zero": 0.0} for a, b in zip(_coarse_levels(0.5, 0.2), (1.0, 1.2, 0.9), strict=True)]
    levels = [{"good": lv["q"], "bad": lv["bad"], "zero": lv["zero"]} for lv in levels]
    est = estimate(levels, heads, timestep_refinement(2.0), companions="coarse")
    assert not est.passed and [r.name for r in est.failed()] == ["bad"]
    assert est.failure_text() == "bad (not monotone: d0 = 0.2, d1 = -0.3 of opposite signs)"
    assert est["good"].passed and est["zero"].check == "converged"
    assert "FAILED" in est.table() and "  bad: not monotone" in est.table()
    assert est.to_dict()["rows"][1]["passed"] is False
    with pytest.raises(ValueError, match="companions"):
        Refinement("solver.timestep", 2.0, 2.0, lambda s, k: s, companions="coarser")
    # every model but the catenary keeps the refined companions
    assert timestep_refinement(2.0).companions == "fine"


def test_run_and_sweep_keep_an_inaccurate_result_with_exit_3(tmp_path, capsys):
    """An estimate above its tolerance keeps the result: `mbsuite run` and `mbsuite sweep` print it, write its files
    (summary.json with `inaccurate`) and exit 3, one `mbsuite: inaccurate:` line on stderr; --allow-inaccurate
    accepts it (exit 0); bad input is still exit 2."""
    from mbsuite.cli import main

    scene = tmp_path / "fourbar_tight.toml"
    scene.write_text('model = "iftomm"\n[input]\ntype = "initial"\nrate = 6.0\n'
                     '[solver]\nintegrator = "euler"\nduration = 0.5\nsample_dt = 1e-2\n'
                     '[accuracy]\nfinal_angle = 1e-9\n')
    out = tmp_path / "out"
    assert main(["run", str(scene), "--error-estimate", "--out", str(out)]) == 3
    cap = capsys.readouterr()
    assert "error_estimate[final_angle]" in cap.out and "INACCURATE RESULT, kept" in cap.out
    err = [ln for ln in cap.err.splitlines() if ln.startswith("mbsuite:")]
    assert len(err) == 1 and err[0].startswith("mbsuite: inaccurate: ") and "error_estimate[final_angle]" in err[0]
    summary = json.loads((out / "summary.json").read_text())
    assert any("error_estimate[final_angle]" in m for m in summary["results"]["inaccurate"])
    assert (out / "run.csv").exists()
    assert main(["run", str(scene), "--error-estimate", "--json"]) == 3
    data = json.loads(capsys.readouterr().out)
    assert data["inaccurate"] and not data["error_estimate"]["rows"][0]["ok"]
    with pytest.warns(UserWarning, match="error_estimate"):
        assert main(["run", str(scene), "--error-estimate", "--allow-inaccurate"]) == 0
    capsys.readouterr()
    assert main(["sweep", str(scene), "--vary", "input.rate=5,6", "--error-estimate", "--workers", "2"]) == 3
    cap = capsys.readouterr()
    assert "sweep point input.rate = 5" in cap.out and cap.err.count("mbsuite: inaccurate:") == 1
    assert main(["run", str(scene), "--error-estimate", "--timestep", "-1"]) == 2
