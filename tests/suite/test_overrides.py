"""One rule composes every flag that changes a scene (`mbsuite.cli.options.overrides`): `--set`, `--vary`, `--over`,
`--start` and the flags that set one key (`--speed`, `--engine`, ...). A key given twice, by one flag or two (even
with the same value), or a key together with a key inside it, is an error naming both flags, before any scene is
loaded; a dotted key reaches into a model's own section on every command that reads such a scene (the one resolution,
`options.resolve`). The numbers of the design studies and the sweep options are checked by `mbsuite.limits`."""

from __future__ import annotations

import json

import numpy as np
import pytest

import mbsuite.scenes
from mbsuite.analysis import optimise, sensitivity
from mbsuite.analysis.sweep import SweepOptions
from mbsuite.cli import main
from mbsuite.cli.options import check_workers
from mbsuite.errors import MbsuiteError, SceneError
from mbsuite.results import Report

LUMPED = "catenary/en50318_lumped2"  # a catenary scene whose [pantograph] section holds params.F0
STUDY = ["--vary", "params.F0=100:140", "--maxiter", "1", "--popsize", "2"]


def _cli(argv, capsys):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.mark.parametrize("argv, named", [
    (["modes", "pantograph", "--vary", "params.m1=14", "--vary", "params.m1=15"],
     ["--vary params.m1=14 and --vary params.m1=15 both set params.m1; give one"]),
    (["modes", "pantograph", "--set", "params.m1=14", "--vary", "params.m1=15"],
     ["--set params.m1=14 and --vary params.m1=15 both set params.m1; give one"]),
    (["modes", "pantograph", "--set", "params.m1=14", "--set", "params.m1=14"],
     ["--set params.m1=14 and --set params.m1=14", "(to the same value)"]),
    (["catenary", LUMPED, "--set", "pantograph.params=1", "--vary", "pantograph.params.F0=100,110"],
     ["--set pantograph.params=1", "--vary pantograph.params.F0=100,110", "pantograph.params holds it"]),
    (["catenary", LUMPED, "--speed", "250", "--vary", "input.speed=200,300"],
     ["--vary input.speed=200,300", "--speed 250", "both set input.speed"]),
    (["run", "pantograph", "--engine", "mujoco", "--set", "solver.engine=reference"],
     ["--set solver.engine=reference", "--engine mujoco"]),
    (["sweep", "pantograph", "--vary", "input.frequency=1,2", "--set", "input.frequency=3"],
     ["--set input.frequency=3", "--vary input.frequency=1,2"]),
    (["optimise", "catenary/en50318", *STUDY, "--set", "input.speed=200", "--speed", "250"],
     ["--set input.speed=200", "--speed 250"]),
    (["optimise", "catenary/en50318", *STUDY, "--speed", "250,300", "--over", "input.speed=250,300"],
     ["--over input.speed=250,300", "--speed 250,300"]),
    (["optimise", "catenary/en50318", *STUDY, "--start", "params.F0=110", "--start", "params.F0=120"],
     ["--start params.F0=110", "--start params.F0=120"]),
    (["sensitivity", "catenary/en50318", "--vary", "params.F0=100:140", "--vary", "params.F0=90:140"],
     ["--vary params.F0=100:140", "--vary params.F0=90:140"]),
])
def test_a_key_set_twice_is_an_error_naming_both_flags_before_anything_loads(monkeypatch, capsys, argv, named):
    def loaded(*a, **k):
        raise AssertionError("the scene was loaded before the command line was checked")

    monkeypatch.setattr(mbsuite.scenes, "load_scene", loaded)
    rc, out, err = _cli(argv, capsys)
    assert rc == 2 and out == "" and err.startswith("mbsuite: error: ") and err.count("\n") == 1, err
    for text in named:
        assert text in err, err


