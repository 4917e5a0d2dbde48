"""Optimisation studies (`mbsuite.analysis.optimise`, `mbsuite optimise`): known optima of test functions (a
constrained quadratic with its Lagrange solution, a worst-case and a mean over operating points, an
epsilon-constraint front in closed form) through the machinery that runs a scene's points; a small catenary
optimisation under the EN 50367 band end to end; bad inputs refused naming them."""

from __future__ import annotations

import json
import math

import pytest

import mbsuite
from mbsuite.analysis import optimise
from mbsuite.analysis.designspace import point_scene
from mbsuite.cli import main
from mbsuite.errors import MbsuiteError

SHORT = {"n_spans": 4, "x_end": 200.0, "window_start": 60.0, "window_end": 180.0, "element_length": 1.0}
SHORT_SETS = [a for k, v in SHORT.items() for a in ("--set", f"params.{k}={v:g}")]


def quadratic(point):
    """f = (a - 1)^2 + (b - 2)^2 and g = a + b; with s (an operating point) f = (a - s)^2."""
    a, b = point["x.a"], point["x.b"]
    s = point.get("x.s")
    f = (a - 1.0) ** 2 + (b - 2.0) ** 2 if s is None else (a - s) ** 2
    return {"f": f, "g": a + b}


def test_constrained_optimum_of_a_quadratic():
    """min (a - 1)^2 + (b - 2)^2 subject to a + b <= 2: the projection of (1, 2) on the line a + b = 2, (0.5, 1.5),
    f = 0.5 (Lagrange multiplier 1, below the penalty 10: the exact penalty's minimum is the constrained one).
    Tolerance 0.02 on the design: measured 4.4e-3 with this seed."""
    res = optimise.run(quadratic, ["x.a=-3:3", "x.b=-3:3"], objective="f", constraints=["g=:2"], maxiter=60,
                       popsize=10, seed=1, workers=1, progress=False)
    assert res.feasible
    assert res.best["x.a"] == pytest.approx(0.5, abs=0.02) and res.best["x.b"] == pytest.approx(1.5, abs=0.02)
    assert res.value == pytest.approx(0.5, abs=1e-3)
    assert len(res.evaluations) == len({tuple(e["design"].values()) for e in res.evaluations})  # each run once


@pytest.mark.parametrize(("aggregate", "a_opt", "value"), [("worst", 1.5, 2.25), ("mean", 4 / 3, 42 / 27)])
def test_robust_optimum_over_operating_points(aggregate, a_opt, value):
    """f = (a - s)^2 at s = 0, 1, 3: the worst case max(a^2, (a - 1)^2, (a - 3)^2) is least at a = 1.5 (2.25); the
    mean at a = 4/3 (42/27). Tolerance 0.02 on a: measured 1.5e-5 (worst) and 2.4e-4 (mean)."""
    res = optimise.run(quadratic, ["x.a=-2:5", "x.b=0:1"], objective="f", over={"x.s": [0.0, 1.0, 3.0]},
                       aggregate=aggregate, maxiter=60, popsize=10, seed=2, workers=1, progress=False)
    assert res.best["x.a"] == pytest.approx(a_opt, abs=0.02)
    assert res.value == pytest.approx(value, abs=0.02)
    assert [c["x.s"] for c in res.contexts] == [0.0, 1.0, 3.0] and len(res.best_outputs) == 3


def cone(point):
    """f = a^2 + b^2 (minimised) against g = a (maximised): the front is f = g^2, g >= 0."""
    return {"f": point["x.a"] ** 2 + point["x.b"] ** 2, "g": point["x.a"]}


def test_epsilon_constraint_front_in_closed_form():
    """Each level's optimum is (level, 0), f = level^2; every non-dominated evaluation lies on or above f = g^2 and
    the front is sorted along g. Tolerance 0.01 on f: measured 7.1e-4 at most."""
    res = optimise.pareto(cone, ["x.a=-2:2", "x.b=-2:2"], objective="f", against="g", levels=[0.5, 1.0, 1.5],
                          maxiter=40, popsize=8, seed=3, workers=1, progress=False)
    for lv, r in zip(res.levels, res.runs, strict=True):
        assert r.value == pytest.approx(lv**2, abs=0.01)
    g = [p["outputs"]["g"] for p in res.front]
    assert g == sorted(g) and len(g) >= 3
    assert all(p["outputs"]["f"] >= p["outputs"]["g"] ** 2 - 1e-12 for p in res.front)


