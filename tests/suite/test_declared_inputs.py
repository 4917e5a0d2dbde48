"""The input declarations of the design tools, the signals, the study ranges and the accuracy tolerances, tested from
the declarations themselves (`mbsuite.schema.Section`): for every declared key, generated bad values (missing where
required, wrong type, NaN, +-inf, bool, a fractional count, below and above its declared range, an unknown word) end
in an `MbsuiteError` naming the key (and, for a value, the value, what is valid and the unit), through the function a
user calls; a numpy scalar of a valid value is accepted and gives what the plain number gives. Plus the cross-field
rule of a design scene: the derived values are what the design inputs give (`design_scene.DESIGN_SECTION`)."""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from mbsuite.analysis.designspace import FACTOR_INPUTS, Factor
from mbsuite.analysis.sweep import parse_values
from mbsuite.cli.design import PARETO_LEVELS, START_VALUE
from mbsuite.engines import inputs as S
from mbsuite.errors import MbsuiteError, SceneError
from mbsuite.limits import Limit
from mbsuite.models.catenary.design import GRID_INPUTS, design_grid
from mbsuite.models.drives import design as D
from mbsuite.models.drives.design_scene import (
    DERIVED_RTOL,
    DERIVED_VALUES,
    DESIGN_INPUTS,
    DESIGN_SECTION,
    DesignInputs,
    derived,
    design_scene,
    validate_section,
)
from mbsuite.models.drives.scene_run import PROFILE, check_profile
from mbsuite.scenes import scene_from_dict
from mbsuite.schema import Items, Section, check_value
from mbsuite.trust.estimate import TOLERANCE, check_tolerances

PLANT = dict(J_l=0.0023, t_s=1 / 14.5, B_total=2.5e-4, tau_l=0.15, w0=400.0)
DESIGN = dict(P=200.0, Sr_min=15.0, w_max=400.0, V_m=100.0, tau_c=8.0, w_op=300.0)
RECORD = {"inputs": DESIGN, "derived": derived(DesignInputs(**DESIGN))}

#: every declared section: (the section, a valid example, the function a user calls with it)
CASES: dict[str, tuple[Section, dict[str, Any], Callable[[dict[str, Any]], Any]]] = {
    "drives.design.SRMIN_INPUTS": (D.SRMIN_INPUTS, dict(P=500.0, w_min=50.0, w_rip=5.0, J_l=0.1),
                                   lambda d: D.srmin(**d)),
    "drives.design.DESIGN_POINT_INPUTS": (D.DESIGN_POINT_INPUTS, dict(P=200.0, Sr_min=15.0, w_min=0.0, w_max=400.0,
                                                                      V_m=100.0, J_s=6e-5),
                                          lambda d: D.design_point(**d)),
    "drives.design.CLUTCH_TORQUE_INPUTS": (D.CLUTCH_TORQUE_INPUTS, dict(P=200.0, Sr_min=15.0, w_min=0.0, w_max=400.0,
                                                                        V_m=100.0, tau_c=8.0),
                                           lambda d: D.at_clutch_torque(**d)),
    "drives.design.SPRING_INPUTS": (D.SPRING_INPUTS, dict(K=0.98, x_max=5.09, fatigue=0.25, sigma_uts=1.465e9,
                                                          E=209e9, U=0.125), lambda d: D.springsz(**d)),
    "drives.design.PLANT_INPUTS": (D.PLANT_INPUTS, PLANT, lambda d: D.plant_AB(**d)),
    "drives.design.B_TOTAL_INPUTS": (D.B_TOTAL_INPUTS, dict(P=100.0, w0=400.0, tau_l=0.15),
                                     lambda d: D.b_total(**d)),
    "drives.design.GAIN_INPUTS": (D.GAIN_INPUTS, dict(Kp=1e-3, Ki=0.0167),
                                  lambda d: D.closed_loop_poles(d["Kp"], d["Ki"], **PLANT)),
    "drives.design_scene.DESIGN_INPUTS": (DESIGN_INPUTS, DESIGN, lambda d: DesignInputs(**d)),
    "drives.design_scene.DESIGN_SECTION": (DESIGN_SECTION, RECORD, validate_section),
    "signals.CONSTANT_INPUTS": (S.CONSTANT_INPUTS, dict(value=-7.25), lambda d: S.Constant(**d)),
    "signals.STEP_INPUTS": (S.STEP_INPUTS, dict(height=-3.0, offset=1.0, t0=0.4), lambda d: S.Step(**d)),
    "signals.SINE_INPUTS": (S.SINE_INPUTS, dict(amplitude=2.0, frequency=0.5, phase=0.1, offset=1.0, t0=0.2),
                            lambda d: S.Sine(**d)),
    "signals.RAMP_INPUTS": (S.RAMP_INPUTS, dict(height=4.0, duration=2.0, offset=0.5, t0=1.0), lambda d: S.Ramp(**d)),
    "signals.PULSE_INPUTS": (S.PULSE_INPUTS, dict(amplitude=1.0, width=0.5, period=1.3, offset=0.0, t0=0.3, n=3),
                             lambda d: S.Pulse(**d)),
    "signals.TABLE_INPUTS": (S.TABLE_INPUTS, dict(times=[0.0, 1.0, 2.0], points=[1.0, -2.0, 0.5]),
                             lambda d: S.Table(**d)),
    "analysis.designspace.FACTOR_INPUTS": (FACTOR_INPUTS, dict(section="params", key="m1", lo=5.0, hi=10.0),
                                           lambda d: Factor(**d)),
    # the grid's own runs are not started here: its declaration is its check (design_grid calls it first)
    "catenary.design.GRID_INPUTS": (GRID_INPUTS, dict(speeds=[250.0, 300.0], vary={"m1": [7.2, 9.0], "n_spans": [4]}),
                                    lambda d: GRID_INPUTS.check(d, "the catenary design grid")),
}


