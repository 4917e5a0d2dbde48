"""The reference path: the FE catenary (`fe.py`, `sim.py`, stepped in the compiled core `native_core.py`) with every
pantograph on its hand-derived equations: the 2-mass one by the catenary's own trapezoidal rule (exactly affine in the
contact force), a registry pantograph on its `reference` path (the Eppinger pantograph: its ODE by RK4 over each
catenary step, coupled by a secant iteration on the contact force)."""

from __future__ import annotations

from ...results import SimResult
from .reports import passage_result


def run(scene) -> SimResult:
    """`RunPath.run` of the reference path: the scene's passage (a `[train]` section: every pantograph of it) with
    its pantographs on their hand-derived equations, as a SimResult (`reports.passage_result`)."""
    return passage_result(scene, "reference")
