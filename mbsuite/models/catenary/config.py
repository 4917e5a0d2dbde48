"""The configuration of a passage under the FE catenary and its checks, written once: one pantograph or a train of
several (leading first, `spacings` between consecutive contact points), its speed, time step, dropper and contact laws,
the engine path of its pantographs and the size guard. `PassageConfig.check` judges all of it before anything is
built: the speed (a number, below the contact wire's wave speed; warned above 70 %), the time step (the 20 Hz filter's
Nyquist bound, then the FE wave resolution), the spacings, the size of the job, each pantograph's aerodynamic uplift
(`aerodynamics.py`: the scene's `[aerodynamics]` section at this speed). The health figures of a run
(`health_of_regime`) are read from the same quantities."""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

from ...errors import ParameterError, SceneError
from ...limits import Limit
from ...schema import Items, Rule, Section
from ...trust.health import Figure, judge
from .aerodynamics import Uplift, uplifts
from .pantographs import PANTOGRAPHS, TWO_MASS, Pantograph
from .params import CatenaryParams

#: length of a pantograph head along the track (m): two contact points closer than this would share one head
HEAD_WIDTH = 0.5
#: most pantographs on one train (the compiled core's fixed per-step buffer)
MAX_PANTOGRAPHS = 64
#: the catenary's time step (its upper bounds depend on the parameters: `check_timestep`)
TIMESTEP = Limit(lo=0.0, lo_open=True, unit="s", doc="time step of the passage")
#: a steady arm's uplift is charged to a pantograph while it is within this distance of it (m)
UPLIFT_REACH = 30.0


#: ratio V / c above which a warning is issued: EN 50119 limits the line speed to 70 % of the CW wave speed
WARN_RATIO = 0.7
#: ratio above which the warning says the regime is near-critical
NEAR_CRITICAL_RATIO = 0.9


class CriticalSpeedWarning(UserWarning):
    """The train speed approaches the contact wire's wave propagation speed sqrt(T/rho)."""


def speed_regime(p: CatenaryParams, speed_ms: float) -> dict[str, Any]:
    """Wave speed, speed ratio and Doppler factor (c - V)/(c + V) of the contact wire; raises for V >= c and warns
    (CriticalSpeedWarning) above 70 % and 90 % of c."""
    c = p.cw_wave_speed
    ratio = speed_ms / c
    info = {"cw_wave_speed_ms": c, "cw_wave_speed_kmh": 3.6 * c, "speed_ratio": ratio,
            "doppler_factor": (c - speed_ms) / (c + speed_ms), "regime": "subcritical", "warnings": []}
    if ratio >= 1.0:
        raise ParameterError(
            f"speed {3.6 * speed_ms:.1f} km/h is at or above the contact wire wave speed sqrt(T/rho) = "
            f"{3.6 * c:.1f} km/h: the critical/supercritical regime has no steady solution in this "
            "small-displacement model")
    if ratio >= WARN_RATIO:
        info["regime"] = "near-critical" if ratio >= NEAR_CRITICAL_RATIO else "above EN 50119 limit"
        msg = (f"speed {3.6 * speed_ms:.1f} km/h is {100 * ratio:.1f} % of the contact wire wave speed "
               f"{3.6 * c:.1f} km/h (Doppler factor {info['doppler_factor']:.3f}); EN 50119 limits operation to "
               f"{100 * WARN_RATIO:.0f} %.")
        if ratio >= NEAR_CRITICAL_RATIO:
            msg += (" Near-critical regime: the wave ahead of the pantograph piles up, uplift and force variation grow"
                    " steeply and depend on mesh and time step; check convergence before using these numbers.")
        info["warnings"].append(msg)
        warnings.warn(msg, CriticalSpeedWarning, stacklevel=3)
    return info


def passage_size(p: CatenaryParams, speed_ms: float, dt: float) -> tuple[int, int]:
    """(FE elements, time steps) of a passage, computed from the parameters without building anything: each wire
    has at least ceil(its length / element_length) elements (key points only add some), the pantograph moves
    x_end - x_start at speed_ms in steps of dt."""
    from .passage import steps_to_cover  # here: the passage module imports the FE (scipy.sparse)

    if p.line is not None:
        elements = sum(math.ceil((w.x1 - w.x0) / p.element_length) for w in p.line.wires)
    else:
        elements = 2 * math.ceil(p.length / p.element_length)
    steps = steps_to_cover(p.x_end - p.x_start, speed_ms, dt)
    return elements, steps


