"""Scenes: a TOML file naming a model, the effects it needs, parameter overrides, the input, outputs and solver
settings.

```toml
model = "pantograph"
description = "Eppinger's lab test: ram attached, linear cylinder"
[effects]            # only what the scene asks for is built; omitted effects take the model's defaults
cylinder = "linear"
[params]             # overrides of the model's parameter dataclass (SI units)
k_s = 180000.0
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
Unknown keys, effects, parameters, input types and engines raise `SceneError` listing the valid ones.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import perturbation
from .accuracy import check_tolerances, declared
from .errors import SceneError
from .limits import Limit
from .registry import ModelSpec, get_model, models
from .solver import DEFAULT_MAX_STEPS, INTEGRATORS, SCIPY_METHODS, SOLVER_LIMITS, SolverSettings  # noqa: F401 (the [solver] section's names)

TOP_KEYS = ("model", "name", "description", "effects", "params", "input", "outputs", "solver", "accuracy")
MAX_SCENE_BYTES = 1_000_000




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
    accuracy: Mapping[str, float] = field(default_factory=dict)  # [accuracy]: headline -> tolerance (mbsuite.accuracy)

    @property
    def spec(self) -> ModelSpec:
        """The model's declaration (ModelSpec)."""
        return get_model(self.model)

    def build_params(self):
        """The model's parameter dataclass with this scene's overrides applied (and validated by the dataclass)."""
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

    def replace(self, **sections: Mapping[str, Any] | Any) -> Scene:
        """A new validated scene with sections merged: `scene.replace(effects={"gravity": False}, solver={"timestep":
        1e-4})`.
        Scalars (`name`, `description`) replace; mappings are merged key by key."""
        d = self.to_dict()
        valid = [*TOP_KEYS[1:], *self.spec.sections]
        for key, val in sections.items():
            if key not in valid:
                raise SceneError(f"cannot replace scene section {key!r}; valid sections: {valid}")
            if key == "outputs" and not isinstance(val, Mapping):
                val = {"signals": [val] if isinstance(val, str) else list(val)}
            if isinstance(val, Mapping):
                merged = dict(d.get(key) or {})
                merged.update(val)
                d[key] = merged
            else:
                d[key] = val
        changed = ", ".join(f"[{k}]" for k in sections)
        origin = f"{self.source} (with overrides of {changed})" if self.source else f"the overrides of {changed}"
        return scene_from_dict(d, source=self.source, origin=origin)


def plain(value: Any) -> Any:
    """`value` with numpy scalars and 0-d arrays as Python numbers (bools, ints, floats), in lists and tables too: what
    a numpy user passes is taken as the number it holds."""
    if isinstance(value, np.generic) or (isinstance(value, np.ndarray) and value.ndim == 0):
        return value.item()
    if isinstance(value, Mapping):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    return value


