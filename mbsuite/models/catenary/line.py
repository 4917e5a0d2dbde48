"""A catenary line (one tension section) as data: wires, supports, droppers, clamps, point masses, presag and a
contact-wire irregularity. `fe.assemble` meshes and solves any `Line`; `lines.py` builds the shipped ones (the
EN 50318 simple line, its stitched variant, a compound line) and `linefile.py` reads one from TOML/CSV.

Conventions (SI units, x along the track from the first pinned end, heights up):
- a `Wire` is a tensioned Euler-Bernoulli beam over [x0, x1]; its ends are pinned (w = 0 from the static state) or
  free (held by whatever springs act there, e.g. a stitch wire's clamps). The wires with role "contact" cover the
  line: one spanning it (a tension section), or several, each over its own x-range (a route: tension sections chained
  into one line, overlapping where a pantograph passes from one contact wire to the next); the first starts the line
  at x = 0 and each next one starts before the previous ones end. A contact wire's tension is uniform; other wires
  may carry `tension_segments` (x_a, x_b, T) that override the wire's tension between x_a and x_b (a messenger
  between the clamps of a stitch wire). A contact wire may carry `heights`, its design-height profile (x, z) points,
  piecewise linear (an overlap's rise out of the running plane); the presag adds to it.
- a `Support` at x holds ground springs `k` (N/m) on named wires (steady arm on the contact wire, messenger support)
  and point masses `m` (kg: clamps, steady arm) on named wires; the contact wire is held at its design height at every
  support in the static state (its reaction is the steady arm's pre-load).
- a `Dropper` at x joins `upper` to `lower` (w displacements): stiffness k, law "slack" (tension only) or "linear"
  (bilateral; "" = the scene's `droppers` effect), its body's mass lumped half on each end, clamp masses on each wire.
  In the static state the lower wire is held at its design height at the dropper (the dropper length is whatever that
  needs); the dropper's static tension is the hold's reaction.
- a `Clamp` at x is a bilateral spring k between the w displacements of wires a and b (rotations independent).
- `Presag`: the contact wire's design height between consecutive supports a, b (of that wire): z(x) = -4 s (x - a)
  (b - x) / (b - a) with s = ratio (mid-span presag / span length; 0: level), plus the wire's `heights` profile.
- Overlapping contact wires never touch: no dropper or clamp joins them (directly or through other wires), and their
  design heights may meet at single points (the crossing of an overlap) but not run together over an interval.
- a `SectionInsulator` centred at x on a wire (any wire; typically the contact wire) over [x - length/2,
  x + length/2] adds its mass spread uniformly over its length (mass/length per m: consistent mass and weight) and its
  bending stiffness EI to the wire's there; its ends are nodes. Insulators on one wire do not overlap (they may
  touch). The wire's point-load correction accounts for the stiffened elements (`point_correction.py`).
- `Irregularity`: a height profile r(x) of the contact wire (m) on a uniform grid, piecewise linear, 0 outside; it
  enters the contact gap (y_wire = N . (w0 + u) + r), the wire-height signal and the pantograph's static state.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import ParameterError
from ...limits import Limit, check_fields, param
from ...schema import Items, check_value
from ...trust import perturbation
from ...trust.perturbation import POSITION

WIRE_ROLES = ("contact", "messenger", "stitch", "auxiliary", "other")
END_KINDS = ("pinned", "free")
DROPPER_LAWS = ("", "slack", "linear")
#: most wires of one mechanical component (wires joined by droppers or clamps) at one position: the compiled core's
#: blocks (a component at a node) hold at most 8 DOFs (w, theta per wire)
MAX_WIRES_AT_A_NODE = 4
#: the contact wire's mid-span presag / span length (parabolic between supports)
PRESAG = Limit(lo=0.0, hi=0.05, hi_open=True, unit="", doc="mid-span presag / span length (absent: 0, level)")


#: a support's ground spring on a wire (`k_<wire>` in a line file) and its point mass there (`m_<wire>`)
SUPPORT_K = Limit(lo=0.0, hi=1e12, unit="N/m", doc="ground spring on the wire named after k_ (steady arm, support)")
SUPPORT_M = Limit(lo=0.0, hi=1e3, unit="kg", doc="point mass on the wire named after m_ (clamp, steady arm)")
#: a point of a contact wire's design-height profile: [x, z]
HEIGHT_POINT = (Limit(lo=0.0, hi=1e6, unit="m", doc="x (m)"), Limit(lo=-10.0, hi=10.0, unit="m", doc="z (m)"))
#: two overlapping contact wires whose design heights differ by less than this (m) at a key point meet there
TOUCH = 1e-6
#: a tension segment of a wire: [x_a, x_b, T]
SEGMENT = (Limit(lo=0.0, hi=1e6, unit="m", doc="x_a (m)"), Limit(lo=0.0, hi=1e6, unit="m", doc="x_b (m)"),
           Limit(lo=0.0, hi=1e6, unit="N", doc="T (N)"))


@dataclass(frozen=True)
class Wire:
    """A tensioned wire over [x0, x1] (module docstring)."""

    name: str = param(kind=str, doc="the wire's name (droppers, clamps, masses and supports name it)")
    role: str = param(kind=str, choices=WIRE_ROLES, doc="contact, messenger, stitch, auxiliary or other")
    mass: float = param(lo=0.0, hi=100.0, unit="kg/m", doc="mass per length (0 only for a massless tie)")
    tension: float = param(lo=0.0, hi=1e6, unit="N", doc="tension (0: a bending beam alone)")
    EI: float = param(lo=0.0, hi=1e6, unit="N m^2", doc="bending stiffness (0: a string)")
    x0: float = param(lo=0.0, hi=1e6, unit="m", doc="start of the wire", draw=POSITION)
    x1: float = param(lo=0.0, lo_open=True, hi=1e6, unit="m", doc="end of the wire", draw=POSITION)
    ends: tuple[str, str] = field(default=("pinned", "pinned"), metadata={"schema": Items(
        Limit(kind=str, choices=END_KINDS), min=2, max=2, default=("pinned", "pinned"),
        doc="the ends at x0 and x1: pinned (w = 0) or free (held by clamps)")})
    #: (x_a, x_b, T): tension T (N) between x_a and x_b instead of `tension`
    tension_segments: tuple[tuple[float, float, float], ...] = field(default=(), metadata={"schema": Items(
        SEGMENT, max=10_000, default=(), doc="tension T (N) between x_a and x_b (m) instead of tension")})
    #: (x, z): a contact wire's design height z (m, 0 = the running plane) at x, piecewise linear from x0 to x1
    heights: tuple[tuple[float, float], ...] = field(default=(), metadata={"schema": Items(
        HEIGHT_POINT, max=10_000, default=(), doc="a contact wire's design height z (m; 0: the running plane) at x "
        "(m), piecewise linear; the first point at x0, the last at x1, x increasing")})

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ParameterError(f"wire name = {self.name!r} is invalid; valid: a non-empty string")
        check_fields(self, f"wire {self.name!r}")
        if not self.x1 > self.x0:
            raise ParameterError(f"wire {self.name!r}: x1 = {self.x1} m must lie beyond x0 = {self.x0} m")
        where = f"wire {self.name!r}"
        ends = tuple(check_value(_WIRE_SCHEMA["ends"], "ends", self.ends, where, ParameterError))
        object.__setattr__(self, "ends", ends)
        segs = []
        rows = check_value(_WIRE_SCHEMA["tension_segments"], "tension_segments", self.tension_segments, where,
                           ParameterError)
        for i, (s, (a, b, T)) in enumerate(zip(self.tension_segments, rows, strict=True)):
            # inside the stability check the segment's ends move as every position does (`perturbation.POSITION`)
            a, b = perturbation.value(a, key=POSITION), perturbation.value(b, key=POSITION)
            if not (self.x0 <= a < b <= self.x1) or T < 0:
                raise ParameterError(f"wire {self.name!r}: tension_segments[{i}] = {list(s)} must satisfy "
                                     f"x0 <= x_a < x_b <= x1 ([{self.x0}, {self.x1}] m) and T >= 0")
            segs.append((a, b, T))
        segs.sort()
        for (a0, b0, _), (a1, _, _) in zip(segs, segs[1:], strict=False):
            if a1 < b0:
                raise ParameterError(f"wire {self.name!r}: tension segments [{a0}, {b0}] and one from {a1} m overlap")
        object.__setattr__(self, "tension_segments", tuple(segs))
        pts = check_value(_WIRE_SCHEMA["heights"], "heights", self.heights, where, ParameterError)
        pts = tuple((float(x), float(z)) for x, z in pts)
        if pts:
            if self.role != "contact":
                raise ParameterError(f"wire {self.name!r}: heights (a design-height profile) is for a contact wire; "
                                     f"this one has role {self.role!r}")
            xs = [x for x, _ in pts]
            if len(pts) < 2 or abs(xs[0] - self.x0) > 1e-9 or abs(xs[-1] - self.x1) > 1e-9:
                raise ParameterError(f"wire {self.name!r}: heights = {[list(q) for q in pts]} must have at least two "
                                     f"points, the first at x0 = {self.x0} m and the last at x1 = {self.x1} m")
            for i in range(1, len(xs)):
                if not xs[i] > xs[i - 1]:
                    raise ParameterError(f"wire {self.name!r}: heights[{i}] x = {xs[i]} m must lie beyond heights"
                                         f"[{i - 1}] x = {xs[i - 1]} m (x increasing)")
        object.__setattr__(self, "heights", pts)

    def height_at(self, x: np.ndarray) -> np.ndarray:
        """The `heights` profile at x (m; 0 without one), linear between its points."""
        x = np.asarray(x, float)
        if not self.heights:
            return np.zeros_like(x)
        px, pz = np.array(self.heights, dtype=float).T
        return np.interp(x, px, pz)

    def tension_at(self, xm: np.ndarray) -> np.ndarray:
        """Tension (N) at positions xm (element midpoints)."""
        T = np.full(np.shape(xm), self.tension, dtype=float)
        for a, b, t in self.tension_segments:
            T[(xm > a) & (xm < b)] = t
        return T

    @property
    def wave_speed(self) -> float:
        """Largest transverse wave speed sqrt(T/rho) of the wire (m/s; inf for a massless wire)."""
        T = max([self.tension] + [s[2] for s in self.tension_segments])
        return math.sqrt(T / self.mass) if self.mass > 0 else math.inf


_WIRE_SCHEMA = {f.name: f.metadata["schema"] for f in dataclasses.fields(Wire) if "schema" in f.metadata}


@dataclass(frozen=True)
class Support:
    """A support at x: ground springs `k` and point masses `m` on named wires."""

    x: float = param(lo=0.0, hi=1e6, unit="m", doc="position of the support", draw=POSITION)
    k: dict[str, float] = field(default_factory=dict)
    m: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_fields(self, "support")
        for what, lim in (("k", SUPPORT_K), ("m", SUPPORT_M)):
            d = getattr(self, what)
            if not isinstance(d, dict):
                raise ParameterError(f"support at x = {self.x} m: {what} must map wire names to numbers, got {d!r}")
            object.__setattr__(self, what, {str(w): lim.check(f"{what}_{w}", v, ParameterError,
                                                              f" at the support at x = {self.x} m")
                                            for w, v in d.items()})


def _without_anchor_zeros(s: Support, wires: dict[str, Wire]) -> Support:
    keep = {what: {w: v for w, v in getattr(s, what).items() if v != 0.0 or not Line.pinned_end(wires[w], s.x)}
            for what in ("k", "m")}
    if keep["k"] == s.k and keep["m"] == s.m:
        return s
    out = copy.copy(s)  # not re-checked (nor re-perturbed): only entries that act on nothing leave
    object.__setattr__(out, "k", keep["k"])
    object.__setattr__(out, "m", keep["m"])
    return out


@dataclass(frozen=True)
class Dropper:
    """A dropper at x from `upper` to `lower` (module docstring)."""

    x: float = param(lo=0.0, hi=1e6, unit="m", doc="position of the dropper", draw=POSITION)
    upper: str = param(kind=str, doc="the wire it hangs from")
    lower: str = param(kind=str, doc="the wire it holds")
    k: float = param(lo=0.0, lo_open=True, hi=1e12, unit="N/m", doc="axial stiffness")
    law: str = param("", kind=str, choices=DROPPER_LAWS, doc="slack, linear or '' (the scene's droppers effect)")
    mass: float = param(0.0, lo=0.0, hi=100.0, unit="kg", doc="dropper body mass (half on each end)")
    clamp_upper: float = param(0.0, lo=0.0, hi=100.0, unit="kg", doc="clamp mass on the upper wire")
    clamp_lower: float = param(0.0, lo=0.0, hi=100.0, unit="kg", doc="clamp mass on the lower wire")

    def __post_init__(self) -> None:
        check_fields(self, f"dropper at x = {self.x!r} m")
        if self.upper == self.lower:
            raise ParameterError(f"dropper at x = {self.x} m joins wire {self.upper!r} to itself")


@dataclass(frozen=True)
class Clamp:
    """A bilateral spring k between wires a and b at x."""

    x: float = param(lo=0.0, hi=1e6, unit="m", doc="position of the clamp", draw=POSITION)
    a: str = param(kind=str, doc="one wire")
    b: str = param(kind=str, doc="the other wire")
    k: float = param(lo=0.0, lo_open=True, hi=1e15, unit="N/m", doc="clamp stiffness")

    def __post_init__(self) -> None:
        check_fields(self, f"clamp at x = {self.x!r} m")
        if self.a == self.b:
            raise ParameterError(f"clamp at x = {self.x} m joins wire {self.a!r} to itself")


@dataclass(frozen=True)
class PointMass:
    """A point mass m on `wire` at x (a registration clamp, an electrical connector)."""

    x: float = param(lo=0.0, hi=1e6, unit="m", doc="position of the mass", draw=POSITION)
    wire: str = param(kind=str, doc="the wire it sits on")
    m: float = param(lo=0.0, hi=1e3, unit="kg", doc="mass")

    def __post_init__(self) -> None:
        check_fields(self, f"point mass at x = {self.x!r} m")


@dataclass(frozen=True)
class SectionInsulator:
    """A section insulator (or any stiffening mass) centred at x on `wire` over [x - length/2, x + length/2]: its
    mass spread uniformly over its length, its bending stiffness EI added to the wire's there (module docstring)."""

    x: float = param(lo=0.0, hi=1e6, unit="m", doc="position of the insulator's centre", draw=POSITION)
    wire: str = param(kind=str, doc="the wire it sits on (typically the contact wire)")
    length: float = param(lo=0.0, lo_open=True, hi=100.0, unit="m", doc="its length along the wire")
    mass: float = param(lo=0.0, hi=1e4, unit="kg", doc="its total mass (spread uniformly over its length)")
    EI: float = param(lo=0.0, hi=1e7, unit="N m^2", doc="bending stiffness added to the wire's over its length")

    def __post_init__(self) -> None:
        check_fields(self, f"insulator at x = {self.x!r} m")

    @property
    def xa(self) -> float:
        """Its start (m)."""
        return self.x - 0.5 * self.length

    @property
    def xb(self) -> float:
        """Its end (m)."""
        return self.x + 0.5 * self.length

    @property
    def mass_per_length(self) -> float:
        """The mass it adds per length of the wire (kg/m)."""
        return self.mass / self.length


