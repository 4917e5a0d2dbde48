"""A line described in a file (TOML, with CSV tables for long lists) and the scene's `[line]` section.

Line file (model README, "Lines of your own"; every length in m, mass in kg or kg/m, force in N, stiffness N/m)::

    name = "my section"
    presag = 0.0005                      # mid-span presag / span length (parabolic), optional
    [[wires]]                            # one table per wire; role = "contact": one spanning the line, or a route's
    name = "contact"; role = "contact"; mass = 1.35; tension = 20000; EI = 195; x0 = 0; x1 = 600   # several
    ends = ["pinned", "pinned"]          # or "free" (held by clamps)
    tension_segments = [[51, 69, 12500]] # optional: T between x_a and x_b
    heights = [[0, 0], [540, 0.1], [600, 0.5]]   # optional, a contact wire: design heights (x, z), linear
    [[supports]]                         # or supports_file = "supports.csv" (same keys as columns)
    x = 0; k_contact = 300; k_messenger = 5e4; m_contact = 1.0     # k_<wire>: ground spring, m_<wire>: mass
    [[droppers]]                         # or droppers_file = "droppers.csv"
    x = 5; upper = "messenger"; lower = "contact"; k = 1e5; law = "slack"; mass = 0.2; clamp_upper = 0.1
    [[clamps]]                           # or clamps_file: x, a, b, k
    [[masses]]                           # or masses_file: x, wire, m
    [[insulators]]                       # or insulators_file: x, wire, length, mass, EI (section insulators)
    x = 30; wire = "contact"; length = 2.0; mass = 12.0; EI = 2000.0
    [irregularity]                       # optional, see `irregularity.py`

Relative file names are read from the line file's folder. Every key is checked: an unknown one is an error naming it
and the file (no silently ignored input).
"""

from __future__ import annotations

import csv
import dataclasses
import re
import tomllib
import warnings
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from ...errors import MbsuiteError, ParameterError, SceneError
from ...limits import Limit, limit_of
from ...schema import Items, Rule, Section, of_dataclass, toml_error
from .irregularity import SECTION as IRREGULARITY
from .irregularity import check_irregularity
from .line import PRESAG, SUPPORT_K, SUPPORT_M, Clamp, Dropper, Line, PointMass, SectionInsulator, Support, Wire
from .lines import CompoundParams, OverlapParams, StitchParams
from .mesh import line_of

TABLES = ("supports", "droppers", "clamps", "masses", "insulators")
#: most rows of one table (a tension section of 1 600 m has ~30 supports and ~250 droppers)
MAX_ROWS = 100_000
#: most wires of one line
MAX_WIRES = 64
#: largest line file (bytes)
MAX_FILE_BYTES = 16_000_000

WIRE = of_dataclass(Wire, "wire", doc="a tensioned wire over [x0, x1]; the wires with role = 'contact' cover the "
                                      "line (one, or a route's several overlapping ones)")
SUPPORT = Section("support", {"x": limit_of(Support, "x")}, required=("x",),
                  prefixed={"k_": SUPPORT_K, "m_": SUPPORT_M},
                  doc="a support at x: k_<wire> ground springs and m_<wire> point masses on the named wires")
DROPPER = of_dataclass(Dropper, "dropper", doc="a dropper from wire upper to wire lower")
CLAMP = of_dataclass(Clamp, "clamp", doc="a bilateral spring between the w displacements of wires a and b")
MASS = of_dataclass(PointMass, "point mass", doc="a point mass on a wire (a connector, a registration clamp)")
INSULATOR = of_dataclass(SectionInsulator, "insulator", doc="a section insulator (or other stiffening mass) centred "
                         "at x on a wire over [x - length/2, x + length/2]: its mass spread over its length, its EI "
                         "added to the wire's")
ROWS = {"supports": SUPPORT, "droppers": DROPPER, "clamps": CLAMP, "masses": MASS, "insulators": INSULATOR}