def _bad_numbers(lim: Limit) -> Iterator[tuple[str, Any]]:
    """Values the declaration `lim` refuses: (what, value)."""
    if lim.kind is bool:
        yield "word", "yes"
        yield "number", 1
        return
    if lim.kind is str or lim.choices is not None:
        yield "number", 3.0
        if lim.choices is not None:
            yield "unknown word", "no-such-word"
        return
    yield from (("word", "1.0"), ("NaN", math.nan), ("+inf", math.inf), ("-inf", -math.inf), ("bool", True),
                ("numpy bool", np.bool_(False)), ("list", [1.0]), ("complex", 1 + 0j))
    if lim.kind is int:
        yield "fractional count", 2.5
    if lim.lo is not None:
        yield "below lo", lim.lo - max(1.0, abs(lim.lo))
        if lim.lo_open:
            yield "at the open lo", lim.lo
    if lim.hi is not None:
        yield "above hi", lim.hi + max(1.0, abs(lim.hi))
        if lim.hi_open:
            yield "at the open hi", lim.hi


def _bad(section: Section, example: dict[str, Any], path: tuple[str, ...] = ()
         ) -> Iterator[tuple[str, dict[str, Any], str, str]]:
    """(case id, bad data, the name the error must carry, a second text it must carry) for every declared key of
    `section` (nested sections walked with their part of `example`)."""
    for key, decl in section.keys.items():
        where = "/".join((*path, key))

        def put(value: Any, key: str = key) -> dict[str, Any]:
            data = copy.deepcopy(example)
            data[key] = value
            return data

        if isinstance(decl, Limit):
            for what, v in _bad_numbers(decl):
                yield f"{where}: {what}", put(v), f"{key} = {v!r}", f"valid: {decl.describe()}"
        elif isinstance(decl, Items):
            yield f"{where}: not a list", put("x"), f"{key} = 'x'", "must be a list"
            if decl.min > 0:
                yield f"{where}: empty", put([]), key, "0 items"
            if isinstance(decl.of, Limit):
                rest = list(example.get(key) or [])[1:]
                for what, v in _bad_numbers(decl.of):
                    yield f"{where}[0]: {what}", put([v, *rest]), f"{key}[0] = {v!r}", f"valid: {decl.of.describe()}"
        elif isinstance(decl, Section):
            yield f"{where}: not a table", put("x"), key, "must be a table"
            for case, sub, name, text in _bad(decl, example.get(key) or {}, (*path, key)):
                yield case, put(sub), name, text


def _generated() -> Iterator[Any]:
    for label, (section, example, call) in CASES.items():
        for case, data, name, text in _bad(section, example):
            yield pytest.param(call, data, name, text, id=f"{label} {case}")


@pytest.mark.parametrize("call, data, name, text", list(_generated()))
def test_a_bad_value_is_refused_naming_the_key_value_and_range(call, data, name, text):
    with pytest.raises(MbsuiteError) as exc:
        call(data)
    msg = str(exc.value)
    assert name in msg and text in msg, msg


def _required(section: Section, example: dict[str, Any], path: tuple[str, ...] = ()) -> Iterator[Any]:
    for key in section.required:
        data = {k: v for k, v in example.items() if k != key}
        yield section, example, path, key, data
    for key, decl in section.keys.items():
        if isinstance(decl, Section) and key in example:
            for sec, ex, p, k, sub in _required(decl, example[key], (*path, key)):
                yield sec, ex, p, k, {**example, key: sub}


