"""The design space of a study: declared parameter ranges (`Factor`, from `SECTION.KEY=LO:HI` read by the one
`--set/--vary` reader), the scene sections of a design point, and the evaluation of a batch of points on the sweep
machinery (`run_sweep`: local processes or threads, Dask, the resumable store).

A point is a plain dict `{"SECTION.KEY": value}` (a nested key such as `pantograph.params.Pg` reaches a model's own
section: the catenary's Eppinger pantograph). `scene_outputs(scene_dict, point)` runs the scene at a point and returns
its declared headline outputs (`scene.spec.accuracy`: for the catenary the eight EN 50318 statistics); any other
module-level function `point -> {name: number}` is evaluated the same way (a test function, a cheaper model)."""

from __future__ import annotations

import copy
import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import MbsuiteError
from ..limits import Limit
from ..overrides import SCENE_SECTIONS
from ..schema import Rule, Section

if TYPE_CHECKING:
    from ..scenes import Scene
    from .sweep import SweepOptions



@dataclass(frozen=True)
class Factor:
    """One parameter of a study: `section.key` (the key may be dotted into a model's own section) varied over
    [lo, hi] in its SI unit."""

    section: str
    key: str
    lo: float
    hi: float

    def __post_init__(self) -> None:
        data = {f: getattr(self, f) for f in FACTOR_INPUTS.keys}
        for name, v in FACTOR_INPUTS.check(data, f"the range of {self.label}", MbsuiteError).items():
            object.__setattr__(self, name, v)

    @property
    def label(self) -> str:
        """`section.key`, the factor's name in points, tables and files."""
        return f"{self.section}.{self.key}"


def _ordered(c: dict[str, Any]) -> str | None:
    return None if c["lo"] < c["hi"] else (f"lower bound {c['lo']:g} must lie below the upper bound {c['hi']:g} "
                                           "(lo < hi)")


#: a study range (`Factor`): the bounds in the varied key's own SI unit, lo < hi
FACTOR_INPUTS = Section("study range (Factor)", {
    "section": Limit(kind=str, doc="scene section (input, params, solver, effects or a model's own)"),
    "key": Limit(kind=str, doc="key in the section (dotted into a model's own section)"),
    "lo": Limit(doc="lower bound (the key's SI unit)"),
    "hi": Limit(doc="upper bound (the key's SI unit)"),
}, required=("section", "key", "lo", "hi"), rules=(Rule("lo < hi", _ordered),))


def parse_factor(text: str, sections: Sequence[str], flag: str = "--vary") -> Factor:
    """A `Factor` from `SECTION.KEY=LO:HI` (the key read by the one override reader, `overrides.parse_override`,
    the two numbers by `sweep.parse_values`, as `--set/--vary`); an error naming the flag and the text."""
    from ..overrides import parse_override, section_of
    from .sweep import parse_values

    o = parse_override(flag, text)
    section, key = section_of(o, tuple(sections))
    value = o.value
    parts = value.split(":")
    if len(parts) != 2:
        raise MbsuiteError(f"{flag} {text!r}: a study range reads SECTION.KEY=LO:HI (two numbers, e.g. "
                           "params.m1=5:10)")
    bounds = []
    for part, role in zip(parts, ("lower bound", "upper bound"), strict=True):
        vals = parse_values(part) if part.strip() else []
        if len(vals) != 1 or isinstance(vals[0], bool | str):
            raise MbsuiteError(f"{flag} {text!r}: {role} {part!r} is not a number")
        bounds.append(vals[0])
    try:
        return Factor(section, key, bounds[0], bounds[1])
    except MbsuiteError as exc:
        raise MbsuiteError(f"{flag} {text!r}: {exc}") from None


def factors_for(scene: Scene | None, factors: Sequence[Factor | str], flag: str = "--vary") -> list[Factor]:
    """`factors` as `Factor`s (strings parsed against the scene's sections; without a scene any section), at least
    one, no name twice, each bound checked against the scene's declared range."""
    out = []
    for f in factors:
        if isinstance(f, Factor):
            out.append(f)
            continue
        if not isinstance(f, str):
            raise MbsuiteError(f"{flag} {f!r}: expected SECTION.KEY=LO:HI text or a Factor")
        sections = (*SCENE_SECTIONS, *scene.spec.sections) if scene is not None else (f.partition(".")[0],)
        out.append(parse_factor(f, sections, flag))
    if not out:
        raise MbsuiteError(f"a study needs at least one parameter range ({flag} SECTION.KEY=LO:HI)")
    seen = [f.label for f in out]
    twice = sorted({x for x in seen if seen.count(x) > 1})
    if twice:
        raise MbsuiteError(f"{flag}: {', '.join(twice)} given twice")
    if scene is not None:
        for f in out:  # the scene validates every value: a bound outside the declared range is refused now
            for v in (f.lo, f.hi):
                point_scene(scene, {f.label: v}, origin=f"in the study range ({flag} {f.label}={f.lo:g}:{f.hi:g})")
    return out