def _one_source(table: str):
    def test(d: Mapping[str, Any]) -> str | None:
        if table in d and f"{table}_file" in d:
            return f"give {table} either inline ([[{table}]]) or as {table}_file, not both"
        return None
    return test


def _supports_given(d: Mapping[str, Any]) -> str | None:
    return None if ("supports" in d or "supports_file" in d) else "no supports: give [[supports]] or supports_file"


#: an example line file with every kind of row and key (the docs show it, the generated input tests move each key):
#: two 50 m spans, a stitch wire, tension segments, masses, a section insulator, presag and a random irregularity
EXAMPLE: dict[str, Any] = {
    "name": "two spans", "presag": 0.0005,
    "wires": [
        {"name": "contact", "role": "contact", "mass": 1.35, "tension": 20000.0, "EI": 195.0, "x0": 0.0, "x1": 100.0},
        {"name": "messenger", "role": "messenger", "mass": 1.07, "tension": 16000.0, "EI": 131.7, "x0": 0.0,
         "x1": 100.0, "tension_segments": [[42.0, 58.0, 12500.0]]},
        {"name": "stitch", "role": "stitch", "mass": 0.31, "tension": 3500.0, "EI": 10.0, "x0": 42.0, "x1": 58.0,
         "ends": ["free", "free"]},
    ],
    "supports": [{"x": 0.0},
                 {"x": 50.0, "k_contact": 300.0, "k_messenger": 5e4, "m_contact": 1.0, "m_messenger": 0.5},
                 {"x": 100.0}],
    "droppers": [{"x": x, "upper": "messenger", "lower": "contact", "k": 1e5} for x in (10.0, 25.0, 40.0, 60.0, 75.0,
                                                                                       90.0)]
    + [{"x": 46.0, "upper": "stitch", "lower": "contact", "k": 1e5, "mass": 0.08, "clamp_upper": 0.065,
        "clamp_lower": 0.165, "law": "linear"}],
    "clamps": [{"x": 42.0, "a": "stitch", "b": "messenger", "k": 1e7},
               {"x": 58.0, "a": "stitch", "b": "messenger", "k": 1e7}],
    "masses": [{"x": 30.0, "wire": "contact", "m": 0.6}],
    "insulators": [{"x": 70.0, "wire": "contact", "length": 2.0, "mass": 12.0, "EI": 2000.0}],
    "irregularity": {"seed": 3, "rms": 0.002, "wavelength_min": 2.0, "wavelength_max": 40.0, "n_waves": 200},
}

#: the declaration of a line file (module docstring); the rows of a CSV table are checked by the same row sections
LINE_FILE = Section("line file", {
    "name": Limit(kind=str, doc="the line's name (default: the file's stem)"),
    "presag": dataclasses.replace(PRESAG, default=0.0),
    "wires": Items(WIRE, min=1, max=MAX_WIRES, doc="the wires ([[wires]] tables)"),
    **{t: Items(ROWS[t], max=MAX_ROWS, doc=f"the {t} ([[{t}]] tables)") for t in TABLES},
    **{f"{t}_file": Limit(kind=str, doc=f"CSV file of the {t} (a column per key of [[{t}]])") for t in TABLES},
    "irregularity": IRREGULARITY,
}, required=("wires",), rules=(
    *(Rule(f"{t} inline or as {t}_file, not both", _one_source(t), given=True) for t in TABLES),
    Rule("supports are given (inline or as supports_file)", _supports_given, given=True),
), doc="one tension section, or a route of several (their contact wires overlapping): wires, supports, droppers, "
       "clamps, point masses, section insulators, presag and an irregularity",
    example=EXAMPLE)