@pytest.mark.parametrize("section, data, key", [
    pytest.param(CASES[label][0], data, key, id=f"{label} {'/'.join((*path, key))}")
    for label in CASES for _, _, path, key, data in _required(CASES[label][0], CASES[label][1])])
def test_a_missing_required_key_is_named(section, data, key):
    with pytest.raises(MbsuiteError, match=rf"\b{key} missing; required: {key} \("):
        section.check(data, "test input")


def _as_numpy(value: Any, lim: Limit) -> Any:
    return np.int64(value) if lim.kind is int else np.float64(value)


def _numpy_variants(section: Section, example: dict[str, Any]) -> Iterator[tuple[str, dict[str, Any]]]:
    """The example with one number at a time given as a numpy scalar (a 0-d array too, for floats)."""
    for key, decl in section.keys.items():
        if key not in example:
            continue
        if isinstance(decl, Limit) and decl.kind in (int, float) and decl.choices is None:
            yield f"{key} numpy", {**example, key: _as_numpy(example[key], decl)}
            if decl.kind is float:
                yield f"{key} 0-d array", {**example, key: np.array(example[key])}
        elif isinstance(decl, Items) and isinstance(decl.of, Limit) and decl.of.kind in (int, float):
            yield f"{key}[0] numpy", {**example, key: [_as_numpy(example[key][0], decl.of), *example[key][1:]]}
        elif isinstance(decl, Section):
            for case, sub in _numpy_variants(decl, example[key]):
                yield f"{key}/{case}", {**example, key: sub}


@pytest.mark.parametrize("call, data, want", [
    pytest.param(call, data, example, id=f"{label} {case}")
    for label, (section, example, call) in CASES.items() for case, data in _numpy_variants(section, example)])
def test_a_numpy_scalar_of_a_valid_value_is_accepted(call, data, want):
    np.testing.assert_equal(call(data), call(want))


def test_integer_counts_are_integers():
    assert S.Pulse(n=np.int64(3)) == S.Pulse(n=3) and type(S.Pulse(n=np.int64(3)).n) is int
    with pytest.raises(MbsuiteError, match=r"n = 2.5 in pulse signal is invalid; valid: integer in \[0, inf\)"):
        S.Pulse(n=2.5)
    g = GRID_INPUTS.check({"speeds": [250], "vary": {"n_spans": [np.int64(4)]}}, "grid")
    assert g["vary"]["n_spans"] == [4] and type(g["vary"]["n_spans"][0]) is int
    with pytest.raises(MbsuiteError, match=r"n_spans\[0\] = 4.5 in the catenary design grid \[vary\] is invalid"):
        design_grid(None, [250.0], {"n_spans": [4.5]})  # refused before the scene is read


# ---- the declarations that are not sections: a list, a single number --------------------------------------------
def test_the_speed_profile_declaration():
    good = [[0.0, 300.0], [4.0, 300.0], [4.01, -300.0]]
    assert check_profile(good).tolist() == good
    assert check_profile([[np.float64(0.0), np.int64(300)], [np.array(1.0), 300.0]]).tolist() == [[0, 300], [1, 300]]
    t_lim, r_lim = PROFILE.of
    for col, lim in ((0, t_lim), (1, r_lim)):
        for _, v in _bad_numbers(lim):
            rows = copy.deepcopy(good)
            rows[1][col] = v
            with pytest.raises(SceneError) as exc:
                check_profile(rows)
            assert f"input.profile[1][{col}] = {v!r}" in str(exc.value) and lim.unit in str(exc.value)
    with pytest.raises(SceneError, match=r"input.profile in \[input\] has 100,001 items"):
        check_profile([[0.0, 0.0]] * 100_001)
    with pytest.raises(SceneError, match="times must be strictly increasing: row 2 t = 4.0 s"):
        check_profile([[0.0, 1.0], [4.0, 1.0], [4.0, 2.0]])


def test_the_accuracy_tolerance_declaration():
    assert check_tolerances({"sigma": np.float64(0.5), "Fm": np.int64(2)}) == {"sigma": 0.5, "Fm": 2.0}
    for _, v in _bad_numbers(TOLERANCE):
        with pytest.raises(SceneError) as exc:
            check_tolerances({"sigma": v}, " in x.toml")
        assert f"accuracy.sigma = {v!r} in x.toml" in str(exc.value) and "valid: (0, inf)" in str(exc.value)


