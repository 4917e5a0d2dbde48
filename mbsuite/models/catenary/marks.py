"""What the catenary's figures and tables mark of the line a passage ran (`mesh.line_of(params)`): its supports,
droppers, stitch-wire spans, the overlaps of its contact wires and their anchors inside a stretch of track
(`line_marks`), and the line's name for titles and table headers (`line_label`). Pure functions of the `Line` (and
the parameters), nothing drawn here."""

from __future__ import annotations

import hashlib
import tomllib
from pathlib import Path
from typing import Any

from .line import Line
from .params import CatenaryParams

#: the simple line's fields (`CatenaryParams`): equal to the defaults, the simple line is the EN 50318 reference line
_SIMPLE_FIELDS = ("n_spans", "span_length", "cw_mass", "cw_tension", "cw_EI", "mw_mass", "mw_tension", "mw_EI",
                  "dropper_positions", "k_dropper", "k_steady_arm", "k_messenger_support")
REFERENCE_LINE = "EN 50318 reference line"
#: the names of the lines `lines.py` builds from the simple line's fields
_BUILT = ("stitched", "compound")


def line_marks(line: Line, x_range: tuple[float, float] | None = None) -> dict[str, list]:
    """The marks of `line` inside `x_range` = (a, b) (m, ends included; None: the whole line), each sorted:

    - `supports`: the supports' x (m);
    - `droppers`: the droppers' x, one per position;
    - `stitch`: the (x0, x1) of every stitch wire that overlaps the range, clipped to it;
    - `overlaps`: the (x0, x1) where two contact wires are both present (a route's overlap of two tension sections:
      the common part of their x-ranges `Wire.x0`..`Wire.x1`), clipped to the range; none on one contact wire;
    - `anchors`: (x, wire name) of every pinned end of a contact wire inside the line (the line's own ends at 0 and at
      its length are not anchors), e.g. (300, "contact_b") and (480, "contact_a") on `catenary/en50318_overlap`;
    - `insulators`: (x_a, x_b, wire name) of every section insulator on a contact wire that overlaps the range (its
      own extent, `SectionInsulator.x_a`..`x_b`)."""
    a, b = (0.0, line.length) if x_range is None else (float(x_range[0]), float(x_range[1]))
    sup = [float(s.x) for s in line.supports if a <= s.x <= b]
    drop = sorted({float(d.x) for d in line.droppers if a <= d.x <= b})
    stitch = sorted((max(float(w.x0), a), min(float(w.x1), b)) for w in line.wires
                    if w.role == "stitch" and w.x1 > a and w.x0 < b)
    cws = line.contacts
    both = {(max(float(u.x0), float(v.x0)), min(float(u.x1), float(v.x1)))
            for i, u in enumerate(cws) for v in cws[i + 1:]}
    overlaps = sorted((max(x0, a), min(x1, b)) for x0, x1 in both if x1 > x0 and x1 > a and x0 < b)
    ends = {(float(x), w.name) for w in cws for x in (w.x0, w.x1)
            if line.pinned_end(w, x) and 0.0 < x < line.length and a <= x <= b}
    names = {w.name for w in cws}
    ins = sorted((float(i.xa), float(i.xb), i.wire) for i in line.insulators
                 if i.wire in names and i.xb > a and i.xa < b)
    return {"supports": sup, "droppers": drop, "stitch": stitch, "overlaps": overlaps, "anchors": sorted(ends),
            "insulators": ins}


def line_label(p: CatenaryParams) -> str:
    """The name of the line of `p` for titles and tables: a line file's "line 'NAME'" (its `name`, else the file's
    stem); the simple line's: "EN 50318 reference line" (the default fields), "EN 50318 line of N spans" (more or
    fewer of its spans), else "simple line, N spans of L m"; "stitched line (on ...)", "compound line (on ...)" for
    the builders of `lines.py` on it."""
    d = CatenaryParams()
    if all(getattr(p, f) == getattr(d, f) for f in _SIMPLE_FIELDS if f != "n_spans"):
        simple = REFERENCE_LINE if p.n_spans == d.n_spans else f"EN 50318 line of {p.n_spans} spans"
    else:
        simple = f"simple line, {p.n_spans} spans of {p.span_length:g} m"
    if p.line is None or p.line.name == "simple":
        return simple
    if p.line.name in _BUILT:
        return f"{p.line.name} line (on the {simple})"
    if p.line.name == "overlap":
        return f"overlap of two sections ({len(p.line.contacts)} contact wires)"
    return f"line {p.line.name!r}"


