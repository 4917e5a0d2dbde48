"""Single and double 4-link (SS-link) couplers of low-floor tram drives (Maniowski & Czauderna).

Kinematics hand-derived (reference.py) and in Pinocchio (pinocchio.py), cross-checked; double-coupler dynamics in
MuJoCo (mujoco.py). See README.md in this package.
"""

from __future__ import annotations

from pathlib import Path

from ...registry import Effect, ModelSpec, RunPath
from ...solver import SolverSettings
from .mujoco import INPUTS, OUTPUTS, run, view_model
from .params import CouplerParams


def _check_file(path: Path, engine: str, model: object) -> None:
    """The loaders' check of a shipped coupler model file (closures at the stated lengths, inertias, names)."""
    from .modelfiles import check_model_file

    check_model_file(path, engine, model)


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
        "mujoco": RunPath(run, "mujoco", "MuJoCo: the double coupler's dynamics (S joints as balls, closures as "
                                         "equalities)"),
        "reference": RunPath(run, "kinematic", "the hand-derived kinematic solution (quasi-static, Maniowski & "
                                               "Czauderna)"),
    },
    cases="mbsuite.models.coupler.cases",
    solver=SolverSettings(integrator="implicitfast", timestep=5e-4, duration=2.0, t_settle=0.5, sample_dt=2e-3),
    mujoco_model=view_model,
    file_checks={"coupler_single": _check_file, "coupler_double": _check_file},
)
