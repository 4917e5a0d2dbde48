"""What a numpy user passes is taken as the number it holds (numpy scalars, 0-d arrays, in lists and tables too), a
single signal name is a signal list of one, and an error in an override says the value came from an override."""

from __future__ import annotations

import numpy as np
import pytest

import mbsuite
from mbsuite.errors import SceneError


@pytest.mark.parametrize("value", [np.float32(14.0), np.float64(14.0), np.int64(14), np.array(14.0), 14.0])
def test_numpy_numbers_are_taken_as_numbers_in_every_section(value):
    sc = mbsuite.load_scene("pantograph/lab")
    plain = sc.replace(params={"mh": 14.0}, input={"frequency": 3.0}, solver={"timestep": 5e-4})
    got = sc.replace(params={"mh": value}, input={"frequency": value / 14.0 * 3.0},
                     solver={"timestep": value / 14.0 * 5e-4})
    assert got.build_params() == plain.build_params()
    assert got.input["frequency"] == pytest.approx(3.0, rel=1e-7) and type(got.input["frequency"]) is float
    assert got.solver.timestep == pytest.approx(5e-4, rel=1e-7) and type(got.solver.timestep) is float
    assert type(got.params["mh"]) in (int, float)


def test_numpy_bools_and_lists_of_numpy_numbers():
    sc = mbsuite.load_scene("pantograph/lab").replace(effects={"gravity": np.bool_(False)})
    assert sc.effects["gravity"] is False
    cat = mbsuite.load_scene("catenary").replace(params={"dropper_positions": list(np.array([5.0, 30.0, 55.0]))})
    assert cat.build_params().dropper_positions == [5.0, 30.0, 55.0]
    assert all(type(x) is float for x in cat.params["dropper_positions"])


def test_one_signal_name_is_a_list_of_one():
    assert mbsuite.load_scene("pantograph/lab").replace(outputs="F1").outputs == ("F1",)
    with pytest.raises(SceneError, match=r"unknown output signal\(s\) \['F9'\]"):
        mbsuite.load_scene("pantograph/lab").replace(outputs="F9")


def test_an_error_in_an_override_says_it_came_from_an_override():
    with pytest.raises(SceneError, match=r"lab\.toml \(with overrides of \[params\]\).*valid parameters"):
        mbsuite.load_scene("pantograph/lab").replace(params={"k_s": 1e5})
    with pytest.raises(mbsuite.MbsuiteError, match=r"mh = \[1\.0\] is not a number"):
        mbsuite.load_scene("pantograph/lab").replace(params={"mh": [1.0]})
