"""The two drives as `RotorSystem`s (Eqs 3.1-3.6) and their simulation in both paths, with losses and energy balance.

Step-up (Fig. 3.3): motor -K- spring end; brake spring end -> ground; clutch spring end -> load (Eqs 3.1-3.3).
Step-up/step-down (Fig. 3.4): spring system -K- ground; clutch a motor -> spring; clutch b spring -> load (3.4-3.6).
Bearings: viscous B w (implicit in each rotor) + Coulomb C as ground friction elements with stiction (event-exact);
the load torque tau_l "always opposes motion" (L727) and is lumped with C_l as a Coulomb element whose share
tau_l/(C_l+tau_l) of the dissipation is the output work (Eq 3.22).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import ParameterError, SceneError
from ...paths import mjcf_path
from .controllers import EnergyPacketController, StepUpController
from .friction import Friction, Part, RefResult, RotorSystem, Source, Spring, simulate_reference
from .params import motor_line

ROTORS = ["motor", "spring", "load"]


def build_system(mechanism: str, p: Mapping[str, Any], effects: Mapping[str, Any]) -> RotorSystem:
    """Rotor system of a drive from resolved parameters; effects `bearing_friction`, `clutch_delays`,
    `added_motor_inertia` decide what is built (an effect that is off adds no element)."""
    bearings = bool(effects.get("bearing_friction", True))
    J = [p["J_m"] + (p["J_add"] or 0.0 if effects.get("added_motor_inertia", False) else 0.0), p["J_s"], p["J_l"]]
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


def build_controller(mechanism: str, kind: str, p: Mapping[str, Any], effects: Mapping[str, Any], ref=None):
    fs = float(p["fs"])
    delays = effects.get("clutch_delays", True)
    cd = p["d_on"] if delays else 0.0
    closed = bool(effects.get("closed_loop", False))
    if mechanism == "step_up":
        if kind not in ("pwm", "resonant", "motor_resonant"):
            raise SceneError(f"unknown controller {kind!r} for the step-up drive; valid: "
                             "['pwm', 'resonant', 'motor_resonant']")
        if delays and p["d_on"] >= p["t_l"]:
            raise ParameterError(f"delay {p['d_on']} s is longer than the PWM cycle t_l = {p['t_l']} s")
        return StepUpController(kind=kind, fs=fs, t_l=p["t_l"], duty=p["duty"], t_n=p["t_n"],
                                twist_tol=p["twist_tol"] or 0.0, min_vel=p["min_vel"], max_vel=p["max_vel"],
                                clutch_matching=bool(effects.get("clutch_matching", False)),
                                Omega=math.sqrt(p["K"] / p["J_s"]), delay_comp=0.0, closed_loop=closed,
                                Kp=p["Kp"], Ki=p["Ki"], ref=p["ref"], max_tk=p["max_tk"],
                                anti_windup=bool(effects.get("anti_windup", False)))
    if kind != "energy_packet":
        raise SceneError(f"unknown controller {kind!r} for the step-up/step-down drive; valid: ['energy_packet']")
    period_free = 2 * math.pi * math.sqrt(p["J_s"] / p["K"])
    if delays and max(p["d_on"], p["d_off"]) >= period_free:
        raise ParameterError(f"clutch delay {max(p['d_on'], p['d_off'])} s is longer than the spring system's free "
                             f"oscillation period {period_free:.4g} s (one energy cycle)")
    K_ctrl = p.get("K_ctrl") or p["K"]
    Om = p.get("Omega_ctrl") or math.sqrt(p["K"] / p["J_s"])
    x_max = p.get("spring_max") or min(p["tau_c1"], p["tau_c2"]) / p["K"]
    return EnergyPacketController(fs=fs, K=K_ctrl, Omega=Om, clutch_delay=cd, spring_max=x_max,
                                  min_motor_vel=p["min_motor_vel"], min_load_vel=p["min_load_vel"] or 0.0,
                                  closed_loop=closed, Kp=p["Kp"], Ki=p["Ki"], ref=ref if ref is not None else p["ref"],
                                  anti_windup=bool(effects.get("anti_windup", True)))


def run_paths(system: RotorSystem, mechanism: str, make_controller, t_end: float, engines=("reference", "mujoco"),
              sample_dt: float = 1e-3, timestep: float = 1e-4, rtol: float = 1e-9, atol: float = 1e-11
              ) -> dict[str, tuple[RefResult, Any]]:
    """Simulate with a fresh controller per engine. Returns {engine: (result, controller)}."""
    out = {}
    q0 = w0 = np.zeros(3)
    for eng in engines:
        ctrl = make_controller()
        if eng == "reference":
            res = simulate_reference(system, q0, w0, t_end, controller=ctrl, sample_dt=sample_dt, rtol=rtol, atol=atol)
        else:
            from .mujoco_path import MujocoRotorSim

            sim = MujocoRotorSim(system, mjcf_path(f"drive_{mechanism}"), timestep=timestep)
            res = sim.run(q0, w0, t_end, controller=ctrl, sample_dt=sample_dt)
        out[eng] = (res, ctrl)
    return out


@dataclass
class Balance:
    input: float
    output: float
    losses: dict[str, float]
    stored: float
    residual: float

    @property
    def relative(self) -> float:
        return self.residual / self.input if self.input else float("nan")


def energy_balance(system: RotorSystem, res: RefResult, i0: int = 0, i1: int = -1) -> Balance:
    """input - output - sum(losses) - delta(stored) between samples i0 and i1 (Eqs 3.21-3.24 corrected)."""
    E = res.energy
    d = {k: float(v[i1] - v[i0]) for k, v in E.items()}
    outputs = {p.label for f in system.frictions for p in f.parts if p.output}
    e_in = d.pop("source")
    e_out = sum(d.pop(k) for k in list(d) if k in outputs)
    reset = float(res.stats.get("reset_energy", 0.0)) if i0 == 0 and i1 in (-1, res.t.size - 1) else 0.0
    if reset:
        d["lock_impact"] = reset
    ke1, pe1 = system.stored_energy(res.q[:, i1], res.w[:, i1])
    ke0, pe0 = system.stored_energy(res.q[:, i0], res.w[:, i0])
    stored = ke1 + pe1 - ke0 - pe0
    resid = e_in - e_out - sum(d.values()) - stored
    return Balance(e_in, e_out, d, stored, resid)


def lock_times(res: RefResult, element: str, to: str = "stuck") -> np.ndarray:
    return np.array([e["t"] for e in res.events if e["element"] == element and e["to"] == to])


def cycle_stats(res: RefResult, ctrl, t0: float = 0.0) -> dict[str, Any]:
    """Energy cycles (from the controller log), switching rate, mean load speed, packet sizes, peak extension."""
    cyc = np.array([e["t"] for e in ctrl.log if e["event"] == "cycle" and e["t"] >= t0])
    out: dict[str, Any] = {"n_cycles": int(max(0, cyc.size - 1))}
    if cyc.size >= 2:
        out["switching_rate"] = float((cyc.size - 1) / (cyc[-1] - cyc[0]))
    m = res.t >= t0  # speeds over the fixed window [t0, t_end] (comparable between runs)
    if np.count_nonzero(m) >= 2:
        span = res.t[m][-1] - res.t[m][0]
        out["mean_load_speed"] = float(np.trapezoid(res.w[2, m], res.t[m]) / span)
        out["mean_motor_speed"] = float(np.trapezoid(res.w[0, m], res.t[m]) / span)
    packets = [e.get("eps") for e in ctrl.log if e["event"] == "cycle" and e.get("eps") is not None and e["t"] >= t0]
    if packets:
        out["packets"] = packets
    th = [e["theta_peak"] for e in ctrl.log if e["event"] == "transferred" and e["t"] >= t0]
    if th:
        out["max_extension"] = float(max(th))
    return out


def compare_events(a: RefResult, b: RefResult, elements: list[str], kinds=("stuck", "free"), t0: float = 0.0
                   ) -> dict[str, Any]:
    """Pair the lock-up (-> stuck) and release (-> free) events of two runs: each event of `a` with the nearest event
    of `b` of the same element and kind. Returns the counts and the largest time difference per element/kind."""
    out: dict[str, Any] = {}
    for el in elements:
        for kind in kinds:
            ta = np.array([e["t"] for e in a.events if e["element"] == el and e["to"] == kind and e["t"] >= t0])
            tb = np.array([e["t"] for e in b.events if e["element"] == el and e["to"] == kind and e["t"] >= t0])
            if ta.size == 0 and tb.size == 0:
                continue
            d = np.array([np.min(np.abs(tb - x)) for x in ta]) if tb.size else np.full(ta.size, np.inf)
            out[f"{el}->{kind}"] = {"n_a": int(ta.size), "n_b": int(tb.size),
                                    "max_dt": float(d.max()) if d.size else float("nan"),
                                    "median_dt": float(np.median(d)) if d.size else float("nan")}
    return out


def transferred_packets(system: RotorSystem, res: RefResult, mechanism: str, ctrl) -> np.ndarray:
    """Energy delivered per energy cycle = 1/2 K theta_peak^2 at each transfer (step-up/step-down), from the log."""
    K = system.springs[0].K
    return np.array([0.5 * K * e["theta_peak"] ** 2 for e in ctrl.log if e["event"] == "transferred"])