def line_identity(p: CatenaryParams, file: str | Path | None = None) -> dict[str, Any]:
    """The line's identity as a rerun needs it: its `name` (`line_label`) and `kind` ("simple": the fields of the
    parameters; "line": a `Line` of its own); with the line's `file` (a scene's `[line] file`) its path and the
    SHA-256 of its content, and `files`: path -> SHA-256 of every table it reads (`*_file` keys: supports, droppers,
    a height profile), so a changed file is seen."""
    out: dict[str, Any] = {"name": line_label(p), "kind": "simple" if p.line is None else "line"}
    if file is not None:
        path = Path(file)
        out["file"] = str(path)
        out["sha256"] = file_sha256(path)
        try:
            data = tomllib.loads(path.read_text())
        except (OSError, tomllib.TOMLDecodeError):
            data = {}
        refs = [v for k, v in data.items() if k.endswith("_file") and isinstance(v, str)]
        irr = data.get("irregularity")
        if isinstance(irr, dict) and isinstance(irr.get("file"), str):
            refs.append(irr["file"])
        out["files"] = {str(path.parent / r): file_sha256(path.parent / r) for r in refs}
    return out


def line_changed(recorded: dict[str, Any]) -> list[str]:
    """The files of a line's identity as `line_identity` recorded it (the line file, the tables it reads) whose
    content is no longer the recorded one (changed or gone), by their paths; [] for a line without files."""
    files = dict(recorded.get("files") or {})
    if recorded.get("file") is not None:
        files = {recorded["file"]: recorded.get("sha256"), **files}
    return [f for f, h in files.items() if file_sha256(Path(f)) != h]


def file_sha256(path: str | Path) -> str | None:
    """The SHA-256 (hex) of the file's content; None where it cannot be read."""
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


# --- the statistics window on the line's supports -------------------------------------------------------------------
#: the default window: the two spans from the fifth support (index 4, counted from the line's start at x = 0) to the
#: seventh, where the line goes on at least one span past it (seven spans or more): [240, 360] m on the EN 50318 line
#: (supports every 60 m), also when it is lengthened for a train; on a shorter line from the support nearest 0.4 L to
#: the support nearest 0.6 L (L: its length; the middle span or two). Either way the first and the last span are out
#: of it from three spans on. Model README, "The statistics window".
WINDOW_SUPPORTS = (4, 6)
WINDOW_FRACTIONS = (0.4, 0.6)
#: a window edge within this distance (m) of a support is on it
ON_SUPPORT_TOL = 1e-6


class WindowOffSupportWarning(UserWarning):
    """A statistics window given in a scene does not start and end on supports of its line."""


def default_window(line: Line) -> tuple[float, float]:
    """The default statistics window of `line` (a scene that sets neither window_start nor window_end; model README,
    "The statistics window"): from its fifth support to its seventh (`WINDOW_SUPPORTS`: [240, 360] m on the EN 50318
    line) where an eighth follows; on a line of fewer than eight supports from the support nearest 0.4 L to the one
    nearest 0.6 L (the lower of two equally near; the next support where both would be one)."""
    xs = sorted(float(s.x) for s in line.supports)
    i, j = WINDOW_SUPPORTS
    if len(xs) > j + 1:
        return xs[i], xs[j]
    L = line.length

    def nearest(x: float) -> int:
        return min(range(len(xs)), key=lambda k: (abs(xs[k] - x), xs[k]))

    i, j = nearest(WINDOW_FRACTIONS[0] * L), nearest(WINDOW_FRACTIONS[1] * L)
    if j <= i:
        j = min(i + 1, len(xs) - 1)
        i = j - 1
    return xs[i], xs[j]


def window_off_supports(line: Line, start: float, end: float) -> str | None:
    """One line naming the window [start, end] and the supports nearest each edge that is not on one (None: both
    edges on supports, to `ON_SUPPORT_TOL`)."""
    xs = [s.x for s in line.supports]
    off = []
    for what, x in (("starts", start), ("ends", end)):
        if min(abs(s - x) for s in xs) > ON_SUPPORT_TOL:
            below = max((s for s in xs if s < x), default=None)
            above = min((s for s in xs if s > x), default=None)
            near = " and ".join(f"{s:g} m" for s in (below, above) if s is not None)
            off.append(f"{what} at {x:g} m between the supports at {near}")
    if not off:
        return None
    return (f"the statistics window [{start:g}, {end:g}] m on the line {line.name!r} " + " and ".join(off)
            + ": EN 50318 statistics are taken over whole spans (set window_start/window_end on supports)")