def _rows(data: Mapping[str, Any], table: str, base: Path, where: str) -> list[tuple[dict[str, Any], str]]:
    """The rows of `table` with where each came from: the checked TOML array of tables, or the CSV file
    `<table>_file` (each row checked by the same section)."""
    fname = data.get(f"{table}_file")
    if fname is None:
        return [(r, f"{where} {table}[{i}]") for i, r in enumerate(data.get(table, []))]
    path = (base / fname) if not Path(fname).is_absolute() else Path(fname)
    rows = []
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            for i, r in enumerate(reader):
                if i >= MAX_ROWS:
                    raise SceneError(f"{path}: more than {MAX_ROWS:,} rows")
                if None in r or any(v is None for v in r.values()):
                    raise SceneError(f"{path} row {i + 2}: {len(r)} columns where the header has "
                                     f"{len(reader.fieldnames or [])}")
                at = f"{path} row {i + 2}"
                rows.append((ROWS[table].check({k.strip(): _cell(v) for k, v in r.items()}, at), at))
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


def line_from_dict(data: Mapping[str, Any], base: Path, where: str) -> Line:
    """A `Line` from the parsed line file `data` (module docstring, `LINE_FILE`); `base` resolves relative CSV and
    profile names, `where` names the file in errors."""
    raw, data = data, LINE_FILE.check(data, where)
    built: dict[str, list[Any]] = {}
    for table, make in (("supports", _support), ("droppers", Dropper), ("clamps", Clamp), ("masses", PointMass),
                        ("insulators", SectionInsulator)):
        built[table] = []
        for row, at in _rows(data, table, base, where):
            try:
                built[table].append(make(**row))
            except ParameterError as exc:
                raise SceneError(f"{at}: {exc}") from None
    wires = []
    for i, w in enumerate(data["wires"]):
        try:
            wires.append(Wire(**w))
        except ParameterError as exc:
            raise SceneError(f"{where} wires[{i}]: {exc}") from None
    if "irregularity" in raw:
        check_irregularity(_resolved(raw["irregularity"], base), f"{where} [irregularity]")
    try:
        return Line(tuple(wires), tuple(built["supports"]), tuple(built["droppers"]), tuple(built["clamps"]),
                    tuple(built["masses"]), presag=data["presag"], name=data.get("name", Path(where).stem),
                    insulators=tuple(built["insulators"]))
    except ParameterError as exc:
        raise SceneError(f"{where}: {exc}") from None


def _support(x: float, **keys: float) -> Support:
    return Support(x, {k[2:]: v for k, v in keys.items() if k.startswith("k_")},
                   {k[2:]: v for k, v in keys.items() if k.startswith("m_")})


def read_line_file(path: str | Path) -> tuple[Line, dict[str, Any] | None]:
    """The `Line` of a line file and its `[irregularity]` table (None if it has none: built with the line's length
    by `irregularity.build`)."""
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > MAX_FILE_BYTES:
            raise SceneError(f"line file {p} is {size:,} bytes; at most {MAX_FILE_BYTES:,} (long tables go in CSV "
                             "files)")
        text = p.read_text(encoding="utf-8")
        data = tomllib.loads(text)
    except OSError as exc:
        raise SceneError(f"cannot read line file {p}: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise SceneError(f"line file {p} is not UTF-8 text (byte {exc.start}): TOML files are UTF-8") from exc
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"line file {p} is not valid TOML: {toml_error(exc, text)}") from exc
    except RecursionError as exc:
        raise SceneError(f"line file {p} nests arrays or tables too deeply to be a line") from exc
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
        with open(p, "rb") as fh:
            head = fh.read(MAX_FILE_BYTES + 1)
        text = head.decode("utf-8", errors="replace")
        data = tomllib.loads(text) if len(head) <= MAX_FILE_BYTES else None
    except OSError:
        return False
    except (tomllib.TOMLDecodeError, RecursionError):
        data = None
    if data is None:  # not readable as TOML: a line file if it says so (its reader then names what is wrong)
        return re.search(r"^\s*\[\[\s*[\"']?wires[\"']?\s*\]\]", text, re.M) is not None and \
            re.search(r"^\s*[\"']?model[\"']?\s*=", text, re.M) is None
    return "wires" in data and "model" not in data


