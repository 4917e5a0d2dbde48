"""The command line: tables, JSON, files with units, clear errors."""

import csv
import json

import numpy as np
import pytest

from mbsuite import load_scene, run
from mbsuite.cli import main


def test_list_json(capsys):
    assert main(["list", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert "pantograph" in data and "lab" in data["pantograph"]["scenes"]
    assert set(data["pantograph"]["effects"]) >= {"gravity", "elbow", "cylinder", "coulomb", "contact"}


def test_equilibrium_json(capsys):
    assert main(["equilibrium", "pantograph", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["max_difference_rad"]["mujoco"] < 1e-8 and data["max_difference_rad"]["pinocchio"] < 1e-8
    assert data["reference"]["contact_force"] > 0


def test_run_writes_csv_with_units_and_summary(tmp_path, capsys):
    sc = tmp_path / "short.toml"
    sc.write_text('model = "pantograph"\n[input]\nfrequency = 3.0\n[solver]\nduration = 0.5\nt_settle = 0.1\n')
    assert main(["run", str(sc), "--out", str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    assert "contact_force" in out
    with open(tmp_path / "o" / "run.csv") as fh:
        header = next(csv.reader(fh))
    assert header[0] == "t [s]" and "F1 [m]" in header and "contact_force [N]" in header
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["versions"]["mujoco"].startswith("4.") and summary["scene"]["model"] == "pantograph"


def test_run_reference_engine_agrees_with_mujoco(tmp_path, capsys):
    """`run --engine reference --json` reports the hand-derived path's run; its signal ranges (lab at 4.25 Hz, Coulomb
    off, 1 s) agree with the MuJoCo path's (RK4, 1 ms). Measured peak-to-peak, relative: F1 3.0e-5, HD 3.0e-5,
    contact force 4.9e-5, y_d 3.0e-5 (RK4's step error); bound 1.5e-4 (3x-5x)."""
    sc = tmp_path / "short.toml"
    sc.write_text('model = "pantograph"\n[effects]\ncoulomb = false\n[input]\nfrequency = 4.25\n'
                  '[solver]\nduration = 1.0\nt_settle = 0.5\n')
    assert main(["run", str(sc), "--engine", "reference", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["engine"] == "reference" and data["solver"]["engine"] == "reference"
    mj = run(load_scene(sc))
    assert mj.engine == "mujoco"
    for s in ("F1", "HD", "contact_force", "y_d"):
        ref = data["signals"][s]["max"] - data["signals"][s]["min"]
        assert abs(ref / np.ptp(mj[s]) - 1.0) < 1.5e-4, s


def test_freqresp_small(tmp_path, capsys):
    assert main(["freqresp", "pantograph", "--f-min", "4", "--f-max", "4.5", "--df", "0.5", "--methods",
                 "linear,mujoco", "--workers", "1", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "linearised modes" in out and "y_w = y_op + A = 1.58185 m (the mean of the input)" in out
    assert (tmp_path / "freqresp.csv").is_file() and (tmp_path / "freqresp.png").is_file()
    assert (tmp_path / "time_histories.png").is_file()


@pytest.mark.parametrize("argv,msg", [
    (["run", "pantograph/nope"], "shipped scenes"),
    (["run", "nomodel"], "valid models"),
    (["freqresp", "pantograph", "--methods", "magic"], "'magic'"),
])
def test_errors_exit_2_with_message(argv, msg, capsys):
    assert main(argv) == 2
    assert msg in capsys.readouterr().err


def test_pantograph_group_equals_the_top_level_aliases(capsys):
    assert main(["pantograph", "equilibrium", "--json"]) == 0  # the scene defaults to the pantograph's
    group = json.loads(capsys.readouterr().out)
    assert main(["equilibrium", "pantograph", "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == group
    assert main(["pantograph", "modes", "pantograph/lab", "--height", "1.6", "--json"]) == 0
    group = json.loads(capsys.readouterr().out)
    assert main(["modes", "pantograph/lab", "--height", "1.6", "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == group
    assert main(["pantograph", "modes", "coupler"]) == 2  # another model's scene
    assert "does not support 'modes'" in capsys.readouterr().err
    assert main(["pantograph", "freqresp", "--f-min", "10", "--f-max", "5"]) == 2
    assert "--f-max" in capsys.readouterr().err