def check_size(p: CatenaryParams, speed_ms: float, dt: float, max_steps: float | None = None) -> None:
    """Refuse a passage whose elements x steps exceed `p.max_element_steps` (or whose steps exceed `max_steps`,
    the scene's solver.max_steps) with a `SceneError` naming the settings, before anything is allocated."""
    elements, steps = passage_size(p, speed_ms, dt)
    what = (f"a passage of {p.x_end - p.x_start:g} m at {3.6 * speed_ms:g} km/h with dt = {dt:g} s is {steps:,} "
            f"steps; element_length = {p.element_length:g} m gives about {elements:,} elements")
    if elements * steps > p.max_element_steps:
        raise SceneError(f"{what}: {float(elements) * steps:.3g} element-steps exceed params.max_element_steps = "
                         f"{p.max_element_steps:.3g}; enlarge element_length or timestep, or raise "
                         "max_element_steps if you mean it")
    if max_steps is not None and steps > max_steps:
        raise SceneError(f"{what}: exceeds solver.max_steps = {max_steps:.3g}; enlarge the timestep or raise "
                         "solver.max_steps (CLI: --max-steps) if you mean it")


def wave_courant(p: CatenaryParams, dt: float) -> Figure:
    """Health figure of the FE wave resolution: c dt / element_length, the elements a wire wave (c = the faster
    wire's sqrt(T/rho)) crosses per step; bound 1. The mesh resolves waves one element long; a longer step skips
    them (the trapezoidal rule stays stable but distorts them), and so does the pantograph, slower than the wave."""
    c = p.max_wave_speed
    dt_max = p.element_length / c
    return Figure("wave_courant", float(c * dt / p.element_length), 1.0, "",
                  f"FE elements a wire wave (sqrt(T/rho) = {c:.1f} m/s) crosses per solver.timestep",
                  f"solver.timestep (--timestep) {dt:g} s is outside its valid range (0, {dt_max:.4g}] s = "
                  f"params.element_length / c = {p.element_length:g} m / {c:.1f} m/s: lower it, or enlarge "
                  "params.element_length")


def check_timestep(p: CatenaryParams, dt: float) -> None:
    """The hard bound of the catenary's time step, checked before anything is built: a positive dt below
    1 / (2 filter_cutoff) (the 20 Hz EN 50318 contact-force filter needs the record's Nyquist frequency above its
    cut-off; past it the statistics do not exist). A `ParameterError` names `solver.timestep` (CLI `--timestep`), the
    valid range and why; the accuracy bound (`wave_courant`) is `check_wave_resolution`'s."""
    dt = TIMESTEP.check("solver.timestep (--timestep)", dt, ParameterError)
    c = p.max_wave_speed
    nyquist, courant = 1.0 / (2.0 * p.filter_cutoff), p.element_length / c
    if not dt < nyquist:
        raise ParameterError(
            f"solver.timestep (--timestep) = {dt:g} s is outside its valid range (0, {nyquist:.4g}) s: the "
            f"{p.filter_cutoff:g} Hz contact-force filter (params.filter_cutoff) needs the record's Nyquist frequency "
            f"1/(2 dt) above its cut-off (and the FE wave resolution asks for at most params.element_length / c = "
            f"{p.element_length:g} m / {c:.1f} m/s = {courant:.4g} s)")


def check_wave_resolution(p: CatenaryParams, dt: float, allow_inaccurate: bool = False) -> list[str]:
    """The FE wave resolution of a (valid) time step, judged before anything is built: `wave_courant` past its bound
    is an `AccuracyError` naming `solver.timestep` and its valid range, unless `allow_inaccurate` (then its warning
    is returned; the run's health figures carry it again)."""
    fig = wave_courant(p, dt)
    if fig.ok:
        return []
    if not allow_inaccurate:
        judge([fig], what="catenary passage")  # raises AccuracyError naming the figure, its bound and the fix
    return ["INACCURATE: " + fig.message("catenary passage")]


def health_of_regime(speed_ms: float, p: CatenaryParams, dt: float | None = None) -> list[Figure]:
    """`health` from the speed (m/s), the catenary parameters and the time step (s; adds `wave_courant`) (used by
    single and train passages)."""
    c = p.cw_wave_speed
    figs = [Figure("speed_ratio", float(speed_ms / c), NEAR_CRITICAL_RATIO, "",
                   "train speed / contact wire wave speed sqrt(T/rho)",
                   f"lower input.speed below {3.6 * NEAR_CRITICAL_RATIO * c:.1f} km/h "
                   "or raise cw_tension; a near-critical passage needs its own mesh and step convergence study")]
    return figs + ([wave_courant(p, dt)] if dt is not None else [])


def check_train(p: CatenaryParams, spacings: Sequence[float], head_width: float = HEAD_WIDTH) -> list[float]:
    """Offsets s_k (m) of the pantographs behind the leading one from the spacings; errors name the bad value: a
    spacing below a head width, or a train whose leading pantograph would leave the line before the last one ends
    its run."""
    if len(spacings) + 1 > MAX_PANTOGRAPHS:
        raise ParameterError(f"{len(spacings) + 1} pantographs; the core takes at most {MAX_PANTOGRAPHS}")
    offsets = [0.0]
    spacing = dataclasses.replace(SPACING, lo=head_width)
    for i, s in enumerate(spacings):
        offsets.append(offsets[-1] + spacing.check(f"spacing[{i}]", s, ParameterError,
                                                   " (two pantographs closer than a head width share one head)"))
    lead_end = p.x_end + offsets[-1]
    if lead_end > p.length + 1e-9:
        raise ParameterError(
            f"spacings {list(spacings)} m: the leading pantograph would be at x = {lead_end:g} m, outside the "
            f"catenary [0, {p.length:g}] m, when the last one reaches x_end = {p.x_end:g} m; valid: total spacing "
            f"<= {p.length - p.x_end:g} m (or lengthen the line)")
    return offsets


