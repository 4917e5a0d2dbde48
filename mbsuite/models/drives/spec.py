"""The drives model's declaration, `SPEC` (a `mbsuite.registry.ModelSpec`), which the package hands on at its first
use (`__init__.py`)."""

from __future__ import annotations

from pathlib import Path

from ...deferred import Deferred
from ...limits import Limit
from ...registry import Effect, ModelSpec, RunPath, Studies
from ...settings import SolverSettings
from ...trust.estimate import AccuracySpec
from . import accuracy
from .params import DriveParams
from .scene_run import PROFILE, SIGNALS, STATISTICS

SPEC = ModelSpec(
    name="drives",
    summary="switched-mode mechanical drives (step-up, step-up/step-down) with exact clutches",
    params_cls=DriveParams,
    effects={
        "mechanism": Effect(("step_up", "step_up_down"), "step_up",
                            "which drive: step-up (Fig 3.3) or step-up/step-down (Fig 3.4)"),
        "controller": Effect(("pwm", "resonant", "motor_resonant", "energy_packet"), "pwm",
                             "switching algorithm (App. E / App. F)"),
        "clutch_matching": Effect((True, False), False,
                                  "step-up: delay clutch engagement to the velocity match (Eq 2.1)"),
        "closed_loop": Effect((True, False), False, "PI on t_k (step-up) / energy-packet PI (step-up/step-down)"),
        "anti_windup": Effect((True, False), True,
                              "PI anti-windup: store the clamped state (energy-packet PI: clamped to the spring "
                              "capacity +-1/2 K x_max^2; step-up t_k PI: to [0, max_tk]). false = the thesis' printed "
                              "step-up PI (state stored before the clamp, winds up), used by step_up_closed_loop"),
        "clutch_delays": Effect((True, False), True, "pure actuation delays quantised to controller samples"),
        "bearing_friction": Effect((True, False), True, "viscous + Coulomb bearings (with stiction)"),
        "added_motor_inertia": Effect((True, False), False, "add J_add to the motor (Sec. 4.2.4, Sec. 6.2)"),
    },
    inputs={
        # `value` has no fixed default: without it (and without a profile) the parameter set's `ref` is the reference
        "reference": {"value": Limit(lo=-1e5, hi=1e5, unit="rad/s",
                                     doc="constant speed reference (default: the parameter set's ref)"),
                      "profile": PROFILE},
        "none": {},
    },
    outputs=SIGNALS,
    scenes_dir=Path(__file__).parent / "scenes",
    default_scene="step_up_pwm",
    paths={
        "reference": RunPath(run=Deferred("mbsuite.models.drives.reference:run"), label="equations",
                             what="hand-derived equations (Oldaker Ch. 3), event-exact stick/slip (scipy DOP853 "
                                  "between events)"),
        "mujoco": RunPath(run=Deferred("mbsuite.models.drives.mujoco:run"), label="mujoco",
                          what="MuJoCo: hinge rotors, real equality locks switched by a native stepper"),
    },
    sections={"design": Deferred("mbsuite.models.drives.design_scene:validate_section")},
    params_builder=Deferred("mbsuite.models.drives.design_scene:scene_params"),
    cases="mbsuite.models.drives.cases",
    accuracy=AccuracySpec(accuracy.headlines, accuracy.values, accuracy.refinement),
    solver=SolverSettings(engine="reference", integrator="rk4", timestep=1e-4, rtol=1e-9, atol=1e-11, duration=2.0),
    commands="mbsuite.models.drives.cli",
    statistics=STATISTICS,
    studies=Studies(threads=("mujoco",)),
    moved_scenes={name: f"rotational/{name}" for name in (
        "coupled_clutches", "msl_friction", "msl_one_way_clutch", "msl_one_way_clutch_disengaged",
        "msl_simple_gear_shift")},
)
