"""Every declared input section, tested from its declaration (`mbsuite.schema`, `mbsuite.scene_schema.sections`):

- for every key, generated bad values (missing where required, wrong type, bool, NaN, +-inf, below and above its
  range, huge, a fractional count, an unknown word, an overlong list) end in an `MbsuiteError` naming the key, through
  the loader a user's file goes through (a line file's reader, a scene section's validator); a numpy scalar of a valid
  value is accepted;
- the generated JSON Schemas accept every shipped scene and line file and refuse what the loader refuses (where JSON
  can carry the value), and the shipped schemas and `docs/inputs.md` are what the declarations give;
- every numeric key of a line file reaches the run: moved, it moves the assembled FE (mass, stiffness or static
  state), or it is refused with a message naming it.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math
import subprocess
import sys
import tomllib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import jsonschema
import numpy as np
import pytest

from mbsuite.errors import MbsuiteError
from mbsuite.limits import Limit
from mbsuite.models.catenary import irregularity
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.linefile import line_from_dict, validate_line_section
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.registry import models
from mbsuite.scene_schema import scene_schema, section_of, sections
from mbsuite.schema import Items, Section

ROOT = Path(__file__).resolve().parents[2]
LINES = ROOT / "mbsuite" / "models" / "catenary" / "lines"

#: a small line with every kind of row and key: two 50 m spans, a stitch wire, tension segments, masses everywhere
LINE: dict[str, Any] = {
    "name": "two spans", "presag": 0.0005,
    "wires": [
        {"name": "contact", "role": "contact", "mass": 1.35, "tension": 20000.0, "EI": 195.0, "x0": 0.0, "x1": 100.0},
        {"name": "messenger", "role": "messenger", "mass": 1.07, "tension": 16000.0, "EI": 131.7, "x0": 0.0,
         "x1": 100.0, "tension_segments": [[42.0, 58.0, 12500.0]]},
        {"name": "stitch", "role": "stitch", "mass": 0.31, "tension": 3500.0, "EI": 10.0, "x0": 42.0, "x1": 58.0,
         "ends": ["free", "free"]},
    ],
    "supports": [{"x": 0.0},
                 {"x": 50.0, "k_contact": 300.0, "k_messenger": 5e4, "m_contact": 1.0, "m_messenger": 0.5},
                 {"x": 100.0}],
    "droppers": [{"x": x, "upper": "messenger", "lower": "contact", "k": 1e5} for x in (10.0, 25.0, 40.0, 60.0, 75.0,
                                                                                       90.0)]
    + [{"x": 46.0, "upper": "stitch", "lower": "contact", "k": 1e5, "mass": 0.08, "clamp_upper": 0.065,
        "clamp_lower": 0.165, "law": "linear"}],
    "clamps": [{"x": 42.0, "a": "stitch", "b": "messenger", "k": 1e7},
               {"x": 58.0, "a": "stitch", "b": "messenger", "k": 1e7}],
    "masses": [{"x": 30.0, "wire": "contact", "m": 0.6}],
    "irregularity": {"seed": 3, "rms": 0.002, "wavelength_min": 2.0, "wavelength_max": 40.0, "n_waves": 200},
}

#: a valid example of every declared section and the loader a user's input goes through
EXAMPLES: dict[str, tuple[dict[str, Any], Callable[[Any], Any]]] = {
    "catenary.line_file": (LINE, lambda d: line_from_dict(d, LINES, "two_spans.toml")),
    "catenary.line": ({"kind": "stitched", "presag": 0.0005, "stitch": {"half_length": 9.0, "k_clamp": 1e7},
                       "irregularity": {"seed": 1, "psd": [[0.01, 1e-6], [0.5, 1e-8]], "dx": 0.05}},
                      lambda d: validate_line_section(d, LINES)),
    "catenary.train": ({"pantographs": ["reference2mass", "reference2mass"], "spacings": [200.0]},
                       models()["catenary"].sections["train"]),
    "catenary.quality": ({"system": "DC3kV", "fm_a": 0.00097, "fm_b": 110.0, "fm_b_lower": 80.0,
                          "sigma_ratio_max": 0.3, "stat_min_floor": 0.0, "loss_max_pct": 0.2, "nq_max_pct": 0.1,
                          "arc_min_duration": 0.0, "uplift_max": 0.12}, models()["catenary"].sections["quality"]),
}


def test_every_declared_section_has_an_example():
    """A new declared section gets an example here, so the generated tests below cover it."""
    assert sorted(sections()) == sorted(EXAMPLES)
    for example, load in EXAMPLES.values():
        load(copy.deepcopy(example))  # the example itself is legal


def _leaves(decl: Section, data: dict[str, Any], path: tuple[Any, ...] = ()) -> Iterator[tuple[tuple, Any, bool]]:
    """(path into the example, the declaration there, required) of every declared key: nested sections and the first
    item of a list of tables are walked; keys the example leaves out are visited too (set, not changed)."""
    keys = dict(decl.keys)
    keys.update({k: decl.prefixed[p] for k in data for p in decl.prefixed if k.startswith(p) and k not in decl.keys})
    for key, d in keys.items():
        here = (*path, key)
        if isinstance(d, Section) and isinstance(data.get(key), dict):
            yield here, d, key in decl.required
            yield from _leaves(d, data[key], here)
        elif isinstance(d, Items) and isinstance(d.of, Section) and data.get(key):
            yield here, d, key in decl.required
            for i, item in enumerate(data[key]):  # every row: a prefixed key or a default may appear in one only
                yield from _leaves(d.of, item, (*here, i))
        else:
            yield here, d, key in decl.required


def _set(data: dict[str, Any], path: tuple, value: Any, delete: bool = False) -> dict[str, Any]:
    out = copy.deepcopy(data)
    node = out
    for p in path[:-1]:
        node = node[p]
    if delete:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return out


def _bad_values(d: Any, current: Any) -> list[Any]:
    """Generated bad values for declaration `d` (the example's value `current`)."""
    if isinstance(d, Section):
        return ["text", 1.0, [1.0]]
    if isinstance(d, Items):
        bad: list[Any] = ["text", 1.0, True, {"a": 1}, [current[0] if current else None] * (d.max + 1)]
        if d.min > 0:
            bad.append([])
        if isinstance(d.of, Limit | tuple) and current:
            inner = d.of if isinstance(d.of, Limit) else d.of[0]
            for v in _bad_values(inner, current[0] if isinstance(d.of, Limit) else current[0][0]):
                row = copy.deepcopy(list(current))
                if isinstance(d.of, Limit):
                    row[0] = v
                else:
                    row[0] = [v, *list(row[0])[1:]]
                bad.append(row)
            if isinstance(d.of, tuple):
                bad.append([list(current[0])[:-1]])  # a short row
        return bad
    lim: Limit = d
    if lim.kind is bool:
        return [1, 0, "true", 1.0, None]
    if lim.kind is str:
        return [1.0, True, ["a"], None] + (["no-such-value"] if lim.choices is not None else [])
    bad = ["text", True, False, None, [1.0], {"a": 1.0}, math.nan, math.inf, -math.inf, 1 + 1j]
    if lim.lo is not None:
        bad.append(lim.lo - 1.0 - abs(lim.lo) if not lim.lo_open else lim.lo)
    if lim.hi is not None:
        bad += [lim.hi + 1.0 + abs(lim.hi) if not lim.hi_open else lim.hi, 1e300]
    if lim.kind is int:
        bad.append((lim.lo or 0) + 2.5)
    return bad


def _cases() -> Iterator[Any]:
    for name, (example, _) in EXAMPLES.items():
        sec = sections()[name]
        for path, d, required in _leaves(sec, example):
            yield pytest.param(name, path, d, required, id=f"{name}:{'.'.join(map(str, path))}")


@pytest.mark.parametrize("name, path, decl, required", list(_cases()))
def test_every_bad_value_of_every_key_is_an_error_naming_it(name, path, decl, required):
    """Every generated bad value of the key (and its absence, where it is required) is an MbsuiteError naming the key;
    a numpy scalar of the example's value is accepted."""
    example, load = EXAMPLES[name]
    key = str(path[-1]) if not isinstance(path[-1], int) else str(path[-2])
    node = example
    for p in path[:-1]:
        node = node[p]
    present = path[-1] in node
    current = node.get(path[-1]) if present else None
    tried = 0
    if required:
        with pytest.raises(MbsuiteError, match=rf"\b{key}\b") as err:
            load(_set(example, path, None, delete=True))
        assert "missing" in str(err.value)
        tried += 1
    for bad in _bad_values(decl, current if current is not None else ([] if isinstance(decl, Items) else None)):
        with pytest.raises(MbsuiteError) as err:
            load(_set(example, path, bad))
        assert key in str(err.value), (bad, str(err.value))
        tried += 1
    if isinstance(decl, Limit) and decl.kind in (float, int) and present and current is not None:
        for np_value in (np.float64(current), np.array(current)) if decl.kind is float else (np.int64(current),):
            load(_set(example, path, np_value))  # numpy users' numbers are numbers
    assert tried >= 1


def test_an_unknown_key_in_every_section_and_row_is_an_error_naming_it():
    for name, (example, load) in EXAMPLES.items():
        for path, d, _ in _leaves(sections()[name], example):
            try:
                _set(example, (*path, None), None)
            except (KeyError, IndexError, TypeError):
                continue  # the example leaves this table out
            if isinstance(d, Section):
                with pytest.raises(MbsuiteError, match="colour"):
                    load(_set(example, (*path, "colour"), 1.0))
            if isinstance(d, Items) and isinstance(d.of, Section):
                with pytest.raises(MbsuiteError, match="colour"):
                    load(_set(example, (*path, 0, "colour"), 1.0))
        with pytest.raises(MbsuiteError, match="colour"):
            load({**example, "colour": 1.0})


# --- JSON Schemas ---------------------------------------------------------------------------------------------------
def test_the_json_schemas_accept_every_shipped_scene_and_line_file():
    for name, spec in models().items():
        validator = jsonschema.Draft202012Validator(scene_schema(name))
        files = list(spec.scene_files().values())
        assert files, name
        for f in files:
            errors = [e.message for e in validator.iter_errors(tomllib.loads(f.read_text()))]
            assert not errors, (f, errors)
    line = jsonschema.Draft202012Validator(section_of(models()["catenary"].input_files["line_file"])
                                           .json_schema(top=True))
    for f in LINES.glob("*.toml"):
        assert not [e.message for e in line.iter_errors(tomllib.loads(f.read_text()))], f
    assert not list(line.iter_errors(LINE))


def test_the_json_schemas_refuse_what_the_loader_refuses():
    """Each generated bad value JSON can carry (no NaN, inf or complex) fails the line file's JSON Schema, as it fails
    the loader; the scene schema refuses an unknown section and an out-of-range parameter."""
    line = jsonschema.Draft202012Validator(sections()["catenary.line_file"].json_schema(top=True))
    n = 0
    for path, d, required in _leaves(sections()["catenary.line_file"], LINE):
        node = LINE
        for p in path[:-1]:
            node = node[p]
        current = node.get(path[-1])
        for bad in _bad_values(d, current if current is not None else ([] if isinstance(d, Items) else None)):
            if _json_can_carry(bad) and not (isinstance(d, Items) and isinstance(bad, list) and len(bad) > 1000):
                assert list(line.iter_errors(_set(LINE, path, bad))), (path, bad)
                n += 1
        if required:
            assert list(line.iter_errors(_set(LINE, path, None, delete=True))), path
    assert n > 300
    scene = jsonschema.Draft202012Validator(scene_schema("catenary"))
    assert list(scene.iter_errors({"model": "catenary", "colour": {}}))
    assert list(scene.iter_errors({"model": "catenary", "params": {"cw_tension": -1.0}}))


def _json_can_carry(v: Any) -> bool:
    try:
        json.dumps(v, allow_nan=False)
    except (TypeError, ValueError):
        return False
    return v is not None and not (isinstance(v, list) and any(x is None for x in v))


def test_the_shipped_schemas_and_input_tables_are_what_the_declarations_give():
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "write_schemas.py"), "--check"],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr


