"""Scenes: a TOML file naming a model, the effects it needs, parameter overrides, the input, outputs and solver
settings.

```toml
model = "pantograph"
description = "Eppinger's lab test: ram attached, linear cylinder"
[effects]            # only what the scene asks for is built; omitted effects take the model's defaults
cylinder = "linear"
[params]             # overrides of the model's parameter dataclass (SI units)
ks = 180000.0
[input]
type = "sine"
amplitude = 1.85e-3
frequency = 4.25
[outputs]
signals = ["F1", "F2", "HD", "y_d"]
[solver]
engine = "mujoco"    # or "reference" (hand-derived numpy/scipy path)
integrator = "implicitfast"
timestep = 5e-4
duration = 10.0
[accuracy]           # optional: tolerances of headline outputs (their units), replacing the model's declared ones
F1_amp = 2e-5          # m
```

`load_scene(x)` accepts a path to a TOML file, a model name (its default scene) or `model/scene` (a shipped scene).
Unknown keys, effects, parameters, input types and engines raise `SceneError` listing the valid ones, and say where
the value came from: the file, the dictionary, Python (`Scene.replace`) or the command line (`origin=`).

Values are taken as a numpy user passes them (`plain`): every real number type (`mbsuite.limits.real`: numpy scalars
and 0-d arrays, `Fraction`, `Decimal`) is the Python number it holds, tuples and arrays are lists. A string is never
split into a list: where a list is meant (`outputs.signals`, list-valued parameters such as the catenary's
`dropper_positions`, a model section's lists; a list of rows, a catenary's `windows`) a string is an error, except
`replace(outputs="F1")`, one signal.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .errors import MbsuiteError, ParameterError, SceneError
from .limits import Limit, real
from .registry import ModelSpec, get_model, models
from .schema import Items, check_value, toml_error
from .settings import DEFAULT_MAX_STEPS, INTEGRATORS, SCIPY_METHODS, SOLVER_LIMITS, SolverSettings  # noqa: F401 (the [solver] section's names)
from .trust import perturbation
from .trust.estimate import check_tolerances, declared

TOP_KEYS = ("model", "name", "description", "effects", "params", "input", "outputs", "solver", "accuracy")
MAX_SCENE_BYTES = 1_000_000

#: where a value set through `Scene.replace` came from, unless the caller says (the CLI: "on the command line (--set)")
PYTHON_ORIGIN = "set in Python (Scene.replace)"

SOLVER_KEYS = tuple(f.name for f in dataclasses.fields(SolverSettings))


@dataclass(frozen=True)
class Scene:
    """A validated scene. `effects` is complete (defaults filled in); `params` holds only the overrides."""

    model: str
    name: str = ""
    description: str = ""
    effects: Mapping[str, Any] = field(default_factory=dict)
    params: Mapping[str, Any] = field(default_factory=dict)
    input: Mapping[str, Any] = field(default_factory=dict)
    outputs: tuple[str, ...] = ()
    solver: SolverSettings = field(default_factory=SolverSettings)
    source: str | None = None
    sections: Mapping[str, Any] = field(default_factory=dict)  # the model's own extra sections (ModelSpec.sections)
    accuracy: Mapping[str, float] = field(default_factory=dict)  # [accuracy]: headline -> tolerance (trust.estimate)

    @property
    def spec(self) -> ModelSpec:
        """The model's declaration (ModelSpec)."""
        return get_model(self.model)

    def build_params(self):
        """The model's parameter dataclass with this scene's overrides applied (and validated by the dataclass); a
        model whose sections change its parameters builds them itself (`ModelSpec.params_builder`)."""
        if self.spec.params_builder is not None:
            return self.spec.params_builder(self)
        return self.spec.params_cls(**dict(self.params))

    def to_dict(self) -> dict[str, Any]:
        """The scene as a plain dictionary (the TOML's structure, every default resolved)."""
        return {
            "model": self.model,
            "name": self.name,
            "description": self.description,
            "effects": dict(self.effects),
            "params": dict(self.params),
            "input": dict(self.input),
            "outputs": {"signals": list(self.outputs)},
            "solver": dataclasses.asdict(self.solver),
            **({"accuracy": dict(self.accuracy)} if self.accuracy else {}),
            **{k: copy.deepcopy(v) for k, v in self.sections.items()},
        }

    def replace(self, *, origin: str | None = None, **sections: Mapping[str, Any] | Any) -> Scene:
        """A new validated scene with sections merged: `scene.replace(effects={"gravity": False}, solver={"timestep":
        1e-4})`. Scalars (`name`, `description`) replace; mappings are merged key by key; `outputs` may be one
        signal name or a sequence of them. `origin` says in error messages where the new values came from (default
        `PYTHON_ORIGIN`; the command line passes e.g. "on the command line (--speed)"); the values kept from the
        scene's file are still blamed on the file."""
        d = self.to_dict()
        valid = [*TOP_KEYS[1:], *self.spec.sections]
        changed: dict[str, frozenset[str] | None] = {}
        for key, val in sections.items():
            if key not in valid:
                raise SceneError(f"cannot replace scene section {key!r}; valid sections: {valid}")
            if key == "outputs" and not isinstance(val, Mapping):
                val = {"signals": [val] if isinstance(val, str) else plain(val)}
            if isinstance(val, Mapping):
                merged = dict(d.get(key) or {})
                merged.update(val)
                d[key] = merged
                changed[key] = frozenset(str(k) for k in val)
            else:
                d[key] = val
                changed[key] = None
        return scene_from_dict(d, source=self.source, origin=origin or PYTHON_ORIGIN, changed=changed)


