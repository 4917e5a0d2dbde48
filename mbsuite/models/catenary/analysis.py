"""One pantograph's passage and the scene's passages: `simulate` (a single pantograph: a `config.PassageConfig` of one
through the passage loop `train.run_passage`, seen as a `CatenaryRun` with its EN 50318 verdicts), and the scene
plumbing (`scene_config`, `run_scene`, `run_train_scene`). What a run gives (SimResult, table, JSON, files) is
`reports.py`'s."""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import SceneError
from .aerodynamics import Uplift
from .config import PassageConfig
from .fe import CatenaryFE
from .pantographs import TWO_MASS, Pantograph
from .params import MAX_ELEMENT_STEPS, CatenaryParams
from .passage import CoupledResult
from .stats import check_ranges, in_window
from .train import TrainRun, run_passage


class ContactLostWarning(UserWarning):
    """The pantograph left the wire for the whole statistics window (no contact to analyse)."""


@dataclass
class CatenaryRun:
    """A coupled run with its EN 50318 statistics."""

    params: CatenaryParams
    speed_kmh: float
    dt: float
    dropper_law: str
    pantograph: str
    result: CoupledResult
    stats: dict
    filtered: np.ndarray
    regime: dict
    timing: dict
    ranges: dict | None = None
    warnings: list[str] = field(default_factory=list)
    static_force: float = 0.0
    engine_warnings: dict[str, int] = field(default_factory=dict)
    is_reference: bool = False  # the EN 50318 reference scene (2-mass pantograph, specification's parameters)
    engine: str = "reference"  # the pantograph's engine path (the catenary is always the FE reference code)
    aerodynamics: Uplift | None = None  # the pantograph's aerodynamic uplift (None: no [aerodynamics] section)


#: the timings of a single passage (`CatenaryRun.timing`, besides `method`)
TIMING_KEYS = ("build_s", "integrate_s", "statistics_s", "total_s", "cpu_s", "steps", "dofs", "us_per_step", "native")


def simulate(p: CatenaryParams, speed_kmh: float, dt: float, dropper_law: str = "slack",
             pantograph: str | Pantograph = TWO_MASS, contact: str = "unilateral",
             progress: Callable[[int, int], None] | None = None, fe: CatenaryFE | None = None,
             engine: str = "reference", pantograph_section: dict[str, Any] | None = None,
             max_steps: float | None = None, native: bool | None = None,
             allow_inaccurate: bool = False, aerodynamics: dict[str, Any] | None = None) -> CatenaryRun:
    """Build, run and analyse one pantograph passage (the EN 50318 procedure): the `PassageConfig` of these arguments
    (a train of one) through `train.run_passage`. `pantograph` is a name (the scene's `pantograph` effect, built on the
    engine path `engine` with the `[pantograph]` section `pantograph_section`; see `pantographs.build`) or an object
    of the pantograph protocol. Everything is checked before anything is built (`PassageConfig.check`). `native`: the
    compiled step core (None: whenever it applies; False: the readable Python path). `aerodynamics`: an
    `[aerodynamics]` section (`aerodynamics.py`: F = c v^2 on the head and the frame)."""
    cfg = PassageConfig(p, speed_kmh, dt, (pantograph,), (), dropper_law, contact, engine, pantograph_section,
                        max_steps, allow_inaccurate, aerodynamics=aerodynamics)
    return single(run_passage(cfg, progress=progress, fe=fe, native=native))


