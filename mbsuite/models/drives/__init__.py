"""Switched-mode mechanical drives (Oldaker 1997): step-up and step-up/step-down three-mass models with event-exact
clutches, switching controllers, losses and Chapter 5 design tools, on the shared rotor library
(`mbsuite.components.rotational`; the Modelica Rotational examples on the same library are the model `rotational`).

Two independent paths (`SPEC.paths`): the hand-derived event-exact stick/slip simulation (`reference.run` on the
library's `event_exact.simulate_reference`) and MuJoCo (`mujoco.run` on the library's `mujoco_sim.MujocoRotorSim`,
hinge rotors with real equality locks, its state machine a native stepper of mbsuite's C core). Suite declarations
(hard cases, work-precision study, random inputs) in `cases.py`. See README.md (its Files table says where
everything is).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...deferred import lazy_names

if TYPE_CHECKING:
    from .spec import SPEC as SPEC

#: `SPEC` (spec.py) imported at its first use: importing the package (its command line's module, for `--help`) loads
#: no other module of the model
__getattr__ = lazy_names(__name__, SPEC="mbsuite.models.drives.spec:SPEC")
