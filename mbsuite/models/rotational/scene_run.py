"""A rotational scene as a run of its example's rotor system: what both paths share - the system, initial state and
output grid the scene's example asks for (`setup`), and the `SimResult` of a run (`sim_result`: the example's signals
on the reference's names, energy balance, mode changes, final values, the energy-residual health figure). The paths
themselves: `reference.py` (hand) and `mujoco.py`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...components.rotational.energy import energy_balance
from ...components.rotational.interfaces import RefResult, RotorSystem
from ...results import SimResult, assemble
from ...scenes import Scene
from ...trust import perturbation
from ...trust.health import Figure
from . import coupled_clutches as cc
from . import examples

#: the examples a scene may choose (`effects.example`): CoupledClutches and the four of `examples.EXAMPLES`
EXAMPLE_NAMES = ("coupled_clutches", *examples.EXAMPLES)

SIGNALS = {
    "w1": "rad/s", "w2": "rad/s", "w3": "rad/s", "w4": "rad/s",
    "J1.w": "rad/s", "J2.w": "rad/s", "J3.w": "rad/s", "J4.w": "rad/s",  # CoupledClutches on the reference's names
    "E_in": "J", "E_out": "J", "E_loss": "J",
    **examples.SIGNAL_UNITS,
}
#: energy_residual bound (|input - output - losses - stored change| / input over the run), per path
ENERGY_BOUND = {"reference": 1e-6, "mujoco": 1e-5}


@dataclass
class RunSetup:
    """What a scene asks either path to simulate: the rotor system, its initial state, the output sample interval [s]
    and the stem of its MJCF file (`mjcf/<stem>.xml`)."""

    system: RotorSystem
    q0: np.ndarray
    w0: np.ndarray
    sample_dt: float
    mjcf: str


def _initial(q0, w0) -> tuple[np.ndarray, np.ndarray]:
    """The initial angles and speeds (perturbed inside the stability check, `mbsuite.trust.perturbation`)."""
    return perturbation.state(q0, "q0"), perturbation.state(w0, "w0")


def setup(scene: Scene) -> RunSetup:
    """The run a scene asks for (any engine): its example's rotor system and initial state."""
    name = scene.effects["example"]
    dt = scene.solver.sample_dt or 5e-4
    if name == "coupled_clutches":
        return RunSetup(cc.build_system(), *_initial(cc.Q0, cc.W0), dt, "coupled_clutches")
    ex = examples.example(name)
    return RunSetup(ex.system, *_initial(ex.q0, ex.w0), dt, f"drive_{name}")


def sim_result(scene: Scene, res: RefResult, system: RotorSystem) -> SimResult:
    """The `SimResult` of a run of the scene (the example's signals, energies; energy balance, mode changes and final
    values in `stats`; the energy residual as a health figure, judged by `mbsuite.run`)."""
    name = scene.effects["example"]
    sig: dict[str, np.ndarray] = {}
    if name == "coupled_clutches":
        for i in range(4):
            sig[f"w{i + 1}"] = res.w[i]
            sig[f"J{i + 1}.w"] = res.w[i]
    else:
        sig.update(examples.signals_of(examples.example(name), res))
    outputs = {p.label for f in system.frictions for p in f.parts if p.output}
    sig["E_in"] = res.energy["source"]
    sig["E_out"] = sum((res.energy[k] for k in outputs), np.zeros_like(res.t))
    sig["E_loss"] = sum((v for k, v in res.energy.items() if k != "source" and k not in outputs),
                        np.zeros_like(res.t))
    bal = energy_balance(system, res)
    stats: dict[str, Any] = dict(res.stats)
    stats.pop("reset_energy", None)  # it is the balance's lock_impact term
    stats["energy_balance"] = {"input": bal.input, "output": bal.output, "stored": bal.stored,
                               "losses": bal.losses, "residual": bal.residual, "relative": bal.relative}
    # the scene's outputs in its order (an output of the other examples is not computed, so not kept)
    ordered = {k: sig[k] for k in scene.outputs if k in sig}
    stats["mode_changes"] = [{"t": e["t"], "component": e["element"], "from": e["from"], "to": e["to"]}
                             for e in res.events]
    stats["final"] = {k: float(v[-1]) for k, v in sig.items() if k in examples.SIGNAL_UNITS or "." in k}
    health = [Figure(
        "energy_residual", abs(bal.residual) / max(abs(bal.input), 1e-300), ENERGY_BOUND[scene.solver.engine], "1",
        "energy balance |input - output - losses - change of stored energy| / input over the run",
        "tighten solver.rtol/atol (reference) or reduce solver.timestep (mujoco)")]
    return assemble(scene, res.t, ordered, engine=scene.solver.engine, events=res.events, stats=stats,
                    health=health)
