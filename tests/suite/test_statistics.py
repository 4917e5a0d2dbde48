"""Declared statistics (`mbsuite.statistics`): a run's statistics are checked against its model's declaration (name,
kind, per-member copies), carry the declared units, and stay apart from the solver's counters; every declaration is
complete. And what the studies take from a model (`SPEC.studies`): the band a model offers, refused by one that
offers none."""

from __future__ import annotations

import math

import pytest

import mbsuite
from mbsuite.cli import main
from mbsuite.registry import models
from mbsuite.statistics import Statistic, checked, describe, lookup

TABLE = {"Fm": Statistic("N", "mean contact force", "the window", per="p{k}_{name}"),
         "ok": Statistic("-", "a verdict", "the window", kind="verdict"),
         "forces": Statistic("N", "one per link", "the window", kind="numbers")}


def test_per_member_names_are_found_and_only_they():
    assert lookup(TABLE, "p1_Fm") is TABLE["Fm"] and lookup(TABLE, "p12_Fm") is TABLE["Fm"]
    for bad in ("p0_Fm", "px_Fm", "p1_ok", "Fm_p1", "p1_"):
        assert lookup(TABLE, bad) is None, bad


def test_the_declaration_checks_names_and_kinds():
    assert checked({"p2_Fm": 3, "ok": True, "forces": (1, 2.5)}, TABLE, "m") == {"p2_Fm": 3.0, "ok": True,
                                                                                   "forces": [1.0, 2.5]}
    with pytest.raises(KeyError, match=r"model 'm' declares no statistic \['sigma'\]"):
        checked({"Fm": 1.0, "sigma": 2.0}, TABLE, "m")
    with pytest.raises(TypeError, match="statistic ok of model 'm' is a verdict"):
        checked({"ok": 1.0}, TABLE, "m")
    with pytest.raises(TypeError, match="statistic Fm of model 'm' is a number"):
        checked({"Fm": True}, TABLE, "m")
    with pytest.raises(TypeError, match="is a list of numbers"):
        checked({"forces": [1.0, "x"]}, TABLE, "m")
    with pytest.raises(ValueError, match="per"):
        Statistic("N", "d", "w", per="p_{name}")
    with pytest.raises(ValueError, match="kind"):
        Statistic("N", "d", "w", kind="text")


@pytest.mark.parametrize("name", sorted(models()))
def test_every_declaration_is_complete(name):
    """Every declared statistic has a definition and a window; a verdict has no unit but '-'."""
    spec = models()[name]
    for key, s in spec.statistics.items():
        assert s.definition.strip() and s.window.strip() and s.unit, (name, key)
        assert s.kind != "verdict" or s.unit == "-", (name, key)
    assert len(describe(spec.statistics)) == len(spec.statistics)


def test_a_run_carries_its_statistics_with_the_declared_units_apart_from_its_counters():
    """The IFToMM four-bar (0.5 s): the energy scale E_kin(0) + m g L per moving bar is 30 + 3 x 9.81 J by hand
    (`tests/iftomm/test_checks.py`); statistics and counters do not share a name."""
    res = mbsuite.run(mbsuite.load_scene("iftomm").replace(solver={"duration": 0.5}))
    spec = mbsuite.get_model("iftomm")
    assert set(res.statistics) == set(spec.statistics)
    assert res.statistic_units == {k: s.unit for k, s in spec.statistics.items()}
    assert not set(res.statistics) & set(res.stats)
    assert res.statistics["energy_scale"] == pytest.approx(30.0 + 3 * 9.81, rel=1e-12)
    summary = res.summary()["statistics"]
    assert summary["branch_angle_max"]["unit"] == "rad" and math.isfinite(summary["branch_angle_max"]["value"])


def test_a_band_is_the_models_own(capsys):
    """`--band` reads the band the scene's model declares: the catenary's systems are listed when one is wrong, and
    a model without a band refuses it, before any run (exit 2)."""
    vary = ["--vary", "params.F0=100:140", "--maxiter", "1", "--popsize", "2"]
    assert main(["optimise", "catenary/en50318", *vary, "--band", "XX"]) == 2
    err = capsys.readouterr().err
    assert "EN 50367 band of model 'catenary' has no system 'XX'; valid: AC, DC3kV, DC1.5kV" in err
    assert main(["optimise", "pantograph/lab", "--vary", "params.ks=1e4:2e4", "--objective", "F1_amplitude",
                 "--band", "AC"]) == 2
    assert "model 'pantograph' declares no band" in capsys.readouterr().err


@pytest.mark.parametrize(("ref", "engine", "executor"), [("pantograph/lab", "mujoco", "threads"),
                                                         ("pantograph/lab", "reference", None),
                                                         ("catenary/en50318", "reference", None)])
def test_studies_run_in_threads_on_the_paths_a_model_declares(ref, engine, executor, monkeypatch):
    """`designspace.evaluate` hands the sweep threads exactly for a path in `SPEC.studies.threads` (the pantograph's
    MuJoCo path: a compiled loop without global state), processes otherwise."""
    import mbsuite.analysis.sweep as sweep
    from mbsuite.analysis.designspace import evaluate

    seen = {}

    def fake(fn, points, **kw):
        seen.update(kw)
        return [{"y": 1.0} for _ in points]

    monkeypatch.setattr(sweep, "run_sweep", fake)
    scene = mbsuite.load_scene(ref).replace(solver={"engine": engine})
    assert engine in scene.spec.paths and (engine in scene.spec.studies.threads) == (executor == "threads")
    assert evaluate(lambda p: {"y": 1.0}, [{}], scene=scene) == [{"y": 1.0}]
    assert seen["executor"] == executor
