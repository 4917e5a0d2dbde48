"""The shipped lines as `line.Line` builders: the EN 50318:2002 simple line from `CatenaryParams` (`simple`), its
stitched variant (`stitched`, the scene `catenary/en50318_stitched`, model README "A stitched line") and a
three-wire compound line (`compound`). `LINE_KINDS` maps the `kind` of a scene's `[line]` section to a builder and
its parameter dataclass."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from ...limits import check_fields, param
from .line import Clamp, Dropper, Line, Support, Wire
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


#: kind of a scene's [line] section -> (builder, parameter dataclass or None)
LINE_KINDS = {"simple": (simple, None), "stitched": (stitched, StitchParams), "compound": (compound, CompoundParams)}