@dataclass(frozen=True)
class Irregularity:
    """The contact wire's height irregularity r(x) = r[i] at x0 + i dx, piecewise linear between, 0 outside."""

    x0: float
    dx: float
    r: np.ndarray
    source: str = ""

    def __post_init__(self) -> None:
        r = np.asarray(self.r, dtype=float)
        if r.ndim != 1 or r.size < 2 or not np.all(np.isfinite(r)):
            raise ParameterError(f"irregularity {self.source}: the profile must be >= 2 finite heights, got {r.size}")
        where = f" in the irregularity {self.source}"
        object.__setattr__(self, "x0", Limit(unit="m").check("x0", self.x0, ParameterError, where))
        dx = Limit(lo=0.0, lo_open=True, unit="m").check("dx", self.dx, ParameterError, where)
        object.__setattr__(self, "dx", dx)
        object.__setattr__(self, "r", r)

    def __call__(self, x: np.ndarray | float) -> np.ndarray:
        """r(x) (m)."""
        g = self.x0 + self.dx * np.arange(self.r.size)
        return np.interp(x, g, self.r, left=0.0, right=0.0)

    def slope(self, x: np.ndarray | float) -> np.ndarray:
        """dr/dx on the interval holding x (0 outside the grid)."""
        i = np.floor((np.asarray(x, float) - self.x0) / self.dx).astype(int)
        ok = (i >= 0) & (i < self.r.size - 1)
        j = np.clip(i, 0, self.r.size - 2)
        return np.where(ok, (self.r[j + 1] - self.r[j]) / self.dx, 0.0)

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Irregularity) and (self.x0, self.dx) == (other.x0, other.dx)
                and np.array_equal(self.r, other.r))

    __hash__ = None  # type: ignore[assignment]


