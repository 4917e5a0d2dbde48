"""Parameter studies on every analysis (`--set`, `--vary`): a varied point is the analysis of the scene changed at
that value through another route (the Python API's `Scene.replace`, or the single command with `--set`)."""

from __future__ import annotations

import csv
import json

import pytest

import mbsuite
from mbsuite.cli import main

G = 9.81  # m/s^2, the pantograph's gravity


def _json(capsys) -> dict:
    return json.loads(capsys.readouterr().out)


def test_modes_against_head_mass_is_one_command(tmp_path, capsys):
    """`mbsuite modes pantograph --vary params.mh=...`: each point's frequencies are those of the scene with that head
    mass (the Python API), the single command with `--set` gives the same, and the files are written."""
    out = tmp_path / "study"
    assert main(["modes", "pantograph", "--vary", "params.mh=12,15", "--workers", "1", "--json",
                 "--out", str(out)]) == 0
    data = _json(capsys)
    assert data["axes"] == {"params.mh": [12, 15]} and data["units"]["params.mh"] == "kg"
    assert data["units"]["reference[1].f_n"] == "Hz"
    base = mbsuite.load_scene("pantograph")
    for point in data["points"]:
        mh = point["values"]["params.mh"]
        direct = base.spec.modes(base.replace(params={"mh": mh})).data
        for i, mode in enumerate(direct["reference"]):
            assert point["results"][f"reference[{i}].f_n"] == mode["f_n"]
            assert point["results"][f"mujoco[{i}].f_n"] == direct["mujoco"][i]["f_n"]
    f = [p["results"]["reference[3].f_n"] for p in data["points"]]
    assert f[1] < f[0]  # a heavier head lowers the head mode
    assert main(["modes", "pantograph", "--set", "params.mh=15", "--json"]) == 0
    single = _json(capsys)
    assert [m["f_n"] for m in single["reference"]] == [data["points"][1]["results"][f"reference[{i}].f_n"]
                                                       for i in range(4)]
    rows = list(csv.reader((out / "study.csv").open()))
    assert rows[0][0] == "params.mh [kg]" and "reference[1].f_n [Hz]" in rows[0] and len(rows) == 3
    assert (out / "study.png").stat().st_size > 10_000
    summary = json.loads((out / "summary.json").read_text())
    assert summary["command"]["argv"][:4] == ["modes", "pantograph", "--vary", "params.mh=12,15"]


def test_equilibrium_set_moves_the_contact_force_by_the_head_weight(capsys):
    """`--set params.mh=15` on the equilibrium: the contact force drops by the added head weight (hand computation,
    Δm g; the frame's geometry moves by the head spring's extra deflection, a few mN), and equals the Python API's."""
    assert main(["equilibrium", "pantograph", "--json"]) == 0
    f0 = _json(capsys)["reference"]["contact_force"]
    assert main(["equilibrium", "pantograph", "--set", "params.mh=15", "--json"]) == 0
    f1 = _json(capsys)["reference"]["contact_force"]
    mh0 = mbsuite.load_scene("pantograph").build_params().mh
    assert f1 - f0 == pytest.approx(-(15 - mh0) * G, abs=0.01)
    sc = mbsuite.load_scene("pantograph").replace(params={"mh": 15})
    assert f1 == sc.spec.equilibrium(sc).data["reference"]["contact_force"]


@pytest.mark.parametrize("argv, words", [
    (["modes", "pantograph", "--set", "params.nosuch=1"], ["nosuch", "--set"]),
    (["modes", "pantograph", "--set", "mh=1"], ["--set", "SECTION.KEY=VALUE"]),
    (["modes", "pantograph", "--vary", "params.mh=-1,2"], ["mh", "-1"]),
])
def test_bad_set_or_vary_is_one_line_naming_it(argv, words, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("mbsuite: error:") and err.count("\n") == 1
    assert all(w in err for w in words), err


def test_a_command_without_a_scene_varies_its_options(capsys):
    """`mbsuite coupler jacobian --vary option.gamma=...`: each point is the single command with `--gamma` at that
    value; an option the command does not have is named with the valid ones."""
    assert main(["coupler", "jacobian", "--vary", "option.gamma=0.25,0.3", "--workers", "1", "--json"]) == 0
    data = _json(capsys)
    assert data["axes"] == {"option.gamma": [0.25, 0.3]} and data["units"]["option.gamma"] == "rad"
    for point in data["points"]:
        assert main(["coupler", "jacobian", "--gamma", str(point["values"]["option.gamma"]), "--json"]) == 0
        single = _json(capsys)
        assert [point["results"][f"singular_values[{i}]"] for i in range(4)] == single["singular_values"]
    assert main(["coupler", "jacobian", "--vary", "option.nosuch=1"]) == 2
    err = capsys.readouterr().err
    assert "no option 'nosuch'" in err and "'gamma'" in err


def test_sweep_set_applies_at_every_point(capsys):
    """`mbsuite sweep --set solver.duration=0.2 --vary solver.timestep=...`: every point runs 0.2 s, so its step
    count is duration / timestep (hand computation)."""
    assert main(["sweep", "iftomm/fourbar", "--set", "solver.duration=0.2", "--vary", "solver.timestep=1e-3,5e-4",
                 "--workers", "1", "--json"]) == 0
    data = _json(capsys)
    assert [p["stats"]["steps"] for p in data["points"]] == [round(0.2 / 1e-3), round(0.2 / 5e-4)]
