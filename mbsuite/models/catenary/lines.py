"""The shipped lines as `line.Line` builders: the EN 50318:2002 simple line from `CatenaryParams` (`simple`), its
stitched variant (`stitched`, the scene `catenary/en50318_stitched`, model README "A stitched line"), a
three-wire compound line (`compound`), a route of tension sections chained into one line (`route`) and the overlap
of two EN 50318 sections (`overlap`, the scene `catenary/en50318_overlap`, model README "Overlaps and routes").
`LINE_KINDS` maps the `kind` of a scene's `[line]` section to a builder and its parameter dataclass."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import ParameterError
from ...limits import check_fields, param
from .line import Clamp, Dropper, Line, SectionInsulator, Support, Wire
from .params import CatenaryParams

CONTACT, MESSENGER, STITCH, AUXILIARY = "contact", "messenger", "stitch", "auxiliary"


def _simple_wires(p: CatenaryParams) -> tuple[Wire, Wire]:
    L = p.n_spans * p.span_length
    return (Wire(CONTACT, CONTACT, p.cw_mass, p.cw_tension, p.cw_EI, 0.0, L),
            Wire(MESSENGER, MESSENGER, p.mw_mass, p.mw_tension, p.mw_EI, 0.0, L))


def _supports(p: CatenaryParams, **extra: float) -> list[Support]:
    """Steady arm and messenger support at every interior support; the end supports hold the wires' pinned ends."""
    return [Support(s * p.span_length, {CONTACT: p.k_steady_arm, MESSENGER: p.k_messenger_support, **extra}
                    if 0 < s < p.n_spans else {}) for s in range(p.n_spans + 1)]


def simple(p: CatenaryParams, presag: float = 0.0) -> Line:
    """The simple catenary of `p` (EN 50318:2002 by default): contact and messenger wire pinned at both ends, steady
    arm and messenger support at every support, `p.dropper_positions` in every span (the scene's dropper law)."""
    drop = [Dropper(s * p.span_length + d, MESSENGER, CONTACT, p.k_dropper)
            for s in range(p.n_spans) for d in p.dropper_positions]
    return Line(_simple_wires(p), tuple(_supports(p)), tuple(drop), presag=presag, name="simple")


@dataclass(frozen=True)
class StitchParams:
    """Stitch wires at every interior support (model README, "A stitched line"; defaults: mbsuite's fixed stitched
    variant of the EN 50318:2002 line, bronze 35 mm^2)."""

    half_length: float = param(9.0, lo=0.0, lo_open=True, hi=100.0, unit="m",
                               doc="stitch wire from x_s - half_length to x_s + half_length")
    mass: float = param(0.31, lo=0.0, hi=100.0, unit="kg/m", doc="stitch wire mass per length")
    tension: float = param(3500.0, lo=0.0, hi=1e6, unit="N", doc="stitch wire tension")
    EI: float = param(10.0, lo=0.0, hi=1e6, unit="N m^2", doc="stitch wire bending stiffness")
    k_clamp: float = param(1e7, lo=0.0, lo_open=True, hi=1e15, unit="N/m",
                           doc="clamps joining the stitch wire's ends to the messenger (bilateral, vertical)")
    dropper_offset: float = param(5.0, lo=0.0, lo_open=True, hi=100.0, unit="m",
                                  doc="the droppers at x_s +- dropper_offset hang from the stitch wire")
    messenger_relief: bool = param(True, kind=bool, doc="the messenger carries T_mw - T_stitch between the clamps "
                                                          "(horizontal equilibrium)")

    def __post_init__(self) -> None:
        check_fields(self, "stitch parameter")
        if not self.dropper_offset < self.half_length:
            raise ParameterError(f"stitch dropper_offset = {self.dropper_offset} m must lie inside the stitch wire "
                                 f"(half_length = {self.half_length} m)")


