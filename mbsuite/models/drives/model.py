"""Scene -> simulation for the drives model (the `run` hook) and the CoupledClutches comparison."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ... import perturbation
from ...errors import SceneError
from ...health import Figure
from ...paths import mjcf_path
from ...results import SimResult, assemble
from ...scenes import Scene
from . import coupled_clutches as cc
from . import drive, msl
from .friction import RefResult, simulate_reference

SIGNALS = {
    "w_motor": "rad/s", "w_spring": "rad/s", "w_load": "rad/s",
    "theta_motor": "rad", "theta_spring": "rad", "theta_load": "rad", "extension": "rad",
    "w1": "rad/s", "w2": "rad/s", "w3": "rad/s", "w4": "rad/s",
    "J1.w": "rad/s", "J2.w": "rad/s", "J3.w": "rad/s", "J4.w": "rad/s",  # CoupledClutches on the reference's names
    "E_in": "J", "E_out": "J", "E_loss": "J", "u_brake": "1", "u_clutch": "1", "u_clutch_a": "1", "u_clutch_b": "1",
    **msl.SIGNAL_UNITS,
}
#: energy_residual bound (|input - output - losses - stored change| / input over the run) of the Modelica scenes
ENERGY_BOUND = {"reference": 1e-6, "mujoco": 1e-5}
#: energy_residual bound of the thesis drives, both paths: their rotors turn through thousands of radians, so the
#: solver's relative tolerance on the angles sets the floor (measured on every shipped scene at its defaults:
#: <= 3.0e-7 hand path, <= 2.3e-7 MuJoCo; in copies perturbed by 1e-9 up to 1.4e-5, one step whose spring twist is
#: the difference of two 2000 rad angles held to rtol 1e-9 - 9e-8 at rtol 1e-10; a clutch sliding against its slip
#: for 21 ms left 3.7e-2)
DRIVE_ENERGY_BOUND = 1e-4


#: bound of a speed reference value (rad/s), as the scene's `input.value` Limit
REF_BOUND = 1e5


def check_profile(profile: Any) -> np.ndarray:
    """`input.profile` as an (n, 2) float array: a non-empty list of [t, r] pairs of finite numbers (t in s, r in
    rad/s with |r| <= 1e5), t strictly increasing. Anything else is a `SceneError` naming `input.profile`, the
    offending row and the valid form."""
    form = "a non-empty list of [t (s), r (rad/s)] pairs of finite numbers, t strictly increasing, |r| <= 1e5"
    if not isinstance(profile, list | tuple) or not profile:
        raise SceneError(f"input.profile = {profile!r} is not {form}")
    for i, row in enumerate(profile):
        if (not isinstance(row, list | tuple) or len(row) != 2
                or any(isinstance(v, bool) or not isinstance(v, int | float) for v in row)):
            raise SceneError(f"input.profile[{i}] = {row!r} is not a [t, r] pair of numbers; input.profile must be "
                             f"{form}")
        if not all(math.isfinite(v) for v in row):
            raise SceneError(f"input.profile[{i}] = {row!r} is not finite; input.profile must be {form}")
        if abs(row[1]) > REF_BOUND:
            raise SceneError(f"input.profile[{i}] reference {row[1]!r} rad/s is outside [-1e5, 1e5] rad/s")
        if i and not row[0] > profile[i - 1][0]:
            raise SceneError(f"input.profile times must be strictly increasing; input.profile[{i}] t = {row[0]!r} "
                             f"<= input.profile[{i - 1}] t = {profile[i - 1][0]!r}")
    return np.asarray(profile, float)


def reference_signal(inp: dict[str, Any], default: float):
    """The speed reference: `value` (rad/s) or `profile` = [[t, r], ...] (piecewise linear, as App. J `ref_signal`;
    checked by `check_profile`)."""
    if "profile" in inp:
        prof = check_profile(inp["profile"])
        return lambda t: float(np.interp(t, prof[:, 0], prof[:, 1]))
    return float(inp.get("value", default))


def _initial(q0, w0) -> tuple[np.ndarray, np.ndarray]:
    """The initial angles and speeds (perturbed inside the stability check, `mbsuite.perturbation`)."""
    return perturbation.state(q0, "q0"), perturbation.state(w0, "w0")


def simulate_scene(scene: Scene) -> tuple[RefResult, Any, Any]:
    """Run a scene on its engine; returns (result, controller, rotor system)."""
    eff = dict(scene.effects)
    mech = eff["mechanism"]
    sv = scene.solver
    if mech in msl.EXAMPLES:
        ex = msl.example(mech)
        if sv.engine == "reference":
            res = simulate_reference(ex.system, *_initial(ex.q0, ex.w0), sv.duration, sample_dt=sv.sample_dt or 5e-4,
                                     rtol=sv.rtol, atol=sv.atol)
        else:
            from .mujoco_path import MujocoRotorSim

            sim = MujocoRotorSim(ex.system, mjcf_path(f"drive_{mech}"), timestep=sv.timestep,
                                 integrator=sv.integrator)
            res = sim.run(*_initial(ex.q0, ex.w0), sv.duration, sample_dt=sv.sample_dt or 5e-4)
        return res, None, ex.system
    if mech == "coupled_clutches":
        system = cc.build_system()
        if sv.engine == "reference":
            res = simulate_reference(system, *_initial(cc.Q0, cc.W0), sv.duration, sample_dt=sv.sample_dt or 5e-4,
                                     rtol=sv.rtol, atol=sv.atol)
        else:
            from .mujoco_path import MujocoRotorSim

            sim = MujocoRotorSim(system, mjcf_path("coupled_clutches"), timestep=sv.timestep,
                                 integrator=sv.integrator)
            res = sim.run(*_initial(cc.Q0, cc.W0), sv.duration, sample_dt=sv.sample_dt or 5e-4)
        return res, None, system
    p = scene.build_params().resolved(eff["param_set"])
    system = drive.build_system(mech, p, eff)
    ref = reference_signal(dict(scene.input), p["ref"] or 0.0)
    kind = eff["controller"]
    if kind == "none":
        raise SceneError(f"mechanism {mech!r} needs a controller; valid: pwm, resonant, motor_resonant, energy_packet")
    ctrl = drive.build_controller(mech, kind, p, eff, ref=ref)
    if mech == "step_up" and callable(ref):
        raise SceneError("the step-up drive takes a constant reference (input.value)")
    if mech == "step_up" and not callable(ref):
        ctrl.ref = ref
    dt_c = 1.0 / p["fs"]
    q0, w0 = np.zeros(3), np.zeros(3)  # at rest: a relative perturbation leaves it there
    if sv.engine == "reference":
        res = simulate_reference(system, q0, w0, sv.duration, controller=ctrl,
                                 sample_dt=sv.sample_dt or dt_c, rtol=sv.rtol, atol=sv.atol)
    else:
        from .mujoco_path import MujocoRotorSim

        if abs(dt_c / sv.timestep - round(dt_c / sv.timestep)) > 1e-9:
            raise SceneError(f"solver.timestep {sv.timestep} must divide the controller period {dt_c}")
        sim = MujocoRotorSim(system, mjcf_path(f"drive_{mech}"), timestep=sv.timestep, integrator=sv.integrator)
        res = sim.run(q0, w0, sv.duration, controller=ctrl, sample_dt=sv.sample_dt or dt_c)
    return res, ctrl, system


def run(scene: Scene) -> SimResult:
    """The `run` hook: simulate the scene on its engine and return a `SimResult` (speeds, angles, twist,
    energies, commands; energy balance, cycle statistics and mode changes in `stats`)."""
    res, ctrl, system = simulate_scene(scene)
    mech = scene.effects["mechanism"]
    sig: dict[str, np.ndarray] = {}
    if mech in msl.EXAMPLES:
        sig.update(msl.signals_of(msl.example(mech), res))
    elif mech == "coupled_clutches":
        for i in range(4):
            sig[f"w{i + 1}"] = res.w[i]
            sig[f"J{i + 1}.w"] = res.w[i]
    else:
        for i, nm in enumerate(("motor", "spring", "load")):
            sig[f"w_{nm}"] = res.w[i]
            sig[f"theta_{nm}"] = res.q[i]
        sig["extension"] = res.q[0] - res.q[1] if mech == "step_up" else res.q[1]
        names = {"brake": "u_brake", "clutch": "u_clutch", "ca": "u_clutch_a", "cb": "u_clutch_b"}
        for c, v in res.u.items():
            sig[names[c]] = v
    outputs = {p.label for f in system.frictions for p in f.parts if p.output}
    sig["E_in"] = res.energy["source"]
    sig["E_out"] = sum((res.energy[k] for k in outputs), np.zeros_like(res.t))
    sig["E_loss"] = sum((v for k, v in res.energy.items() if k != "source" and k not in outputs),
                        np.zeros_like(res.t))
    bal = drive.energy_balance(system, res)
    stats: dict[str, Any] = dict(res.stats)
    stats.pop("reset_energy", None)  # it is the balance's lock_impact term
    stats["energy_balance"] = {"input": bal.input, "output": bal.output, "stored": bal.stored,
                               "losses": bal.losses, "residual": bal.residual, "relative": bal.relative}
    if ctrl is not None:
        cs = drive.cycle_stats(res, ctrl, t0=scene.solver.t_settle)
        cs.pop("packets", None)
        stats["cycles"] = cs
    # the scene's outputs in its order (an output of the other mechanisms is not computed, so not kept)
    ordered = {k: sig[k] for k in scene.outputs if k in sig}
    health = []
    if mech in msl.EXAMPLES or mech == "coupled_clutches":  # the Modelica examples: mode changes, final values
        stats["mode_changes"] = [{"t": e["t"], "component": e["element"], "from": e["from"], "to": e["to"]}
                                 for e in res.events]
        stats["final"] = {k: float(v[-1]) for k, v in sig.items() if k in msl.SIGNAL_UNITS or "." in k}
    eng = scene.solver.engine
    bound = ENERGY_BOUND[eng] if mech in msl.EXAMPLES or mech == "coupled_clutches" else DRIVE_ENERGY_BOUND
    health.append(Figure(
        "energy_residual", abs(bal.residual) / max(abs(bal.input), 1e-300), bound, "1",
        "energy balance |input - output - losses - change of stored energy| / input over the run",
        "tighten solver.rtol/atol (reference) or reduce solver.timestep (mujoco)"))
    return assemble(scene, res.t, ordered, engine=scene.solver.engine, events=res.events, stats=stats,
                    health=health)


def coupled_clutches_table(engines=("reference", "mujoco"), timestep: float = 1e-4) -> dict[str, Any]:
    """Both paths against the Dymola reference: mode sequence with event times, and w1..w4 every 0.1 s."""
    ref = cc.load_reference()
    rev = cc.reference_events(ref)
    out: dict[str, Any] = {"reference_events": rev}
    system = cc.build_system()
    grid = np.round(np.arange(0.0, cc.T_END + 1e-9, 0.1), 10)
    j_ref = [int(np.nonzero(np.isclose(ref["t"], tt))[0][-1]) for tt in grid]
    out["grid"] = grid.tolist()
    out["w_ref"] = ref["w"][:, j_ref].T.tolist()
    for eng in engines:
        if eng == "reference":
            res = simulate_reference(system, cc.Q0, cc.W0, cc.T_END, sample_dt=1e-3)
        else:
            from .mujoco_path import MujocoRotorSim

            res = MujocoRotorSim(system, mjcf_path("coupled_clutches"), timestep=timestep).run(
                cc.Q0, cc.W0, cc.T_END, sample_dt=1e-3)
        ev = cc.events_as_codes(res.events)
        rows = cc.match_events(ev, rev)
        idx = [int(np.argmin(np.abs(res.t - tt))) for tt in grid]
        w = res.w[:, idx].T
        dts = [r["t"] - r["t_ref"] for r in rows if r["t"] is not None and r["t_ref"] is not None]
        out[eng] = {"events": rows, "w": w.tolist(),
                    "same_sequence": all(r["t"] is not None and r["t_ref"] is not None for r in rows),
                    "max_event_dt": float(max(abs(x) for x in dts)) if dts else math.nan,
                    "max_w_err": float(np.max(np.abs(w - np.asarray(out["w_ref"]))))}
    return out