def _capture(monkeypatch, module, name, result):
    """Replace `module.name` by a stub recording the scene it is handed (the scene the CLI built)."""
    seen = {}

    def stub(scene, *args, **kwargs):
        seen["scene"], seen["args"] = scene, args
        return result

    monkeypatch.setattr(module, name, stub)
    return seen


class _Result:
    def report(self):
        return Report({}, "stub")


@pytest.mark.parametrize("argv, module, name", [
    (["catenary", LUMPED], "mbsuite.models.catenary.cli", "catenary_of"),
    (["optimise", LUMPED, "--vary", "params.element_length=0.4:0.6"], "mbsuite.analysis.optimise", "run"),
    (["sensitivity", LUMPED, "--vary", "params.element_length=0.4:0.6"], "mbsuite.analysis.sensitivity", "run"),
    (["run", LUMPED], "mbsuite", "run"),
])
def test_a_nested_set_reaches_the_scene_on_every_command(monkeypatch, capsys, argv, module, name):
    """`--set pantograph.params.F0=100` (the key `optimise --vary` takes) is accepted by every command reading a
    catenary scene, and sets that one value: the scene handed to the analysis has it, the rest of the table kept."""
    import importlib

    result = Report({}, "stub") if name == "catenary_of" else _Result()
    if module == "mbsuite":
        result = type("R", (), {"report": lambda self: Report({}, "stub")})()
    seen = _capture(monkeypatch, importlib.import_module(module), name, result)
    rc, _, err = _cli([*argv, "--set", "pantograph.params.F0=100"], capsys)
    assert rc == 0, err
    table = seen["scene"].to_dict()["pantograph"]["params"]
    kept = mbsuite.scenes.load_scene(LUMPED).to_dict()["pantograph"]["params"]
    assert table == {**kept, "F0": 100.0}


@pytest.mark.parametrize("argv", [
    ["sweep", LUMPED, "--vary", "pantograph.params.F0=90,100"],
    ["catenary", LUMPED, "--vary", "pantograph.params.F0=90,100"],
])
def test_a_nested_vary_reaches_every_point(monkeypatch, capsys, argv):
    """`--vary pantograph.params.F0=...` on `sweep` and on a study of the catenary command: each point's scene
    sections set that one value (the points are recorded, not run)."""
    import mbsuite.analysis.sweep as sweep_api
    import mbsuite.cli.sweep as cli_sweep

    seen = []

    def fake(fn, points, **kwargs):
        seen.extend(points)
        return [{"signals": {}}] * len(points)

    monkeypatch.setattr(cli_sweep, "run_sweep", fake)
    monkeypatch.setattr(sweep_api, "run_sweep", fake)
    rc, _, err = _cli(argv, capsys)
    assert rc == 0, err
    kept = mbsuite.scenes.load_scene(LUMPED).to_dict()["pantograph"]["params"]
    assert [p[1]["pantograph"]["params"] for p in seen] == [{**kept, "F0": 90.0}, {**kept, "F0": 100.0}]


def test_a_legal_combination_still_runs(capsys):
    """`--set` on one key and `--vary` on another: the study runs, every point with the set value (its frequencies
    those of the single command with both values set)."""
    study = ["modes", "pantograph", "--vary", "params.m1=10,12", "--workers", "1", "--json"]
    rc, out, err = _cli([*study, "--set", "params.mh=15"], capsys)
    assert rc == 0, err
    points = json.loads(out)["points"]
    assert [p["values"]["params.m1"] for p in points] == [10.0, 12.0]
    rc, out, err = _cli(["modes", "pantograph", "--set", "params.m1=12", "--set", "params.mh=15", "--json"], capsys)
    assert rc == 0, err
    single = json.loads(out)
    rc, out, _ = _cli(study, capsys)
    assert rc == 0 and json.loads(out)["points"][1]["results"] != points[1]["results"]  # mh=15 changed them
    from mbsuite.cli.study import flatten

    want = flatten({k: v for k, v in single.items() if k != "scene"})
    assert points[1]["results"] == pytest.approx(want, rel=1e-12)


