"""A Chapter 5 design as a runnable scene: `design_scene(DesignInputs(...))` returns the step-up/step-down scene (as a
dictionary the loader validates) whose spring, spring-system inertia, clutch torques, largest twist, motor and
closed-loop gains follow from the design, and `scene_toml` writes it as TOML with the inputs in its `[design]` section.

The design equations (Oldaker 1997, Sec. 5.1: SRMIN 5.1, CADJS 5.9-5.13 corrected, gains 5.32-5.38) describe the
step-up/step-down drive moving energy packets from a motor running at V_m to the load; the scene is that drive under
the energy-packet controller (App. F, fixed) with its velocity-squared PI closed on the operating speed:

* spring rate K, spring-system inertia J_s, clutch torques tau_c1 = tau_c2 = tau_c and the packet twist spring_max =
  x_max from the design point (`design.design_point`, or `design.at_clutch_torque` when `tau_c` is given);
* the switching rate at the operating speed, Sr(w_op) of Eq 5.13, reaches the controller as the energy-cycle period
  t_s = 1/Sr of its gains (Eqs 5.32-5.37, B_total from Eq 5.38): K_p, K_I;
* the motor is the straight line of App. J, tau = tau_0 + tau_slope w, through its stall torque 2 P_m / V_m and its
  no-load speed 2 V_m: it gives its largest power P_m at V_m (the App. J 500 W motor, 10 - 0.05 w at V_m = 100 rad/s,
  is this line for P_m = 500 W). The design model is lossless; the simulated drive is not (bearings, clutch slip:
  efficiency 0.85 on the 200 W example of the README), so P_m defaults to 1.5 P;
* the load: inertia J_l and a Coulomb load torque tau_l that takes the design power at the operating speed,
  tau_l = P / w_op (default w_op: the middle of the speed band [w_min, w_max]);
* bearings, actuation delays, controller rate and motor inertia from a base parameter set (default `design_100w`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...errors import ParameterError, SceneError
from ...limits import Limit, param, positive
from ...schema import Rule, Section, of_dataclass
from . import design as D
from .config import check_scene
from .params import BASE_SETS, PARAM_SETS, DriveParams


def _one_point(c: dict[str, Any]) -> str | None:
    if (c.get("tau_c") is None) == (c.get("J_s") is None):
        return (f"a design point needs exactly one of tau_c (clutch torque) and J_s (spring-system inertia); got "
                f"tau_c = {c.get('tau_c')!r}, J_s = {c.get('J_s')!r}")
    return None


def _band(c: dict[str, Any]) -> str | None:
    if not c["w_min"] < c["w_max"]:
        return f"w_min = {c['w_min']!r} rad/s must be below w_max = {c['w_max']!r} rad/s (the load speed range)"
    if c.get("w_op") is not None and not c["w_min"] <= c["w_op"] <= c["w_max"]:
        return (f"w_op = {c['w_op']!r} rad/s must lie in the design's speed band [w_min, w_max] = "
                f"[{c['w_min']!r}, {c['w_max']!r}] rad/s")
    return None


def _settle(c: dict[str, Any]) -> str | None:
    if c.get("t_settle") is not None and not c["t_settle"] < c["duration"]:
        return f"t_settle = {c['t_settle']!r} s must be below duration = {c['duration']!r} s"
    return None


def _optional(unit: str, doc: str) -> Any:
    """A positive quantity that may be left out (None: the scene derives it, `derived`)."""
    return param(None, lo=0.0, lo_open=True, unit=unit, doc=doc)


def _tool_input(key: str, *default: Any) -> Any:
    """A field declared by the design tools' `design.INPUT_LIMITS[key]` (one declaration per key), with `default`
    when given (None: optional)."""
    lim = D.INPUT_LIMITS[key]
    if not default:
        return dataclasses.field(metadata={"limit": lim})
    return dataclasses.field(default=default[0], metadata={"limit": dataclasses.replace(lim, default=default[0])})


@dataclass(frozen=True)
class DesignInputs:
    """The inputs of a drive design (SI units). `Sr_min`, `w_min`, `w_max`, `V_m`, `P` are CADJS's (Eqs 5.9-5.13);
    give `tau_c` (clutch torque, N m: the family read at it, as Tables 5.2/6.2) or `J_s` (kg m^2) to pick the point.
    Checked by `DESIGN_INPUTS` (each value against its declared range, then the rules)."""

    P: float = _tool_input("P")  # W
    Sr_min: float = _tool_input("Sr_min")  # 1/s (Eq 5.1, `design srmin`)
    w_max: float = _tool_input("w_max")  # rad/s
    V_m: float = _tool_input("V_m")  # rad/s
    w_min: float = _tool_input("w_min", 0.0)  # rad/s
    tau_c: float | None = _tool_input("tau_c", None)  # N m: the design point (or J_s)
    J_s: float | None = _tool_input("J_s", None)  # kg m^2: the design point (or tau_c)
    J_l: float | None = _tool_input("J_l", None)  # kg m^2 (default: the base set's)
    w_op: float | None = _optional("rad/s", "operating speed the scene's PI tracks (default (w_min + w_max) / 2)")
    tau_l: float | None = _optional("N m", "Coulomb load torque (default P / w_op)")
    P_motor: float | None = _optional("W", "largest motor power, at V_m (default 1.5 P: the drive's losses)")
    base: str = param("design_100w", kind=str, choices=BASE_SETS,
                      doc="parameter set for bearings, delays, controller rate, motor inertia")
    duration: float = param(6.0, lo=0.0, lo_open=True, unit="s", doc="simulated time")
    t_settle: float | None = _optional("s", "start of the statistics window (default duration / 2)")

    def __post_init__(self) -> None:
        # any real number type (numpy scalars, 0-d arrays, Fraction) is stored as the float it holds
        given = {k: v for k, v in dataclasses.asdict(self).items() if v is not None}
        for k, v in DESIGN_INPUTS.check(given, "design inputs", ParameterError).items():
            object.__setattr__(self, k, v)

    def to_dict(self) -> dict[str, Any]:
        """The inputs that were given (None left out), as recorded in a scene's `[design]` section."""
        return {k: v for k, v in dataclasses.asdict(self).items() if v is not None}


