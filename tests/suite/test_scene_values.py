"""What a numpy user passes is taken as the number it holds (every real number type: numpy scalars of every width,
0-d arrays, Fraction, Decimal; in lists and tables too), sequences are lists where a list is meant and a string never
is, and an error says where the value came from (the file, the dictionary, Python or the command line)."""

from __future__ import annotations

import decimal
import fractions

import numpy as np
import pytest

import mbsuite
from mbsuite.errors import ParameterError, SceneError
from mbsuite.models.pantograph.params import PantographParams
from mbsuite.settings import SolverSettings

# 14 as every real number type a user may hold; the independent source is the plain Python float 14.0
FOURTEEN = [np.float16(14.0), np.float32(14.0), np.float64(14.0), np.longdouble(14.0), np.int8(14), np.int16(14),
            np.int32(14), np.int64(14), np.uint8(14), np.uint64(14), np.array(14.0), np.array(14, dtype=np.int32),
            fractions.Fraction(28, 2), decimal.Decimal("14"), 14, 14.0]


@pytest.mark.parametrize("value", FOURTEEN, ids=lambda v: type(v).__name__ + str(getattr(v, "dtype", "")))
def test_every_real_number_type_is_the_number_it_holds_in_every_section(value):
    sc = mbsuite.load_scene("pantograph/lab")
    plain = sc.replace(params={"mh": 14.0}, input={"frequency": 3.5}, solver={"duration": 14.0},
                       accuracy={"F1_amp": 14.0})
    got = sc.replace(params={"mh": value}, input={"frequency": value / 4 if not isinstance(value, decimal.Decimal)
                                                  else value / decimal.Decimal(4)},
                     solver={"duration": value}, accuracy={"F1_amp": value})
    assert got.build_params() == plain.build_params()
    assert got.params["mh"] == 14.0 and type(got.params["mh"]) is float
    assert got.input["frequency"] == 3.5 and type(got.input["frequency"]) is float
    assert got.solver.duration == 14.0 and type(got.solver.duration) is float
    assert got.accuracy["F1_amp"] == 14.0


def test_integer_parameters_take_integral_numbers_of_any_type():
    cat = mbsuite.load_scene("catenary")
    for v in (np.int64(4), fractions.Fraction(8, 2), decimal.Decimal("4"), np.float32(4.0)):
        assert cat.replace(params={"filter_order": v}).build_params().filter_order == 4
    with pytest.raises(ParameterError, match=r"filter_order = 4\.5 set in Python \(Scene\.replace\) is invalid"):
        cat.replace(params={"filter_order": fractions.Fraction(9, 2)})


def test_a_narrow_float_is_the_decimal_the_user_wrote():
    """Decision: float16/float32 give the shortest decimal that reads back as the same narrow float (0.001 written
    as np.float32 is 0.001, not its binary neighbour 0.0010000000474974513)."""
    sc = mbsuite.load_scene("pantograph/lab").replace(input={"amplitude": np.float32(1e-3)})
    assert sc.input["amplitude"] == 0.001
    assert np.float32(0.001) == np.float32(sc.input["amplitude"])  # the same narrow float


@pytest.mark.parametrize("value", [True, np.bool_(True), 14 + 0j, np.complex128(14), "14", None],
                         ids=["bool", "np.bool_", "complex", "np.complex128", "str", "None"])
def test_bools_complex_numbers_and_strings_are_not_numbers(value):
    with pytest.raises(mbsuite.MbsuiteError, match=r"mh = .* set in Python \(Scene\.replace\) is not a number"):
        mbsuite.load_scene("pantograph/lab").replace(params={"mh": value})


def test_dataclasses_and_solver_settings_take_numpy_numbers_directly():
    assert PantographParams(mh=np.float32(14.0), m1=fractions.Fraction(63, 2)) == PantographParams(mh=14.0, m1=31.5)
    s = SolverSettings(duration=np.int64(3), timestep=fractions.Fraction(1, 1000)).check(("mujoco",))
    assert (s.duration, s.timestep) == (3.0, 0.001) and type(s.duration) is float and type(s.timestep) is float


def test_numpy_bools_are_bools_for_effects_and_switches():
    sc = mbsuite.load_scene("pantograph/lab").replace(effects={"gravity": np.bool_(False)},
                                                      solver={"allow_inaccurate": np.bool_(True)})
    assert sc.effects["gravity"] is False and sc.solver.allow_inaccurate is True
    with pytest.raises(SceneError, match=r"effect 'gravity' = 0 set in Python \(Scene\.replace\) is not allowed"):
        mbsuite.load_scene("pantograph/lab").replace(effects={"gravity": np.int64(0)})


@pytest.mark.parametrize("seq", [(5.0, 30.0, 55.0), [np.float32(5.0), fractions.Fraction(30), decimal.Decimal("55")],
                                 np.array([5.0, 30.0, 55.0]), list(np.array([5, 30, 55]))],
                         ids=["tuple", "mixed", "array", "list-of-numpy"])