class Admitted(NamedTuple):
    """What `PassageConfig.check` found: the speed (m/s), the regime (`speed_regime`), the pantographs' offsets
    behind the leading one (m), the warnings to carry with the run and each pantograph's aerodynamic uplift
    (`aerodynamics.Uplift`, leading first; None without an `[aerodynamics]` section)."""

    V: float
    regime: dict[str, Any]
    offsets: list[float]
    warnings: list[str]
    uplift: list[Uplift] | None = None


@dataclass(frozen=True)
class PassageConfig:
    """One passage: catenary parameters `params`, train speed `speed_kmh`, time step `dt` (s), the `pantographs`
    (names of the `pantograph` effect or objects of the `pantographs.Pantograph` protocol, leading first) with the
    `spacings` (m) between consecutive contact points (a single pantograph: a train of one, no spacings), the
    `dropper_law` and `contact` effects, the pantographs' engine path `engine` with the scene's `[pantograph]` section,
    the scene's `solver.max_steps` and `solver.allow_inaccurate`, the head width below which two contact points
    would share one head, and the scene's `[aerodynamics]` section (`aerodynamics.py`; None: no aerodynamic force)."""

    params: CatenaryParams
    speed_kmh: float
    dt: float
    pantographs: tuple[str | Pantograph, ...] = (TWO_MASS,)
    spacings: tuple[float, ...] = ()
    dropper_law: str = "slack"
    contact: str = "unilateral"
    engine: str = "reference"
    pantograph_section: Mapping[str, Any] | None = None
    max_steps: float | None = None
    allow_inaccurate: bool = False
    head_width: float = HEAD_WIDTH
    aerodynamics: Mapping[str, Any] | None = None

    def check(self) -> Admitted:
        """Every check of the passage, before anything is built: the pantograph count against the spacings, the
        speed, the time step, the spacings (`check_train`), the speed regime, the size of the whole train's job
        (`check_size`), the FE wave resolution (`check_wave_resolution`) and the aerodynamic uplift of each pantograph
        (`aerodynamics.uplifts`: the case each one runs, its coefficients); errors name the culprit."""
        p, dt, speed = self.params, self.dt, self.speed_kmh
        n, ns = len(self.pantographs), len(self.spacings)
        if n != ns + 1:
            raise ParameterError(f"{n} pantographs need {n - 1} spacings, got {ns}")
        speed = Limit(lo=0.0, lo_open=True, unit="km/h").check("speed", speed, ParameterError)
        dt = TIMESTEP.check("solver.timestep (--timestep)", dt, ParameterError)
        check_timestep(p, dt)
        offsets = check_train(p, self.spacings, self.head_width)
        V = speed / 3.6
        regime = speed_regime(p, V)
        check_size(dataclasses.replace(p, x_end=p.x_end + offsets[-1]), V, dt, self.max_steps)
        step_warn = check_wave_resolution(p, dt, self.allow_inaccurate)
        up = uplifts(self.aerodynamics, V, n)
        return Admitted(V, regime, offsets, list(regime["warnings"]) + step_warn, up)


# --- the scene's [train] section -------------------------------------------------------------------------------------
#: the distance between consecutive contact points of a train
SPACING = Limit(lo=HEAD_WIDTH, hi=1e4, unit="m", doc="distance between consecutive contact points, >= a head width")


def _one_fewer(d: Mapping[str, Any]) -> str | None:
    n, ns = len(d["pantographs"]), len(d["spacings"])
    return None if ns == n - 1 else f"{n} pantographs need {n - 1} spacings (m), got {ns}"


#: the declaration of a scene's `[train]` section; spacing limits against the line are checked when the passage
#: starts (`check_train`)
SECTION = Section("[train]", {
    "pantographs": Items(Limit(kind=str, choices=tuple(PANTOGRAPHS)), min=1, max=MAX_PANTOGRAPHS,
                         doc="the pantographs, leading first (values of the pantograph effect)"),
    "spacings": Items(SPACING, max=MAX_PANTOGRAPHS - 1, default=(), unit="m",
                      doc="distances between consecutive contact points (one fewer than pantographs)"),
}, required=("pantographs",), rules=(Rule("one spacing fewer than pantographs", _one_fewer),),
    doc="several pantographs on one train",
    example={"pantographs": ["reference2mass", "reference2mass"], "spacings": [200.0]})


def validate_train_section(value: Any) -> dict[str, Any]:
    """Validator of a scene's `[train]` section (`SECTION`)."""
    out = SECTION.check(value, "[train]")
    return {"pantographs": list(out["pantographs"]), "spacings": [float(s) for s in out["spacings"]]}


validate_train_section.schema = SECTION