#: the inputs of a drive design: the `[design.inputs]` table of a design scene, `DesignInputs` in Python
DESIGN_INPUTS = of_dataclass(DesignInputs, "drive design inputs (design.inputs)", rules=(
    Rule("exactly one of tau_c and J_s (the design point)", _one_point),
    Rule("0 <= w_min < w_max; w_op, when given, in [w_min, w_max]", _band),
    Rule("t_settle, when given, below duration", _settle)))


def design_of(inp: DesignInputs) -> D.Design:
    """The design point of the inputs (CADJS at tau_c, or at J_s)."""
    if inp.tau_c is not None:
        return D.at_clutch_torque(inp.P, inp.Sr_min, inp.w_min, inp.w_max, inp.V_m, inp.tau_c)
    return D.design_point(inp.P, inp.Sr_min, inp.w_min, inp.w_max, inp.V_m, inp.J_s)


def derived(inp: DesignInputs) -> dict[str, float]:
    """What the scene takes from the design: the design point, the operating point and the controller gains."""
    d = design_of(inp)
    base = PARAM_SETS[inp.base]
    J_l = inp.J_l if inp.J_l is not None else float(base["J_l"])
    w_op = inp.w_op if inp.w_op is not None else 0.5 * (inp.w_min + inp.w_max)
    tau_l = inp.tau_l if inp.tau_l is not None else inp.P / w_op
    Sr_op = D.sr_from_kjs(inp.P, w_op, inp.V_m, d.K, d.J_s)
    B_total = D.b_total(inp.P, w_op, tau_l)
    Kp, Ki = D.gains(J_l, 1.0 / Sr_op, B_total, tau_l, w_op)
    P_m = inp.P_motor if inp.P_motor is not None else 1.5 * inp.P
    return {"J_s": d.J_s, "K": d.K, "tau_c": d.tau_c, "x_max": d.x_max, "Sr_max": d.Sr_max,
            "capacity": d.capacity, "J_l": J_l, "w_op": w_op, "tau_l": tau_l, "Sr_op": Sr_op, "B_total": B_total,
            "Kp": Kp, "Ki": Ki, "tau_0": 2 * P_m / inp.V_m, "tau_slope": -P_m / inp.V_m**2}


