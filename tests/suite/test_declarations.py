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
from mbsuite.schema import Items, Section, bad_values, leaves

ROOT = Path(__file__).resolve().parents[2]
LINES = ROOT / "mbsuite" / "models" / "catenary" / "lines"

#: how a user's input reaches each declared section: its loader (a line file's reader, a scene section's validator)
LOADERS: dict[str, Callable[[Any], Any]] = {
    "catenary.line_file": lambda d: line_from_dict(d, LINES, "two_spans.toml"),
    "catenary.line": lambda d: validate_line_section(d, LINES),
    "catenary.train": models()["catenary"].sections["train"],
    "catenary.quality": models()["catenary"].sections["quality"],
    "catenary.aerodynamics": models()["catenary"].sections["aerodynamics"],
    "drives.design": models()["drives"].sections["design"],
    "catenary.pantograph_lumped": lambda d: models()["catenary"].sections["pantograph"]({"params": d}),
    "catenary.pantograph_transfer": lambda d: models()["catenary"].sections["pantograph"]({"params": d}),
}
EXAMPLES = {name: (sec.example, LOADERS[name]) for name, sec in sections().items()}
LINE = sections()["catenary.line_file"].example


def test_every_declared_section_has_an_example_and_a_loader():
    """A new declared section declares an example and gets its loader here, so the generated tests below cover it."""
    assert sorted(sections()) == sorted(LOADERS)
    assert all(sec.example is not None for sec in sections().values())
    for example, load in EXAMPLES.values():
        load(copy.deepcopy(example))  # the example itself is legal


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
    return [v for _, v in bad_values(d, current)]


def _cases() -> Iterator[Any]:
    for name, (example, _) in EXAMPLES.items():
        sec = sections()[name]
        for path, d, required in leaves(sec, example):
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
        for path, d, _ in leaves(sections()[name], example):
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
    for path, d, required in leaves(sections()["catenary.line_file"], LINE):
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
    for path, d, _ in leaves(sections()["catenary.line_file"], LINE):
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


# --- the scene sections every model has: [params], [input], [solver], [effects] -------------------------------------
def _scene_keys() -> Iterator[Any]:
    from mbsuite.settings import SOLVER_LIMITS, SOLVER_WORDS

    for name, spec in models().items():
        for f in dataclasses.fields(spec.params_cls):
            if "limit" in f.metadata:
                yield pytest.param(name, "params", f.name, f.metadata["limit"], id=f"{name}:params.{f.name}")
        for itype, keys in spec.inputs.items():
            for k, d in keys.items():
                if isinstance(d, Limit | Items):
                    yield pytest.param(name, "input", k, d, id=f"{name}:input.{itype}.{k}", marks=())
        for k, d in {**SOLVER_LIMITS, **SOLVER_WORDS}.items():
            yield pytest.param(name, "solver", k, d, id=f"{name}:solver.{k}")
        for k, e in spec.effects.items():
            yield pytest.param(name, "effects", k, e, id=f"{name}:effects.{k}")


@pytest.mark.parametrize("model, section, key, decl", list(_scene_keys()))
def test_every_bad_value_of_every_scene_key_is_an_error_naming_it(model, section, key, decl):
    """Every model's [params], [input], [solver] and [effects] keys, from their declarations: each generated bad value
    is a SceneError or ParameterError naming `<section>.<key>` or the key, loaded as a scene dictionary."""
    from mbsuite.registry import Effect
    from mbsuite.scenes import scene_from_dict

    spec = models()[model]
    base: dict[str, Any] = {"model": model}
    if section == "input":
        base["input"] = {"type": next(t for t, keys in spec.inputs.items() if key in keys)}
    if isinstance(decl, Effect):
        bad = ["no-such-value", 1.5, [1], None] + ([1, 0] if any(isinstance(c, bool) for c in decl.choices) else [])
    else:
        bad = [v for label, v in bad_values(decl, None) if label not in ("too long",)]
    for value in bad:
        data = copy.deepcopy(base)
        data.setdefault(section, {})[key] = value
        with pytest.raises(MbsuiteError) as err:
            scene_from_dict(data)
        assert key in str(err.value), (value, str(err.value))


@pytest.mark.slow
def test_the_declared_robustness_corpus_ends_in_clear_errors(tmp_path):
    """The robustness corpus's area generated from the declarations (`scripts/robustness_corpus.py --area declared`:
    every declared key written into a file as a user writes one, each bad value, ~1,460 attempts, ~20 min on 2
    cores): every attempt ends in one clear error line naming the key."""
    out = tmp_path / "corpus.json"
    run = subprocess.run([sys.executable, str(ROOT / "scripts" / "robustness_corpus.py"), "--area", "declared",
                          "--workers", "2", "--json-out", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-2000:]
    report = json.loads(out.read_text())
    bad = [(o["name"], o["outcome"], o["last_line"][:200]) for o in report["outcomes"] if o["outcome"] != "clear"]
    assert report["attempts"] > 1000 and not bad, bad[:20]


def test_a_profile_too_fine_or_too_many_waves_is_refused_before_anything_is_allocated():
    """The size guards of an irregularity, by hand: dx = 1 mm over 100 km is 1e8 grid points (> 2e7, 800 MB); 1e5
    waves on 1.2e4 points (dx = 0.05 m over 600 m) is 1.2e9 multiply-adds (within 2e10), on 1e6 points (50 km) 1e11
    (refused); each error names the input and the estimate."""
    from mbsuite.errors import SceneError

    rand = {"seed": 1, "rms": 0.001, "wavelength_min": 1.0, "wavelength_max": 50.0}
    d = irregularity.SECTION.check({**rand, "dx": 0.001}, "t")
    with pytest.raises(SceneError, match=r"dx = 0.001 m over the line's 100000 m is 100,000,001 grid points"):
        irregularity.size_of(d, 1e5, "t")
    d = irregularity.SECTION.check({**rand, "n_waves": 100_000}, "t")
    assert irregularity.size_of(d, 600.0, "t") == 12_001
    with pytest.raises(SceneError, match=r"n_waves = 100,000 on 1,000,001 grid points .* 1e\+11 multiply-adds"):
        irregularity.size_of(d, 5e4, "t")