# --- the scene's [line] section ----------------------------------------------------------------------------------
LINE_KINDS = ("simple", "stitched", "compound", "overlap", "file")


def _kind_matches(d: Mapping[str, Any]) -> str | None:
    kind = d.get("kind", "file" if "file" in d else "simple")
    if (kind == "file") != ("file" in d):
        return "file = ... goes with kind = 'file' (and only with it)"
    for sub, owner in (("stitch", "stitched"), ("compound", "compound"), ("overlap", "overlap")):
        if sub in d and kind != owner:
            return f"[line.{sub}] is read only with kind = {owner!r} (kind is {kind!r})"
    return None


#: the declaration of a scene's [line] section
LINE_SECTION = Section("[line]", {
    "kind": Limit(kind=str, choices=LINE_KINDS, doc="simple, stitched, compound or overlap (built from [params]), "
                                                    "or file (absent: file with file = ..., else simple)"),
    "file": Limit(kind=str, doc="a line file, relative to the scene's folder"),
    "presag": PRESAG,
    "stitch": of_dataclass(StitchParams, "[line.stitch]", doc="the stitch wires of kind = 'stitched'"),
    "compound": of_dataclass(CompoundParams, "[line.compound]", doc="the auxiliary wire of kind = 'compound'"),
    "overlap": of_dataclass(OverlapParams, "[line.overlap]", doc="the sections and overlaps of kind = 'overlap'"),
    "masses": Items(MASS, max=MAX_ROWS, doc="point masses added to the line, any kind ([[line.masses]] tables)"),
    "insulators": Items(INSULATOR, max=MAX_ROWS, doc="section insulators added to the line, any kind "
                                                     "([[line.insulators]] tables)"),
    "irregularity": IRREGULARITY,
}, rules=(Rule("kind = 'file' with file, and [line.stitch] / [line.compound] / [line.overlap] only with their kind",
               _kind_matches,
               given=True),), doc="the line of a catenary scene",
    example={"kind": "stitched", "presag": 0.0005, "stitch": {"half_length": 9.0, "k_clamp": 1e7},
             "irregularity": {"seed": 1, "psd": [[0.01, 1e-6], [0.5, 1e-8]], "dx": 0.05}})


def validate_line_section(value: Any, base: Path | None = None) -> dict[str, Any]:
    """Validator of a scene's `[line]` section (`LINE_SECTION`): `kind`, `file` (a line file, relative to the
    scene's folder; read and checked here), `presag`, the builder's parameters (`[line.stitch]`, `[line.compound]`:
    `lines.StitchParams`, `lines.CompoundParams`) and `[line.irregularity]`. The line itself is built when the
    passage starts (`build_line`), from the scene's parameters."""
    given = set(value) if isinstance(value, Mapping) else set()
    out = {k: v for k, v in LINE_SECTION.check(value, "[line]").items() if k in given}
    kind = out.setdefault("kind", "file" if "file" in out else "simple")
    for sub, cls in (("stitch", StitchParams), ("compound", CompoundParams), ("overlap", OverlapParams)):
        if sub in out:
            try:
                cls(**out[sub])
            except MbsuiteError as exc:
                raise SceneError(f"[line.{sub}]: {exc}") from None
    if kind == "file":
        f = Path(out["file"])
        if not f.is_absolute() and base is not None:
            f = base / f
        out["file"] = str(f.resolve())
        line, irr = read_line_file(f)  # checked now: errors name the file
        if irr is not None and "irregularity" in out:
            raise SceneError(f"[line.irregularity] and the line file {f} both give an irregularity; keep one")
        if "presag" in out and line.presag:
            raise SceneError(f"[line] presag and the line file {f} both give a presag; keep one")
    if "irregularity" in out:
        irr = _resolved(value["irregularity"], base or Path.cwd())
        check_irregularity(irr, "[line.irregularity]")
        out["irregularity"] = irr
    return out