@dataclass(frozen=True)
class Where:
    """Where a scene's values came from, as error messages say it: `base` for the file's (or dictionary's) values,
    `origin` for the keys in `changed` (section -> the keys set there; None: the whole section)."""

    base: str = ""
    origin: str = ""
    changed: Mapping[str, frozenset[str] | None] = field(default_factory=dict)

    def __call__(self, section: str | None = None, key: str | None = None) -> str:
        """The phrase (with a leading space) for `section.key`, or for the section as a whole (key None: names the
        keys set elsewhere too, since a check across keys may involve them)."""
        if section in self.changed:
            keys = self.changed[section]
            if keys is None or key in keys:
                return f" {self.origin}"
            if key is None and keys:
                names = ", ".join(f"{section}.{k}" for k in sorted(keys))
                return f"{self.base} with {names} {self.origin}"
        return self.base

    def any_of(self, section: str, keys: list[str]) -> str:
        """The phrase for a list of bad keys of `section`: the origin if any of them was set there."""
        return next((self(section, k) for k in keys if self(section, k) != self.base), self.base)


def _told(exc: MbsuiteError, where: str) -> MbsuiteError:
    """`exc` (an error of a check that does not know the origin) with `where` appended in parentheses."""
    return type(exc)(f"{exc} ({where.strip()})") if where else exc


def plain(value: Any) -> Any:
    """`value` as plain Python data, in lists and tables too: every real number type (`mbsuite.limits.real`) as the
    int or float it holds, numpy bools as bools, other numpy scalars (strings) as their Python value, tuples and
    arrays of any dimension as lists. Strings stay strings (never a list of characters)."""
    if isinstance(value, np.ndarray) and value.ndim > 0:
        return [plain(v) for v in value]
    number = real(value)
    if number is not None:
        return number
    if isinstance(value, np.generic | np.ndarray):
        return value.item() if isinstance(value, np.generic) else value[()].item()
    if isinstance(value, Mapping):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    return value


def _list_field(f: dataclasses.Field) -> bool:
    """True if dataclass field `f` holds a list (its type says list/tuple, or its default factory makes one)."""
    if f.default_factory is not dataclasses.MISSING and isinstance(f.default_factory(), list | tuple):
        return True
    return str(f.type).startswith(("list", "tuple"))


def _param_value(spec: ModelSpec, key: str, value: Any, where: str) -> Any:
    """A `[params]` value checked against its field: a list-valued field takes a list of numbers (a string is an
    error, not a list of characters), any other field a single value within its declared `Limit`."""
    f = next(f for f in dataclasses.fields(spec.params_cls) if f.name == key)
    lim = f.metadata.get("limit")
    if value is None and f.default is None:
        return None  # unset: the model derives it
    if _list_field(f):
        if isinstance(value, str):
            raise SceneError(f"parameter {key} = {value!r}{where} is a string, but a list of numbers is meant: "
                             f"{key} = [x1, x2, ...] (SI units)")
        if str(f.type).startswith("list[list"):  # a list of rows of numbers (a catenary's windows)
            if not isinstance(value, list) or any(not isinstance(r, list) or any(real(x) is None for x in r)
                                                  for r in value):
                raise SceneError(f"parameter {key} = {value!r}{where} must be a list of lists of numbers "
                                 f"({key} = [[a, b], ...], SI units)")
            return [[float(real(x)) for x in r] for r in value]
        if not isinstance(value, list) or any(real(x) is None for x in value):
            raise SceneError(f"parameter {key} = {value!r}{where} must be a list of numbers (SI units)")
        return [float(real(x)) if "float" in str(f.type) else real(x) for x in value]
    if isinstance(value, list | Mapping):
        raise SceneError(f"parameter {key} = {value!r}{where} must be a single value (SI units), not a "
                         f"{'list' if isinstance(value, list) else 'table'}")
    if lim is not None:
        return lim.check(f"{spec.name} parameter {key}", value, ParameterError, where)
    if isinstance(value, str) or real(value) is None:
        raise SceneError(f"parameter {key} = {value!r}{where} must be a number (SI units)")
    if not math.isfinite(real(value)):
        raise SceneError(f"parameter {key} = {value!r}{where} must be a finite number (SI units)")
    return real(value)


