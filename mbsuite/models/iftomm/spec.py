"""The iftomm model's declaration, `SPEC` (a `mbsuite.registry.ModelSpec`), which the package hands on at its first
use (`__init__.py`)."""

from __future__ import annotations

from pathlib import Path

from ...deferred import Deferred
from ...limits import Limit
from ...registry import Effect, ModelSpec, RunPath, Studies, Uses
from ...settings import SolverSettings
from ...trust.estimate import AccuracySpec
from . import accuracy
from .outputs import OUTPUTS, STATISTICS
from .params import IftommParams

#: which path uses which parameters (measured: a 10 % change moves no output of a 1 s run on the other path;
#: `tests/suite/test_unused_input.py`): the closures' softness is MuJoCo's, the penalty formulation the reference
#: path's on the Bricard only (the four-bar's reference integrates its reduced branch dynamics)
USES = {
    "params.solref_timeconst": Uses(engines=("mujoco",)),
    **{f"params.{k}": Uses(effects={"mechanism": ("bricard",)}, engines=("reference",))
       for k in ("penalty", "penalty_omega")},
}

SPEC = ModelSpec(
    name="iftomm",
    summary="IFToMM benchmark gates: four-bar through singular positions (A02), over-constrained Bricard (A04)",
    params_cls=IftommParams,
    effects={"mechanism": Effect(("fourbar", "bricard"), "fourbar", "which benchmark mechanism")},
    inputs={"initial": {"rate": Limit(lo=-100.0, hi=100.0, unit="rad/s", default=0.0,
                                      doc="initial rate of the first (input) joint on the free motion (0: at rest)")}},
    outputs=OUTPUTS,
    scenes_dir=Path(__file__).parent / "scenes",
    default_scene="fourbar",
    paths={
        "mujoco": RunPath(Deferred("mbsuite.models.iftomm.mujoco:run"), "mujoco",
                          "MuJoCo: the mechanism with its closures as equality constraints"),
        "reference": RunPath(Deferred("mbsuite.models.iftomm.pinocchio:run"), "pinocchio",
                             "Pinocchio: M(q), h(q, v) of the same file, closures by a "
                             "penalty formulation (four-bar on its branch), scipy ODE"),
    },
    cases="mbsuite.models.iftomm.cases",
    solver=SolverSettings(engine="mujoco", integrator="rk4", timestep=1e-3, method="DOP853", rtol=1e-8, atol=1e-10,
                          duration=10.0, sample_dt=1e-2),
    mujoco_model=Deferred("mbsuite.models.iftomm.mujoco:view_model"),
    file_checks={"iftomm_fourbar": Deferred("mbsuite.models.iftomm.modelfiles:check_model_file"),
                 "iftomm_bricard": Deferred("mbsuite.models.iftomm.modelfiles:check_model_file")},
    accuracy=AccuracySpec(accuracy.headlines, accuracy.values, accuracy.refinement),
    uses=USES,
    studies=Studies(threads=("mujoco",)),
    statistics=STATISTICS,
)
