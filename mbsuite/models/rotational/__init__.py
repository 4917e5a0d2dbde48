"""Modelica Rotational examples (Modelica Standard Library 4.1.0, Modelica Association): CoupledClutches, Friction,
OneWayClutch, OneWayClutchDisengaged and SimpleGearShift on the shared rotor library (`mbsuite.components.rotational`),
checked against the Modelica Association's reference results.

Two independent paths (`SPEC.paths`): the hand-derived event-exact stick/slip simulation (`reference.run` on the
library's `event_exact.simulate_reference`) and MuJoCo (`mujoco.run` on the library's `mujoco_sim.MujocoRotorSim`,
hinge rotors with real equality locks switched by a native stepper). Suite declarations in `cases.py`. See README.md
(its Files table says where everything is).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...deferred import lazy_names

if TYPE_CHECKING:
    from .spec import SPEC as SPEC

#: `SPEC` (spec.py) imported at its first use: importing the package (its command line's module, for `--help`) loads
#: no other module of the model
__getattr__ = lazy_names(__name__, SPEC="mbsuite.models.rotational.spec:SPEC")