def scene_from_dict(data: Mapping[str, Any], source: str | None = None, *, origin: str | None = None,
                    changed: Mapping[str, frozenset[str] | None] | None = None) -> Scene:
    """Validate a scene dictionary against its model's spec. Errors name the offending key and list valid ones, and
    say where the value came from: "in SOURCE" (the file; "in the scene dictionary" without one), or `origin` (a
    phrase such as "set in Python" or "on the command line (--set)") for the keys in `changed` (section -> keys,
    None: the whole section; without `changed`, every value). Values are taken as `plain` makes them.

    The checks run in this order, one step each: the model, the shape of the top-level keys, the model's own sections,
    effects, params, input, outputs, solver (then the values the scene's effects leave unused), the accuracy
    tolerances, and the parameters and accuracy names across fields."""
    base = f" in {source}" if source else " in the scene dictionary"
    if origin and changed is None:
        base, changed = f" {origin}", {}
    where = Where(base, origin or "", dict(changed or {}))
    data = {k: plain(v) for k, v in copy.deepcopy(dict(data)).items()}
    spec = _model_of(data, where)
    _check_top_keys(data, spec, where)
    extra = _model_sections(data, spec, source, where)
    effects = _effects_of(data, spec, where)
    params = _params_of(data, spec, where)
    inp = _input_of(data, spec, where)
    signals = _outputs_of(data, spec, where)
    solver = _solver_of(data, spec, where)
    spec.refuse_unused(effects, None, params, data.get("input") or {}, inp, extra, where)

    scene = Scene(
        model=spec.name,
        name=str(data.get("name") or ""),
        description=str(data.get("description") or ""),
        effects=effects,
        params=dict(params),
        input=inp,
        outputs=signals,
        solver=solver,
        source=source,
        sections=extra,
        accuracy=check_tolerances(data.get("accuracy") or {}, where("accuracy")),
    )
    _check_across_fields(scene, spec, where)
    return scene


def _model_of(data: dict[str, Any], where: Where) -> ModelSpec:
    """The spec of the model the scene names."""
    if "model" not in data:
        raise SceneError(f"scene{where()} does not name a model; valid models: {sorted(models())}")
    if not isinstance(data["model"], str):
        raise SceneError(f"model = {data['model']!r}{where('model')} must be a model name; valid models: "
                         f"{sorted(models())}")
    return get_model(data["model"])


def _check_top_keys(data: dict[str, Any], spec: ModelSpec, where: Where) -> None:
    """Strings where strings are meant, tables where sections are, and no unknown top-level key."""
    for key in ("name", "description"):
        if key in data and not isinstance(data[key], str):
            raise SceneError(f"{key} = {data[key]!r}{where(key)} must be a string")
    for key in ("effects", "params", "input", "solver", "accuracy", *spec.sections):
        if key in data and not isinstance(data[key], Mapping):
            raise SceneError(f"{key} = {data[key]!r}{where(key)} must be a table ([{key}] section with key = value "
                             "lines)")
    if "outputs" in data and not isinstance(data["outputs"], Mapping | list):
        raise SceneError(f"outputs = {data['outputs']!r}{where('outputs')} must be a table with signals = [...]")
    unknown = sorted(set(data) - set(TOP_KEYS) - set(spec.sections))
    if unknown:
        raise SceneError(f"unknown scene key(s) {unknown}{where()}; valid keys: {[*TOP_KEYS, *spec.sections]}")