def joined(n: int, pairs: list[tuple[int, int]]) -> list[int]:
    """The representative of each of `n` items joined by the index `pairs` (union-find): items joined directly or
    through others share one."""
    parent = list(range(n))

    def root(a: int) -> int:
        while parent[a] != a:
            a = parent[a]
        return a

    for a, b in pairs:
        parent[root(a)] = root(b)
    return [root(k) for k in range(n)]


@dataclass(frozen=True)
class Line:
    """A tension section, or several chained into a route (module docstring). `supports` sorted by x; the contact
    wires define the line's extent [0, length]."""

    wires: tuple[Wire, ...]
    supports: tuple[Support, ...]
    droppers: tuple[Dropper, ...] = ()
    clamps: tuple[Clamp, ...] = ()
    masses: tuple[PointMass, ...] = ()
    presag: float = 0.0
    irregularity: Irregularity | None = None
    name: str = "line"
    insulators: tuple[SectionInsulator, ...] = ()

    def __post_init__(self) -> None:
        for what in ("wires", "supports", "droppers", "clamps", "masses", "insulators"):
            object.__setattr__(self, what, tuple(getattr(self, what)))
        names = [w.name for w in self.wires]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ParameterError(f"line {self.name!r}: wire name(s) {dup} appear more than once")
        contact = sorted((w for w in self.wires if w.role == "contact"), key=lambda w: (w.x0, w.x1))
        if not contact:
            raise ParameterError(f"line {self.name!r} needs a wire with role 'contact', has none")
        cw = contact[0]
        if cw.x0 != 0.0:
            raise ParameterError(f"line {self.name!r}: the contact wire {cw.name!r} has x0 = {cw.x0!r} m; valid: 0 "
                                 "(it starts the line)")
        reach = cw.x1
        for w in contact[1:]:
            if not w.x0 < reach:
                raise ParameterError(f"line {self.name!r}: the contact wire {w.name!r} starts at x0 = {w.x0} m, past "
                                     f"the end of the contact wires before it ({reach} m): a pantograph would have no "
                                     "wire between; the contact wires of a route overlap")
            if w.x1 <= reach:
                raise ParameterError(f"line {self.name!r}: the contact wire {w.name!r} [{w.x0}, {w.x1}] m lies inside "
                                     f"the contact wires before it (to {reach} m): each next one reaches further")
            reach = w.x1
        beyond = [w.name for w in self.wires if w.x1 > reach]
        if beyond:
            raise ParameterError(f"line {self.name!r}: wire(s) {beyond} end beyond the contact wire (x1 > "
                                 f"{reach} m); every wire lies on [0, {reach}] m")
        for w in contact:
            if w.tension_segments:
                raise ParameterError(f"line {self.name!r}: the contact wire's tension must be uniform (one tension "
                                     "section); tension_segments are for the other wires")
            if not w.tension > 0 or not w.mass > 0:
                raise ParameterError(f"line {self.name!r}: the contact wire needs a positive mass and tension")
        # the contact wires first, in the order they start (the FE's DOF order)
        object.__setattr__(self, "wires", (*contact, *[w for w in self.wires if w.role != "contact"]))
        wires = {w.name: w for w in self.wires}

        def on(wire: str, x: float, what: str) -> None:
            w = wires.get(wire)
            if w is None:
                raise ParameterError(f"line {self.name!r}: {what} names wire {wire!r}; wires: {list(wires)}")
            if not w.x0 - 1e-9 <= x <= w.x1 + 1e-9:
                raise ParameterError(f"line {self.name!r}: {what} lies off wire {wire!r} [{w.x0}, {w.x1}] m")

        sup = tuple(sorted(self.supports, key=lambda s: s.x))
        if len(sup) < 2:
            raise ParameterError(f"line {self.name!r} needs at least two supports, has {len(sup)}")
        for a, b in zip(sup, sup[1:], strict=False):
            if not b.x > a.x:
                raise ParameterError(f"line {self.name!r}: two supports at x = {a.x} m")
        object.__setattr__(self, "supports", sup)
        for s in sup:
            if not any(w.x0 - 1e-9 <= s.x <= w.x1 + 1e-9 for w in contact):
                on(cw.name, s.x, f"a support at x = {s.x} m")
            for w in (*s.k, *s.m):
                on(w, s.x, f"support at x = {s.x} m")
            for what, d in (("k", s.k), ("m", s.m)):
                for w, v in d.items():
                    if v != 0.0 and self.pinned_end(wires[w], s.x):
                        raise ParameterError(
                            f"line {self.name!r}: the support at x = {s.x} m gives {what}_{w} = {v!r} on the pinned "
                            f"end of wire {w!r}, where w = 0: it would act on nothing (a mass only on the anchor's "
                            "reaction). Remove it (or 0), or make that end free")
        # a 0 on a pinned end (a CSV table's empty place) is no spring and no mass: the same line as without it
        sup = tuple(_without_anchor_zeros(s, wires) for s in sup)
        object.__setattr__(self, "supports", sup)
        ends: dict[tuple[str, float], float] = {}
        for d in self.droppers:
            on(d.upper, d.x, f"dropper at x = {d.x} m (upper wire)")
            on(d.lower, d.x, f"dropper at x = {d.x} m (lower wire)")
            key = (d.lower, round(d.x, 9))
            if key in ends:  # the static state holds the lower wire there: one reaction, not two tensions
                raise ParameterError(f"line {self.name!r}: two droppers hang wire {d.lower!r} at x = {d.x} m; one "
                                     "dropper per point of a wire (merge them: the sum of their stiffnesses)")
            ends[key] = d.x
        for c in self.clamps:
            on(c.a, c.x, f"clamp at x = {c.x} m")
            on(c.b, c.x, f"clamp at x = {c.x} m")
        for m in self.masses:
            on(m.wire, m.x, f"point mass at x = {m.x} m")
        self._check_insulators(wires)
        object.__setattr__(self, "presag", PRESAG.check("presag", self.presag, ParameterError,
                                                        f" of the line {self.name!r}"))
        if self.irregularity is not None and not isinstance(self.irregularity, Irregularity):
            raise ParameterError(f"line {self.name!r}: irregularity must be an Irregularity, got "
                                 f"{type(self.irregularity).__name__}")
        group = self.wire_components()
        for x in self.key_points():
            here = [g for w, g in zip(self.wires, group, strict=True) if w.x0 <= x <= w.x1]
            n = max(here.count(g) for g in set(here)) if here else 0
            if n > MAX_WIRES_AT_A_NODE:
                raise ParameterError(f"line {self.name!r}: {n} wires joined by droppers or clamps at x = {x} m; at "
                                     f"most {MAX_WIRES_AT_A_NODE}")
        if len(contact) > 1:
            self._check_apart(contact)

    def _check_insulators(self, wires: dict[str, Wire]) -> None:
        """Each insulator on a wire of the line, within its x-range, none overlapping another on the same wire."""
        for s in self.insulators:
            if not isinstance(s, SectionInsulator):
                raise ParameterError(f"line {self.name!r}: insulators must be SectionInsulator, got "
                                     f"{type(s).__name__}")
            what = f"insulator at x = {s.x} m [{s.xa:g}, {s.xb:g}] m"
            w = wires.get(s.wire)
            if w is None:
                raise ParameterError(f"line {self.name!r}: {what} names wire {s.wire!r}; wires: {list(wires)}")
            if not (w.x0 - 1e-9 <= s.xa and s.xb <= w.x1 + 1e-9):
                raise ParameterError(f"line {self.name!r}: {what} lies off wire {s.wire!r} [{w.x0}, {w.x1}] m; valid: "
                                     f"x - length/2 >= {w.x0} and x + length/2 <= {w.x1}")
        by = sorted(self.insulators, key=lambda s: (s.wire, s.xa))
        for a, b in zip(by, by[1:], strict=False):
            if a.wire == b.wire and b.xa < a.xb - 1e-9:
                raise ParameterError(f"line {self.name!r}: the insulators at x = {a.x} m [{a.xa:g}, {a.xb:g}] m and "
                                     f"x = {b.x} m [{b.xa:g}, {b.xb:g}] m on wire {a.wire!r} overlap")

    def beam_properties(self, wire: Wire, xm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The bending stiffness (N m^2) and mass per length (kg/m) of `wire` at the element midpoints `xm`: the
        wire's own plus its insulators' (`SectionInsulator`) where a midpoint lies inside one."""
        xm = np.asarray(xm, float)
        EI, rho = np.full(xm.shape, wire.EI), np.full(xm.shape, wire.mass)
        for s in self.insulators:
            if s.wire == wire.name:
                inside = (xm > s.xa) & (xm < s.xb)
                EI[inside] = wire.EI + s.EI
                rho[inside] = wire.mass + s.mass_per_length
        return EI, rho

    def insulators_on(self, wire: Wire) -> tuple[SectionInsulator, ...]:
        """The insulators on `wire`, in the order they start."""
        return tuple(sorted((s for s in self.insulators if s.wire == wire.name), key=lambda s: s.xa))

    def _check_apart(self, contact: list[Wire]) -> None:
        """Overlapping contact wires never touch (module docstring): not joined by droppers or clamps, directly or
        through other wires; their design heights not equal (to `TOUCH`) at two consecutive key points both have."""
        group = self.wire_components()
        wi = {w.name: k for k, w in enumerate(self.wires)}
        keys = self.key_points()
        for i, a in enumerate(contact):
            for b in contact[i + 1:]:
                lo, hi = max(a.x0, b.x0), min(a.x1, b.x1)
                if not lo < hi:
                    continue
                if group[wi[a.name]] == group[wi[b.name]]:
                    direct = [f"{d.x:g}" for d in self.droppers if {d.upper, d.lower} == {a.name, b.name}]
                    direct += [f"{c.x:g}" for c in self.clamps if {c.a, c.b} == {a.name, b.name}]
                    which = (f"by the dropper(s) or clamp(s) at x = {', '.join(direct[:4])} m" if direct else
                             "by droppers or clamps through other wires")
                    raise ParameterError(f"line {self.name!r}: the contact wires {a.name!r} and {b.name!r} overlap on "
                                         f"[{lo}, {hi}] m and are joined {which}: overlapping contact wires must not "
                                         "touch (each section hangs from its own wires)")
                xs = keys[(keys >= lo - 1e-9) & (keys <= hi + 1e-9)]
                near = np.abs(self.design_height(xs, a) - self.design_height(xs, b)) < TOUCH
                both = np.nonzero(near[:-1] & near[1:])[0]
                if both.size:
                    j = int(both[0])
                    raise ParameterError(f"line {self.name!r}: the contact wires {a.name!r} and {b.name!r} are at the "
                                         f"same design height from x = {xs[j]:g} to {xs[j + 1]:g} m: overlapping "
                                         "contact wires must not touch (they may cross at a point); change heights")

    def wire_components(self) -> list[int]:
        """The mechanical component of each wire (in `wires` order): wires joined by droppers or clamps, directly or
        through other wires, share one (numbered 0, 1, ... in the order of their first wire). The sections of a route
        are its components: nothing but a pantograph joins them."""
        wi = {w.name: k for k, w in enumerate(self.wires)}
        roots = joined(len(self.wires), [(wi[d.upper], wi[d.lower]) for d in self.droppers]
                       + [(wi[c.a], wi[c.b]) for c in self.clamps])
        number = {r: i for i, r in enumerate(dict.fromkeys(roots))}
        return [number[r] for r in roots]

    @staticmethod
    def pinned_end(wire: Wire, x: float) -> bool:
        """True when x (m) is a pinned end of `wire` (to 1e-9 m)."""
        return any(e == "pinned" and abs(x - xe) <= 1e-9 for e, xe in zip(wire.ends, (wire.x0, wire.x1), strict=True))

    def steady_arm(self, s: Support, wire: Wire | None = None) -> bool:
        """True when support `s` holds the contact wire `wire` (default: the first) at its design height: a ground
        spring on it, or its pinned end (the static state's hold; its reaction is the support's pre-load)."""
        w = self.contact if wire is None else wire
        return w.name in s.k or self.pinned_end(w, s.x)

    @property
    def contact(self) -> Wire:
        """The (first) contact wire (always `wires[0]`)."""
        return self.wires[0]

    @property
    def contacts(self) -> tuple[Wire, ...]:
        """The contact wires, in the order they start (`wires[:n]`)."""
        return tuple(w for w in self.wires if w.role == "contact")

    @property
    def length(self) -> float:
        """Length of the line (m): the contact wires' reach."""
        return max(w.x1 for w in self.contacts)

    def wire(self, name: str) -> Wire:
        """The wire called `name`."""
        for w in self.wires:
            if w.name == name:
                return w
        raise ParameterError(f"line {self.name!r} has no wire {name!r}; wires: {[w.name for w in self.wires]}")

    def key_points(self) -> np.ndarray:
        """Every position that must be a node (supports, droppers, clamps, masses, insulator ends, wire ends and
        tension changes),
        sorted, equal to 1e-9 m merged."""
        xs = [s.x for s in self.supports] + [d.x for d in self.droppers] + [c.x for c in self.clamps]
        xs += [m.x for m in self.masses]
        xs += [v for s in self.insulators for v in (s.xa, s.xb)]
        for w in self.wires:
            xs += [w.x0, w.x1] + [v for s in w.tension_segments for v in s[:2]]
        k = np.unique(np.round(np.asarray(xs, float), 9))
        return k

    def design_height(self, x: np.ndarray, wire: Wire | None = None) -> np.ndarray:
        """The design height z(x) (m) of the contact wire `wire` (default: the first): the parabolic presag between
        consecutive supports on it, plus its `heights` profile."""
        x = np.asarray(x, float)
        w = self.contact if wire is None else wire
        if w.heights:
            return self._presag(x, w) + w.height_at(x)
        return self._presag(x, w)

    def _presag(self, x: np.ndarray, w: Wire) -> np.ndarray:
        if self.presag == 0.0:
            return np.zeros_like(x)
        sx = np.array([s.x for s in self.supports if w.x0 - 1e-9 <= s.x <= w.x1 + 1e-9])
        i = np.clip(np.searchsorted(sx, x, side="right") - 1, 0, sx.size - 2)
        a, b = sx[i], sx[i + 1]
        inside = (x >= sx[0]) & (x <= sx[-1])
        return np.where(inside, -4.0 * self.presag * (x - a) * (b - x) / (b - a), 0.0)

    def contacts_at(self, x: float) -> list[int]:
        """The indices (in `contacts`) of the contact wires whose x-range holds x (m)."""
        return [c for c, w in enumerate(self.contacts) if w.x0 <= x <= w.x1]

    @property
    def wave_speed(self) -> float:
        """The fastest wire's transverse wave speed (m/s)."""
        return max(w.wave_speed for w in self.wires)
