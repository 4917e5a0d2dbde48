"""Regression tests of the robustness corpus' catenary findings: bad inputs end in one clear error naming the culprit
(the scene key or CLI option) and its valid range, before anything is built."""

from __future__ import annotations

import dataclasses
import math

import pytest

import mbsuite
from mbsuite.cli import main
from mbsuite.errors import ParameterError
from mbsuite.models.catenary import train
from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.config import check_timestep, check_wave_resolution
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.train import simulate_train
from mbsuite.scenes import load_scene
from mbsuite.trust.health import AccuracyError, InaccurateResultWarning

SHORT = ('model = "catenary"\n[params]\nn_spans = 2\nelement_length = 0.5\nx_end = 110.0\nwindow_start = 50.0\n'
         'window_end = 100.0\n[input]\nspeed = 200.0\n[solver]\ntimestep = {dt}\n')


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


def test_cli_timestep_far_too_large_names_the_option_and_range(capsys):
    assert main(["catenary", "--json", "--timestep", "1"]) == 2
    err = _one_line_error(capsys)
    assert "--timestep" in err and "solver.timestep" in err and "valid range (0, 0.025) s" in err
    assert "Nyquist" in err and "filter_cutoff" in err and "element_length / c" in err and "0.004089 s" in err


def test_scene_timestep_half_a_second_names_the_key(tmp_path, capsys):
    path = tmp_path / "coarse.toml"
    path.write_text(SHORT.format(dt=0.5))
    assert main(["run", str(path), "--json"]) == 2
    err = _one_line_error(capsys)
    assert "solver.timestep" in err and "= 0.5 s" in err and "valid range (0, 0.025) s" in err


def test_timestep_past_the_wave_resolution_is_not_trusted(tmp_path, capsys, monkeypatch):
    """0.01 s: a valid record for the 20 Hz filter, but a wire wave crosses 2.4 elements per step: refused before
    anything is built (AccuracyError naming solver.timestep and its range) unless inaccurate results are allowed."""
    monkeypatch.setattr(train, "assemble", lambda *_a, **_k: pytest.fail("built past the timestep check"))
    path = tmp_path / "coarse.toml"
    path.write_text(SHORT.format(dt=0.01))
    assert main(["run", str(path)]) == 2
    err = _one_line_error(capsys)
    assert "wave_courant = 2.446 exceeds its bound 1" in err
    assert "solver.timestep (--timestep) 0.01 s is outside its valid range (0, 0.004089] s" in err
    assert "--allow-inaccurate" in err
    p = CatenaryParams(element_length=0.5, n_spans=5, x_end=150.0, window_start=60.0, window_end=120.0)
    with pytest.raises(AccuracyError, match="solver.timestep"):
        simulate_train(p, 250.0, 0.01, ["reference2mass", "reference2mass"], [100.0])
    with pytest.raises(AccuracyError, match="solver.timestep"):
        simulate(p, 250.0, 0.01)


def test_timestep_past_the_wave_resolution_runs_when_allowed():
    p = CatenaryParams(element_length=0.5, n_spans=2, x_end=110.0, window_start=50.0, window_end=100.0)
    with pytest.warns(InaccurateResultWarning, match="wave_courant"):
        scene = load_scene("catenary").replace(params=dataclasses.asdict(p), input={"speed": 200.0},
                                               solver={"timestep": 0.005, "allow_inaccurate": True})
        res = mbsuite.run(scene)
    assert any("wave_courant" in w for w in res.warnings)
    (fig,) = [f for f in res.health if f.name == "wave_courant"]
    # c dt / h with c the faster wire's sqrt(T/rho) (the messenger: sqrt(16000 / 1.07) = 122.28 m/s)
    assert fig.value == pytest.approx(math.sqrt(16000.0 / 1.07) * 0.005 / 0.5, rel=1e-12) and not fig.ok


def test_timestep_bounds():
    p = CatenaryParams(element_length=0.5)
    check_timestep(p, 2e-4)  # the shipped scene
    assert check_wave_resolution(p, 2e-4) == []
    assert check_wave_resolution(p, 0.5 / p.mw_wave_speed) == []  # the bound itself is allowed
    with pytest.raises(AccuracyError, match=r"valid range \(0, 0\.004089\] s"):
        check_wave_resolution(p, 0.005)
    assert "wave_courant" in check_wave_resolution(p, 0.005, allow_inaccurate=True)[0]
    coarse = CatenaryParams(element_length=10.0)
    with pytest.raises(ParameterError, match=r"valid range \(0, 0\.025\) s"):
        check_timestep(coarse, 0.025)
    for bad in (0.0, -1e-4, float("nan"), float("inf"), True):
        with pytest.raises(ParameterError, match="solver.timestep"):
            check_timestep(p, bad)


@pytest.mark.parametrize("params, culprit", [
    ({"window_start": 400.0}, "params.window_start = 400.0 m must be below params.window_end = 360.0 m"),
    ({"window_end": 500.0}, "params.window_end = 500.0 m lies beyond params.x_end = 420.0 m"),
    ({"x_start": 100.0, "window_start": 50.0}, "params.window_start = 50.0 m lies before params.x_start = 100.0 m"),
    ({"x_end": 700.0}, "params.x_end = 700.0 m"),
])
def test_window_and_run_errors_name_the_parameter(tmp_path, capsys, params, culprit):
    lines = "".join(f"{k} = {v}\n" for k, v in params.items())
    path = tmp_path / "window.toml"
    path.write_text(f'model = "catenary"\n[params]\n{lines}[input]\nspeed = 250.0\n')
    assert main(["run", str(path), "--json"]) == 2
    err = _one_line_error(capsys)
    assert culprit in err, err