def stitched(p: CatenaryParams, s: StitchParams | None = None, presag: float = 0.0) -> Line:
    """The simple line of `p` with a stitch wire at every interior support x_s: a tensioned beam over
    [x_s - a, x_s + a] with free ends clamped to the messenger, the droppers at x_s +- dropper_offset hanging from it;
    the messenger carries T_mw - T_stitch between the clamps (`messenger_relief`)."""
    s = s or StitchParams()
    base = simple(p)
    cw, mw = base.wires
    interior = [k * p.span_length for k in range(1, p.n_spans)]
    a = s.half_length
    for xs in interior:
        if xs - a < 0 or xs + a > base.length:
            raise ParameterError(f"stitch wire at x = {xs} m reaches beyond the line [0, {base.length}] m")
    if a > p.span_length / 2:
        raise ParameterError(f"stitch half_length = {a} m exceeds half a span ({p.span_length / 2} m): neighbouring "
                             "stitch wires would overlap")
    if s.messenger_relief:
        if not s.tension < mw.tension:
            raise ParameterError(f"stitch tension {s.tension} N must be below the messenger's {mw.tension} N")
        mw = Wire(mw.name, mw.role, mw.mass, mw.tension, mw.EI, mw.x0, mw.x1,
                  tension_segments=tuple((xs - a, xs + a, mw.tension - s.tension) for xs in interior))
    stitches = [Wire(f"{STITCH}{i + 1}", STITCH, s.mass, s.tension, s.EI, xs - a, xs + a, ends=("free", "free"))
                for i, xs in enumerate(interior)]
    clamps = [Clamp(xs + side * a, w.name, MESSENGER, s.k_clamp) for xs, w in zip(interior, stitches, strict=True)
              for side in (-1, 1)]
    # the droppers at x_s +- dropper_offset, matched to 1e-9 of the line's length (the dropper's x is computed from
    # the span and its position in the span, this one from the support: equal up to rounding, and up to the draws
    # of the stability check)
    tol = 1e-9 * max(1.0, base.length)
    dx = np.array([d.x for d in base.droppers])
    on_stitch: dict[int, str] = {}
    missing = []
    for xs, w in zip(interior, stitches, strict=True):
        for side in (-1, 1):
            xt = xs + side * s.dropper_offset
            near = np.nonzero(np.abs(dx - xt) <= tol)[0]
            if near.size:
                on_stitch[int(near[0])] = w.name
            else:
                missing.append(xt)
    if missing:
        raise ParameterError(f"stitch droppers: no dropper at x = {missing[:4]} m (dropper_offset = "
                             f"{s.dropper_offset} m from the interior supports); dropper_positions are "
                             f"{p.dropper_positions}")
    droppers = [Dropper(d.x, on_stitch[i], d.lower, d.k, d.law) if i in on_stitch else d
                for i, d in enumerate(base.droppers)]
    return Line((cw, mw, *stitches), base.supports, tuple(droppers), tuple(clamps), presag=presag, name="stitched")


@dataclass(frozen=True)
class CompoundParams:
    """The auxiliary wire of a compound catenary (mbsuite's example: messenger and contact wire of `CatenaryParams`,
    an auxiliary wire between them; values of a copper 120 mm^2 wire, not a standard's)."""

    mass: float = param(1.07, lo=0.0, lo_open=True, hi=100.0, unit="kg/m", doc="auxiliary wire mass per length")
    tension: float = param(15000.0, lo=0.0, lo_open=True, hi=1e6, unit="N", doc="auxiliary wire tension")
    EI: float = param(130.0, lo=0.0, hi=1e6, unit="N m^2", doc="auxiliary wire bending stiffness")
    k_support: float = param(5.0e4, lo=0.0, hi=1e10, unit="N/m", doc="auxiliary wire to ground at each support")
    contact_dropper_spacing: float = param(5.0, lo=0.5, hi=100.0, unit="m",
                                           doc="contact-wire droppers (to the auxiliary wire) every this, "
                                               "starting half of it from each support")

    def __post_init__(self) -> None:
        check_fields(self, "compound parameter")