# --- every key reaches the run --------------------------------------------------------------------------------------
#: keys whose change is refused rather than read: (why, what the message says)
REFUSED = {
    ("wires", 0, "x0"): ("the contact wire starts the line at x = 0", r"x0 = 0.25 m; valid: 0"),
    ("wires", 1, "x1"): ("no wire ends beyond the contact wire", r"\['messenger'\] end beyond the contact wire"),
    ("wires", 2, "x0"): ("a clamp holds the stitch wire's end", r"clamp at x = 42.0 m lies off wire 'stitch'"),
    ("supports", 2, "x"): ("the last support is the contact wire's end", r"support at x = 100.25 m lies off wire"),
    ("clamps", 1, "x"): ("the clamp holds the stitch wire's end", r"clamp at x = 58.25 m lies off wire 'stitch'"),
}


def _fe(data: dict[str, Any]):
    line = line_from_dict(data, LINES, "two_spans.toml")
    line = dataclasses.replace(line, irregularity=irregularity.build(data["irregularity"], line.length))
    fe = assemble(CatenaryParams(line=line, element_length=0.5, x_end=line.length, window_start=10.0,
                                 window_end=90.0))
    return fe, line


def _moved(key: str, value: float) -> float:
    if key in ("x", "x0", "x1"):
        return value + 0.25
    return value * 1.05 if value else 0.1


