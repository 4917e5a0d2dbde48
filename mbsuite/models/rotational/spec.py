"""The rotational model's declaration, `SPEC` (a `mbsuite.registry.ModelSpec`), which the package hands on at its first
use (`__init__.py`)."""

from __future__ import annotations

from pathlib import Path

from ...deferred import Deferred
from ...registry import Effect, ModelSpec, RunPath, Studies
from ...settings import SolverSettings
from ...trust.estimate import AccuracySpec
from . import accuracy
from .params import RotationalParams
from .scene_run import EXAMPLE_NAMES, SIGNALS

SPEC = ModelSpec(
    name="rotational",
    summary="Modelica Rotational examples (CoupledClutches, Friction, OneWayClutch, SimpleGearShift), exact clutches",
    params_cls=RotationalParams,
    effects={
        "example": Effect(EXAMPLE_NAMES, "coupled_clutches",
                          "which Modelica.Mechanics.Rotational.Examples model: CoupledClutches, Friction, "
                          "OneWayClutch, OneWayClutchDisengaged, SimpleGearShift (MSL 4.1.0)"),
    },
    inputs={"none": {}},
    outputs=SIGNALS,
    scenes_dir=Path(__file__).parent / "scenes",
    default_scene="coupled_clutches",
    paths={
        "reference": RunPath(run=Deferred("mbsuite.models.rotational.reference:run"), label="equations",
                             what="hand-derived equations (MSL component equations), event-exact stick/slip (scipy "
                                  "DOP853 between events)"),
        "mujoco": RunPath(run=Deferred("mbsuite.models.rotational.mujoco:run"), label="mujoco",
                          what="MuJoCo: hinge rotors, real equality locks switched by a native stepper"),
    },
    cases="mbsuite.models.rotational.cases",
    accuracy=AccuracySpec(accuracy.headlines, accuracy.values, accuracy.refinement),
    solver=SolverSettings(engine="reference", integrator="rk4", timestep=1e-4, rtol=1e-9, atol=1e-11, duration=1.5),
    commands="mbsuite.models.rotational.cli",
    studies=Studies(threads=("mujoco",)),
)
