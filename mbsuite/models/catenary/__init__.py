"""Pantograph-catenary interaction: a 2-D finite-element catenary (EN 50318:2002 reference scene), the 2-mass reference
pantograph, a consistent coupled integrator and the EN 50318 statistics. The catenary owns the coupling: any pantograph
model of the registry that declares `under_wire` runs under the wire through the protocol of `pantographs.py`."""

from __future__ import annotations

from pathlib import Path

from ...limits import Limit
from ...registry import Effect, ModelSpec, RunPath
from ...solver import SolverSettings
from .pantographs import validate_section
from .params import CatenaryParams
from .quality import validate_section as validate_quality
from .train import validate_section as validate_train


def _run(scene, engine: str | None = None, **kw):
    """`run` hook: one passage at the scene's input.speed as a SimResult (time histories, loss events, the eight
    EN 50318 statistics and timings in `stats`). `mbsuite catenary` gives the full EN 50318 report."""
    from .analysis import run_scene, to_simresult

    if engine:
        scene = scene.replace(solver={"engine": engine})
    if "train" in scene.sections:
        from .train import run_train_scene, train_to_simresult

        return train_to_simresult(run_train_scene(scene, **kw), scene)
    return to_simresult(run_scene(scene, **kw), scene)


SPEC = ModelSpec(
    name="catenary",
    summary="FE catenary (EN 50318 reference) under a moving pantograph: contact force and uplift statistics",
    params_cls=CatenaryParams,
    effects={
        "droppers": Effect(("slack", "linear"), "slack", "slack: tension-only droppers (status solved each step); "
                                                          "linear: bilateral springs"),
        "pantograph": Effect(("reference2mass", "eppinger"), "reference2mass",
                             "reference2mass: EN 50318 2-mass pantograph (parameters m1 ... F0 in [params]); "
                             "eppinger: the registry model 'pantograph' (Brecknell-Willis), its own effects and "
                             "parameters in the [pantograph] section, its path = solver.engine (reference = "
                             "hand-derived ODE, mujoco = MuJoCo)"),
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
        "reference": RunPath(_run, "fe", "FE catenary (compiled core) + the pantograph's hand-derived equations"),
        "mujoco": RunPath(_run, "fe+mujoco", "FE catenary (compiled core) + the pantograph on MuJoCo (eppinger only)"),
    },
    sections={"pantograph": validate_section, "quality": validate_quality, "train": validate_train},
    cases="mbsuite.models.catenary.cases",
    solver=SolverSettings(engine="reference", timestep=1e-4, duration=6.1),
)