@pytest.mark.parametrize("decl, name", [(START_VALUE, "--start params.m1"), (PARETO_LEVELS, "--pareto")])
def test_the_command_line_number_declarations(decl, name):
    assert check_value(decl, name, parse_values("5"), "the command line", MbsuiteError) == [5.0]
    assert check_value(decl, name, [np.float64(5.0)], "the command line", MbsuiteError) == [5.0]
    for text in ("abc", "true", "nan"):
        with pytest.raises(MbsuiteError, match=rf"{name}\[0\] = .* in the command line"):
            check_value(decl, name, parse_values(text) if text != "nan" else [math.nan], "the command line",
                        MbsuiteError)
    with pytest.raises(MbsuiteError, match="has 0 items"):
        check_value(decl, name, [], "the command line", MbsuiteError)


# ---- the cross-field rules --------------------------------------------------------------------------------------
def test_a_design_record_inconsistent_with_its_inputs_is_refused_naming_both_keys():
    """Hand-made: K off by 1e-6 relative (above DERIVED_RTOL = 1e-9) names [design.derived] K and the inputs it comes
    from; an input recorded again as a derived value (w_op) names it on both sides; 1e-12 relative is accepted."""
    assert DERIVED_RTOL == 1e-9
    rec = copy.deepcopy(RECORD)
    k = rec["derived"]["K"]
    rec["derived"]["K"] = k * (1 + 1e-6)
    with pytest.raises(SceneError) as exc:
        validate_section(rec)
    msg = str(exc.value)
    assert "[design.derived] K = " in msg and "[design.inputs] (P, Sr_min, w_min, w_max, V_m, tau_c) give" in msg
    assert f"K = {k!r}" in msg and "relative tolerance 1e-09" in msg, msg
    rec["derived"]["K"] = k * (1 + 1e-12)
    assert validate_section(rec)["derived"]["K"] == k
    rec = copy.deepcopy(RECORD)
    rec["derived"]["w_op"] = 301.0  # the inputs say w_op = 300
    with pytest.raises(SceneError, match=r"\[design.derived\] w_op = 301.0 is not what \[design.inputs\] \(w_op, "
                                         r"w_min, w_max\) give: w_op = 300.0"):
        validate_section(rec)
    # in a scene file: the loader refuses the stale record with the same message
    scene = design_scene(DesignInputs(**DESIGN))
    scene["design"]["derived"]["tau_l"] *= 1.001
    with pytest.raises(SceneError, match=r"\[design.derived\] tau_l = .* \[design.inputs\] \(P, w_op\) give"):
        scene_from_dict(scene)


@pytest.mark.parametrize("change, needle", [
    ({"J_s": 6e-5}, "exactly one of tau_c"),  # tau_c and J_s both given
    ({"w_min": 500.0}, "w_min = 500.0 rad/s must be below w_max = 400.0 rad/s"),
    ({"w_op": 450.0}, "w_op = 450.0 rad/s must lie in the design's speed band"),
    ({"t_settle": 7.0}, "t_settle = 7.0 s must be below duration = 6.0 s"),
])
def test_the_design_input_rules(change, needle):
    with pytest.raises(MbsuiteError, match=needle):
        DesignInputs(**{**DESIGN, **change})
    with pytest.raises(SceneError, match=needle):
        validate_section({"inputs": {**DESIGN, **change}})


def test_the_design_tool_rules():
    with pytest.raises(MbsuiteError, match="w_min = 400 rad/s must be below w_max = 400 rad/s"):
        D.design_point(200.0, 15.0, 400.0, 400.0, 100.0, 6e-5)
    with pytest.raises(MbsuiteError, match=r"w0 \(operating speed\) = 0.0 rad/s must be nonzero"):
        D.b_total(100.0, 0.0, 0.15)
    with pytest.raises(MbsuiteError, match=r"lower bound 10 must lie below the upper bound 5 \(lo < hi\)"):
        Factor("params", "m1", 10.0, 5.0)
    with pytest.raises(MbsuiteError, match=r"times \(2 values\) and points \(1 values\) must have equal lengths"):
        S.Table((0.0, 1.0), (1.0,))


def test_the_declarations_give_docs_and_a_json_schema():
    for section, _, _ in CASES.values():
        assert section.markdown().startswith(f"**{section.title}**")
        assert section.json_schema(top=True)["title"] == section.title
    schema = DESIGN_SECTION.json_schema()
    assert schema["required"] == ["inputs"] and "relative tolerance 1e-09" in schema["description"]
    assert schema["properties"]["inputs"]["required"] == ["P", "Sr_min", "w_max", "V_m"]
    assert set(DERIVED_VALUES.keys) == set(RECORD["derived"])
