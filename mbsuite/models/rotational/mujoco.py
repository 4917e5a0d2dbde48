"""The MuJoCo path of a rotational scene ("mujoco"): the example's rotor system on its MJCF topology
(`mjcf/coupled_clutches.xml`, `mjcf/drive_msl_<example>.xml`), run by the shared rotor library's
`mbsuite.components.rotational.mujoco_sim.MujocoRotorSim` (hinge rotors, real equality locks switched by a native
stepper; its conventions are stated there)."""

from __future__ import annotations

from ...components.rotational.interfaces import RefResult, RotorSystem
from ...components.rotational.mujoco_sim import MujocoRotorSim
from ...paths import mjcf_path
from ...results import SimResult
from ...scenes import Scene
from .scene_run import setup, sim_result


def simulate(scene: Scene) -> tuple[RefResult, RotorSystem]:
    """The scene on the MuJoCo path (solver.timestep, integrator, duration); returns (result, rotor system)."""
    s, sv = setup(scene), scene.solver
    sim = MujocoRotorSim(s.system, mjcf_path(s.mjcf), timestep=sv.timestep, integrator=sv.integrator)
    return sim.run(s.q0, s.w0, sv.duration, sample_dt=s.sample_dt), s.system


def run(scene: Scene) -> SimResult:
    """The path's run (`SPEC.paths["mujoco"]`): the scene's `SimResult` (`scene_run.sim_result`)."""
    return sim_result(scene, *simulate(scene))