def test_any_sequence_of_numbers_is_a_list_valued_parameter(seq):
    cat = mbsuite.load_scene("catenary").replace(params={"dropper_positions": seq})
    assert cat.build_params().dropper_positions == [5.0, 30.0, 55.0]
    assert all(type(x) is float for x in cat.params["dropper_positions"])


def test_the_catenary_parameters_take_an_array_of_droppers_directly():
    from mbsuite.models.catenary.params import CatenaryParams

    p = CatenaryParams(dropper_positions=np.array([5, 30, 55], dtype=np.int32))
    assert p.dropper_positions == [5.0, 30.0, 55.0] and all(type(x) is float for x in p.dropper_positions)
    with pytest.raises(ParameterError, match="must be a list of numbers"):
        CatenaryParams(dropper_positions="5, 30")


def test_a_string_where_a_list_is_meant_is_an_error_never_a_list_of_characters():
    cat = mbsuite.load_scene("catenary")
    with pytest.raises(SceneError, match=r"dropper_positions = '5, 30' set in Python .* is a string, but a list"):
        cat.replace(params={"dropper_positions": "5, 30"})
    with pytest.raises(SceneError, match=r"dropper_positions = 5\.0 .* must be a list of numbers"):
        cat.replace(params={"dropper_positions": 5.0})
    with pytest.raises(SceneError, match=r"mh = \[1\.0\] set in Python .* must be a single value"):
        mbsuite.load_scene("pantograph/lab").replace(params={"mh": [1.0]})
    with pytest.raises(SceneError, match=r"outputs\.signals = 'F1' .* is a string, but a list of signal names"):
        mbsuite.load_scene("pantograph/lab").replace(outputs={"signals": "F1"})
    with pytest.raises(SceneError, match=r"pantographs = 'reference2mass' in \[train\] must be a list"):
        cat.replace(train={"pantographs": "reference2mass"})


def test_one_signal_name_or_any_sequence_of_names_is_a_signal_list():
    sc = mbsuite.load_scene("pantograph/lab")
    assert sc.replace(outputs="F1").outputs == ("F1",)
    assert sc.replace(outputs=np.array(["F1", "F2"])).outputs == ("F1", "F2")
    assert sc.replace(outputs=("F2",)).outputs == ("F2",)
    with pytest.raises(SceneError, match=r"unknown output signal\(s\) \['F9'\]"):
        sc.replace(outputs="F9")


def test_model_sections_take_sequences_of_numpy_values():
    cat = mbsuite.load_scene("catenary").replace(
        train={"pantographs": ("reference2mass", "reference2mass"), "spacings": np.array([200.0])})
    assert cat.sections["train"] == {"pantographs": ["reference2mass", "reference2mass"], "spacings": [200.0]}


def test_an_error_says_where_the_value_came_from():
    sc = mbsuite.load_scene("pantograph/lab")
    # a value set in Python is not blamed on the shipped file
    with pytest.raises(SceneError) as e:
        sc.replace(params={"k_s": 1e5})
    assert "set in Python (Scene.replace)" in str(e.value) and "lab.toml" not in str(e.value)
    with pytest.raises(ParameterError) as e:
        sc.replace(params={"mh": -1.0})
    assert "mh = -1.0 set in Python (Scene.replace) is invalid" in str(e.value) and "lab.toml" not in str(e.value)
    # the command line says so (the CLI passes its origin)
    with pytest.raises(SceneError, match=r"input\.speed = -250\.0 on the command line \(--speed\) is invalid"):
        mbsuite.load_scene("catenary").replace(input={"speed": -250.0}, origin="on the command line (--speed)")
    # a check across keys names the file and the key set elsewhere
    with pytest.raises(SceneError, match=r"t_settle \(5\.0\) must be shorter than solver\.duration \(2\.0\) in .*lab\."
                                         r"toml with solver\.duration set in Python"):
        sc.replace(solver={"duration": 2.0})
    # a dictionary without a file
    with pytest.raises(ParameterError, match=r"mh = -2 in the scene dictionary is invalid"):
        mbsuite.scene_from_dict({"model": "pantograph", "params": {"mh": -2}})


def test_a_bad_value_in_a_file_is_blamed_on_the_file(tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text('model = "pantograph"\n[params]\nmh = -1.0\n')
    with pytest.raises(ParameterError, match=r"mh = -1\.0 in .*bad\.toml is invalid"):
        mbsuite.load_scene(f)
    f.write_text('model = "pantograph"\n[solver]\nt_settle = 0.5\n')
    with pytest.raises(SceneError, match=r"t_settle \(0\.5\) must be shorter than solver\.duration \(0\.4\) "
                                         r"in .*bad\.toml with solver\.duration set in Python"):
        mbsuite.load_scene(f).replace(solver={"duration": 0.4})
