"""Aerodynamic uplift of the pantographs under the catenary: the scene's `[aerodynamics]` section, its one check and
the constant forces it gives at a passage's speed.

The airflow lifts a running pantograph with a force that grows with the square of the speed (the reason the EN 50367
target mean force rises with speed). It is declared per body as

    F = c v^2        (upward, N; v the train speed in m/s, c in N s^2/m^2)

with one coefficient for the head (`head`) and one for the frame (`frame`), per running direction of the pantograph
(`knuckle_leading`, `knuckle_trailing`: the knuckle ahead of or behind the head) and, on a train of several, separately
for the trailing pantograph(s) (`trailing_pantograph`, whose air is the wake of the leading one):

    [aerodynamics]
    running = "knuckle-leading"                    # the case that applies: knuckle-leading | knuckle-trailing
    knuckle_leading = { head = 0.0024, frame = 0.0037 }
    knuckle_trailing = { head = 0.0020, frame = 0.0031 }
    [aerodynamics.trailing_pantograph]             # a train's trailing pantograph(s); `running` optional (default:
    knuckle_leading = { head = 0.0012, frame = 0.0019 }   # the section's)

Which coefficients apply: the leading (or only) pantograph takes the table of `running`; every pantograph behind it
takes `trailing_pantograph`'s table of its running direction (`trailing_pantograph.running`, else `running`). A case
that applies and has no table is an error naming it (`uplifts`): no coefficient of the user's design is assumed, not
even the leading pantograph's for a trailing one. An absent section is no aerodynamic force. The coefficients are
declared once (`SECTION`, its `Limit`s: finite, >= 0, <= 1 N s^2/m^2; numpy scalars are the numbers they hold).

The speed is constant over a passage, so each force is a constant: `Uplift.head`, `Uplift.frame` (N) are handed to
the pantograph (`aerodynamic(head, frame)` of the pantograph protocol, `pantographs.py`) before its static state, which
therefore includes them, and act in every step of the Python loops and the compiled loop alike. How each kind of
pantograph applies them: the model README, "Aerodynamic uplift".
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ...errors import SceneError
from ...limits import Limit
from ...schema import Rule, Section

#: the running directions of a pantograph: the knuckle (the frame's elbow) ahead of the head, or behind it
RUNNING = ("knuckle-leading", "knuckle-trailing")
#: the key of each running direction's coefficient table
CASE_KEY = {"knuckle-leading": "knuckle_leading", "knuckle-trailing": "knuckle_trailing"}
#: the bodies a coefficient is declared for
BODIES = ("head", "frame")
#: an aerodynamic coefficient: F = c v^2, upward (1 N s^2/m^2 is 7.7 kN at 1000 km/h)
COEFFICIENT = Limit(lo=0.0, hi=1.0, unit="N s^2/m^2")


def _coefficient(body: str) -> Limit:
    return Limit(lo=COEFFICIENT.lo, hi=COEFFICIENT.hi, unit=COEFFICIENT.unit,
                 doc=f"the {body}'s aerodynamic uplift F = c v^2 (upward; v the train speed in m/s)")


#: one case's coefficients: both bodies, each required (a coefficient of the user's design has no default)
CASE = Section("[aerodynamics] coefficients of one case", {body: _coefficient(body) for body in BODIES},
               required=BODIES, doc="F = c v^2 on the head and on the frame (N s^2/m^2, v in m/s)")
RUNNING_LIMIT = Limit(kind=str, choices=RUNNING, doc="the pantograph's running direction: which case applies")
#: the trailing pantograph(s) of a train: their own cases (the wake of the leading one), their own direction
TRAILING = Section("[aerodynamics.trailing_pantograph]", {
    "running": Limit(kind=str, choices=RUNNING, doc="the trailing pantographs' running direction (absent: the "
                                                      "section's `running`)"),
    "knuckle_leading": CASE, "knuckle_trailing": CASE},
    doc="the coefficients of a train's trailing pantograph(s), per running direction")


def _direction(d: Mapping[str, Any]) -> str:
    t = d.get("trailing_pantograph") or {}
    return t.get("running", d["running"])


def _cases_given(d: Mapping[str, Any]) -> str | None:
    key = CASE_KEY[d["running"]]
    if key not in d:
        return (f"running = {d['running']!r} applies {key} = {{head = ..., frame = ...}} (N s^2/m^2), which is "
                f"missing")
    if "trailing_pantograph" in d:
        run = _direction(d)
        tkey = CASE_KEY[run]
        if tkey not in d["trailing_pantograph"]:
            return (f"the trailing pantographs run {run}: trailing_pantograph.{tkey} = {{head = ..., frame = ...}} "
                    f"(N s^2/m^2) is missing")
    return None


#: the declaration of a scene's `[aerodynamics]` section
SECTION = Section("[aerodynamics]", {
    "running": RUNNING_LIMIT,
    "knuckle_leading": CASE,
    "knuckle_trailing": CASE,
    "trailing_pantograph": TRAILING,
}, required=("running",), rules=(
    Rule("the case that applies has its coefficients: the table of `running`, and trailing_pantograph's table of its "
         "direction when trailing_pantograph is given (a train of several needs it)", _cases_given),),
    doc="aerodynamic uplift F = c v^2 on each pantograph's head and frame (v the train speed in m/s, c in "
        "N s^2/m^2), per running direction, for the leading pantograph and a train's trailing ones; absent: none",
    example={"running": "knuckle-leading",
             "knuckle_leading": {"head": 0.0024, "frame": 0.0037},
             "knuckle_trailing": {"head": 0.0020, "frame": 0.0031},
             "trailing_pantograph": {"running": "knuckle-leading",
                                     "knuckle_leading": {"head": 0.0012, "frame": 0.0019}}})


def validate_section(value: Any) -> dict[str, Any]:
    """Validator of a scene's `[aerodynamics]` section (`SECTION`: unknown keys, bad or missing coefficients of the
    case that applies are `SceneError`s naming them)."""
    return SECTION.check(value, "[aerodynamics]")


validate_section.schema = SECTION


@dataclass(frozen=True)
class Uplift:
    """The aerodynamic uplift of one pantograph of a passage: its `position` on the train ("leading" or
    "trailing"), the `case` (running direction) that applies, its coefficients `c_head`, `c_frame` (N s^2/m^2) and the
    train speed `speed` (m/s); `head` and `frame` are the forces (N, upward)."""

    position: str
    case: str
    c_head: float
    c_frame: float
    speed: float

    def force(self, c: float) -> float:
        """The force c v^2 (N, upward) of a coefficient c (N s^2/m^2) at this speed."""
        return c * self.speed ** 2

    @property
    def head(self) -> float:
        """The head's force c_head v^2 (N, upward)."""
        return self.force(self.c_head)

    @property
    def frame(self) -> float:
        """The frame's force c_frame v^2 (N, upward)."""
        return self.force(self.c_frame)

    def describe(self) -> str:
        """One line: the case and the forces at this speed."""
        v = self.speed
        return (f"aerodynamic uplift on ({self.position} pantograph, {self.case}): head {self.c_head:g} x "
                f"{v:.2f}^2 = {self.head:.2f} N, frame {self.c_frame:g} x {v:.2f}^2 = {self.frame:.2f} N "
                "(F = c v^2, v in m/s); the mean contact force Fm includes it")

    def as_dict(self) -> dict[str, Any]:
        """The JSON of a run's report."""
        return {"position": self.position, "case": self.case, "c_head": self.c_head, "c_frame": self.c_frame,
                "speed_ms": self.speed, "head_force_N": self.head, "frame_force_N": self.frame}


def uplifts(section: Mapping[str, Any] | None, speed_ms: float, n: int) -> list[Uplift] | None:
    """The uplift of each of the `n` pantographs of a passage (leading first) at `speed_ms` (m/s) under the
    `[aerodynamics]` section `section` (checked here again: a section built in Python takes the scene's one check);
    None without a section. A train of several needs `trailing_pantograph` (a `SceneError` names it)."""
    if section is None:
        return None
    d = SECTION.check(section, "[aerodynamics]")
    if n > 1 and "trailing_pantograph" not in d:
        raise SceneError(f"[aerodynamics]: the train's {n - 1} trailing pantograph(s) have no coefficients: give "
                         f"[aerodynamics.trailing_pantograph] with {CASE_KEY[d['running']]} = {{head = ..., frame = "
                         "...}} (N s^2/m^2); the leading pantograph's are not assumed for them")
    out = []
    for k in range(n):
        if k == 0:
            case, table = d["running"], d
        else:
            case, table = _direction(d), d["trailing_pantograph"]
        c = table[CASE_KEY[case]]
        out.append(Uplift("leading" if k == 0 else "trailing", case, c["head"], c["frame"], float(speed_ms)))
    return out
