"""A line described in a file (TOML, with CSV tables for long lists) and the scene's `[line]` section.

Line file (model README, "A line of your own"; every length in m, mass in kg or kg/m, force in N, stiffness N/m)::

    name = "my section"
    presag = 0.0005                      # mid-span presag / span length (parabolic), optional
    [[wires]]                            # one table per wire; exactly one with role = "contact"
    name = "contact"; role = "contact"; mass = 1.35; tension = 20000; EI = 195; x0 = 0; x1 = 600
    ends = ["pinned", "pinned"]          # or "free" (held by clamps)
    tension_segments = [[51, 69, 12500]] # optional: T between x_a and x_b
    [[supports]]                         # or supports_file = "supports.csv" (same keys as columns)
    x = 0; k_contact = 300; k_messenger = 5e4; m_contact = 1.0     # k_<wire>: ground spring, m_<wire>: mass
    [[droppers]]                         # or droppers_file = "droppers.csv"
    x = 5; upper = "messenger"; lower = "contact"; k = 1e5; law = "slack"; mass = 0.2; clamp_upper = 0.1
    [[clamps]]                           # or clamps_file: x, a, b, k
    [[masses]]                           # or masses_file: x, wire, m
    [irregularity]                       # optional, see `irregularity.py`

Relative file names are read from the line file's folder. Every key is checked: an unknown one is an error naming it
and the file (no silently ignored input).
"""

from __future__ import annotations

import csv
import dataclasses
import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from ...errors import MbsuiteError, ParameterError, SceneError
from ...limits import real
from .irregularity import check_irregularity
from .line import Clamp, Dropper, Line, PointMass, Support, Wire

WIRE_KEYS = ("name", "role", "mass", "tension", "EI", "x0", "x1", "ends", "tension_segments")
DROPPER_KEYS = ("x", "upper", "lower", "k", "law", "mass", "clamp_upper", "clamp_lower")
CLAMP_KEYS = ("x", "a", "b", "k")
MASS_KEYS = ("x", "wire", "m")
TABLES = ("supports", "droppers", "clamps", "masses")
LINE_FILE_KEYS = ("name", "presag", "wires", "irregularity", *TABLES, *(f"{t}_file" for t in TABLES))
#: most rows of one table (a tension section of 1 600 m has ~30 supports and ~250 droppers)
MAX_ROWS = 100_000


def _rows(data: Mapping[str, Any], table: str, base: Path, where: str) -> list[dict[str, Any]]:
    """The rows of `table`: the TOML array of tables or the CSV file `<table>_file` (not both)."""
    inline, fname = data.get(table), data.get(f"{table}_file")
    if inline is not None and fname is not None:
        raise SceneError(f"{where}: give {table} either inline ([[{table}]]) or as {table}_file, not both")
    if fname is None:
        rows = inline or []
        if not isinstance(rows, list) or any(not isinstance(r, dict) for r in rows):
            raise SceneError(f"{where}: {table} must be an array of tables ([[{table}]]), got {type(rows).__name__}")
        return [dict(r) for r in rows]
    if not isinstance(fname, str):
        raise SceneError(f"{where}: {table}_file = {fname!r} must be a file name")
    path = (base / fname) if not Path(fname).is_absolute() else Path(fname)
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            rows = []
            for i, r in enumerate(reader):
                if i >= MAX_ROWS:
                    raise SceneError(f"{path}: more than {MAX_ROWS} rows")
                if None in r or any(v is None for v in r.values()):
                    raise SceneError(f"{path} row {i + 2}: {len(r)} columns where the header has "
                                     f"{len(reader.fieldnames or [])}")
                rows.append({k.strip(): _cell(v) for k, v in r.items()})
    except OSError as exc:
        raise SceneError(f"{where}: cannot read {table}_file {path}: {exc.strerror or exc}") from exc
    return rows


def _cell(v: str) -> Any:
    """A CSV cell: a number where it reads as one, else the stripped text."""
    s = v.strip()
    try:
        return float(s)
    except ValueError:
        return s


def _check_keys(row: Mapping[str, Any], valid: tuple[str, ...], what: str, prefixed: tuple[str, ...] = ()) -> None:
    bad = sorted(k for k in row if k not in valid and not any(k.startswith(p) for p in prefixed))
    if bad:
        extra = f" and {', '.join(p + '<wire>' for p in prefixed)}" if prefixed else ""
        raise SceneError(f"{what}: unknown key(s) {bad}; valid keys: {list(valid)}{extra}")


def _num(v: Any, what: str) -> float:
    x = real(v)
    if x is None:
        raise SceneError(f"{what} = {v!r} must be a number")
    return float(x)