def single(run: TrainRun) -> CatenaryRun:
    """A passage of one pantograph as a `CatenaryRun`: its contact loss over the whole window warned about
    (`ContactLostWarning`), its engine's warnings, the EN 50318 ranges if it is the reference scene."""
    p, res, stats = run.params, run.results[0], run.stats[0]
    warn = list(run.warnings)
    if not np.any(res.force[in_window(res.x, p)] > 0):
        msg = (f"the pantograph is off the wire for the whole window [{p.window_start}, {p.window_end}] m "
               f"(static uplift F0 = {p.F0} N): no contact force to analyse")
        warn.append(msg)
        warnings.warn(msg, ContactLostWarning, stacklevel=3)
        stats["contact_lost_entirely"] = True
    else:
        stats["contact_lost_entirely"] = False
    timing = {k: run.timing[k] for k in TIMING_KEYS}
    timing["method"] = ("trapezoidal rule (Newmark beta=1/4), banded Cholesky factorised once, "
                        + ("compiled step core (native/catenary.c: block sweeps, fused mat-vec and recursions)"
                           if timing["native"] else "LAPACK dpbtrs per step (Python path)")
                        + ", exact per-step contact/slack-dropper active set on precomputed influence columns")
    eng_warn = run.engine_warnings[0]
    if eng_warn:
        warn.append(f"MuJoCo warnings in the pantograph model: {eng_warn}")
    name = run.names[0]
    # the EN 50318 ranges apply to the reference scene only: 2-mass pantograph, specification's parameters
    is_reference = name == TWO_MASS and dataclasses.replace(
        p, element_length=1.0, max_element_steps=MAX_ELEMENT_STEPS) == CatenaryParams(element_length=1.0)
    return CatenaryRun(params=p, speed_kmh=run.speed_kmh, dt=run.dt, dropper_law=run.dropper_law, pantograph=name,
                       result=res, stats=stats, filtered=run.filtered[0], regime=run.regime, timing=timing,
                       ranges=check_ranges(stats, run.speed_kmh) if is_reference else None, warnings=warn,
                       static_force=float(res.force[0]), engine_warnings=eng_warn, is_reference=is_reference,
                       engine=run.engines[0], aerodynamics=None if run.aerodynamics is None else run.aerodynamics[0])


# --- scene plumbing ---------------------------------------------------------------------------------------------
def scene_speed(scene, speed_kmh: float | None) -> float:
    """The passage speed (km/h): `speed_kmh` if given, else the scene's `input.speed`; SceneError if neither."""
    v = speed_kmh if speed_kmh is not None else scene.input.get("speed")
    if v is None:
        raise SceneError("no speed: give --speed KMH or [input] speed = ... (km/h) in the scene")
    return float(v)


def scene_config(scene, engine: str, speed_kmh: float | None = None, spacings: Sequence[float] | None = None,
                 train: bool = True, **overrides: Any) -> PassageConfig:
    """The passage of a catenary scene with its pantographs on the engine path `engine`: its parameters (with
    `overrides`), speed, time step, effects, the `[pantograph]` and `[aerodynamics]` sections; the pantographs of its
    `[train]` section (`spacings` overrides the section's; `train = False` ignores the section), else the one its
    `pantograph` effect names."""
    p = scene.build_params()
    if overrides:
        p = dataclasses.replace(p, **overrides)
    section = scene.sections.get("train") if train else None
    if section is not None:
        names, sp = tuple(section["pantographs"]), tuple(section["spacings"] if spacings is None else spacings)
    else:
        names, sp = (scene.effects["pantograph"],), ()
    sv = scene.solver
    return PassageConfig(p, scene_speed(scene, speed_kmh), sv.timestep, names, sp, scene.effects["droppers"],
                         scene.effects["contact"], engine, scene.sections.get("pantograph"), sv.max_steps,
                         sv.allow_inaccurate, aerodynamics=scene.sections.get("aerodynamics"))


def run_scene(scene, speed_kmh: float | None = None, progress=None, **overrides) -> CatenaryRun:
    """One passage of a catenary scene on its path `solver.engine` (`scene_config`; a `[train]` section is not read
    here: `run_train_scene`)."""
    cfg = scene_config(scene, scene.solver.engine, speed_kmh, train=False, **overrides)
    return single(run_passage(cfg, progress=progress))


def run_train_scene(scene, speed_kmh: float | None = None, progress=None, spacings: Sequence[float] | None = None,
                    **overrides: Any) -> TrainRun:
    """The train passage of a scene with a `[train]` section on its path `solver.engine` (`scene_config`)."""
    return run_passage(scene_config(scene, scene.solver.engine, speed_kmh, spacings, **overrides), progress=progress)
