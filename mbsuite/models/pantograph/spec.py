"""The pantograph model's declaration, `SPEC` (a `mbsuite.registry.ModelSpec`), which the package hands on at its first
use (`__init__.py`)."""

from __future__ import annotations

from pathlib import Path

from ...deferred import Deferred
from ...registry import Effect, ModelSpec, RunPath, Studies, Uses
from ...settings import SolverSettings
from ...trust.estimate import AccuracySpec
from . import accuracy
from .inputs import INPUTS
from .outputs import UNITS
from .params import PantographParams

#: the corrected orifice / ideal-gas cylinder's parameters (Eqs 3.15-3.22): only the nonlinear cylinder reads them
GAS = ("Ao", "V0", "R_gas", "gamma", "cd", "Pa", "T", "r_laminar")

#: which effects use which parameters (measured: a 10 % change of each moves no output of a 0.4 s run of the lab scene
#: with the effect value that does not use it, on either path; `tests/suite/test_unused_input.py`)
USES = {
    **{f"params.{k}": Uses(effects={"cylinder": ("nonlinear",)}) for k in GAS},
    **{f"params.{k}": Uses(effects={"cylinder": ("linear",)}) for k in ("kc", "bc")},
    **{f"params.{k}": Uses(effects={"elbow": ("compliant",)}) for k in ("ke", "be")},
    **{f"params.{k}": Uses(effects={"viscous": (True,)}) for k in ("b1", "b2", "bh")},
    **{f"params.{k}": Uses(effects={"coulomb": (True, "smooth")}) for k in ("c1", "c2", "ch")},
    "params.omega_s": Uses(effects={"coulomb": ("smooth",)}),
    "params.g": Uses(effects={"gravity": (True,)}),
}

SPEC = ModelSpec(
    name="pantograph",
    summary="Brecknell-Willis pantograph (Eppinger 1984): 3 links, compliant elbow, pneumatic cylinder, contact spring",
    params_cls=PantographParams,
    effects={
        "gravity": Effect((True, False), True, "gravity on the links"),
        "elbow": Effect(("compliant", "rigid"), "compliant", "elbow spring ke (3 DOF) or theta_2 = theta_e(theta_1)"),
        "elbow_kinematics": Effect(("B6", "exact"), "B6", "thesis B.6 or exact chain wrap (erratum 22)"),
        "cylinder": Effect(("linear", "nonlinear", "constant"), "linear",
                           "linear spring+damper (3.24-3.26), corrected orifice/ideal gas (3.15-3.22), constant Pg Ap"),
        "viscous": Effect((True, False), True, "joint viscous damping b1, b2, bh"),
        "coulomb": Effect((True, False, "smooth"), True,
                          "joint Coulomb friction: event-exact stick/slip (reference) / frictionloss (MuJoCo)"),
        "contact": Effect(("bilateral", "unilateral"), "bilateral", "ram attached (both ways) or push-only wire"),
    },
    inputs=INPUTS,
    outputs=UNITS,
    scenes_dir=Path(__file__).parent / "scenes",
    default_scene="lab",
    paths={
        "mujoco": RunPath(run=Deferred("mbsuite.models.pantograph.mujoco:run_mujoco"), label="mujoco",
                          what="MuJoCo: the MJCF of the scene's effects, cylinder and elbow as engine plugins, the "
                               "native core's loop",
                          lacks={"coulomb": ("smooth",)}),  # frictionloss only: c tanh(w/omega_s) is the reference's
        "reference": RunPath(run=Deferred("mbsuite.models.pantograph.reference:run_reference"), label="equations",
                             what="hand-derived equations (numpy/scipy, Eppinger Ch. 3), event-exact stick/slip"),
    },
    equilibrium=Deferred("mbsuite.models.pantograph.reports:equilibrium_report"),
    modes=Deferred("mbsuite.models.pantograph.reports:modes_report"),
    freqresp=Deferred("mbsuite.models.pantograph.freqresp:freqresp"),
    under_wire=Deferred("mbsuite.models.pantograph.under_wire:make"),
    mujoco_model=Deferred("mbsuite.models.pantograph.mujoco:view_model"),
    cases="mbsuite.models.pantograph.cases",
    accuracy=AccuracySpec(accuracy.headlines, accuracy.values, accuracy.refinement),
    sections={"freqresp": Deferred("mbsuite.models.pantograph.freqresp:validate_section")},
    uses=USES,
    # defaults chosen from scripts/pantograph_workprecision.py: RK4 at 1e-3 s reaches 3e-5 relative physics error
    # (implicitfast needs 5e-5 s for 6e-4) at the lowest cost of all MuJoCo settings; see the README.
    solver=SolverSettings(engine="mujoco", integrator="rk4", timestep=1e-3, method="LSODA", rtol=1e-8, atol=1e-10,
                          duration=10.0, t_settle=5.0),
    studies=Studies(threads=("mujoco",)),
    commands="mbsuite.models.pantograph.cli",
)