def _model_sections(data: dict[str, Any], spec: ModelSpec, source: str | None, where: Where) -> dict[str, Any]:
    """The model's own sections (`ModelSpec.sections`), each through its validator."""
    extra = {}
    for k in spec.sections:
        if k in data:
            try:
                check = spec.sections[k]
                if getattr(check, "wants_base", False):  # a section naming files: relative to the scene's folder
                    extra[k] = check(data[k], base=Path(source).parent if source else None)
                else:
                    extra[k] = check(data[k])
            except MbsuiteError as exc:
                raise _told(exc, where(k)) from None
    return extra


def _effects_of(data: dict[str, Any], spec: ModelSpec, where: Where) -> dict[str, Any]:
    """Every effect of the model: the scene's value, else its default, each checked."""
    effects_in = data.get("effects") or {}
    bad = sorted(set(effects_in) - set(spec.effects))
    if bad:
        raise SceneError(
            f"unknown effect(s) {bad} for model '{spec.name}'{where.any_of('effects', bad)}; valid effects: "
            f"{sorted(spec.effects)}")
    effects = {}
    for name, eff in spec.effects.items():
        effects[name] = eff.check(name, effects_in.get(name, eff.default), where("effects", name))
    return effects


def _params_of(data: dict[str, Any], spec: ModelSpec, where: Where) -> dict[str, Any]:
    """The `[params]` overrides, each a known parameter checked against its field (`_param_value`)."""
    params = dict(data.get("params") or {})
    valid_params = spec.param_names()
    bad = sorted(set(params) - set(valid_params))
    if bad:
        raise SceneError(f"unknown parameter(s) {bad} for model '{spec.name}'{where.any_of('params', bad)}; "
                         f"valid parameters: {valid_params}")
    for k, v in params.items():
        params[k] = _param_value(spec, k, v, where("params", k))
    return params


def _input_of(data: dict[str, Any], spec: ModelSpec, where: Where) -> dict[str, Any]:
    """The `[input]`: its type (default: the model's first), its declared keys checked with their defaults resolved,
    every other value at least finite and not a table."""
    inp = dict(data.get("input") or {})
    if spec.inputs:
        itype = inp.get("type", next(iter(spec.inputs)))
        if not isinstance(itype, str) or itype not in spec.inputs:
            raise SceneError(f"input type {itype!r}{where('input', 'type')} unknown for '{spec.name}'; valid types: "
                             f"{list(spec.inputs)}")
        bad = sorted(set(inp) - set(spec.inputs[itype]) - {"type"})
        if bad:
            raise SceneError(
                f"unknown input key(s) {bad} for input type {itype!r}{where.any_of('input', bad)}; valid keys: "
                f"{sorted(spec.inputs[itype])}")
        inp["type"] = itype
        _input_values(inp, spec.inputs[itype], where)
    for key, v in inp.items():  # keys without a declared Limit: at least finite, never a nested table
        if isinstance(v, float) and not math.isfinite(v):
            raise SceneError(f"input.{key} = {v!r}{where('input', key)} must be a finite number")
        if isinstance(v, Mapping):
            raise SceneError(f"input.{key}{where('input', key)} must be a value, not a table")
    return inp


def _input_values(inp: dict[str, Any], decls: Mapping[str, Any], where: Where) -> None:
    """The input's declared keys in place: lists of items checked, limited values checked or set to their default."""
    for key, decl in decls.items():
        if isinstance(decl, Items):
            if key in inp:
                inp[key] = [list(r) if isinstance(r, tuple) else r for r in
                            check_value(decl, f"input.{key}", inp[key], f"[input]{where('input', key)}",
                                        SceneError)]
            continue
        if not isinstance(decl, Limit):
            continue
        if key in inp:
            inp[key] = decl.check(f"input.{key}", inp[key], SceneError, where('input', key))
        elif decl.has_default:
            inp[key] = decl.default  # resolved defaults are part of the scene: shown in every output
        if decl.kind is float and decl.choices is None and isinstance(inp.get(key), float):
            inp[key] = perturbation.value(inp[key], decl, f"input.{key}")  # unchanged outside the stability check