def test_the_design_studies_numbers_are_checked_by_the_core_limits():
    """numpy scalars and 0-d arrays accepted as the Python numbers they hold; 2.5 for a count, NaN, inf and bools
    refused naming the number."""
    got = optimise._check("f", "worst", penalty=np.float32(10), tol=np.array(1e-3), maxiter=np.int64(3),
                          popsize=np.int32(2), seed=np.uint8(7))
    assert got == {"penalty": 10.0, "tol": 1e-3, "maxiter": 3, "popsize": 2, "seed": 7}
    assert all(type(v) is int for k, v in got.items() if k in ("maxiter", "popsize", "seed"))
    for bad, name in ((dict(popsize=2.5), "popsize"), (dict(seed=float("nan")), "seed"),
                      (dict(penalty=np.inf), "penalty"), (dict(maxiter=True), "maxiter")):
        with pytest.raises(MbsuiteError, match=f"optimise {name} = "):
            optimise._check("f", "worst", **bad)
    assert sensitivity._check("morris", np.int64(4), np.int64(1), 4, np.float64(0.9)) == (4, 1, 4, 0.9)
    with pytest.raises(MbsuiteError, match="sensitivity seed = nan"):
        sensitivity._check("morris", 4, float("nan"), 4, 0.95)
    with pytest.raises(MbsuiteError, match="sensitivity n = 2.5"):
        sensitivity._check("morris", 2.5, 0, 4, 0.95)
    b = optimise.Bound("Fm", np.float32(100), np.array(130.0))
    assert (b.lo, b.hi) == (100.0, 130.0)
    for bad in (float("nan"), True, "100"):
        with pytest.raises(MbsuiteError, match="constraint on Fm: lo"):
            optimise.Bound("Fm", lo=bad)
    with pytest.raises(MbsuiteError, match="pareto level"):
        optimise.pareto(lambda p: {}, ["x.a=0:1"], levels=["abc"])
    assert SweepOptions(max_points=np.int64(5)).max_points == 5
    with pytest.raises(SceneError, match="max_points = 2.5 is invalid"):
        SweepOptions(max_points=2.5)
    assert check_workers(np.int64(2)) == 2
    with pytest.raises(MbsuiteError, match="--workers = 2.5 is invalid"):
        check_workers(2.5)


@pytest.mark.parametrize("argv, named", [
    (["optimise", "catenary/en50318", *STUDY[:2], "--popsize", "2.5"], "--popsize"),
    (["optimise", "catenary/en50318", *STUDY, "--penalty", "nan"], "penalty"),
    (["sweep", "pantograph", "--vary", "input.frequency=1", "--max-points", "0"], "--max-points"),
])
def test_bad_counts_on_the_command_line_name_the_flag_before_anything_runs(monkeypatch, capsys, argv, named):
    def ran(*a, **k):
        raise AssertionError("a point ran before the numbers were checked")

    import mbsuite.analysis.sweep as sweep_api

    monkeypatch.setattr(sweep_api, "run_sweep", ran)
    rc, _, err = _cli(argv, capsys)
    assert rc == 2 and named in err and "internal error" not in err, err


@pytest.mark.parametrize("argv, flag", [(["catenary", "catenary/en50318", "--speed", "250", "--speed", "300"],
                                         "--speed"),
                                        (["run", "pantograph", "--engine", "mujoco", "--engine=reference"], "--engine"),
                                        (["run", "pantograph", "--allow-inaccurate", "--allow-inaccurate"],
                                         "--allow-inaccurate")])
def test_a_one_value_flag_given_twice_is_an_error_naming_it(argv, flag, capsys):
    """argparse keeps the last of a repeated flag; the rule refuses it before anything loads."""
    from mbsuite.cli import main

    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{flag} given 2 times" in err, err