def test_every_numeric_key_of_a_line_file_moves_the_fe_or_is_refused_naming_it():
    """Each numeric key of every row of the example line (positions by 0.25 m, the others by 5 %, zeros to a
    positive value): the assembled mass and stiffness matrices, static state or irregularity change, or the change
    is refused naming the key (`REFUSED`, with the reason)."""
    base_fe, base_line = _fe(LINE)

    def signature(fe, line) -> np.ndarray:
        K = fe.K0 + fe.Kd
        return np.concatenate([[fe.M.sum(), abs(fe.M).sum(), K.sum(), abs(K).sum(), np.abs(fe.w0_full).sum(),
                                float(fe.x.sum()), float(np.abs(fe.T0).sum())],
                               line.irregularity.r[:50] if line.irregularity is not None else []])

    base = signature(base_fe, base_line)
    moved, failed = 0, []
    for path, d, _ in _leaves(sections()["catenary.line_file"], LINE):
        node = LINE
        for p in path[:-1]:
            node = node[p]
        if not isinstance(d, Limit) or d.kind not in (float, int) or path[-1] not in node:
            continue
        if path[-1] == "seed":
            new = node[path[-1]] + 1
        elif d.kind is int:
            new = node[path[-1]] + 7
        else:
            new = _moved(path[-1], float(node[path[-1]]))
        data = _set(LINE, path, new)
        if path in REFUSED:
            with pytest.raises(MbsuiteError, match=REFUSED[path][1]):
                _fe(data)
            continue
        try:
            sig = signature(*_fe(data))
        except MbsuiteError as exc:
            failed.append(f"{'.'.join(map(str, path))} = {new} refused: {exc}")
            continue
        if np.array_equal(sig, base):
            failed.append(f"{'.'.join(map(str, path))} = {new} changed nothing")
        moved += 1
    assert not failed, "\n".join(failed)
    assert moved > 40
    # the tension segments' rows too
    for j in range(3):
        seg = copy.deepcopy(LINE["wires"][1]["tension_segments"])
        seg[0][j] = seg[0][j] + (0.5 if j < 2 else 500.0)
        assert not np.array_equal(signature(*_fe(_set(LINE, ("wires", 1, "tension_segments"), seg))), base), j


def test_a_numpy_users_line_reads_the_same():
    """np.float32 / np.int64 / 0-d arrays in a line dict give the line of the Python numbers (float32 as the decimal
    the user wrote)."""
    data = copy.deepcopy(LINE)
    data["wires"][0]["tension"] = np.float32(20000.0)
    data["supports"][1]["k_contact"] = np.array(300.0)
    data["irregularity"]["seed"] = np.int64(3)
    assert line_from_dict(data, LINES, "a") == line_from_dict(LINE, LINES, "a")