def design_scene(inp: DesignInputs, name: str = "") -> dict[str, Any]:
    """The step-up/step-down scene of a design, as a scene dictionary (`mbsuite.scenes.scene_from_dict` validates it;
    `mbsuite.run` runs it), its inputs and derived values in the `[design]` section."""
    v = derived(inp)
    period = 2 * math.pi * math.sqrt(v["J_s"] / v["K"])
    base = PARAM_SETS[inp.base]
    if max(base["d_on"], base["d_off"]) >= period:
        raise ParameterError(f"the design's free oscillation period 2 pi sqrt(J_s/K) = {period:.4g} s is not longer "
                             f"than the clutch delay {max(base['d_on'], base['d_off'])} s of the base set "
                             f"{inp.base!r}: choose a larger clutch torque tau_c or spring-system inertia J_s")
    params = {"set": inp.base, "J_s": v["J_s"], "K": v["K"], "tau_c1": v["tau_c"], "tau_c2": v["tau_c"],
              "spring_max": v["x_max"], "J_l": v["J_l"], "tau_l": v["tau_l"], "Kp": v["Kp"], "Ki": v["Ki"],
              "tau_0": v["tau_0"], "tau_slope": v["tau_slope"]}
    desc = (f"{inp.P:g} W step-up/step-down drive designed by CADJS (Sr_min {inp.Sr_min:g} /s, load speed "
            f"{inp.w_min:g}-{inp.w_max:g} rad/s, motor {inp.V_m:g} rad/s), closed loop at {v['w_op']:g} rad/s")
    return {
        "model": "drives", "name": name, "description": desc,
        "effects": {"mechanism": "step_up_down", "controller": "energy_packet",
                    "closed_loop": True, "added_motor_inertia": bool(base.get("J_add"))},
        "params": params,
        "input": {"type": "reference", "value": v["w_op"]},
        "solver": {"duration": inp.duration,
                   "t_settle": inp.t_settle if inp.t_settle is not None else inp.duration / 2},
        "design": {"inputs": inp.to_dict(), "derived": v},
    }


#: the values a design scene takes from its design (`derived`), each with the `[design.inputs]` keys it comes from
DERIVED_FROM: dict[str, tuple[str, ...]] = {
    **{k: ("P", "Sr_min", "w_min", "w_max", "V_m", "tau_c", "J_s")
       for k in ("J_s", "K", "tau_c", "x_max", "Sr_max", "capacity")},
    "J_l": ("J_l", "base"), "w_op": ("w_op", "w_min", "w_max"), "tau_l": ("tau_l", "P", "w_op"),
    "Sr_op": ("P", "w_op", "V_m", "tau_c", "J_s"), "B_total": ("P", "w_op", "tau_l"),
    "Kp": ("J_l", "P", "w_op", "tau_l", "V_m", "tau_c", "J_s"), "Ki": ("J_l", "P", "w_op", "V_m", "tau_c", "J_s"),
    "tau_0": ("P_motor", "P", "V_m"), "tau_slope": ("P_motor", "P", "V_m"),
}
#: relative tolerance of a recorded derived value against what its inputs give
DERIVED_RTOL = 1e-9

#: the `[design.derived]` table: what the scene took from its design (each checked against its inputs); a value that
#: is also a design-tool input keeps that declaration (`design.INPUT_LIMITS`)
DERIVED_VALUES = Section("design values derived from the inputs (design.derived)", {
    **{k: D.INPUT_LIMITS[k] for k in ("J_s", "K", "tau_c", "x_max", "J_l", "tau_l", "B_total", "Kp", "Ki")},
    "Sr_max": positive("1/s", "highest switching rate (at w_max, Eq 5.13)"),
    "capacity": positive("J", "spring capacity 1/2 K x_max^2"),
    "w_op": positive("rad/s", "operating speed"),
    "Sr_op": positive("1/s", "switching rate at w_op (Eq 5.13)"),
    "tau_0": positive("N m", "motor stall torque 2 P_m / V_m"),
    "tau_slope": Limit(hi=0.0, hi_open=True, unit="N m s/rad", doc="motor torque slope -P_m / V_m^2"),
})


def _consistent(c: dict[str, Any]) -> str | None:
    """None when every recorded derived value is what the recorded inputs give (to `DERIVED_RTOL`)."""
    try:
        v = derived(DesignInputs(**c["inputs"]))
    except ParameterError as exc:
        return f"[design.inputs] give no design: {exc}"
    for k, x in (c.get("derived") or {}).items():
        if not math.isclose(x, v[k], rel_tol=DERIVED_RTOL, abs_tol=1e-300):
            return (f"[design.derived] {k} = {x!r} is not what [design.inputs] "
                    f"({', '.join(i for i in DERIVED_FROM[k] if c['inputs'].get(i) is not None)}) give: {k} = {v[k]!r} "
                    f"(relative tolerance {DERIVED_RTOL:g}); remove [design.derived] or write the scene again "
                    "(mbsuite drive design cadjs ... --scene-out)")
    return None


