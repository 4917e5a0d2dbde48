"""The hand-derived path of a rotational scene ("reference", label "equations"): the example's rotor system simulated
event-exactly by the shared rotor library's `event_exact.simulate_reference` (DOP853, stick/slip events located by
root finding)."""

from __future__ import annotations

from ...components.rotational.event_exact import simulate_reference
from ...components.rotational.interfaces import RefResult, RotorSystem
from ...results import SimResult
from ...scenes import Scene
from .scene_run import setup, sim_result


def simulate(scene: Scene) -> tuple[RefResult, RotorSystem]:
    """The scene on the hand path (solver.rtol/atol, duration); returns (result, rotor system)."""
    s, sv = setup(scene), scene.solver
    res = simulate_reference(s.system, s.q0, s.w0, sv.duration, sample_dt=s.sample_dt, rtol=sv.rtol, atol=sv.atol)
    return res, s.system


def run(scene: Scene) -> SimResult:
    """The path's run (`SPEC.paths["reference"]`): the scene's `SimResult` (`scene_run.sim_result`)."""
    return sim_result(scene, *simulate(scene))