def _outputs_of(data: dict[str, Any], spec: ModelSpec, where: Where) -> tuple[str, ...]:
    """The output signals (`[outputs] signals`, or a plain list), each one of the model's."""
    outputs = data.get("outputs") or {}
    if isinstance(outputs, Mapping):
        bad = sorted(set(outputs) - {"signals"})
        if bad:
            raise SceneError(f"unknown key(s) {bad} in [outputs]{where.any_of('outputs', bad)}; valid keys: "
                             "['signals']")
        signals = outputs.get("signals", tuple(spec.outputs))
    else:
        signals = outputs
    w = where("outputs", "signals")
    if isinstance(signals, str):
        raise SceneError(f"outputs.signals = {signals!r}{w} is a string, but a list of signal names is meant: "
                         f"signals = [{signals!r}]; valid signals: {list(spec.outputs)}")
    if not isinstance(signals, list | tuple) or not all(isinstance(x, str) for x in signals):
        raise SceneError(f"outputs.signals = {signals!r}{w} must be a list of signal names; valid signals: "
                         f"{list(spec.outputs)}")
    signals = tuple(signals)
    bad = [s for s in signals if s not in spec.outputs]
    if bad:
        raise SceneError(f"unknown output signal(s) {bad}{w}; valid signals: {list(spec.outputs)}")
    return signals


def _solver_of(data: dict[str, Any], spec: ModelSpec, where: Where) -> SolverSettings:
    """The `[solver]` over the model's defaults (a path's label names its key), checked against its engines."""
    solver_in = dict(data.get("solver") or {})
    bad = sorted(set(solver_in) - set(SOLVER_KEYS))
    if bad:
        raise SceneError(f"unknown solver key(s) {bad}{where.any_of('solver', bad)}; valid keys: {list(SOLVER_KEYS)}")
    if isinstance(solver_in.get("engine"), str):
        solver_in["engine"] = spec.path_key(solver_in["engine"])  # a path's label ("equations") names its key
    solver = dataclasses.replace(spec.solver, **solver_in)
    return solver.check(spec.engines, lambda key=None: where("solver", key))


def _check_across_fields(scene: Scene, spec: ModelSpec, where: Where) -> None:
    """The checks across fields: the parameter dataclass validates itself (d1 <= l1 etc.), and every `[accuracy]`
    name is a headline of this scene."""
    try:
        scene.build_params()  # parameter dataclasses validate themselves across fields (d1 <= l1 etc.)
    except MbsuiteError as exc:
        raise _told(exc, where("params")) from None
    if scene.accuracy:
        if spec.accuracy is None:
            raise SceneError(f"[accuracy]{where('accuracy')}: model '{spec.name}' declares no headline outputs")
        try:
            declared(scene)  # every name a headline of this scene
        except MbsuiteError as exc:
            raise _told(exc, where("accuracy")) from None


def load_scene(ref: str | Path) -> Scene:
    """Load a scene from a TOML path, a model name (its default scene) or `model/scene` (a shipped scene)."""
    p = Path(ref)
    if p.is_dir():
        raise SceneError(f"scene {p} is a directory, not a scene file (give a .toml file, a model name or "
                         "model/scene)")
    if p.suffix == ".toml" or p.is_file():
        if not p.is_file():
            raise SceneError(f"scene file not found: {p}")
        try:
            raw = p.read_bytes()
        except OSError as exc:
            raise SceneError(f"cannot read scene file {p}: {exc.strerror or exc}") from exc
        if len(raw) > MAX_SCENE_BYTES:
            raise SceneError(f"scene file {p} is {len(raw)} bytes; a scene is at most {MAX_SCENE_BYTES} bytes")
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise SceneError(f"scene file {p} is not UTF-8 text (byte {exc.start}): TOML files are UTF-8") from exc
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise SceneError(f"scene file {p} is not valid TOML: {toml_error(exc, text)}") from exc
        except RecursionError as exc:
            raise SceneError(f"scene file {p} nests arrays or tables too deeply to be a scene") from exc
        data.setdefault("name", p.stem)
        return scene_from_dict(data, source=str(p))
    text = str(ref)
    model, _, scene_name = text.partition("/")
    spec = get_model(model)
    files = spec.scene_files()
    scene_name = scene_name or spec.default_scene
    if scene_name not in files and scene_name in spec.moved_scenes:
        new = spec.moved_scenes[scene_name]
        warnings.warn(f"scene '{model}/{scene_name}' is now '{new}'; load it by that name (the old name will go)",
                      DeprecationWarning, stacklevel=2)
        return load_scene(new)
    if scene_name not in files:
        raise SceneError(f"model '{model}' has no scene '{scene_name}'; shipped scenes: {sorted(files)}")
    return load_scene(files[scene_name])


def shipped_scenes() -> dict[str, list[str]]:
    """Every model's shipped scenes, by model."""
    return {name: sorted(spec.scene_files()) for name, spec in models().items()}