def line_from_dict(data: Mapping[str, Any], base: Path, where: str) -> Line:
    """A `Line` from the parsed line file `data` (module docstring); `base` resolves relative CSV names, `where`
    names the file in errors."""
    if not isinstance(data, Mapping):
        raise SceneError(f"{where}: a line must be a table, got {type(data).__name__}")
    _check_keys(data, LINE_FILE_KEYS, where)
    try:
        wires = []
        for i, w in enumerate(data.get("wires") or []):
            if not isinstance(w, dict):
                raise SceneError(f"{where}: wires[{i}] must be a table")
            _check_keys(w, WIRE_KEYS, f"{where} wires[{i}]")
            kw = dict(w)
            if "ends" in kw:
                kw["ends"] = tuple(kw["ends"]) if isinstance(kw["ends"], list) else kw["ends"]
            if "tension_segments" in kw:
                kw["tension_segments"] = tuple(tuple(s) if isinstance(s, list) else s
                                               for s in kw["tension_segments"])
            wires.append(Wire(**kw))
        if not wires:
            raise SceneError(f"{where}: no wires ([[wires]] tables)")
        supports = []
        for i, r in enumerate(_rows(data, "supports", base, where)):
            _check_keys(r, ("x",), f"{where} supports[{i}]", prefixed=("k_", "m_"))
            if "x" not in r:
                raise SceneError(f"{where} supports[{i}]: no x")
            k = {n[2:]: _num(v, f"{where} supports[{i}] {n}") for n, v in r.items() if n.startswith("k_")}
            m = {n[2:]: _num(v, f"{where} supports[{i}] {n}") for n, v in r.items() if n.startswith("m_")}
            supports.append(Support(r["x"], k, m))
        droppers = []
        for i, r in enumerate(_rows(data, "droppers", base, where)):
            _check_keys(r, DROPPER_KEYS, f"{where} droppers[{i}]")
            droppers.append(Dropper(**r))
        clamps = []
        for i, r in enumerate(_rows(data, "clamps", base, where)):
            _check_keys(r, CLAMP_KEYS, f"{where} clamps[{i}]")
            clamps.append(Clamp(**r))
        masses = []
        for i, r in enumerate(_rows(data, "masses", base, where)):
            _check_keys(r, MASS_KEYS, f"{where} masses[{i}]")
            masses.append(PointMass(**r))
    except TypeError as exc:  # a missing required key: the dataclass says which
        raise SceneError(f"{where}: {exc}") from None
    except ParameterError as exc:
        raise SceneError(f"{where}: {exc}") from None
    irr = data.get("irregularity")
    if irr is not None:
        check_irregularity(_resolved(irr, base), f"{where} [irregularity]")
    try:
        return Line(tuple(wires), tuple(supports), tuple(droppers), tuple(clamps), tuple(masses),
                    presag=data.get("presag", 0.0), name=str(data.get("name", Path(where).stem)))
    except ParameterError as exc:
        raise SceneError(f"{where}: {exc}") from None


def read_line_file(path: str | Path) -> tuple[Line, dict[str, Any] | None]:
    """The `Line` of a line file and its `[irregularity]` table (None if it has none: built with the line's length
    by `irregularity.build`)."""
    p = Path(path)
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as exc:
        raise SceneError(f"cannot read line file {p}: {exc.strerror or exc}") from exc
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise SceneError(f"line file {p} is not valid TOML: {exc}") from exc
    if "model" in data:
        raise SceneError(f"{p} is a scene (it has model = ...), not a line file")
    line = line_from_dict(data, p.parent, str(p))
    irr = data.get("irregularity")
    return line, (None if irr is None else _resolved(irr, p.parent))


def _resolved(irr: Any, base: Path) -> Any:
    """An irregularity table with its profile file relative to `base` made absolute."""
    if isinstance(irr, Mapping) and isinstance(irr.get("file"), str) and not Path(irr["file"]).is_absolute():
        return {**irr, "file": str((base / irr["file"]).resolve())}
    return irr


def is_line_file(path: str | Path) -> bool:
    """True when `path` is a TOML file holding a line (`[[wires]]`, no `model`): `mbsuite catenary FILE` runs it
    under the default scene."""
    p = Path(path)
    if p.suffix != ".toml" or not p.is_file():
        return False
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError):
        return False
    return "wires" in data and "model" not in data


# --- the scene's [line] section ----------------------------------------------------------------------------------
LINE_SECTION_KEYS = ("kind", "file", "presag", "stitch", "compound", "irregularity")
LINE_KINDS = ("simple", "stitched", "compound", "file")


