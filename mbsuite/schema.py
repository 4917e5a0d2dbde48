"""One declaration per input section, one checker: `Section` (keys with their `limits.Limit`, lists, nested sections,
keys named by a prefix, the keys required and the cross-field `Rule`s). From the same declaration come the check and
its messages (`Section.check`: the key, its value, what is valid, the unit and where the value came from), the docs'
parameter tables (`Section.markdown`) and a JSON Schema an editor checks a TOML file with (`Section.json_schema`).

- A key is required when it is listed in `required`; otherwise its declared default is filled in (a `Limit` default),
  or it stays absent (an optional part, e.g. an irregularity). A physical quantity of the user's own design is
  required: it has no default.
- `Items(of, min, max)`: a list of numbers or words (`of` a `Limit`), of tables (`of` a `Section`) or of fixed-length
  rows (`of` a tuple of `Limit`s, e.g. `[x_a, x_b, T]`). `max` bounds its length before any item is read (a size
  guard); a list with no natural bound gets `MAX_ITEMS`.
- `prefixed`: keys `<prefix><name>` with one declaration (a support's `k_<wire>`).
- `Rule(doc, test)`: a cross-field rule; `test(checked)` returns None or the message of the broken rule.

A dataclass whose fields are declared with `limits.param` gives its section with `of_dataclass` (one declaration for
the Python API and the file). Rows of a CSV table go through the same `Section` as the TOML tables.

A library was weighed (pydantic, msgspec, attrs/cattrs; `docs/dependencies.md`, "Input declarations"): the checks
extend `limits.Limit`, which every parameter dataclass already declares, and keep its messages and its numpy scalars.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import SceneError
from .limits import Limit

#: the longest list of a section whose declaration states no bound (a size guard, checked before any item is read)
MAX_ITEMS = 100_000


@dataclass(frozen=True)
class Items:
    """A list of `of` (a `Limit`, a `Section`, an `Items` (a list of lists) or a tuple of `Limit`s: fixed-length
    rows) of `min` ... `max` items."""

    of: Any
    min: int = 0
    max: int = MAX_ITEMS
    doc: str = ""
    unit: str = ""
    default: Any = None  # filled in when the key is absent and not required (None: left absent)
    rules: tuple[Rule, ...] = ()  # on the checked list (e.g. times strictly increasing)

    def describe(self) -> str:
        """The valid values in words."""
        n = (f"{self.min}" if self.min == self.max else f"{self.min} to {self.max:,}") + " "
        if isinstance(self.of, Section):
            return f"{n}tables ({self.of.title})"
        if isinstance(self.of, tuple):
            return f"{n}rows [{', '.join(lim.doc or lim.describe() for lim in self.of)}]"
        if isinstance(self.of, Items):
            return f"{n}lists, each {self.of.describe()}"
        return f"{n}values, each {self.of.describe()}"


@dataclass(frozen=True)
class Rule:
    """A cross-field rule of a section: `doc` (shown in the docs and the JSON Schema) and `test(checked) -> message or
    None` (run once every key has passed; `given`: on the keys given only, without the defaults filled in, for rules
    on which keys go together)."""

    doc: str
    test: Callable[[dict[str, Any]], str | None]
    given: bool = False


@dataclass(frozen=True)
class Section:
    """The declaration of one input section (module docstring)."""

    title: str
    keys: Mapping[str, Limit | Items | Section]
    required: tuple[str, ...] = ()
    prefixed: Mapping[str, Limit] = field(default_factory=dict)
    rules: tuple[Rule, ...] = ()
    doc: str = ""
    #: a valid example (the docs show it; the generated tests and the robustness corpus move each key of it)
    example: Mapping[str, Any] | None = None

    def __post_init__(self) -> None:
        bad = [k for k in self.required if k not in self.keys]
        if bad:
            raise ValueError(f"section {self.title!r}: required keys {bad} are not declared")

    def check(self, data: Any, where: str, error: type[Exception] = SceneError) -> dict[str, Any]:
        """`data` checked: a dict of every key given (numbers as Python int/float) with the declared defaults filled
        in. Errors (`error`) read `<where>: ...` and name the key, its value, what is valid and its unit."""
        if not isinstance(data, Mapping):
            raise error(f"{where} must be a table ({self.title}) with keys {list(self.keys)}, got {data!r}")
        unknown = [k for k in data if k not in self.keys and not self._prefix(k)]
        if unknown:
            extra = [f"{p}<name>" for p in self.prefixed]
            raise error(f"{where}: unknown key(s) {sorted(map(str, unknown))}; valid keys: {list(self.keys) + extra}")
        missing = [k for k in self.required if k not in data]
        if missing:
            raise error(f"{where}: {', '.join(missing)} missing; required: "
                        + "; ".join(f"{k} ({_describe(self.keys[k])})" for k in missing))
        out: dict[str, Any] = {}
        for key, decl in self.keys.items():
            if key in data:
                out[key] = check_value(decl, key, data[key], where, error)
        for key, value in data.items():
            prefix = self._prefix(key)
            if prefix is not None and key not in self.keys:
                if len(key) == len(prefix):
                    raise error(f"{where}: key {key!r} names nothing after {prefix!r}")
                out[key] = check_value(self.prefixed[prefix], key, value, where, error)
        given = dict(out)
        for key, decl in self.keys.items():
            if key not in out and isinstance(decl, Limit) and decl.has_default:
                out[key] = decl.default
            elif key not in out and isinstance(decl, Items) and decl.default is not None:
                out[key] = decl.default
        for rule in self.rules:
            msg = rule.test(given if rule.given else out)
            if msg:
                raise error(f"{where}: {msg}")
        return out

    def _prefix(self, key: Any) -> str | None:
        return next((p for p in self.prefixed if isinstance(key, str) and key.startswith(p)), None)

    # --- the docs and the JSON Schema, from the same declaration ------------------------------------------------
    def json_schema(self, top: bool = False) -> dict[str, Any]:
        """A JSON Schema (draft 2020-12) of the section; `top`: with `$schema` and `title`."""
        props = {k: json_of(d) for k, d in self.keys.items()}
        out: dict[str, Any] = {"type": "object", "properties": props, "additionalProperties": False}
        if self.required:
            out["required"] = list(self.required)
        if self.prefixed:
            out["patternProperties"] = {f"^{p}.+$": json_of(lim) for p, lim in self.prefixed.items()}
        doc = " ".join([self.doc, *(f"Rule: {r.doc}." for r in self.rules)]).strip()
        if doc:
            out["description"] = doc
        if top:
            out = {"$schema": "https://json-schema.org/draft/2020-12/schema", "title": self.title, **out}
        return out

    def rows(self) -> list[tuple[str, str, str, str, str]]:
        """(key, required or default, valid values, unit, doc) of every key, prefixed keys last."""
        rows = []
        for k, d in self.keys.items():
            if k in self.required:
                need = "required"
            elif isinstance(d, Limit) and d.has_default:
                need = f"default {d.default!r}"
            elif isinstance(d, Items) and d.default is not None:
                need = f"default {list(d.default)!r}"
            else:
                need = "optional"
            unit = d.unit if isinstance(d, Limit | Items) else ""
            doc = d.doc if isinstance(d, Limit | Items) else d.doc or d.title
            rows.append((k, need, _describe(d), unit, doc))
        for p, lim in self.prefixed.items():
            rows.append((f"{p}<name>", "optional", lim.describe(), lim.unit, lim.doc))
        return rows

    def markdown(self, _seen: set[int] | None = None) -> str:
        """The section's parameter table (Markdown), its rules below it; nested sections follow as their own (a
        section nested at several keys once)."""
        seen = set() if _seen is None else _seen
        seen.add(id(self))
        lines = [f"**{self.title}**" + (f": {self.doc}" if self.doc else ""), "",
                 "| key | required / default | valid | unit | meaning |", "|---|---|---|---|---|"]
        lines += [f"| `{k}` | {need} | {valid} | {unit} | {doc} |" for k, need, valid, unit, doc in self.rows()]
        if self.rules:
            lines += [""] + [f"- {r.doc}" for r in self.rules]
        out = ["\n".join(lines)]
        for d in self.keys.values():
            sub = d if isinstance(d, Section) else d.of if isinstance(d, Items) and isinstance(d.of, Section) else None
            if sub is not None and id(sub) not in seen:
                out.append(sub.markdown(seen))
        return "\n\n".join(out)

    def walk(self, path: tuple[str, ...] = ()) -> list[tuple[tuple[str, ...], Limit | Items | Section]]:
        """Every declared key, nested ones as paths (what the generated tests and the robustness corpus walk)."""
        out = []
        for k, d in self.keys.items():
            out.append(((*path, k), d))
            if isinstance(d, Section):
                out += d.walk((*path, k))
        return out


def _describe(d: Limit | Items | Section) -> str:
    if isinstance(d, Section):
        return f"a table ({d.title})"
    return d.describe()


def check_value(decl: Limit | Items | Section, key: str, value: Any, where: str, error: type[Exception]) -> Any:
    """`value` of `key` checked against its declaration (a `Limit`, an `Items` list or a nested `Section`); `where`
    names the place in errors of type `error`."""
    if isinstance(decl, Section):
        return decl.check(value, f"{where} [{key}]", error)
    if isinstance(decl, Limit):
        return decl.check(key, value, error, f" in {where}")
    if isinstance(value, np.ndarray) and value.ndim >= 1:
        value = value.tolist()  # a numpy user's array: its numbers
    if isinstance(value, str) or not isinstance(value, list | tuple):
        raise error(f"{key} = {value!r} in {where} must be a list: {decl.describe()}")
    if not decl.min <= len(value) <= decl.max:
        raise error(f"{key} in {where} has {len(value):,} items; valid: {decl.describe()}")
    out = []
    for i, item in enumerate(value):
        name = f"{key}[{i}]"
        if isinstance(decl.of, Section):
            out.append(decl.of.check(item, f"{where} {name}", error))
        elif isinstance(decl.of, Items):
            out.append(check_value(decl.of, name, item, where, error))
        elif isinstance(decl.of, tuple):
            if isinstance(item, str) or not isinstance(item, list | tuple) or len(item) != len(decl.of):
                raise error(f"{name} = {item!r} in {where} must be a row of {len(decl.of)} values "
                            f"[{', '.join(lim.doc or lim.describe() for lim in decl.of)}]")
            out.append(tuple(lim.check(f"{name}[{j}]", v, error, f" in {where}")
                             for j, (lim, v) in enumerate(zip(decl.of, item, strict=True))))
        else:
            out.append(decl.of.check(name, item, error, f" in {where}"))
    for rule in decl.rules:
        msg = rule.test(out)
        if msg:
            raise error(f"{key} in {where}: {msg}")
    return out


def json_of(d: Limit | Items | Section) -> dict[str, Any]:
    """The JSON Schema of one declaration."""
    if isinstance(d, Section):
        return d.json_schema()
    if isinstance(d, Items):
        if isinstance(d.of, tuple):
            items: dict[str, Any] = {"type": "array", "prefixItems": [json_of(lim) for lim in d.of],
                                     "minItems": len(d.of), "maxItems": len(d.of)}
        else:
            items = json_of(d.of)
        out = {"type": "array", "items": items, "minItems": d.min, "maxItems": d.max}
        doc = " ".join([d.doc, *(f"Rule: {r.doc}." for r in d.rules)]).strip()
        return {**out, **({"description": doc} if doc else {})}
    lim = d
    out = {}
    if lim.kind is bool:
        out["type"] = "boolean"
    elif lim.choices is not None:
        out["enum"] = list(lim.choices)
    elif lim.kind is str:
        out["type"] = "string"
    else:
        out["type"] = "integer" if lim.kind is int else "number"
        if lim.lo is not None:
            out["exclusiveMinimum" if lim.lo_open else "minimum"] = lim.lo
        if lim.hi is not None:
            out["exclusiveMaximum" if lim.hi_open else "maximum"] = lim.hi
    if lim.has_default and lim.default is not None:
        out["default"] = lim.default
    doc = lim.doc + (f" ({lim.unit})" if lim.unit else "")
    if doc:
        out["description"] = doc
    return out


def of_dataclass(cls: type, title: str, *, omit: tuple[str, ...] = (), rules: tuple[Rule, ...] = (),
                 doc: str = "", extra: Mapping[str, Limit | Items | Section] | None = None) -> Section:
    """The section of a dataclass declared with `limits.param` (a field's `Limit`, or an `Items` / `Section` under
    metadata key "schema"): fields without a default are required. `omit`: fields a file does not write."""
    keys: dict[str, Limit | Items | Section] = {}
    required = []
    for f in dataclasses.fields(cls):
        if f.name in omit:
            continue
        decl = f.metadata.get("limit", f.metadata.get("schema"))
        if decl is None:
            raise ValueError(f"{cls.__name__}.{f.name} declares no Limit or schema")
        keys[f.name] = decl
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            required.append(f.name)
    keys.update(extra or {})
    return Section(title, keys, tuple(required), rules=rules, doc=doc)


def toml_error(exc: Exception, text: str) -> str:
    """A TOML parser's message with the line it names quoted (a key given twice reads "Cannot overwrite a value (at
    line 12, column 7)", which names no key; the quoted line does)."""
    m = re.search(r"at line (\d+)", str(exc))
    lines = text.splitlines()
    if m is not None and 0 < int(m.group(1)) <= len(lines):
        line = lines[int(m.group(1)) - 1].strip()
    elif "end of document" in str(exc) and any(x.strip() for x in lines):
        line = next(x for x in reversed(lines) if x.strip()).strip()  # the last line
    else:
        return str(exc)
    hint = " (a key or table given twice)" if "overwrite" in str(exc).lower() else ""
    return f"{exc}: `{line[:200]}`{hint}"


