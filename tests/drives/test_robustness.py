"""Regression tests of the robustness corpus' drives findings: the speed reference profile of a scene and the
design tools' options end in one clear error naming the culprit and its valid form or range."""

from __future__ import annotations

import pytest

from mbsuite.cli import main
from mbsuite.errors import ParameterError, SceneError
from mbsuite.models.drives import design as D
from mbsuite.models.drives.scene_run import check_profile

SUSD = ('model = "drives"\n[effects]\nmechanism = "step_up_down"\ncontroller = "energy_packet"\nclosed_loop = true\n'
        '[params]\nset = "design_100w"\n[input]\ntype = "reference"\nprofile = {profile}\n'
        '[solver]\nengine = "mujoco"\nduration = 1.0\n')


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


@pytest.mark.parametrize("profile, culprit", [  # the messages of the declaration (`scene_run.PROFILE`)
    ('"abc"', ("input.profile = 'abc'", "must be a list: 1 to 100,000 rows [t (s), r (rad/s)]")),
    ("[[0.0, nan], [1.0, 2.0]]", ("input.profile[0][1] = nan", "valid: [-100000, 100000] rad/s")),
    ("[[0.0, inf]]", ("input.profile[0][1] = inf", "valid: [-100000, 100000] rad/s")),
    ("[]", ("input.profile", "has 0 items; valid: 1 to 100,000 rows")),
    ("[[0.0]]", ("input.profile[0] = [0.0]", "must be a row of 2 values [t (s), r (rad/s)]")),
    ("[[0.0, 1.0, 2.0]]", ("input.profile[0] = [0.0, 1.0, 2.0]", "must be a row of 2 values")),
    ('[[0.0, "x"]]', ("input.profile[0][1] = 'x'", "is not a number; valid: [-100000, 100000] rad/s")),
    ("[[0.0, true]]", ("input.profile[0][1] = True", "is not a number")),
    ("[[1.0, 2.0], [0.0, 3.0]]", ("input.profile", "times must be strictly increasing: row 1 t = 0.0 s")),
    ("[[0.0, 1.0], [0.0, 3.0]]", ("input.profile", "times must be strictly increasing")),
    ("[[0.0, 1e6]]", ("input.profile[0][1] = 1000000.0", "valid: [-100000, 100000] rad/s")),
])
def test_bad_profiles_are_clear_errors(tmp_path, capsys, profile, culprit):
    path = tmp_path / "susd.toml"
    path.write_text(SUSD.format(profile=profile))
    assert main(["run", str(path), "--json"]) == 2
    err = _one_line_error(capsys)
    assert all(c in err for c in culprit), err
    assert "internal error" not in err


def test_check_profile_accepts_the_shipped_form():
    prof = check_profile([[0.0, 300.0], [4.0, 300.0], [4.01, -300.0], [8, -300]])
    assert prof.shape == (4, 2) and prof.dtype == float
    with pytest.raises(SceneError, match="input.profile"):
        check_profile((("a", 1.0),))


def test_cadjs_wmin_above_wmax_names_both_options(capsys):
    rc = main(["drive", "design", "cadjs", "--P", "100", "--wmax", "400", "--vm", "100", "--srmin", "10",
               "--wmin", "500"])
    assert rc == 2
    err = _one_line_error(capsys)
    assert "--wmin 500 rad/s must be below --wmax 400 rad/s" in err
    with pytest.raises(ParameterError, match="w_min = 500 rad/s must be below w_max = 400 rad/s"):
        D.cadjs(100.0, 10.0, 500.0, 400.0, 100.0)
    with pytest.raises(ParameterError, match="w_min"):
        D.design_point(100.0, 10.0, 400.0, 400.0, 100.0, 1e-5)


@pytest.mark.parametrize("argv, flag, bad", [
    (["drive", "design", "cadjs", "--P", "100", "--wmax", "400", "--vm", "100", "--srmin", "abc"], "--srmin", "abc"),
    (["drive", "design", "cadjs", "--P", "100", "--wmax", "400", "--vm", "100", "--srmin", "10",
      "--js", "1e-5,x"], "--js", "x"),
    (["drive", "efficiency", "drives/step_up_efficiency", "--loads", "abc", "--duration", "1"], "--loads", "abc"),
])
def test_non_numeric_list_entries_name_the_option_and_entry(capsys, argv, flag, bad):
    assert main(argv) == 2
    err = _one_line_error(capsys)
    assert flag in err and f"'{bad}' is not a number" in err and "_floats" not in err
