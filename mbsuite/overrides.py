"""The one rule that composes scene overrides (`--set`, `--vary`, `--over`, `--start`, the flags that set one key,
and the design studies' factors): `SECTION.KEY=VALUE` read by `parse_override` (KEY may be dotted into a model's
section: `pantograph.params.F0`), composed by `compose` (a key given twice, even to the same value, or a key and a
key inside it, is an error naming both flags), its section checked by `section_of`. Model-agnostic: the command
line (`cli.options`) and the design studies (`analysis.designspace`) read keys through it."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from .errors import MbsuiteError

#: the sections every scene has (a model adds its own: `SPEC.sections`)
SCENE_SECTIONS = ("input", "params", "solver", "effects")


@dataclass(frozen=True)
class Override:
    """One scene key a flag sets: the flag, the dotted key, its value (the text after `=` of an entry, else the
    flag's value) and how the command line gave it (`text`, for messages)."""

    flag: str
    key: str
    value: Any
    text: str

    def __str__(self) -> str:
        return self.text


def parse_override(flag: str, text: str) -> Override:
    """`SECTION.KEY=VALUE` (KEY may be dotted: `pantograph.params.F0`) as an `Override` of `flag`; an error naming the
    flag and the text unless every part of the key is a non-empty name."""
    key, sep, value = str(text).partition("=")
    parts = [p.strip() for p in key.split(".")]
    if not sep or len(parts) < 2 or not all(parts):
        what = "VALUE" if flag in ("--set", "--start") else "VALUES"
        raise MbsuiteError(f"{flag} {text!r}: expected SECTION.KEY={what} (e.g. params.mh=14; a KEY may reach into a "
                           "model's section: pantograph.params.F0=100)")
    return Override(flag, ".".join(parts), value, f"{flag} {text}")


def compose(items: Iterable[Override]) -> dict[str, Override]:
    """The rule: dotted key -> its `Override`; a key given twice (even with the same value), or a key and a key
    inside it, is an error naming both flags."""
    out: dict[str, Override] = {}
    for new in items:
        for old in out.values():
            if old.key == new.key:
                same = " (to the same value)" if str(old.value).strip() == str(new.value).strip() else ""
                raise MbsuiteError(f"{old} and {new} both set {new.key}{same}; give one")
            outer, inner = (old, new) if new.key.startswith(old.key + ".") else (new, old)
            if inner.key.startswith(outer.key + "."):
                raise MbsuiteError(f"{old} and {new} both set {inner.key} ({outer.key} holds it); give one")
        out[new.key] = new
    return out


def section_of(o: Override, sections: tuple[str, ...]) -> tuple[str, str]:
    """(section, the rest of the key) of an override; an error naming the flag unless the section is in
    `sections`."""
    section, _, name = o.key.partition(".")
    if section not in sections:
        example = "params.mh=14" if "params" in sections else "option.gamma=0.3"
        raise MbsuiteError(f"{o}: expected SECTION.KEY={'VALUE' if o.flag in ('--set', '--start') else 'VALUES'} "
                           f"with SECTION in {', '.join(sections)} (e.g. {example})")
    return section, name
