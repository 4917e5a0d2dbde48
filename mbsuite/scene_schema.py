"""A model's scene file as a JSON Schema (draft 2020-12) and its input files' parameter tables, written from the
declarations the scene loader checks with: the effects' choices (`registry.Effect`), the parameters' `Limit`s, the
input types' `Limit`s, the solver's (`solver.SOLVER_LIMITS`) and each model section's `schema.Section` (a section
validator carries it as `.schema`). An editor given the schema checks a TOML scene while it is typed (e.g. Taplo or
Even Better TOML with `#:schema ./catenary.scene.json` on the first line); the loader checks the same ranges again,
with the cross-field rules a JSON Schema cannot state.

`scripts/write_schemas.py` writes `docs/schemas/*.json` and `docs/inputs.md` from here.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from .deferred import Deferred
from .limits import Limit
from .registry import ModelSpec, get_model, models
from .schema import Items, Section, json_of
from .settings import INTEGRATORS, SCIPY_METHODS, SOLVER_LIMITS

DRAFT = "https://json-schema.org/draft/2020-12/schema"


def section_of(validator: Any) -> Section | None:
    """The `Section` a model-section validator declares (None: it declares none), or the `Section` itself."""
    if isinstance(validator, Deferred):
        validator = validator.resolve()
    return validator if isinstance(validator, Section) else getattr(validator, "schema", None)


def _params(spec: ModelSpec) -> dict[str, Any]:
    props = {}
    for f in dataclasses.fields(spec.params_cls):
        lim = f.metadata.get("limit")
        if lim is None and str(f.type).startswith("list[list"):  # rows of numbers (a catenary's windows)
            props[f.name] = {"type": "array", "items": {"type": "array", "items": {"type": "number"}}}
        elif lim is None:
            props[f.name] = {"type": "array", "items": {"type": "number"}}
        else:
            props[f.name] = json_of(lim)
    return {"type": "object", "properties": props, "additionalProperties": False,
            "description": f"parameters of {spec.params_cls.__name__} (SI units)"}


def _effects(spec: ModelSpec) -> dict[str, Any]:
    props = {k: {"enum": list(e.choices), "default": e.default, **({"description": e.doc} if e.doc else {})}
             for k, e in spec.effects.items()}
    return {"type": "object", "properties": props, "additionalProperties": False}


def _input(spec: ModelSpec) -> dict[str, Any]:
    props: dict[str, Any] = {"type": {"enum": list(spec.inputs)}}
    for keys in spec.inputs.values():
        for k, lim in keys.items():
            if isinstance(lim, Limit | Items) and k not in props:
                props[k] = json_of(lim)
    return {"type": "object", "properties": props, "additionalProperties": False,
            "description": "the input; the keys valid for each type are checked by the loader"}


def _solver(spec: ModelSpec) -> dict[str, Any]:
    props: dict[str, Any] = {"engine": {"enum": sorted({*spec.paths, *(p.label for p in spec.paths.values())})},
                             "integrator": {"enum": list(INTEGRATORS)}, "method": {"enum": list(SCIPY_METHODS)},
                             "allow_inaccurate": {"type": "boolean"}}
    props.update({k: json_of(lim) for k, lim in SOLVER_LIMITS.items()})
    return {"type": "object", "properties": props, "additionalProperties": False}


def scene_schema(model: str) -> dict[str, Any]:
    """The JSON Schema of a scene file of `model`."""
    spec = get_model(model)
    props: dict[str, Any] = {
        "model": {"const": spec.name},
        "name": {"type": "string"},
        "description": {"type": "string"},
        "effects": _effects(spec),
        "params": _params(spec),
        "input": _input(spec),
        "outputs": {"type": "object", "properties": {"signals": {"type": "array",
                                                                 "items": {"enum": list(spec.outputs)}}},
                    "additionalProperties": False},
        "solver": _solver(spec),
        "accuracy": {"type": "object", "additionalProperties": {"type": "number", "exclusiveMinimum": 0},
                     "description": "headline name = tolerance (the headline's unit)"},
    }
    for name, validator in spec.sections.items():
        sec = section_of(validator)
        props[name] = sec.json_schema() if sec is not None else {"type": "object"}
    return {"$schema": DRAFT, "title": f"mbsuite {spec.name} scene", "type": "object", "properties": props,
            "required": ["model"], "additionalProperties": False}


def sections() -> dict[str, Section]:
    """Every declared input section of every model, by `<model>.<section>` (what the generated tests and the
    robustness corpus walk), the input files a model reads (`ModelSpec.input_files`) included."""
    out = {}
    for name, spec in models().items():
        for key, validator in spec.sections.items():
            sec = section_of(validator)
            if sec is not None:
                out[f"{name}.{key}"] = sec
            v = validator.resolve() if isinstance(validator, Deferred) else validator
            for sub, s in getattr(v, "schemas", {}).items():  # a section of several kinds: one declaration each
                out[f"{name}.{sub}"] = s
        for key, sec in spec.input_files.items():
            out[f"{name}.{key}"] = section_of(sec)
    return out
