"""A drives scene as a run of a rotor system: what both paths share - the system, initial state, controller and output
grid a scene asks for (`setup`), and the `SimResult` of a run (`sim_result`: signals, energy balance, cycle statistics,
the energy-residual health figure). The paths themselves: `reference.py` (hand) and `mujoco.py`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...components.rotational.commands import Controller
from ...components.rotational.interfaces import RefResult, RotorSystem
from ...errors import SceneError
from ...limits import Limit
from ...results import SimResult, assemble
from ...scenes import Scene
from ...schema import Items, Rule, check_value
from ...statistics import Statistic
from ...trust.health import Figure
from . import drive
from .accuracy import window_efficiency

#: the window of a drive's statistics: the settled part of the run
WINDOW = "t >= solver.t_settle (controller times within drive.T0_TOL count in)"
#: the statistics of a drive run (`SPEC.statistics`; `SimResult.statistics`): `drive.cycle_stats`,
#: `accuracy.window_efficiency` (Oldaker 1997, Sec. 3.3 and Eqs 3.21-3.24 corrected)
STATISTICS = {
    "n_cycles": Statistic("-", "energy cycles completed (from the controller's log)", WINDOW),
    "switching_rate": Statistic("1/s", "switching rate Sr: energy cycles per second, first to last cycle start",
                                WINDOW),
    "mean_load_speed": Statistic("rad/s", "time-mean load speed: the angle travelled over the time", WINDOW),
    "mean_motor_speed": Statistic("rad/s", "time-mean motor speed: the angle travelled over the time", WINDOW),
    "packets": Statistic("J", "the energy packet of each cycle (energy-packet controller)", WINDOW, kind="numbers"),
    "max_extension": Statistic("rad", "largest spring twist at a transfer", WINDOW),
    "efficiency": Statistic("1", "efficiency E_out / E_in (Eq 3.22 corrected; a scene with a load torque)", WINDOW),
}

SIGNALS = {
    "w_motor": "rad/s", "w_spring": "rad/s", "w_load": "rad/s",
    "theta_motor": "rad", "theta_spring": "rad", "theta_load": "rad", "extension": "rad",
    "E_in": "J", "E_out": "J", "E_loss": "J", "u_brake": "1", "u_clutch": "1", "u_clutch_a": "1", "u_clutch_b": "1",
}
#: energy_residual bound of the thesis drives, both paths: their rotors turn through thousands of radians, so the
#: solver's relative tolerance on the angles sets the floor (measured on every shipped scene at its defaults:
#: <= 3.0e-7 hand path, <= 2.3e-7 MuJoCo; in copies perturbed by 1e-9 up to 1.4e-5, one step whose spring twist is
#: the difference of two 2000 rad angles held to rtol 1e-9 - 9e-8 at rtol 1e-10; a clutch sliding against its slip
#: for 21 ms left 3.7e-2)
DRIVE_ENERGY_BOUND = 1e-4


#: bound of a speed reference value (rad/s), as the scene's `input.value` Limit
REF_BOUND = 1e5


def _increasing(rows: list) -> str | None:
    bad = next((i for i in range(1, len(rows)) if not rows[i][0] > rows[i - 1][0]), None)
    return None if bad is None else (f"times must be strictly increasing: row {bad} t = {rows[bad][0]!r} s <= row "
                                     f"{bad - 1} t = {rows[bad - 1][0]!r} s")


#: `input.profile`: the piecewise-linear speed reference, [[t, r], ...] (the scene's declaration of the key)
PROFILE = Items((Limit(lo=0.0, hi=1e5, unit="s", doc="t (s)"),
                 Limit(lo=-REF_BOUND, hi=REF_BOUND, unit="rad/s", doc="r (rad/s)")), min=1, max=100_000,
                rules=(Rule("t strictly increasing", _increasing),),
                doc="[[t, r], ...] piecewise-linear speed reference")


def check_profile(profile: Any) -> np.ndarray:
    """`input.profile` as an (n, 2) float array, checked by its declaration `PROFILE` (a `SceneError` naming
    `input.profile`, the offending row, its value and the valid form)."""
    return np.asarray(check_value(PROFILE, "input.profile", profile, "[input]", SceneError), float).reshape(-1, 2)


def reference_signal(inp: dict[str, Any], default: float):
    """The speed reference: `value` (rad/s) or `profile` = [[t, r], ...] (piecewise linear, as App. J `ref_signal`;
    checked by `check_profile`)."""
    if "profile" in inp:
        prof = check_profile(inp["profile"])
        return lambda t: float(np.interp(t, prof[:, 0], prof[:, 1]))
    return float(inp.get("value", default))


@dataclass
class RunSetup:
    """What a scene asks either path to simulate: the rotor system, its initial state, the controller, the output
    sample interval [s] and the stem of its MJCF file (`mjcf/<stem>.xml`)."""

    system: RotorSystem
    q0: np.ndarray
    w0: np.ndarray
    controller: Controller | None
    sample_dt: float
    mjcf: str


def setup(scene: Scene) -> RunSetup:
    """The run a scene asks for (any engine): a drive (Eqs 3.1-3.6) with its controller and speed reference."""
    eff = dict(scene.effects)
    mech = eff["mechanism"]
    sv = scene.solver
    p = scene.build_params().resolved()  # checked: nothing set the configuration does not read (config.check_scene)
    system = drive.build_system(mech, p, eff)
    ref = reference_signal(dict(scene.input), p["ref"] or 0.0)
    kind = eff["controller"]
    ctrl = drive.build_controller(mech, kind, p, eff, ref=ref)
    if mech == "step_up" and not callable(ref):
        ctrl.ref = ref
    dt_c = 1.0 / p["fs"]
    q0, w0 = np.zeros(3), np.zeros(3)  # at rest: a relative perturbation leaves it there
    return RunSetup(system, q0, w0, ctrl, sv.sample_dt or dt_c, f"drive_{mech}")


def sim_result(scene: Scene, res: RefResult, ctrl: Any, system: RotorSystem) -> SimResult:
    """The `SimResult` of a run of the scene (speeds, angles, twist, energies, commands as signals; the cycle
    statistics in `statistics` (`STATISTICS`); the energy balance and the solver's counters in `stats`; the energy
    residual as a health figure, judged by `mbsuite.run`)."""
    mech = scene.effects["mechanism"]
    sig: dict[str, np.ndarray] = {}
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
    statistics: dict[str, Any] = {}
    if ctrl is not None:
        statistics = drive.cycle_stats(res, ctrl, t0=scene.solver.t_settle)
        statistics.pop("packets", None)
        if outputs:  # a load torque: the efficiency over the same window (Eq 3.22 corrected)
            statistics["efficiency"] = window_efficiency(res.t, sig["E_in"], sig["E_out"], scene.solver.t_settle)
    # the scene's outputs in its order (an output of the other mechanisms is not computed, so not kept)
    ordered = {k: sig[k] for k in scene.outputs if k in sig}
    health = [Figure(
        "energy_residual", abs(bal.residual) / max(abs(bal.input), 1e-300), DRIVE_ENERGY_BOUND, "1",
        "energy balance |input - output - losses - change of stored energy| / input over the run",
        "tighten solver.rtol/atol (reference) or reduce solver.timestep (mujoco)")]
    return assemble(scene, res.t, ordered, engine=scene.solver.engine, events=res.events, stats=stats,
                    statistics=statistics, health=health)
