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
from . import design as D
from .params import PARAM_SETS

#: the parameter sets whose motor, bearings, delays and controller rate a design scene may take (step-up/step-down)
BASE_SETS = ("design_100w", "proto_100w", "proto_50w", "example_500w")


@dataclass(frozen=True)
class DesignInputs:
    """The inputs of a drive design (SI units). `Sr_min`, `w_min`, `w_max`, `V_m`, `P` are CADJS's (Eqs 5.9-5.13);
    give `tau_c` (clutch torque, N m: the family read at it, as Tables 5.2/6.2) or `J_s` (kg m^2) to pick the point."""

    P: float  # W: design power
    Sr_min: float  # 1/s: lowest switching rate (Eq 5.1, `design srmin`)
    w_max: float  # rad/s: highest load speed
    V_m: float  # rad/s: motor speed
    w_min: float = 0.0  # rad/s: lowest load speed
    tau_c: float | None = None  # N m: clutch torque of the design point
    J_s: float | None = None  # kg m^2: spring-system inertia of the design point (instead of tau_c)
    J_l: float | None = None  # kg m^2: load inertia (default: the base set's)
    w_op: float | None = None  # rad/s: operating speed the scene's PI tracks (default (w_min + w_max) / 2)
    tau_l: float | None = None  # N m: Coulomb load torque (default P / w_op)
    P_motor: float | None = None  # W: largest motor power, at V_m (default 1.5 P: the drive's losses)
    base: str = "design_100w"  # parameter set for bearings, delays, controller rate, motor inertia
    duration: float = 6.0  # s: simulated time
    t_settle: float | None = None  # s: start of the statistics window (default duration / 2)

    def __post_init__(self) -> None:
        # any real number type (numpy scalars, 0-d arrays, Fraction) is stored as the float it holds
        for nm in ("P", "Sr_min", "w_max", "V_m", "duration"):
            object.__setattr__(self, nm, D._pos(nm, getattr(self, nm)))
        object.__setattr__(self, "w_min", D._real("w_min", self.w_min))
        for nm in ("tau_c", "J_s", "J_l", "w_op", "tau_l", "P_motor", "t_settle"):
            if getattr(self, nm) is not None:
                object.__setattr__(self, nm, D._pos(nm, getattr(self, nm)))
        if (self.tau_c is None) == (self.J_s is None):
            raise ParameterError(f"a design point needs exactly one of tau_c (clutch torque) and J_s (spring-system "
                                 f"inertia); got tau_c = {self.tau_c!r}, J_s = {self.J_s!r}")
        if not 0 <= self.w_min < self.w_max:
            raise ParameterError(f"w_min = {self.w_min!r} rad/s must be >= 0 and below w_max = {self.w_max!r} rad/s")
        if self.w_op is not None and not self.w_min <= self.w_op <= self.w_max:
            raise ParameterError(f"w_op = {self.w_op!r} rad/s must lie in the design's speed band [w_min, w_max] = "
                                 f"[{self.w_min!r}, {self.w_max!r}] rad/s")
        if self.base not in BASE_SETS:
            raise ParameterError(f"base = {self.base!r} is not a step-up/step-down parameter set; valid: "
                                 f"{list(BASE_SETS)}")
        if self.t_settle is not None and self.t_settle >= self.duration:
            raise ParameterError(f"t_settle = {self.t_settle!r} s must be below duration = {self.duration!r} s")

    def to_dict(self) -> dict[str, Any]:
        """The inputs that were given (None left out), as recorded in a scene's `[design]` section."""
        return {k: v for k, v in dataclasses.asdict(self).items() if v is not None}


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
    params = {"J_s": v["J_s"], "K": v["K"], "tau_c1": v["tau_c"], "tau_c2": v["tau_c"], "spring_max": v["x_max"],
              "J_l": v["J_l"], "tau_l": v["tau_l"], "Kp": v["Kp"], "Ki": v["Ki"], "tau_0": v["tau_0"],
              "tau_slope": v["tau_slope"]}
    desc = (f"{inp.P:g} W step-up/step-down drive designed by CADJS (Sr_min {inp.Sr_min:g} /s, load speed "
            f"{inp.w_min:g}-{inp.w_max:g} rad/s, motor {inp.V_m:g} rad/s), closed loop at {v['w_op']:g} rad/s")
    return {
        "model": "drives", "name": name, "description": desc,
        "effects": {"mechanism": "step_up_down", "param_set": inp.base, "controller": "energy_packet",
                    "closed_loop": True, "added_motor_inertia": bool(base.get("J_add"))},
        "params": params,
        "input": {"type": "reference", "value": v["w_op"]},
        "solver": {"duration": inp.duration,
                   "t_settle": inp.t_settle if inp.t_settle is not None else inp.duration / 2},
        "design": {"inputs": inp.to_dict(), "derived": v},
    }


def validate_section(section: Any) -> dict[str, Any]:
    """The `[design]` section of a scene: a record of the design it came from (`inputs`: the `DesignInputs` given,
    `derived`: the values the scene took from it). The run reads `[params]`; this checks that the inputs form a valid
    design and that `derived` is what they give (to 1e-9), so a scene edited by hand cannot carry a stale record."""
    if not isinstance(section, dict) or set(section) - {"inputs", "derived"} or "inputs" not in section:
        raise SceneError(f"[design] = {section!r} must hold an [design.inputs] table (the DesignInputs) and optionally "
                         "[design.derived]")
    fields = {f.name for f in dataclasses.fields(DesignInputs)}
    bad = sorted(set(section["inputs"]) - fields)
    if bad:
        raise SceneError(f"unknown key(s) {bad} in [design.inputs]; valid keys: {sorted(fields)}")
    try:
        inp = DesignInputs(**section["inputs"])
        v = derived(inp)
    except (ParameterError, TypeError) as exc:
        raise SceneError(f"[design.inputs]: {exc}") from exc
    for k, x in (section.get("derived") or {}).items():
        if k not in v:
            raise SceneError(f"unknown key {k!r} in [design.derived]; valid keys: {sorted(v)}")
        if not isinstance(x, int | float) or not math.isclose(x, v[k], rel_tol=1e-9, abs_tol=1e-300):
            raise SceneError(f"[design.derived] {k} = {x!r} is not what [design.inputs] give ({v[k]!r}); remove "
                             "[design.derived] or write the scene again (mbsuite drive design cadjs ... --scene-out)")
    return {"inputs": inp.to_dict(), "derived": v}


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
