"""What a drives scene's configuration uses: the parameters, input keys and effects read by its mechanism, controller,
switching scheme and options (`used_params`), the mechanisms each parameter set is made for (`SET_MECHANISMS`), and the
check that refuses a scene setting something its configuration does not read, or lacking something it does
(`check_scene`; both are `SceneError`s naming the key, the value and the configuration)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ...errors import SceneError

#: the mechanisms each parameter set describes (a set is complete for these: `tests/drives/test_config.py`)
SET_MECHANISMS: dict[str, tuple[str, ...]] = {
    "table_4_2": ("step_up",),
    "design_100w": ("step_up_down",),
    "proto_100w": ("step_up_down",),
    "proto_50w": ("step_up_down",),
    "example_500w": ("step_up_down",),
}
#: the controllers of each drive mechanism
CONTROLLERS: dict[str, tuple[str, ...]] = {"step_up": ("pwm", "resonant", "motor_resonant"),
                                           "step_up_down": ("energy_packet",)}
#: parameters that may stay unset (None) in a set: the controller then takes a documented default
#: (max_tk = t_l / 2; K_ctrl = K, Omega_ctrl = sqrt(K/J_s), spring_max = min(tau_c1, tau_c2) / K; speeds 70 and 0
#: rad/s), or the reference comes from the scene's input
OPTIONAL = frozenset({"max_tk", "K_ctrl", "Omega_ctrl", "spring_max", "min_motor_vel", "min_load_vel", "ref",
                      "tau_l", "J_add"})
MOTOR_EQ_4_1 = ("K_t", "K_e", "R", "V_s")
MOTOR_LINE = ("tau_0", "tau_slope")


def used_params(mechanism: str, effects: Mapping[str, Any], inp: Mapping[str, Any],
                straight_line_motor: bool) -> set[str]:
    """The `DriveParams` fields a drive of this configuration reads.
    `straight_line_motor`: the motor is App. J's tau_0 + tau_slope w (tau_0 set) rather than Eq 4.1."""
    kind = effects["controller"]
    closed = bool(effects.get("closed_loop", False))
    used = {"set", "J_m", "J_s", "J_l", "K", "tau_l", "fs", "peak"}
    used |= set(MOTOR_LINE if straight_line_motor else MOTOR_EQ_4_1)
    if effects.get("bearing_friction", True):
        used |= {"B_m", "B_s", "B_l", "C_m", "C_s", "C_l"}
    if effects.get("added_motor_inertia", False):
        used.add("J_add")
    if effects.get("clutch_delays", True):
        used |= {"d_on", "d_off"}
    has_ref = "value" in inp or "profile" in inp
    if mechanism == "step_up":
        used |= {"tau_b", "tau_c", "twist_tol"}
        if kind == "motor_resonant":  # restarts on the motor speed band, no storage time
            used |= {"t_n", "min_vel", "max_vel"}
        else:
            used.add("t_l")  # PWM cycle; resonant: the storage time duty x t_l, the PI's clamp t_l / 2
            if closed:
                used |= {"Kp", "Ki", "max_tk"} | (set() if has_ref else {"ref"})
            else:
                used.add("duty")
            if kind == "resonant":
                used.add("t_n")
    else:
        used |= {"tau_c1", "tau_c2", "K_ctrl", "Omega_ctrl", "spring_max", "min_motor_vel", "min_load_vel"}
        if closed:
            used |= {"Kp", "Ki"}
        if not has_ref:
            used.add("ref")
    return used


def check_scene(scene, resolved: Mapping[str, Any]) -> None:
    """Refuse a scene whose configuration does not read something it sets (a parameter, an input key, an effect),
    or whose parameter set lacks something the configuration reads: a `SceneError` naming the key, its value and
    what would read it. `resolved`: the scene's parameters merged with its set."""
    eff = scene.effects
    mech = eff["mechanism"]
    # the scene by name (a value may have come from its file, from Python or from the command line)
    where = f" (scene {scene.name!r})" if scene.name else ""
    kind = eff["controller"]
    if kind not in CONTROLLERS[mech]:
        raise SceneError(f"effects.controller = {kind!r}{where} does not drive mechanism {mech!r}; valid: "
                         f"{list(CONTROLLERS[mech])}")
    closed = bool(eff.get("closed_loop", False))
    if mech == "step_up" and kind == "motor_resonant" and closed:
        raise SceneError(f"effects.closed_loop = true{where} has no effect on the motor-resonant controller (it "
                         "switches on the motor speed band min_vel/max_vel, not on a storage time t_k); set it false")
    if not closed and not eff.get("anti_windup", True):
        raise SceneError(f"effects.anti_windup = false{where} acts on the PI only, and effects.closed_loop is false")
    if mech == "step_up_down" and eff.get("clutch_matching", False):
        raise SceneError(f"effects.clutch_matching = true{where} is the step-up drive's (Eq 2.1); the energy-packet "
                         "controller of the step-up/step-down drive times its clutches itself (App. F)")
    if mech == "step_up" and "profile" in scene.input:
        raise SceneError(f"input.profile{where}: the step-up drive takes a constant reference (input.value)")
    if mech == "step_up" and not closed and "value" in scene.input:
        # open loop the step-up controllers switch on duty x t_l, t_n or the motor speed band: no reference acts
        raise SceneError(f"input.value = {scene.input['value']!r} rad/s{where} has no effect on the open-loop step-up "
                         f"drive (controller {kind!r} switches on its duty/timing parameters); leave input.value out, "
                         "or set effects.closed_loop = true for the PI on t_k to track it")
    line = resolved.get("tau_0") is not None
    used = used_params(mech, eff, scene.input, line)
    config = f"mechanism {mech!r}, controller {kind!r}, closed_loop = {str(closed).lower()}"
    unused = sorted(set(scene.params) - used)
    if unused:
        extra = ""
        if line and set(unused) & set(MOTOR_EQ_4_1):
            extra = " (the motor is the straight line tau_0 + tau_slope w: tau_0 is set)"
        elif set(unused) & {"ref"}:
            extra = " (the input gives the reference)"
        raise SceneError(f"parameter(s) {', '.join(f'{k} = {scene.params[k]!r}' for k in unused)}{where} are not "
                         f"read by this configuration ({config}){extra}; remove them. Read: {sorted(used)}")
    missing = sorted(k for k in used - OPTIONAL if resolved.get(k) is None)
    if missing:
        ps = resolved["set"]
        made = [s for s, m in SET_MECHANISMS.items() if mech in m]
        raise SceneError(f"parameter set {ps!r}{where} is made for {list(SET_MECHANISMS.get(ps, ()))} and lacks "
                         f"{missing} needed by {config}; set them in [params] or use a set for {mech!r} "
                         f"([params] set = one of {made})")