# --- generated cases: what the tests and the robustness corpus try on every declared key ------------------------------
def leaves(section: Section, data: Mapping[str, Any], path: tuple[Any, ...] = (), every_row: bool = True
           ) -> list[tuple[tuple[Any, ...], Limit | Items | Section, bool]]:
    """(path into `data`, the declaration there, required) of every declared key: nested sections and the rows of a
    list of tables are walked (`every_row` False: a row only for the keys no earlier row had); keys `data` leaves out
    are listed too (a test sets them)."""
    out = []
    keys: dict[str, Any] = dict(section.keys)
    keys.update({k: section.prefixed[p] for k in data for p in section.prefixed
                 if isinstance(k, str) and k.startswith(p) and k not in section.keys})
    for key, d in keys.items():
        here = (*path, key)
        out.append((here, d, key in section.required))
        if isinstance(d, Section) and isinstance(data.get(key), Mapping):
            out += leaves(d, data[key], here, every_row)
        elif isinstance(d, Items) and isinstance(d.of, Section) and data.get(key):
            seen: set[Any] = set()
            for i, item in enumerate(data[key]):
                rows = [r for r in leaves(d.of, item, (*here, i), every_row) if every_row or r[0][len(here) + 1:]
                        not in seen]
                seen |= {r[0][len(here) + 1:] for r in rows}
                out += rows
    return out