def scene_from_dict(data: Mapping[str, Any], source: str | None = None, *, origin: str | None = None) -> Scene:
    """Validate a scene dictionary against its model's spec. Errors name the offending key and list valid ones, and
    where the value came from (`origin`, default `source`). Numpy scalars and 0-d arrays count as the numbers they
    hold."""
    where = f" in {origin or source}" if (origin or source) else ""
    data = {k: plain(v) for k, v in copy.deepcopy(dict(data)).items()}
    if "model" not in data:
        raise SceneError(f"scene{where} does not name a model; valid models: {sorted(models())}")
    if not isinstance(data["model"], str):
        raise SceneError(f"model = {data['model']!r}{where} must be a model name; valid models: {sorted(models())}")
    spec = get_model(data["model"])
    for key in ("name", "description"):
        if key in data and not isinstance(data[key], str):
            raise SceneError(f"{key} = {data[key]!r}{where} must be a string")
    for key in ("effects", "params", "input", "solver", "accuracy", *spec.sections):
        if key in data and not isinstance(data[key], Mapping):
            raise SceneError(f"{key} = {data[key]!r}{where} must be a table ([{key}] section with key = value lines)")
    if "outputs" in data and not isinstance(data["outputs"], Mapping | list | tuple):
        raise SceneError(f"outputs = {data['outputs']!r}{where} must be a table with signals = [...]")
    unknown = sorted(set(data) - set(TOP_KEYS) - set(spec.sections))
    if unknown:
        raise SceneError(f"unknown scene key(s) {unknown}{where}; valid keys: {[*TOP_KEYS, *spec.sections]}")
    extra = {k: spec.sections[k](data[k]) for k in spec.sections if k in data}

    effects_in = data.get("effects") or {}
    if not isinstance(effects_in, Mapping):
        raise SceneError(f"[effects]{where} must be a table")
    bad = sorted(set(effects_in) - set(spec.effects))
    if bad:
        raise SceneError(
            f"unknown effect(s) {bad} for model '{spec.name}'{where}; valid effects: {sorted(spec.effects)}")
    effects = {}
    for name, eff in spec.effects.items():
        effects[name] = eff.check(name, effects_in.get(name, eff.default))

    params = data.get("params") or {}
    valid_params = spec.param_names()
    bad = sorted(set(params) - set(valid_params))
    if bad:
        raise SceneError(f"unknown parameter(s) {bad} for model '{spec.name}'{where}; valid parameters: {valid_params}")
    for k, v in params.items():
        if isinstance(v, bool) or not isinstance(v, int | float | str | list):
            raise SceneError(f"parameter {k!r}{where} must be a number (SI units), got {v!r}")
        if isinstance(v, float) and not math.isfinite(v):
            raise SceneError(f"parameter {k} = {v!r}{where} must be a finite number (SI units)")

    inp = dict(data.get("input") or {})
    if spec.inputs:
        itype = inp.get("type", next(iter(spec.inputs)))
        if not isinstance(itype, str) or itype not in spec.inputs:
            raise SceneError(f"input type {itype!r}{where} unknown for '{spec.name}'; valid types: {list(spec.inputs)}")
        bad = sorted(set(inp) - set(spec.inputs[itype]) - {"type"})
        if bad:
            raise SceneError(
                f"unknown input key(s) {bad} for input type {itype!r}{where}; valid keys: {sorted(spec.inputs[itype])}"
            )
        inp["type"] = itype
        for key, decl in spec.inputs[itype].items():
            if not isinstance(decl, Limit):
                continue
            if key in inp:
                inp[key] = decl.check(f"input.{key}{where}", inp[key], SceneError)
            elif decl.has_default:
                inp[key] = decl.default  # resolved defaults are part of the scene: shown in every output
            if decl.kind is float and decl.choices is None and isinstance(inp.get(key), float):
                inp[key] = perturbation.value(inp[key], decl, f"input.{key}")  # unchanged outside the stability check
    for key, v in inp.items():  # keys without a declared Limit: at least finite, never a nested table
        if isinstance(v, float) and not math.isfinite(v):
            raise SceneError(f"input.{key} = {v!r}{where} must be a finite number")
        if isinstance(v, Mapping):
            raise SceneError(f"input.{key}{where} must be a value, not a table")

    outputs = data.get("outputs") or {}
    if isinstance(outputs, Mapping):
        bad = sorted(set(outputs) - {"signals"})
        if bad:
            raise SceneError(f"unknown key(s) {bad} in [outputs]{where}; valid keys: ['signals']")
        signals = outputs.get("signals", tuple(spec.outputs))
    else:
        signals = outputs
    if isinstance(signals, str) or not isinstance(signals, list | tuple) or not all(
            isinstance(x, str) for x in signals):
        raise SceneError(f"outputs.signals = {signals!r}{where} must be a list of signal names; valid signals: "
                         f"{list(spec.outputs)}")
    signals = tuple(signals)
    bad = [s for s in signals if s not in spec.outputs]
    if bad:
        raise SceneError(f"unknown output signal(s) {bad}{where}; valid signals: {list(spec.outputs)}")

    solver_in = data.get("solver") or {}
    bad = sorted(set(solver_in) - set(SOLVER_KEYS))
    if bad:
        raise SceneError(f"unknown solver key(s) {bad}{where}; valid keys: {list(SOLVER_KEYS)}")
    if isinstance(solver_in.get("engine"), str):
        solver_in["engine"] = spec.path_key(solver_in["engine"])  # a path's label ("equations") names its key
    try:
        solver = dataclasses.replace(spec.solver, **solver_in)
    except TypeError as exc:
        raise SceneError(f"[solver]{where}: {exc}") from exc
    solver.check(spec.engines)

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
        accuracy=check_tolerances(data.get("accuracy") or {}, where),
    )
    scene.build_params()  # parameter dataclasses validate themselves (negative mass etc.)
    if scene.accuracy:
        if spec.accuracy is None:
            raise SceneError(f"[accuracy]{where}: model '{spec.name}' declares no headline outputs")
        declared(scene)  # every name a headline of this scene
    return scene


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
            raise SceneError(f"scene file {p} is not valid TOML: {exc}") from exc
        except RecursionError as exc:
            raise SceneError(f"scene file {p} nests arrays or tables too deeply to be a scene") from exc
        data.setdefault("name", p.stem)
        return scene_from_dict(data, source=str(p))
    text = str(ref)
    model, _, scene_name = text.partition("/")
    spec = get_model(model)
    files = spec.scene_files()
    scene_name = scene_name or spec.default_scene
    if scene_name not in files:
        raise SceneError(f"model '{model}' has no scene '{scene_name}'; shipped scenes: {sorted(files)}")
    return load_scene(files[scene_name])


def shipped_scenes() -> dict[str, list[str]]:
    """Every model's shipped scenes, by model."""
    return {name: sorted(spec.scene_files()) for name, spec in models().items()}
