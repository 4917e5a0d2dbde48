"""The catenary model's declaration, `SPEC` (a `mbsuite.registry.ModelSpec`), which the package hands on at its first
use (`__init__.py`)."""

from __future__ import annotations

from pathlib import Path

from ...deferred import Deferred
from ...limits import Limit
from ...registry import Band, Effect, ModelSpec, RunPath, Studies, Uses
from ...settings import SolverSettings
from ...trust.estimate import AccuracySpec
from . import accuracy
from .aerodynamics import validate_section as validate_aerodynamics
from .config import validate_train_section
from .linefile import scene_params, validate_line_section
from .pantographs import PANTOGRAPHS, SECTION_PANTOGRAPHS, TWO_MASS, validate_section
from .params import CatenaryParams
from .quality import SYSTEMS
from .quality import validate_section as validate_quality
from .stats import STATISTICS

#: the 2-mass reference pantograph's parameters are read only when it runs; a registry pantograph takes its own from the
#: [pantograph] section (measured: m1 and F0 10 % up leave every signal of a 3-span Eppinger passage identical,
#: difference 0.0; `tests/suite/test_unused_input.py`)
USES = {
    **{f"params.{k}": Uses(effects={"pantograph": (TWO_MASS,)}) for k in ("m1", "k1", "c1", "m2", "k2", "c2", "F0")},
    "pantograph": Uses(effects={"pantograph": tuple(SECTION_PANTOGRAPHS)}),
}

SPEC = ModelSpec(
    name="catenary",
    summary="FE catenary (EN 50318 reference) under a moving pantograph: contact force and uplift statistics",
    params_cls=CatenaryParams,
    effects={
        "droppers": Effect(("slack", "linear"), "slack", "slack: tension-only droppers (status solved each step); "
                                                          "linear: bilateral springs"),
        "pantograph": Effect(PANTOGRAPHS, "reference2mass",
                             "reference2mass: EN 50318 2-mass pantograph (parameters m1 ... F0 in [params]); "
                             "eppinger: the registry model 'pantograph' (Brecknell-Willis), its own effects and "
                             "parameters in the [pantograph] section, its path = solver.engine (reference = "
                             "hand-derived ODE, mujoco = MuJoCo); lumped: an n-stage lumped pantograph (m, k, c, F0 "
                             "lists in [pantograph] params); transfer: a state-space receptance (A, B, C, F0 in "
                             "[pantograph] params; `mbsuite pantograph fit-lumped` writes both)"),
        "contact": Effect(("unilateral", "bilateral"), "unilateral",
                          "unilateral: penalty spring that only pushes; bilateral: attached (no contact loss)"),
    },
    inputs={"passage": {"speed": Limit(lo=0.0, lo_open=True, hi=1000.0, unit="km/h",
                                       doc="train speed; --speed overrides it (below the CW wave speed: checked "
                                           "against the parameters when the passage starts)")}},
    outputs={"contact_force": "N", "contact_force_filtered": "N", "position": "m", "head_height": "m",
             "wire_height": "m", "slack_droppers": "-", "uplift": "m"},
    scenes_dir=Path(__file__).parent / "scenes",
    default_scene="en50318",
    paths={
        "reference": RunPath(Deferred("mbsuite.models.catenary.reference:run"), "fe",
                             "FE catenary (compiled core) + the pantographs' hand-derived "
                             "equations (2-mass: the wire's trapezoidal rule, exact; Eppinger: its ODE by RK4 per "
                             "catenary step, secant-coupled)"),
        "mujoco": RunPath(Deferred("mbsuite.models.catenary.mujoco:run"), "fe+mujoco",
                          "FE catenary (compiled core) + the Eppinger pantograph on MuJoCo, "
                          "one MuJoCo step per catenary step, secant-coupled (no 2-mass pantograph alone)"),
    },
    solver=SolverSettings(engine="reference", timestep=1e-4, duration=6.1),
    #: scene keys recorded but without effect on a passage (it runs from x_start to x_end at its speed): `mbsuite
    #: compare` does not list them among the scenes' differences
    extra={"informative": ("solver.duration",)},
    sections={"pantograph": validate_section, "quality": validate_quality, "train": validate_train_section,
              "line": validate_line_section, "aerodynamics": validate_aerodynamics},
    cases="mbsuite.models.catenary.cases",
    accuracy=AccuracySpec(accuracy.headlines, accuracy.values, accuracy.refinement),
    uses=USES,
    params_builder=scene_params,
    input_files={"line_file": Deferred("mbsuite.models.catenary.linefile:LINE_FILE")},
    studies=Studies(objective="sigma", against="Fm",
                    band=Band("Fm", tuple(SYSTEMS), Deferred("mbsuite.models.catenary.quality:band_target"),
                              "EN 50367 band", "the target band of the mean contact force Fm at the scene's speed "
                              "(EN 50367 / TSI Energy), per supply system"),
                    threads=("mujoco",)),
    commands="mbsuite.models.catenary.cli",
    statistics=STATISTICS,
)