def test_catenary_optimisation_end_to_end_on_a_short_line(tmp_path):
    """`mbsuite optimise` of the 2-mass pantograph under a short line: sigma minimised with Fm in the EN 50367 AC
    band at 250 km/h (0.00047 v^2 + 60 .. + 90 N = 89.375 .. 119.375 N), the start design (the scene's values) in the
    first population, so the optimum is no worse than it; the reported outputs equal `mbsuite.run` of the optimum."""
    out = tmp_path / "opt"
    rc = main(["optimise", "catenary/en50318", *SHORT_SETS, "--vary", "params.F0=100:140", "--objective", "sigma",
               "--band", "AC", "--speed", "250", "--maxiter", "1", "--popsize", "2", "--seed", "5", "--workers", "2",
               "--out", str(out)])
    assert rc == 0
    data = json.loads((out / "summary.json").read_text())["results"]
    assert data["constraints"] == ["Fm in the EN 50367 band (AC)"] and data["seed"] == 5
    assert data["feasible"] and 89.375 <= data["best_outputs"][0]["Fm"] <= 119.375
    assert data["start"]["design"] == {"params.F0": 120.0}
    assert data["value"] <= data["start"]["value"]
    scene = mbsuite.load_scene("catenary/en50318").replace(params=SHORT)
    direct = mbsuite.run(point_scene(scene, data["best"])).statistics
    assert data["best_outputs"][0]["sigma"] == direct["sigma"] and data["best_outputs"][0]["Fm"] == direct["Fm"]
    band = optimise.band("AC").at(scene)
    assert band == pytest.approx((0.00047 * 250**2 + 60, 0.00047 * 250**2 + 90))
    assert (out / "evaluations.csv").stat().st_size > 0 and (out / "optimise.png").stat().st_size > 0


@pytest.mark.parametrize(("argv", "words"), [
    (["--constraint", "Fm=abc:1"], "'abc' is not a number"),
    (["--constraint", "Fm"], "expected OUTPUT=LO:HI"),
    (["--constraint", "sigma=band"], "bounds Fm only"),
    (["--objective", "sigmaa"], "not a headline output"),
    (["--speed", "250,abc"], "input.speed = 'abc'"),
    (["--start", "params.k1=4000"], "params.k1 is not a factor"),
    (["--start", "params.c1=500"], "params.c1 = 500 outside [0, 100]"),
])
def test_bad_optimise_inputs_are_refused_naming_them(argv, words, capsys):
    rc = main(["optimise", "catenary/en50318", "--vary", "params.c1=0:100", *argv])
    err = capsys.readouterr().err
    assert rc == 2 and words in err and err.count("\n") == 1, err


def test_bad_settings_are_refused():
    with pytest.raises(MbsuiteError, match="aggregate 'median' is unknown"):
        optimise.run(quadratic, ["x.a=0:1", "x.b=0:1"], objective="f", aggregate="median")
    with pytest.raises(MbsuiteError, match="maxiter"):
        optimise.run(quadratic, ["x.a=0:1", "x.b=0:1"], objective="f", maxiter=0)
    with pytest.raises(MbsuiteError, match="EN 50367 band of model 'catenary' has no system 'XX'; valid: AC"):
        optimise.Bound("Fm", band="XX").for_scene(mbsuite.load_scene("catenary"))
    with pytest.raises(MbsuiteError, match="lower bound 3 above upper bound 1"):
        optimise.parse_bound("Fm=3:1")
    with pytest.raises(MbsuiteError, match="model 'pantograph' declares no band"):
        optimise.band("AC").at(mbsuite.load_scene("pantograph"))
    assert not math.isinf(optimise.parse_bound("Fm=100:").at(None)[0])
