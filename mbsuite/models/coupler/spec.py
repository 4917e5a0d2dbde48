"""The coupler model's declaration, `SPEC` (a `mbsuite.registry.ModelSpec`), which the package hands on at its first
use (`__init__.py`)."""

from __future__ import annotations

from pathlib import Path

from ...deferred import Deferred
from ...registry import Effect, ModelSpec, RunPath, Studies, Uses
from ...settings import SolverSettings
from ...trust.estimate import AccuracySpec
from . import accuracy
from .params import CouplerParams
from .scenario import INPUTS, OUTPUTS, STATISTICS


def _check_file(path: Path, engine: str, model: object) -> None:
    """The loaders' check of a shipped coupler model file (closures at the stated lengths, inertias, names)."""
    from .filechecks import check_model_file

    check_model_file(path, engine, model)


#: which effects use which parameters (measured: a 10 % change moves no output of a 0.5 s MuJoCo run without the
#: effect; `tests/suite/test_unused_input.py`). The reference path is the rigid kinematic limit of any scene (massless
#: rigid links, no gravity, friction or closure compliance: its `what`), the comparison for the MuJoCo path of the same
#: scene, so its configuration is not narrowed further here.
USES = {
    "params.massless_factor": Uses(effects={"link_inertia": ("massless",)}),
    "params.joint_friction": Uses(effects={"friction": (True,)}),
    "params.solref_friction_timeconst": Uses(effects={"friction": (True,)}),
}

SPEC = ModelSpec(
    name="coupler",
    summary="single/double 4-link SS couplers: kinematics (rank, screws, criteria) and double-coupler dynamics",
    params_cls=CouplerParams,
    effects={
        "gravity": Effect((True, False), True, "gravity along -z (shaft axis y horizontal)"),
        "link_inertia": Effect(("real", "massless"), "real",
                               "real link mass/inertia, or the massless limit (scaled by massless_factor)"),
        "friction": Effect((False, True), False, "dry friction joint_friction in the S joints and output bearing"),
    },
    inputs={"constant_speed": INPUTS},
    outputs=OUTPUTS,
    scenes_dir=Path(__file__).resolve().parent / "scenes",
    default_scene="double_lateral",
    paths={
        "mujoco": RunPath(run=Deferred("mbsuite.models.coupler.mujoco:run_mujoco"), label="mujoco",
                          what="MuJoCo: the double coupler's dynamics (S joints as balls, SS links closed by soft "
                               "equalities)"),
        "reference": RunPath(run=Deferred("mbsuite.models.coupler.reference:run_reference"), label="kinematic",
                             what="the kinematic solution (hand-derived FPP of the rigid mechanism, Maniowski & "
                                  "Czauderna; torque from the power balance)"),
    },
    cases="mbsuite.models.coupler.cases",
    solver=SolverSettings(integrator="implicitfast", timestep=5e-4, duration=2.0, t_settle=0.5, sample_dt=2e-3),
    mujoco_model=Deferred("mbsuite.models.coupler.mujoco:view_model"),
    file_checks={"coupler_single": _check_file, "coupler_double": _check_file},
    accuracy=AccuracySpec(accuracy.headlines, accuracy.values, accuracy.refinement),
    uses=USES,
    studies=Studies(threads=("mujoco",)),
    commands="mbsuite.models.coupler.cli",
    statistics=STATISTICS,
)
