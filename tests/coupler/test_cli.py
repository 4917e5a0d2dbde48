"""`mbsuite coupler ...` commands: JSON output, files, clear errors (exit code 2)."""

from __future__ import annotations

import json
import math

import pytest

from mbsuite.cli import main


def test_jacobian_json(capsys):
    assert main(["coupler", "jacobian", "--gamma", "0.2967059728390360", "--ey", "0.1", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["rank"] == 4
    assert d["cond"] == pytest.approx(math.cos(2 * 0.2967059728390360) / 0.1, rel=1e-13)  # measured 0
    assert len(d["principal_screws"]) == 2 and len(d["zero_pitch_screws"]) == 2


def test_jacobian_coplanar_warns_and_reports_infinite_cond(capsys):
    assert main(["coupler", "jacobian", "--ey", "0", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["rank"] == 3 and d["cond"] is None and "coplanar" in d["warnings"][0]


def test_fpp_pinocchio_cross_check(capsys):
    assert main(["coupler", "fpp", "--engine", "pinocchio", "--n", "25", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["max_abs_diff_pinocchio"] < 1e-13 and len(d["phi_b"]) == 25  # measured 1.1e-14


def test_criteria_quick_writes_plots(tmp_path, capsys):
    assert main(["coupler", "criteria", "--quick", "--out", str(tmp_path)]) == 0
    names = {p.name for p in tmp_path.iterdir()}
    assert {"fig9_criteria_single.png", "fig10_c5_double.png", "fig6_phi_difference.png", "criteria_single.csv",
            "summary.json"} <= names


@pytest.mark.parametrize("argv, msg", [
    (["coupler", "jacobian", "--gamma", "0.9"], "gamma"),
    (["coupler", "jacobian", "--ey", "-0.1"], "e_y"),
    (["coupler", "fpp", "--ey", "0.02", "--alpha-bx", "0.06"], "cross"),
    (["coupler", "jacobian", "--R", "0"], "R"),
])
def test_bad_input_exit_code_2(argv, msg, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("mbsuite: error:") and msg in err


def test_dynamics_command_json_and_csv(tmp_path, capsys):
    scene = tmp_path / "short.toml"
    scene.write_text('model = "coupler"\n[input]\ntype = "constant_speed"\nz_c = 0.05\nt_ramp = 0.25\n'
                     '[solver]\nduration = 0.45\nt_settle = 0.3\n')
    assert main(["coupler", "dynamics", str(scene), "--json", "--out", str(tmp_path / "o")]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["stats"]["warnings"] == {} and d["stats"]["closure_residual_max"] < 2e-4
    header = (tmp_path / "o" / "timeseries.csv").read_text().splitlines()[0]
    assert "torque_in [N m]" in header and "link_force_8 [N]" in header
