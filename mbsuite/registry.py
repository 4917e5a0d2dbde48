"""The model registry: every package under `mbsuite/models/` that exports `SPEC: ModelSpec` is a model.

A model package declares what its scenes may contain (effects with their allowed values, parameter dataclass, input
types,
output signals, engines) and the analysis hooks it supports. Nothing else in mbsuite knows a model by name: the scene
loader validates against the spec and the CLI dispatches through the hooks, so a new model is one new package.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import pkgutil
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import MbsuiteError, SceneError
from .limits import Limit
from .settings import SolverSettings


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


def _matches(value: Any, choices: tuple[Any, ...]) -> bool:
    """True if the effect value `value` is one of `choices` (bools by identity, as `Effect.check`)."""
    return any((value is c) if isinstance(c, bool) else (value == c and not isinstance(value, bool)) for c in choices)


@dataclass(frozen=True)
class Uses:
    """When a parameter, input key or model section takes part in a run (a row of `ModelSpec.uses`): under the listed
    effect values (effect -> the values that use it; all listed effects must hold) and on the listed paths (empty:
    every path). A scene that sets a key its configuration does not use is an error naming the key and the reason,
    so that no input is silently ignored."""

    effects: Mapping[str, tuple[Any, ...]] = field(default_factory=dict)
    engines: tuple[str, ...] = ()

    def unused_because(self, effects: Mapping[str, Any], engine: str | None) -> str | None:
        """Why a scene with these effects on this path does not use the key (None: it does; `engine` None: the
        effects alone are judged)."""
        for name, values in self.effects.items():
            if not _matches(effects[name], values):
                shown = [v if not isinstance(v, bool) else str(v).lower() for v in values]
                value = str(effects[name]).lower() if isinstance(effects[name], bool) else repr(effects[name])
                return f"effects.{name} = {value} (it is used with {name} = {' or '.join(map(str, shown))})"
        if engine is not None and self.engines and engine not in self.engines:
            return f"solver.engine = {engine!r} (it is used on the {' and '.join(self.engines)} path only)"
        return None


@dataclass(frozen=True)
class RunPath:
    """One way to run a model's time simulation: a row of the model's path table (like scipy's `METHODS`).

    `run(scene) -> SimResult` takes a validated scene whose `solver.engine` is this path's key; it neither tests the
    engine again nor judges health (`mbsuite.run` picks the path and judges the result, once). `label` says what the
    path is (`equations`, `kinematic`, `pinocchio`, `fe`, `mujoco`, ...; a scene may write it in `solver.engine`),
    `what` says it in one line for `mbsuite list`. `lacks`: effect -> the values this path does not model (a scene
    asking for one of them on this path is an error naming it, never a run of something else)."""

    run: Callable[..., Any]
    label: str
    what: str
    lacks: Mapping[str, tuple[Any, ...]] = field(default_factory=dict)


@dataclass(frozen=True)
class Band:
    """A bound a model offers the design studies (`mbsuite optimise --band SYSTEM`, `OUTPUT=band:SYSTEM`): its headline
    output `output` inside a target band that depends on the scene's operating point, one band per named system (the
    catenary's: the EN 50367 band of the mean contact force per supply system). `target(system, scene) -> (lo, hi)`
    in the output's unit, at the scene's operating point; `name` says what it is in tables."""

    output: str
    systems: tuple[str, ...]
    target: Callable[[str, Any], tuple[float, float]]
    name: str
    doc: str = ""

    def check(self, system: str, output: str, model: str) -> str:
        """The system (the first when `system` is empty), or an MbsuiteError naming the valid ones."""
        if output != self.output:
            raise MbsuiteError(f"the {self.name} of model '{model}' bounds {self.output} only, not {output}")
        if not system:
            return self.systems[0]
        if system not in self.systems:
            raise MbsuiteError(f"the {self.name} of model '{model}' has no system {system!r}; valid: "
                               f"{', '.join(self.systems)}")
        return system


@dataclass(frozen=True)
class Studies:
    """What the design studies (`mbsuite.analysis`: optimise, sensitivity, sweeps) take from a model, so that they name
    none: the default `objective` of `optimise` and the output a Pareto front trades against (`against`), both
    headline outputs (`accuracy`); the `band` the model offers as a constraint; and the paths whose runs may share a
    process in threads (`threads`: their loop is compiled and holds no global state, so a study runs them in a thread
    pool instead of processes)."""

    objective: str | None = None
    against: str | None = None
    band: Band | None = None
    threads: tuple[str, ...] = ()


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
    - `uses`: `"params.KEY"`, `"input.KEY"` or a section name -> `Uses`, the configurations (effect values, paths)
      that use it; a key not listed is used by every configuration. Setting an unused key is an error naming it and
      why (an input key only when it differs from its declared default): against the effects when the scene is
      built, against the path (and the path's `lacks`) when a path runs it, so a scene may carry one path's
      settings while another path's run is asked for on the way.
    - `statistics`: the statistics its runs state (name -> `mbsuite.statistics.Statistic`), declared like `outputs`.
    - `studies`: what the design studies take from the model (`Studies`: default objective, a band constraint, the
      paths that may run in threads).
    - `commands`: the dotted name of the module whose `register(subparsers, add_common, emit)` adds the model's
      command group to `mbsuite` (None: no group).
    - `accuracy`: the model's accuracy declaration (`mbsuite.trust.estimate.AccuracySpec`: headline outputs with the
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
    uses: Mapping[str, Uses] = field(default_factory=dict)
    #: the parameters of a scene when its own sections change them (the catenary's [line]); None: params_cls(**params)
    params_builder: Callable[[Any], Any] | None = None
    #: the input files a model reads besides scenes (the catenary's line file): name -> `schema.Section` (or a
    #: `Deferred` naming one); docs, JSON Schemas and the generated input tests walk them
    input_files: Mapping[str, Any] = field(default_factory=dict)
    #: shipped scenes that moved to another model: old scene name -> "model/scene". `load_scene("<this>/<old>")`
    #: loads the new one with a `DeprecationWarning` naming it (`mbsuite list` shows only the new name)
    moved_scenes: Mapping[str, str] = field(default_factory=dict)
    studies: Studies = field(default_factory=Studies)
    #: the statistics a run of the model states (`mbsuite.statistics.Statistic`: unit, definition, window), name ->
    #: declaration; `SimResult.statistics` holds their values
    statistics: Mapping[str, Any] = field(default_factory=dict)
    commands: str | None = None

    def __post_init__(self) -> None:
        self._check_uses()
        if any(u.engines for u in self.uses.values()) or any(p.lacks for p in self.paths.values()):
            object.__setattr__(self, "paths", {k: dataclasses.replace(p, run=self._checked(k, p.run))
                                               for k, p in self.paths.items()})
        labels = [p.label for p in self.paths.values()]
        clash = [p.label for k, p in self.paths.items() if p.label in self.paths and p.label != k]
        if len(set(labels)) != len(labels) or clash:
            raise ValueError(f"model '{self.name}': path labels must be unique and name no other path: {labels}")
        if set(self.studies.threads) - set(self.paths):
            raise ValueError(f"model '{self.name}': studies.threads names unknown paths {self.studies.threads}")
        if self.paths and self.solver.engine not in self.paths:
            raise ValueError(f"model '{self.name}': default engine {self.solver.engine!r} is not one of its paths "
                             f"{list(self.paths)}")

    def _check_uses(self) -> None:
        """Every `uses` row and `lacks` entry names a real key, effect value and path (a typo would switch the check
        off silently)."""
        keys = {*(f"params.{f.name}" for f in dataclasses.fields(self.params_cls)),
                *(f"input.{k}" for decl in self.inputs.values() for k in decl), *self.sections}
        rows = [(f"uses[{k!r}]", u.effects) for k, u in self.uses.items()]
        rows += [(f"paths[{k!r}].lacks", p.lacks) for k, p in self.paths.items()]
        for key, use in self.uses.items():
            if key not in keys:
                raise ValueError(f"model '{self.name}': uses names {key!r}, not a parameter, input key or section")
            if set(use.engines) - set(self.paths):
                raise ValueError(f"model '{self.name}': uses[{key!r}] names unknown paths {use.engines}")
        for where, effects in rows:
            for name, values in effects.items():
                if name not in self.effects or not all(_matches(v, self.effects[name].choices) for v in values):
                    raise ValueError(f"model '{self.name}': {where} names effect values {name} = {values} that are "
                                     "not declared")

    def _checked(self, key: str, run: Callable[..., Any]) -> Callable[..., Any]:
        """`run` of path `key`, first refusing a scene that sets what this path does not use (`used_keys`)."""

        @functools.wraps(run)
        def checked(scene: Any, *args: Any, **kwargs: Any) -> Any:
            self.check_used(scene, key)
            return run(scene, *args, **kwargs)

        return checked

    def check_used(self, scene: Any, engine: str) -> None:
        """Refuse to run `scene` on path `engine` if it sets a key that path does not use, or asks for an effect value
        the path does not model (`uses`, `RunPath.lacks`; every path's run calls this first)."""
        src = f" in {scene.source}" if scene.source else " in the scene"
        self.refuse_unused(scene.effects, engine, scene.params, scene.input, scene.input, scene.sections,
                           lambda section=None, key=None: src)

    def refuse_unused(self, effects: Mapping[str, Any], engine: str | None, params: Mapping[str, Any],
                      given: Mapping[str, Any], inp: Mapping[str, Any], sections: Mapping[str, Any],
                      where: Callable[..., str]) -> None:
        """No input silently ignored: a parameter, input key (`given`, the scene's own; away from its declared
        default) or model section that the effects (and path `engine`; None: the effects only) do not use (`uses`), or
        an effect value the path does not model, is a SceneError naming each such key, where it came from
        (`where(section, key)`, a phrase with a leading space) and why."""
        decls = self.inputs.get(inp.get("type"), {}) if self.inputs else {}
        inputs = [k for k in given if k != "type" and not (
            isinstance(decls.get(k), Limit) and decls[k].has_default and inp.get(k) == decls[k].default)]
        unused = self.unused(effects, engine, [*(f"params.{k}" for k in params), *(f"input.{k}" for k in inputs),
                                               *sections])
        if not unused:
            return
        shown = []
        for key, why in unused.items():
            section, _, name = key.partition(".")
            value = {"params": params, "input": inp, "effects": effects}.get(section, {}).get(name)
            what = f"[{key}]" if not name else f"{key} = {value!r}"
            shown.append(f"{what}{where(section, name or None)}: {why}")
        on = f"on the {engine} path" if engine else "with these effects"
        raise SceneError(f"not used by this scene {on} (model '{self.name}'), so it would be silently ignored: "
                         f"{'; '.join(shown)}. Remove it, or change the effects or path so that it takes part")

    def unused(self, effects: Mapping[str, Any], engine: str | None, keys: Iterable[str]) -> dict[str, str]:
        """Of `keys` (`"params.KEY"`, `"input.KEY"`, section names) those this configuration does not use, with why;
        and `"effects.NAME"` for an effect value the path `engine` does not model (`engine` None: judge the effects
        only)."""
        out = {k: why for k in keys if k in self.uses
               and (why := self.uses[k].unused_because(effects, engine)) is not None}
        path = self.paths.get(engine) if engine is not None else None
        for name, values in (path.lacks if path else {}).items():
            if _matches(effects[name], values):
                able = [k for k, p in self.paths.items() if not _matches(effects[name], p.lacks.get(name, ()))]
                out[f"effects.{name}"] = (f"the {engine} path does not model {name} = {effects[name]!r} (paths that "
                                          f"do: {able})")
        return out

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