def sections_for(scene_dict: Mapping[str, Any], point: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """The `Scene.replace` sections of a point `{"SECTION.KEY": value}`; a dotted key's enclosing tables are copied
    from the scene so that only the named value changes."""
    out: dict[str, dict[str, Any]] = {}
    for label, value in point.items():
        section, _, key = label.partition(".")
        keys = key.split(".")
        node = out.setdefault(section, {})
        base: Any = scene_dict.get(section) or {}
        for k in keys[:-1]:
            base = base.get(k) if isinstance(base, Mapping) else None
            if k not in node:
                node[k] = copy.deepcopy(dict(base)) if isinstance(base, Mapping) else {}
            node = node[k]
        node[keys[-1]] = float(value) if isinstance(value, np.floating | np.integer) else value
    return out


def point_scene(scene: Scene, point: Mapping[str, Any], origin: str = "at a design point") -> Scene:
    """The scene at a design point (validated: a value outside its declared range is an error naming it)."""
    if not point:
        return scene
    return scene.replace(origin=origin, **sections_for(scene.to_dict(), point))


def scene_outputs(scene_dict: dict, point: dict[str, Any]) -> dict[str, float]:
    """Run the scene at `point` and return its headline outputs (module-level: it pickles to any executor)."""
    from ..pathrun import run_judged
    from ..scenes import scene_from_dict

    scene = scene_from_dict(scene_dict)
    try:
        scene = point_scene(scene, point)
        res = run_judged(scene)
    except MbsuiteError as exc:
        where = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in point.items())
        raise type(exc)(f"{exc} (design point {where})") from None
    return {k: float(v) for k, v in scene.spec.accuracy.values(scene, res).items()}


def scene_evaluator(scene: Scene) -> Callable[[dict[str, Any]], dict[str, float]]:
    """The evaluation of `scene` at a point (its headline outputs); an error if the model declares none."""
    if scene.spec.accuracy is None:
        raise MbsuiteError(f"model '{scene.model}' declares no headline outputs: nothing for a design study to read")
    return functools.partial(scene_outputs, scene.to_dict())


def headline_units(scene: Scene | None) -> dict[str, str]:
    """Headline name -> SI unit of the scene's declared outputs (empty without a scene)."""
    if scene is None or scene.spec.accuracy is None:
        return {}
    from ..trust.estimate import declared

    return {h.name: h.unit for h in declared(scene)}


def factor_unit(scene: Scene | None, factor: Factor) -> str:
    """The SI unit the scene's model declares for the varied key (`key_unit`)."""
    return key_unit(scene, factor.label)


def key_unit(scene: Scene | None, label: str) -> str:
    """The SI unit the scene's model declares for the scene key `label` = "section.key" (`param(..., unit=...)` of
    its parameters, an input type's or the solver's `Limit`, a key of a model section's `schema.Section`, dotted into
    it); "" where none is declared (no scene, an undeclared key, a dimensionless "-")."""
    if scene is None:
        return ""
    import dataclasses

    from ..limits import limit_of
    from ..scene_schema import section_of
    from ..settings import SOLVER_LIMITS

    spec = scene.spec
    section, _, key = label.partition(".")
    lim: Any = None
    if section == "params" and key in {f.name for f in dataclasses.fields(spec.params_cls)}:
        lim = limit_of(spec.params_cls, key)
    elif section == "input":
        lim = (spec.inputs.get(scene.input.get("type"), {}) or {}).get(key)
    elif section == "solver":
        lim = SOLVER_LIMITS.get(key)
    elif section in spec.sections:
        lim = section_of(spec.sections[section])
        for part in key.split("."):
            lim = getattr(lim, "keys", {}).get(part) if lim is not None else None
    unit = getattr(lim, "unit", "") or ""
    return "" if unit == "-" else unit


def evaluate(fn: Callable[[dict[str, Any]], Mapping[str, Any]], points: Sequence[dict[str, Any]], *,
             scene: Scene | None = None, workers: int = 0, options: SweepOptions | None = None,
             progress: bool | None = None, desc: str = "study") -> list[dict[str, float]]:
    """`fn` at every point on the sweep machinery, in the order of the points. A scene runs its points in threads when
    its model declares the scene's path thread-safe (`SPEC.studies.threads`: a compiled loop that releases the GIL),
    else in processes, unless `options` names an executor. Each result must be a mapping of output name -> number."""
    from .sweep import run_sweep

    auto = "threads" if scene is not None and scene.solver.engine in scene.spec.studies.threads else None
    results = run_sweep(fn, list(points), workers=workers, progress=progress, desc=desc, executor=auto,
                        options=options)
    out = []
    for i, r in enumerate(results):
        if not isinstance(r, Mapping):
            raise MbsuiteError(f"{desc}: the evaluation of point {i} returned {type(r).__name__}, not a mapping of "
                               "output name -> number")
        try:
            out.append({str(k): float(v) for k, v in r.items()})
        except (TypeError, ValueError):
            raise MbsuiteError(f"{desc}: the evaluation of point {i} returned a value that is not a number: "
                               f"{dict(r)!r}") from None
    return out


def output_names(results: Sequence[Mapping[str, float]], wanted: Sequence[str] | None, what: str) -> list[str]:
    """The outputs a study reads: `wanted` (each checked against the evaluations) or all of them."""
    have = list(results[0]) if results else []
    if not wanted:
        return have
    missing = [w for w in wanted if w not in have]
    if missing:
        raise MbsuiteError(f"{what}: output(s) {', '.join(missing)} not among the evaluated outputs; valid: "
                           f"{', '.join(have)}")
    return list(wanted)
