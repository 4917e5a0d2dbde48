"""The shipped catenary scenes at their defaults against a refined solution of a method that does not use the
point-load correction: every statistic of every pantograph within 1 N (forces) and 0.5 mm (uplift).

The refined solution is the plain Hermite FE (`assemble(p, point_correction=False)`) at 0.125 m and dt 5e-5 s; it is
itself within REF_SPREAD of the plain FE at 0.0625 m and 5e-5 s and at 0.0625 m and 1e-4 s on these scenes
(`scripts/catenary_convergence.py`, the model README's "Convergence"), so a default within the bound of it is
within the bound plus that of the converged statistics. The shipped defaults (0.5 m elements with the correction,
dt 2e-4 s) are measured within `MEASURED` of it.
"""

from __future__ import annotations

import warnings

import pytest

from mbsuite.models.catenary.analysis import scene_config
from mbsuite.models.catenary.config import CriticalSpeedWarning
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.stats import STAT_NAMES
from mbsuite.models.catenary.train import run_passage
from mbsuite.scenes import load_scene

#: the issue's accuracy criterion: every force statistic (N) and the uplift (mm)
BOUND = {**{k: 1.0 for k in STAT_NAMES if k not in ("uplift_mm", "loss_pct")}, "uplift_mm": 0.5}
#: the refined solution's own distance to 0.0625 m (mesh halved) and to dt 1e-4 s there (README, "Convergence")
REF_SPREAD = {"force_N": 0.15, "uplift_mm": 0.02}
#: largest |default - refined| measured over both speeds and every pantograph of each scene (force N, uplift mm)
MEASURED = {"catenary/en50318": (0.2, 0.1), "catenary/en50318_two_pantographs": (0.3, 0.1)}


def _stats(scene_name: str, speed: float, h: float | None, dt: float | None, correction: bool) -> list[dict]:
    scene = load_scene(scene_name)
    over = {"max_element_steps": 1e13} if h is None else {"element_length": h, "max_element_steps": 1e13}
    sc = scene.replace(params=over, solver={"timestep": dt or scene.solver.timestep, "max_steps": 1e9})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CriticalSpeedWarning)
        cfg = scene_config(sc, sc.solver.engine, speed_kmh=speed)
        return run_passage(cfg, fe=assemble(cfg.params, point_correction=correction)).stats


@pytest.mark.slow
@pytest.mark.parametrize("speed", [250.0, 300.0])
@pytest.mark.parametrize("scene_name", ["catenary/en50318", "catenary/en50318_two_pantographs"])
def test_shipped_defaults_within_1N_and_half_a_millimetre_of_the_refined_solution(scene_name, speed):
    """The scene as shipped (no setting changed) against the plain Hermite FE at 0.125 m, dt 5e-5 s: every
    statistic of every pantograph within `BOUND` (measured `MEASURED`). The plain Hermite FE at the shipped 0.5 m is
    off by up to 8 N (the trailing pantograph's actual max at 300 km/h): the test can fail."""
    default = _stats(scene_name, speed, None, None, True)
    refined = _stats(scene_name, speed, 0.125, 5e-5, False)
    assert len(default) == len(refined) == (2 if "two" in scene_name else 1)
    for k, (a, b) in enumerate(zip(default, refined, strict=True)):
        for stat, bound in BOUND.items():
            assert abs(a[stat] - b[stat]) <= bound, (k, stat, a[stat], b[stat])