#: the `[design]` section of a scene: the design inputs and, optionally, the values derived from them
DESIGN_SECTION = Section("drive design record ([design])", {"inputs": DESIGN_INPUTS, "derived": DERIVED_VALUES},
                         required=("inputs",), rules=(Rule(
                             f"every [design.derived] value is what [design.inputs] give (relative tolerance "
                             f"{DERIVED_RTOL:g})", _consistent),),
                         doc="a record of the design the scene came from; the run reads [params]",
                         example={"inputs": {"P": 200.0, "Sr_min": 15.0, "w_max": 400.0, "V_m": 100.0, "tau_c": 8.0,
                                             "w_op": 300.0}})


def validate_section(section: Any) -> dict[str, Any]:
    """The `[design]` section of a scene (`DESIGN_SECTION`): a record of the design it came from (`inputs`: the
    `DesignInputs` given, `derived`: the values the scene took from it). The run reads `[params]`; this checks that
    the inputs form a valid design and that `derived` is what they give (to `DERIVED_RTOL`), so a scene edited by
    hand cannot carry a stale record."""
    checked = DESIGN_SECTION.check(section, "[design]", SceneError)
    inp = DesignInputs(**checked["inputs"])
    return {"inputs": inp.to_dict(), "derived": derived(inp)}


validate_section.schema = DESIGN_SECTION

#: the scene values a design sets: [params] key (or "input.value") -> its [design.derived] key
SCENE_FROM_DESIGN = {"J_s": "J_s", "K": "K", "tau_c1": "tau_c", "tau_c2": "tau_c", "spring_max": "x_max", "J_l": "J_l",
                     "tau_l": "tau_l", "Kp": "Kp", "Ki": "Ki", "tau_0": "tau_0", "tau_slope": "tau_slope",
                     "input.value": "w_op"}


def scene_params(scene: Any) -> DriveParams:
    """The `DriveParams` of a drives scene (`ModelSpec.params_builder`, run when the scene loads). A scene that carries
    a `[design]` record must run what it records: each [params] value (and input.value) a design sets must equal its
    [design.derived] value (to `DERIVED_RTOL`), else a SceneError names both keys. Then the configuration's rules
    (`config.check_scene`): a parameter, input key or effect the configuration does not read, or a parameter it reads
    that the set lacks, is a SceneError naming it, when the scene loads."""
    design = scene.sections.get("design")
    if design is not None:
        v = design["derived"]
        for key, dkey in SCENE_FROM_DESIGN.items():
            have = scene.input.get("value") if key == "input.value" else scene.params.get(key)
            if have is not None and not math.isclose(have, v[dkey], rel_tol=DERIVED_RTOL, abs_tol=0.0):
                name = key if key.startswith("input.") else f"params.{key}"
                raise SceneError(f"{name} = {have!r} is not the design's [design.derived] {dkey} = {v[dkey]!r} "
                                 f"(relative tolerance {DERIVED_RTOL:g}): a scene edited by hand away from its design; "
                                 "remove [design] or write the scene again (mbsuite drive design cadjs ... "
                                 "--scene-out)")
    params = DriveParams(**dict(scene.params))
    check_scene(scene, params.resolved())
    return params


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int | float):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    raise TypeError(f"no TOML form for {v!r}")


def scene_toml(scene: dict[str, Any]) -> str:
    """A scene dictionary of `design_scene` as TOML text (flat tables; `[design.inputs]`, `[design.derived]`)."""
    lines = [f"model = {_toml_value(scene['model'])}", f"description = {_toml_value(scene['description'])}"]
    for sec in ("effects", "params", "input", "solver"):
        lines.append(f"[{sec}]")
        lines += [f"{k} = {_toml_value(x)}" for k, x in scene[sec].items()]
    for sub in ("inputs", "derived"):
        lines.append(f"[design.{sub}]")
        lines += [f"{k} = {_toml_value(x)}" for k, x in scene["design"][sub].items()]
    return "\n".join(lines) + "\n"


def write_scene(inp: DesignInputs, path: str | Path) -> Path:
    """Write the design's scene to `path` (TOML) and return the path."""
    path = Path(path)
    path.write_text(scene_toml(design_scene(inp, name=path.stem)), encoding="utf-8")
    return path