validate_line_section.wants_base = True  # the scene loader passes the scene file's folder
validate_line_section.schema = LINE_SECTION


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
    added = {"masses": [PointMass(**r) for r in section.get("masses", ())],
             "insulators": [SectionInsulator(**r) for r in section.get("insulators", ())]}
    if added["masses"] or added["insulators"]:  # checked with the line they join (on its wires, not overlapping)
        try:
            line = dataclasses.replace(line, masses=(*line.masses, *added["masses"]),
                                       insulators=(*line.insulators, *added["insulators"]))
        except MbsuiteError as exc:
            raise SceneError(f"[line] masses / insulators: {exc}") from None
    irr = section.get("irregularity", irr)
    if irr is not None:
        line = dataclasses.replace(line, irregularity=irregularity.build(irr, line.length, "[line.irregularity]"))
    return line


def scene_params(scene) -> Any:
    """The `CatenaryParams` of a catenary scene (`ModelSpec.params_builder`): its [params] with the line of its
    [line] section (`build_line`; a line file's before the run's positions are checked against its length) and the
    statistics window (`_windowed`: the scene's, else the line's default)."""
    from .params import CatenaryParams

    section = scene.sections.get("line")
    given = dict(scene.params)
    if section is not None and section["kind"] == "overlap":  # its length is its own: the run is checked against it
        base = CatenaryParams(**{k: v for k, v in given.items() if k not in RUN_KEYS})
        line = build_line(section, base, scene.params)
        return _windowed(line, given, lambda **w: CatenaryParams(**{**given, **w}, line=line))
    if section is not None and section["kind"] == "file":
        line = build_line(section, None, scene.params)
        return _windowed(line, given, lambda **w: CatenaryParams(**{**given, **w}, line=line))
    p = CatenaryParams(**given, **_provisional_window(given))
    line = build_line(section, p, scene.params) or line_of(p)
    return _windowed(line, given, lambda **w: dataclasses.replace(
        p, **w, **({} if section is None else {"line": line})))


#: the run's and the statistics' keys of [params] (checked against a line's length once it is built)
RUN_KEYS = ("x_start", "x_end", "window_start", "window_end", "windows")


def _provisional_window(given: Mapping[str, Any]) -> dict[str, Any]:
    """Where the scene sets no window: the whole run [x_start, x_end] as the window while the line is built (the
    parameters' own default, [240, 360] m, need not lie in the run of a shorter simple line); `_windowed` replaces
    it by the line's default."""
    if "window_start" in given or "window_end" in given:
        return {}
    from .params import CatenaryParams

    d = CatenaryParams()
    return {"window_start": given.get("x_start", d.x_start), "window_end": given.get("x_end", d.x_end)}


def _windowed(line: Line, given: Mapping[str, Any], make: Any) -> Any:
    """The parameters `make(**window)` with the statistics window: the scene's (a `WindowOffSupportWarning` where an
    edge of it, or of a further window `windows`, is off the supports of `line`), else `marks.default_window(line)`
    (on the EN 50318 line the parameters' own default, [240, 360] m); a default window outside the run is a
    ParameterError naming the rule and the keys to set."""
    from .marks import WindowOffSupportWarning, default_window, window_off_supports

    def warned(p: Any, windows: list) -> Any:
        for a, b in windows:  # the headline window (when the scene gives it) and every further one
            msg = window_off_supports(line, a, b)
            if msg is not None:
                warnings.warn(msg, WindowOffSupportWarning, stacklevel=5)
        return p

    if "window_start" in given or "window_end" in given:
        p = make()
        return warned(p, [(p.window_start, p.window_end), *p.windows])
    a, b = default_window(line)
    try:
        p = make(window_start=a, window_end=b)
        return warned(p, p.windows)
    except ParameterError as exc:
        if "statistics window" not in str(exc):
            raise
        raise ParameterError(
            f"the default statistics window [{a:g}, {b:g}] m of the line {line.name!r} (its supports: model README, "
            f"'The statistics window') does not lie in the run: {exc}; set params.window_start and "
            "params.window_end, or params.x_start and params.x_end around it") from exc
