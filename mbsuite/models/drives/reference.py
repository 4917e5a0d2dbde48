"""The hand-derived path of a drives scene ("reference", label "equations"): the scene's rotor system (Eqs 3.1-3.6,
or a Modelica example) simulated event-exactly by `event_exact.simulate_reference` (DOP853, stick/slip events located
by root finding)."""

from __future__ import annotations

from typing import Any

from ...components.rotational.event_exact import simulate_reference
from ...components.rotational.interfaces import RefResult, RotorSystem
from ...results import SimResult
from ...scenes import Scene
from .scene_run import setup, sim_result


def simulate(scene: Scene) -> tuple[RefResult, Any, RotorSystem]:
    """The scene on the hand path (solver.rtol/atol, duration); returns (result, controller, rotor system)."""
    s, sv = setup(scene), scene.solver
    res = simulate_reference(s.system, s.q0, s.w0, sv.duration, controller=s.controller, sample_dt=s.sample_dt,
                             rtol=sv.rtol, atol=sv.atol)
    return res, s.controller, s.system


def run(scene: Scene) -> SimResult:
    """The path's run (`SPEC.paths["reference"]`): the scene's `SimResult` (`scene_run.sim_result`)."""
    return sim_result(scene, *simulate(scene))