def bad_values(decl: Limit | Items | Section, current: Any = None) -> list[tuple[str, Any]]:
    """(label, value) of values `decl` refuses: wrong types, bools, NaN, +-inf, complex, below and above its range,
    huge, a fractional count, an unknown word, a list too long or too short, a bad first item (`current`: the value
    the example holds there, which a list's bad item replaces)."""
    if isinstance(decl, Section):
        return [("text", "text"), ("number", 1.0), ("list", [1.0])]
    if isinstance(decl, Items):
        first = current[0] if current else None
        bad: list[tuple[str, Any]] = [("text", "text"), ("number", 1.0), ("bool", True), ("table", {"a": 1}),
                                      ("too long", [first] * (decl.max + 1))]
        if decl.min > 0:
            bad.append(("empty", []))
        if isinstance(decl.of, Limit | tuple) and current:
            inner = decl.of if isinstance(decl.of, Limit) else decl.of[0]
            for label, v in bad_values(inner, first if isinstance(decl.of, Limit) else first[0]):
                row = list(current)
                row[0] = v if isinstance(decl.of, Limit) else [v, *list(first)[1:]]
                bad.append((f"item {label}", row))
            if isinstance(decl.of, tuple):
                bad.append(("short row", [list(first)[:-1], *list(current)[1:]]))
        return bad
    lim = decl
    if lim.kind is bool:
        return [("number", 1), ("zero", 0), ("text", "true"), ("float", 1.0)]
    if lim.kind is str:
        return [("number", 1.0), ("bool", True), ("list", ["a"])] + (
            [("unknown word", "no-such-value")] if lim.choices is not None else [])
    bad = [("text", "text"), ("bool", True), ("list", [1.0]), ("table", {"a": 1.0}), ("nan", math.nan),
           ("inf", math.inf), ("-inf", -math.inf), ("complex", 1 + 1j)]
    if lim.lo is not None:
        bad.append(("below", lim.lo if lim.lo_open else lim.lo - 1.0 - abs(lim.lo)))
    if lim.hi is not None:
        bad += [("above", lim.hi if lim.hi_open else lim.hi + 1.0 + abs(lim.hi)), ("huge", 1e300)]
    if lim.kind is int:
        bad.append(("fraction", (lim.lo or 0) + 2.5))
    return bad
