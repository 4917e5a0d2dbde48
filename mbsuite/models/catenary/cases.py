"""The catenary's suite declarations: its hard case and the random admissible inputs of the random-input test
(collected by `mbsuite.hardcases` and the suite's tests through `SPEC.cases`). The catenary declares no work-precision
study: its accuracy evidence is the mesh/time-step convergence of the EN 50318 statistics (README, slow tests)."""

from __future__ import annotations

import warnings

import numpy as np

from ...errors import ParameterError
from ...hardcases import Checker, HardCase
from ...scenes import Scene
from .pantographs import PANTOGRAPH_MODELS


def _catenary_critical_speed(ck: Checker) -> None:
    from .analysis import CriticalSpeedWarning, speed_regime
    from .params import CatenaryParams

    p = CatenaryParams()
    c = p.cw_wave_speed
    ck.raises("speed at the wave speed sqrt(T/rho)", lambda: speed_regime(p, c), ParameterError, "wave speed")
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        info = speed_regime(p, 0.95 * c)
    ck.true("95 % of c: CriticalSpeedWarning, regime near-critical",
            any(issubclass(x.category, CriticalSpeedWarning) for x in w) and info["regime"] == "near-critical")
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        info = speed_regime(p, 0.5 * c)
    ck.true("50 % of c: no warning, subcritical", not w and info["regime"] == "subcritical")


HARD_CASES: tuple[HardCase, ...] = (
    HardCase("catenary_critical_speed", "catenary",
             "train speed approaching the contact wire's wave speed: no steady solution",
             "catenary speed regime at 50 %, 95 %, 100 % of sqrt(T/rho)",
             "ParameterError at c; CriticalSpeedWarning near c; nothing at 50 %", _catenary_critical_speed),
)


def random_input(scene: Scene, rng: np.random.Generator) -> dict:
    """A random train speed of 150-300 km/h over a 1 s stretch of line from the scene's start (statistics window:
    20-90 % of the stretch). The pantograph keeps its engine path where it has a MuJoCo one; the 2-mass reference
    pantograph runs on the reference path (the catenary is FE code, only registry pantographs have other paths)."""
    v = rng.uniform(150.0, 300.0)
    length = v / 3.6 * 1.0  # 1 s of travel
    x0 = float(scene.build_params().x_start)
    out = {"input": {**scene.input, "speed": v},
           "params": {"x_end": x0 + length, "window_start": x0 + 0.2 * length, "window_end": x0 + 0.9 * length},
           "solver": {"duration": 1.0}}
    if scene.effects["pantograph"] not in PANTOGRAPH_MODELS:
        out["solver"]["engine"] = "reference"
    return out
