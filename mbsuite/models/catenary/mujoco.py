"""The MuJoCo path: the FE catenary (`fe.py`, `sim.py`, stepped in the compiled core `native_core.py`) with a registry
pantograph on its `mujoco` path (the Eppinger pantograph: the MuJoCo model of its effects, one MuJoCo step per catenary
step, coupled by a secant iteration on the contact force). The 2-mass pantograph has no MuJoCo model: alone it is
refused on this path; on a train beside one that has, it runs on its equations (`pantographs.build_train`)."""

from __future__ import annotations

from ...results import SimResult
from .reports import passage_result


def run(scene) -> SimResult:
    """`RunPath.run` of the MuJoCo path: the scene's passage with its pantographs on MuJoCo where they have it, as a
    SimResult (`reports.passage_result`)."""
    return passage_result(scene, "mujoco")