def compound(p: CatenaryParams, c: CompoundParams | None = None, presag: float = 0.0) -> Line:
    """A compound catenary: the messenger (p) carries the auxiliary wire by droppers at `p.dropper_positions`, the
    auxiliary carries the contact wire by droppers every `contact_dropper_spacing`; all three pinned at both ends,
    ground springs at every support on each."""
    c = c or CompoundParams()
    cw, mw = _simple_wires(p)
    L = p.n_spans * p.span_length
    aux = Wire(AUXILIARY, AUXILIARY, c.mass, c.tension, c.EI, 0.0, L)
    n = int(p.span_length // c.contact_dropper_spacing)
    if n < 1:
        raise ParameterError(f"contact_dropper_spacing = {c.contact_dropper_spacing} m exceeds the span "
                             f"({p.span_length} m)")
    first = (p.span_length - (n - 1) * c.contact_dropper_spacing) / 2
    drop = [Dropper(s * p.span_length + d, MESSENGER, AUXILIARY, p.k_dropper)
            for s in range(p.n_spans) for d in p.dropper_positions]
    drop += [Dropper(s * p.span_length + first + i * c.contact_dropper_spacing, AUXILIARY, CONTACT, p.k_dropper)
             for s in range(p.n_spans) for i in range(n)]
    sup = _supports(p, **{AUXILIARY: c.k_support})
    return Line((cw, mw, aux), tuple(sup), tuple(drop), presag=presag, name="compound")


def shifted(line: Line, dx: float) -> list[Any]:
    """The parts of `line` moved by dx (m) along the track: wires (their heights profile and tension segments
    too), supports, droppers, clamps, masses, insulators."""
    wires = [dataclasses.replace(w, x0=w.x0 + dx, x1=w.x1 + dx,
                                 tension_segments=tuple((a + dx, b + dx, T) for a, b, T in w.tension_segments),
                                 heights=tuple((x + dx, z) for x, z in w.heights)) for w in line.wires]
    return [wires, [Support(s.x + dx, dict(s.k), dict(s.m)) for s in line.supports],
            [dataclasses.replace(d, x=d.x + dx) for d in line.droppers],
            [dataclasses.replace(c, x=c.x + dx) for c in line.clamps],
            [dataclasses.replace(m, x=m.x + dx) for m in line.masses],
            [dataclasses.replace(s, x=s.x + dx) for s in line.insulators]]


def route(sections: Sequence[Line | tuple[float, Line]], name: str = "route") -> Line:
    """Tension sections chained into one line (one FE system: the sections' wires are simply more wires). Each
    section is a `Line` from x = 0, or (start, line): that line moved to start at `start` m (`shifted`). Their wires,
    droppers, clamps, masses and insulators together, supports at the same x (to 1e-9 m) merged into one (each
    section's springs and masses on its own wires). Wire names must differ between sections; the sections' presags
    must agree (the route's), and an irregularity belongs to the route, not to a section. One section from 0: that
    section's line."""
    if not sections:
        raise ParameterError("a route needs at least one section")
    placed = [(0.0, sec) if isinstance(sec, Line) else (float(sec[0]), sec[1]) for sec in sections]
    if len(placed) == 1 and placed[0][0] == 0.0:
        return placed[0][1]
    sections = [sec for _, sec in placed]
    names = [w.name for sec in sections for w in sec.wires]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ParameterError(f"route {name!r}: wire name(s) {dup} appear in more than one section; give each "
                             "section's wires their own names")
    presags = {sec.presag for sec in sections}
    if len(presags) > 1:
        raise ParameterError(f"route {name!r}: its sections' presags {sorted(presags)} differ; a route has one")
    if any(sec.irregularity is not None for sec in sections):
        raise ParameterError(f"route {name!r}: a section carries an irregularity; give it to the route")
    parts = [shifted(sec, dx) if dx else [list(sec.wires), list(sec.supports), list(sec.droppers),
                                          list(sec.clamps), list(sec.masses), list(sec.insulators)]
             for dx, sec in placed]
    merged: dict[float, Support] = {}
    for part in parts:
        for sup in part[1]:
            key = round(sup.x, 9)
            old = merged.get(key)
            merged[key] = sup if old is None else Support(old.x, {**old.k, **sup.k}, {**old.m, **sup.m})
    return Line(tuple(w for part in parts for w in part[0]), tuple(merged.values()),
                tuple(d for part in parts for d in part[2]), tuple(c for part in parts for c in part[3]),
                tuple(m for part in parts for m in part[4]), presag=sections[0].presag, name=name,
                insulators=tuple(s for part in parts for s in part[5]))


def with_insulators(line: Line, insulators: Sequence[SectionInsulator]) -> Line:
    """`line` with `insulators` added to its own (`SectionInsulator`: section insulators or other stiffening masses
    on its wires), checked as a new `Line`."""
    return dataclasses.replace(line, insulators=(*line.insulators, *insulators))


@dataclass(frozen=True)
class OverlapParams:
    """EN 50318 tension sections chained by overlaps (model README, "Overlaps and routes"): `sections` sections (the
    scene `catenary/en50318_overlap`: two, A and B; the route `catenary/en50318_route`: three) of `spans` spans each,
    each next one starting at the start of the last `overlap_spans` spans of the one before. In an overlap the wire
    that leaves rises out of the running plane: its contact wire is at `rise_inner` at the overlap's last interior
    support and at `rise_anchor` at its anchor (its section's end), the coming one's mirrored (`rise_anchor` at its
    start, `rise_inner` at the overlap's first interior support), each at 0 elsewhere, linear between supports."""

    sections: int = param(2, lo=2, hi=100, kind=int, unit="-", doc="tension sections, each next one overlapping the "
                                                                     "one before")
    spans: int = param(8, lo=3, hi=500, kind=int, unit="-", doc="spans of each section")
    overlap_spans: int = param(3, lo=2, hi=50, kind=int, unit="-", doc="spans the two sections share")
    rise_inner: float = param(0.10, lo=0.0, hi=2.0, unit="m", doc="height of the leaving contact wire at the "
                                                                   "overlap's interior support next to its anchor")
    rise_anchor: float = param(0.50, lo=0.0, lo_open=True, hi=2.0, unit="m",
                               doc="height of the leaving contact wire at its anchor (the section's end)")

    def __post_init__(self) -> None:
        check_fields(self, "overlap parameter")
        if not self.overlap_spans < self.spans:
            raise ParameterError(f"overlap overlap_spans = {self.overlap_spans} must be below spans = {self.spans}")
        if self.sections > 2 and not 2 * self.overlap_spans <= self.spans:
            raise ParameterError(f"overlap spans = {self.spans} must be at least twice overlap_spans = "
                                 f"{self.overlap_spans} with {self.sections} sections: an inner section's two "
                                 "overlaps would cross")
        if not self.rise_inner < self.rise_anchor:
            raise ParameterError(f"overlap rise_inner = {self.rise_inner} m must lie below rise_anchor = "
                                 f"{self.rise_anchor} m (the wire rises towards its anchor)")


def section(p: CatenaryParams, n_spans: int, suffix: str, heights: Sequence[tuple[float, float]] = (),
            presag: float = 0.0) -> Line:
    """One EN 50318 tension section of `p`'s wires and springs over `n_spans` spans from x = 0, its wires named
    contact_<suffix> and messenger_<suffix>: both pinned at its ends, steady arm and messenger support at every
    interior support, `p.dropper_positions` in every span, the contact wire's design heights `heights` ((x, z))."""
    L = p.span_length
    x0, x1 = 0.0, n_spans * L
    cw, mw = f"{CONTACT}_{suffix}", f"{MESSENGER}_{suffix}"
    wires = (Wire(cw, CONTACT, p.cw_mass, p.cw_tension, p.cw_EI, x0, x1, heights=tuple(heights)),
             Wire(mw, MESSENGER, p.mw_mass, p.mw_tension, p.mw_EI, x0, x1))
    sup = [Support(x0 + s * L, {cw: p.k_steady_arm, mw: p.k_messenger_support} if 0 < s < n_spans else {})
           for s in range(n_spans + 1)]
    drop = [Dropper(x0 + s * L + d, mw, cw, p.k_dropper) for s in range(n_spans) for d in p.dropper_positions]
    return Line(wires, tuple(sup), tuple(drop), presag=presag, name=f"section {suffix}")


def overlap(p: CatenaryParams, o: OverlapParams | None = None, presag: float = 0.0) -> Line:
    """EN 50318 sections of `p` chained by overlaps (`OverlapParams`; default: the scene `catenary/en50318_overlap`,
    A over 0-480 m, B over 300-780 m, the overlap 300-480 m): a route of `o.sections` sections named a, b, c, ...,
    each contact wire in the running plane (0) outside its overlaps, coming down from its anchor in the overlap at
    its start and rising to its anchor in the overlap at its end."""
    o = o or OverlapParams()
    L = p.span_length
    Ls = o.spans * L
    step = (o.spans - o.overlap_spans) * L
    placed = []
    for i in range(o.sections):
        pts = [(0.0, o.rise_anchor), (L, o.rise_inner)] if i > 0 else [(0.0, 0.0)]
        pts += [(2 * L, 0.0)] if i > 0 else []
        pts += [(Ls - 2 * L, 0.0), (Ls - L, o.rise_inner), (Ls, o.rise_anchor)] if i < o.sections - 1 else [(Ls, 0.0)]
        pts = [q for j, q in enumerate(pts) if j == 0 or q[0] > pts[j - 1][0]]  # 2 L = Ls - 2 L: one point
        placed.append((i * step, section(p, o.spans, chr(ord("a") + i) if i < 26 else f"s{i + 1}", pts, presag)))
    return route(placed, name="overlap" if o.sections == 2 else f"route of {o.sections} sections")


#: kind of a scene's [line] section -> (builder, parameter dataclass or None)
LINE_KINDS = {"simple": (simple, None), "stitched": (stitched, StitchParams), "compound": (compound, CompoundParams),
              "overlap": (overlap, OverlapParams)}
