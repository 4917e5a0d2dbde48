"""The MuJoCo path of a drives scene ("mujoco"): the scene's rotor system (Eqs 3.1-3.6) on its MJCF topology
(`mjcf/drive_step_up.xml`, `mjcf/drive_step_up_down.xml`), run by the shared rotor library's
`mbsuite.components.rotational.mujoco_sim.MujocoRotorSim` (hinge rotors, real equality locks switched by a native
stepper; its conventions are stated there) with the scene's controller sampled at its period."""

from __future__ import annotations

from typing import Any

from ...components.rotational.interfaces import RefResult, RotorSystem
from ...components.rotational.mujoco_sim import MujocoRotorSim
from ...errors import SceneError
from ...paths import mjcf_path
from ...results import SimResult
from ...scenes import Scene
from .scene_run import setup, sim_result


def simulate(scene: Scene) -> tuple[RefResult, Any, RotorSystem]:
    """The scene on the MuJoCo path (solver.timestep, integrator, duration); returns (result, controller, rotor
    system). A controller period that the timestep does not divide is a SceneError."""
    s, sv = setup(scene), scene.solver
    if s.controller is not None:
        dt_c = s.controller.dt
        if abs(dt_c / sv.timestep - round(dt_c / sv.timestep)) > 1e-9:
            raise SceneError(f"solver.timestep {sv.timestep} must divide the controller period {dt_c}")
    sim = MujocoRotorSim(s.system, mjcf_path(s.mjcf), timestep=sv.timestep, integrator=sv.integrator)
    res = sim.run(s.q0, s.w0, sv.duration, controller=s.controller, sample_dt=s.sample_dt)
    return res, s.controller, s.system


def run(scene: Scene) -> SimResult:
    """The path's run (`SPEC.paths["mujoco"]`): the scene's `SimResult` (`scene_run.sim_result`)."""
    return sim_result(scene, *simulate(scene))
