"""The model registry: every package under `mbsuite/models/` that exports `SPEC: ModelSpec` is a model.

A model package declares what its scenes may contain (effects with their allowed values, parameter dataclass, input
types,
output signals, engines) and the analysis hooks it supports. Nothing else in mbsuite knows a model by name: the scene
loader validates against the spec and the CLI dispatches through the hooks, so a new model is one new package.
"""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import SceneError
from .solver import SolverSettings


@dataclass(frozen=True)
class Effect:
    """One switchable effect of a model: `choices` are the allowed values (bools and/or strings)."""

    choices: tuple[Any, ...]
    default: Any
    doc: str = ""

    def check(self, name: str, value: Any, where: str = "") -> Any:
        """Return `value` if it is one of the choices, else a SceneError listing them (`where`: where the value came
        from, a phrase with a leading space)."""
        # bools are compared by identity so that 1/0 are not silently taken for true/false
        ok = any((value is c) if isinstance(c, bool) else (value == c and not isinstance(value, bool))
                 for c in self.choices)
        if not ok:
            raise SceneError(f"effect '{name}' = {value!r}{where} is not allowed; valid values: {list(self.choices)}")
        return value


@dataclass(frozen=True)
class RunPath:
    """One way to run a model's time simulation: a row of the model's path table (like scipy's `METHODS`).

    `run(scene) -> SimResult` takes a validated scene whose `solver.engine` is this path's key; it neither tests the
    engine again nor judges health (`mbsuite.run` picks the path and judges the result, once). `label` says what the
    path is (`equations`, `kinematic`, `pinocchio`, `fe`, `mujoco`, ...; a scene may write it in `solver.engine`),
    `what` says it in one line for `mbsuite list`."""

    run: Callable[..., Any]
    label: str
    what: str


@dataclass(frozen=True)
class ModelSpec:
    """What a model offers. Hooks take a validated `Scene` and return plain results (dicts / result objects).

    - `paths`: the path table, engine key (what scenes write in `solver.engine`) -> `RunPath`; `engines` lists its keys
    - `solver`: the model's default solver settings (a scene's `[solver]` overrides them key by key)
    - `equilibrium(scene) -> Report`, `modes(scene) -> Report`, `freqresp(scene, f_min, f_max, df, methods, workers,
      progress, options, time_histories) -> Report` (the pantograph's)
    Any hook may be None: the CLI then says the model does not support that analysis.

    Suite declarations (read by the model-agnostic suite layer, which names no model):
    - `cases`: dotted name of the module holding the model's `HARD_CASES` (a tuple of `mbsuite.hardcases.HardCase`),
      `workprecision_study(scene, quick) -> mbsuite.analysis.workprecision.Study` and
      `random_input(scene, rng) -> dict` (admissible random scene sections for the random-input test of every scene);
      imported only when the suite asks.
    - `sections`: extra top-level scene sections of this model, name -> validator (takes the section's value,
      returns the validated value or raises SceneError naming the bad key); e.g. the catenary's `[pantograph]`.
    - `under_wire(params, effects, engine, timestep) -> pantograph`: a pantograph of this model that the catenary can
      drive through its `static / trial / commit` protocol (None: the model is not a pantograph).
    - `mujoco_model(scene) -> (MjModel, MjData)`: the MuJoCo model of exactly the scene's effects, in its initial state
      (what `mbsuite view` shows; None: the model has no MuJoCo model).
    - `accuracy`: the model's accuracy declaration (`mbsuite.accuracy.AccuracySpec`: headline outputs with the
      tolerances the defaults meet, their values from a result, how a run is refined for `--error-estimate`).
    - `file_checks`: model-file stem -> `check(path, engine, model)`, handed to the engines' loaders for a file of
      that name by `mbsuite.load_model_file` (engine "mujoco" with an MjModel, "pinocchio" or "urdf" with a
      pin.Model); raises ModelFileError naming the file, the body and the residual (e.g. a loop that cannot close at
      the stated link lengths).
    """

    name: str
    summary: str
    params_cls: type
    effects: Mapping[str, Effect]
    inputs: Mapping[str, Mapping[str, Any]]  # input type -> {key: mbsuite.limits.Limit (range, unit, doc, default)}
    outputs: Mapping[str, str]  # signal -> SI unit
    scenes_dir: Path
    default_scene: str
    paths: Mapping[str, RunPath] = field(default_factory=dict)
    solver: SolverSettings = field(default_factory=SolverSettings)
    equilibrium: Callable[..., Any] | None = None
    modes: Callable[..., Any] | None = None
    freqresp: Callable[..., Any] | None = None
    extra: Mapping[str, Any] = field(default_factory=dict)
    sections: Mapping[str, Callable[[Any], Any]] = field(default_factory=dict)
    cases: str | None = None
    under_wire: Callable[..., Any] | None = None
    mujoco_model: Callable[..., Any] | None = None
    file_checks: Mapping[str, Callable[..., None]] = field(default_factory=dict)
    accuracy: Any = None

    def __post_init__(self) -> None:
        labels = [p.label for p in self.paths.values()]
        clash = [p.label for k, p in self.paths.items() if p.label in self.paths and p.label != k]
        if len(set(labels)) != len(labels) or clash:
            raise ValueError(f"model '{self.name}': path labels must be unique and name no other path: {labels}")
        if self.paths and self.solver.engine not in self.paths:
            raise ValueError(f"model '{self.name}': default engine {self.solver.engine!r} is not one of its paths "
                             f"{list(self.paths)}")

    @property
    def engines(self) -> tuple[str, ...]:
        """The keys of the path table (what a scene may write in `solver.engine`)."""
        return tuple(self.paths)

    def path_key(self, engine: str) -> str:
        """The path table's key for `engine` (a key or a path's label), or `engine` itself if it names no path."""
        if engine in self.paths:
            return engine
        return next((k for k, p in self.paths.items() if p.label == engine), engine)

    def suite(self) -> Any:
        """The model's suite module (`cases`), or None if it declares none."""
        return importlib.import_module(self.cases) if self.cases else None

    def param_names(self) -> list[str]:
        """The names of the model's parameters (its parameter dataclass's fields)."""
        return [f.name for f in dataclasses.fields(self.params_cls)]

    def scene_files(self) -> dict[str, Path]:
        """The shipped scenes, name -> TOML path."""
        return {p.stem: p for p in sorted(self.scenes_dir.glob("*.toml"))}


_MODELS: dict[str, ModelSpec] | None = None


def models() -> dict[str, ModelSpec]:
    """All registered models, discovered once from `mbsuite.models.*` packages exporting `SPEC`."""
    global _MODELS
    if _MODELS is None:
        pkg = importlib.import_module(__package__ + ".models")
        found: dict[str, ModelSpec] = {}
        for info in pkgutil.iter_modules(pkg.__path__):
            if not info.ispkg:
                continue
            mod = importlib.import_module(f"{pkg.__name__}.{info.name}")
            spec = getattr(mod, "SPEC", None)
            if isinstance(spec, ModelSpec):
                found[spec.name] = spec
        _MODELS = found
    return _MODELS


def get_model(name: str) -> ModelSpec:
    """The model called `name` (a SceneError listing the valid models if unknown)."""
    ms = models()
    if name not in ms:
        raise SceneError(f"unknown model '{name}'; valid models: {sorted(ms)}")
    return ms[name]