def validate_line_section(value: Any, base: Path | None = None) -> dict[str, Any]:
    """Validator of a scene's `[line]` section: `kind` (simple, stitched, compound; `file` when `file` is given),
    `file` (a line file, relative to the scene's folder; read and checked here), `presag`, the builder's parameters
    (`[line.stitch]`, `[line.compound]`: `lines.StitchParams`, `lines.CompoundParams`) and `[line.irregularity]`.
    The line itself is built when the passage starts (`build_line`), from the scene's parameters."""
    from .lines import CompoundParams, StitchParams  # here: lines imports the parameters

    if not isinstance(value, dict):
        raise SceneError(f"[line] must be a table with keys {list(LINE_SECTION_KEYS)}, got {value!r}")
    _check_keys(value, LINE_SECTION_KEYS, "[line]")
    out = dict(value)
    kind = out.setdefault("kind", "file" if "file" in out else "simple")
    if kind not in LINE_KINDS:
        raise SceneError(f"[line] kind = {kind!r}; valid: {list(LINE_KINDS)}")
    if (kind == "file") != ("file" in out):
        raise SceneError("[line] file = ... goes with kind = 'file' (and only with it)")
    for sub, cls in (("stitch", StitchParams), ("compound", CompoundParams)):
        if sub in out:
            if kind != ("stitched" if sub == "stitch" else sub):
                raise SceneError(f"[line.{sub}] is read only with kind = "
                                 f"{'stitched' if sub == 'stitch' else sub!r} (kind is {kind!r})")
            if not isinstance(out[sub], dict):
                raise SceneError(f"[line.{sub}] must be a table")
            try:
                cls(**out[sub])
            except TypeError as exc:
                raise SceneError(f"[line.{sub}]: {exc}") from None
            except MbsuiteError as exc:
                raise SceneError(f"[line.{sub}]: {exc}") from None
    if "presag" in out:
        p = real(out["presag"])
        if p is None or not 0.0 <= p < 0.05:
            raise SceneError(f"[line] presag = {out['presag']!r} (mid-span presag / span length) must lie in [0, 0.05)")
        out["presag"] = float(p)
    if kind == "file":
        f = Path(out["file"]) if isinstance(out["file"], str) else None
        if f is None:
            raise SceneError(f"[line] file = {out['file']!r} must be a file name")
        if not f.is_absolute() and base is not None:
            f = base / f
        out["file"] = str(f.resolve())
        line, irr = read_line_file(f)  # checked now: errors name the file
        if irr is not None and "irregularity" in out:
            raise SceneError(f"[line.irregularity] and the line file {f} both give an irregularity; keep one")
        if "presag" in out and line.presag:
            raise SceneError(f"[line] presag and the line file {f} both give a presag; keep one")
    if "irregularity" in out:
        irr = _resolved(out["irregularity"], base or Path.cwd())
        check_irregularity(irr, "[line.irregularity]")
        out["irregularity"] = irr
    return out


validate_line_section.wants_base = True  # the scene loader passes the scene file's folder


#: the simple line's fields of `CatenaryParams`: a [line] of kind 'file' replaces them (setting one is an error)
SIMPLE_LINE_FIELDS = ("n_spans", "span_length", "cw_mass", "cw_tension", "cw_EI", "mw_mass", "mw_tension", "mw_EI",
                      "dropper_positions", "k_dropper", "k_steady_arm", "k_messenger_support")


def build_line(section: Mapping[str, Any] | None, p, set_params: Iterable[str] = ()) -> Line | None:
    """The `Line` of a checked `[line]` section for the scene's parameters `p` (`CatenaryParams`; `set_params`: the
    keys the scene sets in [params]), or None without a section (the simple line of `p`). A line file replaces the
    simple line's fields: setting one of them as well is a SceneError naming it."""
    from . import irregularity
    from .lines import LINE_KINDS as BUILDERS  # here: lines imports the parameters

    if section is None:
        return None
    kind, presag = section["kind"], float(section.get("presag", 0.0))
    irr = None
    if kind == "file":
        clash = sorted(set(set_params) & set(SIMPLE_LINE_FIELDS))
        if clash:
            raise SceneError(f"[params] {clash} describe the simple line, which [line] file = {section['file']} "
                             "replaces: remove them (or describe them in the line file)")
        line, irr = read_line_file(section["file"])
        if presag:
            line = dataclasses.replace(line, presag=presag)
    else:
        builder, cls = BUILDERS[kind]
        sub = section.get({"stitched": "stitch"}.get(kind, kind), {})
        line = builder(p, cls(**sub), presag=presag) if cls is not None else builder(p, presag=presag)
    irr = section.get("irregularity", irr)
    if irr is not None:
        line = dataclasses.replace(line, irregularity=irregularity.build(irr, line.length, "[line.irregularity]"))
    return line


def scene_params(scene) -> Any:
    """The `CatenaryParams` of a catenary scene (`ModelSpec.params_builder`): its [params] with the line of its
    [line] section (`build_line`; a line file's before the run's positions are checked against its length)."""
    from .params import CatenaryParams

    section = scene.sections.get("line")
    if section is not None and section["kind"] == "file":
        return CatenaryParams(**dict(scene.params), line=build_line(section, None, scene.params))
    p = CatenaryParams(**dict(scene.params))
    line = build_line(section, p, scene.params)
    return p if line is None else dataclasses.replace(p, line=line)
