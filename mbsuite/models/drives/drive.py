"""The two drives as `RotorSystem`s (Eqs 3.1-3.6) with their controllers, and the analysis of a run: energy balance,
cycle statistics, energy packets, the comparison of two runs.

Step-up (Fig. 3.3): motor -K- spring end; brake spring end -> ground; clutch spring end -> load (Eqs 3.1-3.3).
Step-up/step-down (Fig. 3.4): spring system -K- ground; clutch a motor -> spring; clutch b spring -> load (3.4-3.6).
Bearings: viscous B w (implicit in each rotor) + Coulomb C as ground friction elements with stiction (event-exact);
the load torque tau_l "always opposes motion" (Sec. 3.1.1) and is lumped with C_l as a Coulomb element whose share
tau_l/(C_l+tau_l) of the dissipation is the output work (Eq 3.22).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ...components.rotational.commands import delay_samples
from ...components.rotational.energy import Balance, energy_balance  # noqa: F401 (the drives' analysis API)
from ...components.rotational.interfaces import Friction, Part, RefResult, RotorSystem, Source, Spring
from ...errors import ParameterError, SceneError
from .controllers import EnergyPacketController, StepUpController
from .params import motor_line

ROTORS = ["motor", "spring", "load"]
T0_TOL = 1e-9  # s: window starts compare controller times with this tolerance


def build_system(mechanism: str, p: Mapping[str, Any], effects: Mapping[str, Any]) -> RotorSystem:
    """Rotor system of a drive from resolved parameters; effects `bearing_friction`, `clutch_delays`,
    `added_motor_inertia` decide what is built (an effect that is off adds no element)."""
    bearings = bool(effects.get("bearing_friction", True))
    J = [p["J_m"] + ((p["J_add"] or 0.0) if effects.get("added_motor_inertia", False) else 0.0), p["J_s"], p["J_l"]]
    if effects.get("added_motor_inertia", False) and not p["J_add"]:
        raise ParameterError("effect added_motor_inertia is on but parameter J_add is 0")
    B = [p["B_m"], p["B_s"], p["B_l"]] if bearings else [0.0, 0.0, 0.0]
    C = [p["C_m"], p["C_s"], p["C_l"]] if bearings else [0.0, 0.0, 0.0]
    peak = float(p["peak"])
    c0, c1 = motor_line(p)
    src = [Source("motor", 0, c0, c1)]
    load_parts = [Part("load_bearing", C[2])] + ([Part("load", p["tau_l"], output=True)] if p["tau_l"] else [])
    delays = effects.get("clutch_delays", True)
    d = (p["d_on"], p["d_off"]) if delays else (0.0, 0.0)
    if mechanism == "step_up":
        for k in ("tau_b", "tau_c"):
            if not p.get(k):
                raise ParameterError(f"step-up drive needs a positive {k}, got {p.get(k)!r}")
        fr = [
            Friction("motor_ground", 0, -1, [Part("motor_bearing", C[0])]),
            Friction("spring_ground", 1, -1, [Part("spring_bearing", C[1]), Part("brake", p["tau_b"], "brake")],
                     peak=peak),
            Friction("clutch", 1, 2, [Part("clutch", p["tau_c"], "clutch")], peak=peak),
            Friction("load_ground", 2, -1, load_parts),
        ]
        springs = [Spring("twist", 0, 1, p["K"])]
        delay_map = {"brake": d, "clutch": d}
    elif mechanism == "step_up_down":
        for k in ("tau_c1", "tau_c2"):
            if not p.get(k):
                raise ParameterError(f"step-up/step-down drive needs a positive {k}, got {p.get(k)!r}")
        fr = [
            Friction("motor_ground", 0, -1, [Part("motor_bearing", C[0])]),
            Friction("spring_ground", 1, -1, [Part("spring_bearing", C[1])]),
            Friction("load_ground", 2, -1, load_parts),
            Friction("clutch_a", 0, 1, [Part("clutch_a", p["tau_c1"], "ca")], peak=peak),
            Friction("clutch_b", 1, 2, [Part("clutch_b", p["tau_c2"], "cb")], peak=peak),
        ]
        springs = [Spring("ground", 1, -1, p["K"])]
        delay_map = {"ca": d, "cb": d}
    else:
        raise SceneError(f"unknown mechanism {mechanism!r}; valid: ['step_up', 'step_up_down']")
    # only what is asked for is built: a Coulomb part of zero level (bearings off, no load torque) is not an element
    fr2 = []
    for f in fr:
        f.parts = [pt for pt in f.parts if pt.command is not None or pt.level > 0.0]
        if f.parts:
            fr2.append(f)
    return RotorSystem(names=list(ROTORS), J=np.array(J), B=np.array(B), springs=springs, frictions=fr2, sources=src,
                       delays=delay_map)


def _given(p: Mapping[str, Any], key: str, default: float) -> float:
    """p[key] if it is set (not None), else the default; 0 is a value, not 'unset' (DriveParams rejects a 0 where it
    is not allowed)."""
    v = p.get(key)
    return float(default if v is None else v)


def build_controller(mechanism: str, kind: str, p: Mapping[str, Any], effects: Mapping[str, Any], ref=None):
    """Controller of a drive from resolved parameters. The delays it compensates are the ones actually applied:
    `delay_samples(d, fs) / fs` (the command queue quantises the same way): step-up clutch matching subtracts the
    clutch's engagement delay minus the brake's release delay from the loiter time (Sec. 2.1.3: the spring starts
    when the brake lets go, the clutch acts when it engages); the energy-packet controller waits d_on less before an
    engagement and predicts each release d_off ahead."""
    fs = float(p["fs"])
    delays = effects.get("clutch_delays", True)
    cd = delay_samples(p["d_on"], fs) / fs if delays else 0.0  # engagement delay applied
    rd = delay_samples(p["d_off"], fs) / fs if delays else 0.0  # release delay applied
    closed = bool(effects.get("closed_loop", False))
    anti_windup = bool(effects.get("anti_windup", True))
    if mechanism == "step_up":
        if kind not in ("pwm", "resonant", "motor_resonant"):
            raise SceneError(f"unknown controller {kind!r} for the step-up drive; valid: "
                             "['pwm', 'resonant', 'motor_resonant']")
        if delays and kind != "motor_resonant" and p["d_on"] >= p["t_l"]:
            raise ParameterError(f"delay {p['d_on']} s is longer than the PWM cycle t_l = {p['t_l']} s")
        # the transfer ends when the twist falls below twist_tol; the friction on the spring end and the load holds a
        # static twist (C_s + C_l)/K, so a smaller twist_tol is never reached and the transfer never ends
        bearings = bool(effects.get("bearing_friction", True))
        held = (p["C_s"] + p["C_l"]) / p["K"] if bearings else 0.0
        twist_tol = _given(p, "twist_tol", 0.0)
        if twist_tol <= held:
            raise ParameterError(f"parameter twist_tol = {twist_tol} rad must exceed the friction-held static twist "
                                 f"(C_s + C_l)/K = {held:.4g} rad, else a transfer never ends")
        return StepUpController(kind=kind, fs=fs, t_l=p["t_l"], duty=p["duty"], t_n=p["t_n"],
                                twist_tol=twist_tol, min_vel=p["min_vel"], max_vel=p["max_vel"],
                                clutch_matching=bool(effects.get("clutch_matching", False)),
                                Omega=math.sqrt(p["K"] / p["J_s"]), delay_comp=cd - rd, closed_loop=closed,
                                Kp=p["Kp"], Ki=p["Ki"], ref=p["ref"], max_tk=p["max_tk"], anti_windup=anti_windup)
    if kind != "energy_packet":
        raise SceneError(f"unknown controller {kind!r} for the step-up/step-down drive; valid: ['energy_packet']")
    period_free = 2 * math.pi * math.sqrt(p["J_s"] / p["K"])
    if delays and max(p["d_on"], p["d_off"]) >= period_free:
        raise ParameterError(f"clutch delay {max(p['d_on'], p['d_off'])} s is longer than the spring system's free "
                             f"oscillation period {period_free:.4g} s (one energy cycle)")
    K_ctrl = _given(p, "K_ctrl", p["K"])
    Om = _given(p, "Omega_ctrl", math.sqrt(p["K"] / p["J_s"]))
    x_max = _given(p, "spring_max", min(p["tau_c1"], p["tau_c2"]) / p["K"])
    return EnergyPacketController(fs=fs, K=K_ctrl, Omega=Om, clutch_delay=cd, release_delay=rd, spring_max=x_max,
                                  min_motor_vel=_given(p, "min_motor_vel", 70.0),
                                  min_load_vel=_given(p, "min_load_vel", 0.0),
                                  closed_loop=closed, Kp=p["Kp"], Ki=p["Ki"], ref=ref if ref is not None else p["ref"],
                                  anti_windup=anti_windup)


def mean_speeds(res: RefResult, t0: float) -> dict[str, float]:
    """Time-mean load and motor speeds over the window [t_i0, T] from the first sample t_i0 >= t0 (controller times
    compared with `T0_TOL`): the angle travelled over the time, (theta(T) - theta(t_i0)) / (T - t_i0), exact for the
    integrated motion (a mean of the sampled speeds would add the output grid's quadrature error: 3e-3 to 1.8e-2
    rad/s on the shipped drives at their 1-2 ms sample)."""
    i0 = int(np.searchsorted(res.t, t0 - T0_TOL))
    if i0 >= res.t.size - 1:
        return {}
    span = float(res.t[-1] - res.t[i0])
    return {"mean_load_speed": float(res.q[2, -1] - res.q[2, i0]) / span,
            "mean_motor_speed": float(res.q[0, -1] - res.q[0, i0]) / span}


def cycle_stats(res: RefResult, ctrl, t0: float = 0.0) -> dict[str, Any]:
    """Energy cycles (from the controller log), switching rate, mean load speed, packet sizes, peak extension."""
    means = mean_speeds(res, t0)
    t0 = t0 - T0_TOL  # controller times are k/fs in one path and step*dt in the other: a boundary sample counts in both
    cyc = np.array([e["t"] for e in ctrl.log if e["event"] == "cycle" and e["t"] >= t0])
    out: dict[str, Any] = {"n_cycles": int(max(0, cyc.size - 1))}
    if cyc.size >= 2:
        out["switching_rate"] = float((cyc.size - 1) / (cyc[-1] - cyc[0]))
    out.update(means)
    packets = [e.get("eps") for e in ctrl.log if e["event"] == "cycle" and e.get("eps") is not None and e["t"] >= t0]
    if packets:
        out["packets"] = packets
    th = [e["theta_peak"] for e in ctrl.log if e["event"] == "transferred" and e["t"] >= t0]
    if th:
        out["max_extension"] = float(max(th))
    return out


def cycle_phases(ctrl, t0: float = 0.0) -> dict[str, float]:
    """Mean duration (s) of the phases of the step-up/step-down energy cycle from the controller log, over the cycles
    started at t >= t0: `wait_extraction` (cycle start -> input clutch commanded on), `extraction` (-> commanded off),
    `wait_transfer` (-> output clutch on), `transfer` (-> off), `restart` (-> next cycle start)."""
    keys = ("cycle", "extract_on", "extracted", "transfer_on", "transferred")
    rows = []
    log = [e for e in ctrl.log if e["event"] in keys]
    for i in range(len(log) - 5):
        seq = log[i:i + 6]
        if [e["event"] for e in seq] == [*keys, "cycle"] and seq[0]["t"] >= t0 - T0_TOL:
            rows.append(np.diff([e["t"] for e in seq]))
    if not rows:
        return {}
    m = np.mean(rows, axis=0)
    names = ("wait_extraction", "extraction", "wait_transfer", "transfer", "restart")
    out = {k: float(v) for k, v in zip(names, m, strict=True)}
    out["cycle"] = float(m.sum())
    out["n"] = len(rows)
    return out


def compare_events(a: RefResult, b: RefResult, elements: list[str], kinds=("stuck", "free"), t0: float = 0.0
                   ) -> dict[str, Any]:
    """Pair the lock-up (-> stuck) and release (-> free) events of two runs in order, per element and kind. Returns
    the counts n_a, n_b, the paired times t_a and differences dt = t_b - t_a, and max/median |dt|; when the counts
    differ nothing is paired and max_dt = inf (the runs do not have the same event sequence)."""
    out: dict[str, Any] = {}
    for el in elements:
        for kind in kinds:
            ta = np.array([e["t"] for e in a.events if e["element"] == el and e["to"] == kind and e["t"] >= t0])
            tb = np.array([e["t"] for e in b.events if e["element"] == el and e["to"] == kind and e["t"] >= t0])
            if ta.size == 0 and tb.size == 0:
                continue
            same = ta.size == tb.size
            d = tb - ta if same else np.full(0, np.nan)
            out[f"{el}->{kind}"] = {"n_a": int(ta.size), "n_b": int(tb.size), "t_a": ta if same else None, "dt": d,
                                    "max_dt": float(np.max(np.abs(d))) if same and d.size else
                                    (0.0 if same else float("inf")),
                                    "median_dt": float(np.median(np.abs(d))) if same and d.size else float("nan")}
    return out


def short_locks(res: RefResult, elements: list[str], max_len: float) -> list[tuple[str, float, float]]:
    """Stuck episodes that break loose again within `max_len` s: (element, t_stuck, t_release). In MuJoCo a grazing
    slip reversal near the breakaway torque can lock for a step or two where the exact path passes through."""
    out = []
    for el in elements:
        ev = [e for e in res.events if e["element"] == el]
        out += [(el, a["t"], b["t"]) for a, b in zip(ev, ev[1:], strict=False)
                if a["to"] == "stuck" and b["from"] == "stuck" and b["t"] - a["t"] < max_len]
    return out


def without_events(res: RefResult, episodes: list[tuple[str, float, float]]) -> RefResult:
    """The result with the events of `episodes` (from `short_locks`) removed, for pairing the remaining events."""
    drop = {(el, t) for el, a, b in episodes for t in (a, b)}
    return dataclasses.replace(res, events=[e for e in res.events if (e["element"], e["t"]) not in drop])


def compare_commands(ca, cb) -> dict[str, Any]:
    """Pair the two controllers' logs entry by entry. `same_sequence`: same events in the same order; `flips`: the
    entries whose controller sample differs, each with the computed waits (in samples, before the int() truncation)
    of both runs taken from the entry that set the wait."""
    la, lb = ca.log, cb.log
    same = len(la) == len(lb) and all(x["event"] == y["event"] for x, y in zip(la, lb, strict=False))
    flips = []
    if same:
        dt = ca.dt
        wait_a = wait_b = None
        for x, y in zip(la, lb, strict=True):
            if round(x["t"] / dt) != round(y["t"] / dt):
                flips.append({"event": x["event"], "t_a": x["t"], "t_b": y["t"], "wait_a": wait_a, "wait_b": wait_b})
            if "wait_samples" in x:
                wait_a, wait_b = x["wait_samples"], y.get("wait_samples")
    return {"same_sequence": same, "n": len(la), "n_b": len(lb), "flips": flips}


def _spring_system_energy(system: RotorSystem, res: RefResult, t: np.ndarray) -> np.ndarray:
    """Energy of the step-up/step-down spring system 1/2 J_s w_s^2 + 1/2 K theta_s^2 at times t (interpolated on the
    samples; exact when t is on the sample grid, as the actuation times are when sample_dt = the controller period)."""
    ws = np.interp(t, res.t, res.w[1])
    th = np.interp(t, res.t, res.q[1])
    return 0.5 * system.J[1] * ws**2 + 0.5 * system.springs[0].K * th**2


def energy_packets(system: RotorSystem, res: RefResult, ctrl, t0: float = 0.0) -> dict[str, np.ndarray]:
    """Energy packets of the step-up/step-down drive, one per complete energy cycle (cycle started at t >= t0).

    A packet is the energy the spring system takes up while the input clutch is applied (extraction):
    `stored = E_s(input clutch released) - E_s(input clutch engaged)`, E_s = 1/2 J_s w_s^2 + 1/2 K theta_s^2 (with the
    velocities matched at both ends this is 1/2 K (theta_end^2 - theta_start^2), the packet the controller asks for);
    `delivered = E_s(output clutch engaged) - E_s(output clutch released)` is what it hands on during the transfer.
    The engage/release times are the controller's commands plus the quantised actuation delays (`delay_samples`),
    i.e. when the clutch torque actually switches. Returns arrays t (cycle start), stored, delivered, demand (the PI's
    signed packet demand eps) and dir (+1 motor -> load, -1 load -> motor: regeneration).
    """
    if len(system.springs) != 1 or system.springs[0].a != 1 or system.springs[0].b >= 0:
        raise SceneError("energy packets are defined for the step-up/step-down drive (spring system to ground)")
    fs = 1.0 / ctrl.dt

    def act(e: dict, on: bool) -> float:
        d_on, d_off = system.delays.get(e["clutch"], (0.0, 0.0))
        return e["t"] + delay_samples(d_on if on else d_off, fs) / fs

    out: dict[str, list[float]] = {"t": [], "stored": [], "delivered": [], "demand": [], "dir": []}
    log = ctrl.log
    t_last = res.t[-1]
    for i, e in enumerate(log):
        if e["event"] != "cycle" or e["t"] < t0 - T0_TOL:
            continue
        seq = {}
        for f in log[i + 1:]:
            if f["event"] == "cycle":
                break
            seq[f["event"]] = f
        if not all(k in seq for k in ("extract_on", "extracted", "transfer_on", "transferred")):
            continue
        times = np.array([act(seq["extract_on"], True), act(seq["extracted"], False), act(seq["transfer_on"], True),
                          act(seq["transferred"], False)])
        if times[-1] > t_last:
            continue
        E = _spring_system_energy(system, res, times)
        out["t"].append(e["t"])
        out["stored"].append(E[1] - E[0])
        out["delivered"].append(E[2] - E[3])
        out["demand"].append(float(e.get("eps", 0.0)))
        out["dir"].append(float(e.get("dir", 1)))
    return {k: np.asarray(v, float) for k, v in out.items()}
