"""The menagerie test applied to mbsuite: every shipped scene of every model steps 1 s under random admissible inputs
(the model's own `random_input`, on its MuJoCo path where it has one) with no NaN/inf, zero MuJoCo warnings and no
MuJoCo callback left installed. The test names no model: what is admissible is each model's declaration."""

from __future__ import annotations

import math
import zlib

import mujoco
import numpy as np
import pytest

import mbsuite
from mbsuite.registry import models
from mbsuite.scenes import shipped_scenes

SCENES = [f"{m}/{s}" for m, ss in sorted(shipped_scenes().items()) for s in ss]


def test_every_model_declares_random_inputs():
    for name, spec in models().items():
        assert callable(getattr(spec.suite(), "random_input", None)), f"model {name} declares no random_input"


@pytest.mark.parametrize("ref", SCENES)
def test_scene_steps_one_second_without_warnings(ref):
    scene = mbsuite.load_scene(ref)
    rng = np.random.default_rng(zlib.crc32(ref.encode()))
    engine = "mujoco" if "mujoco" in scene.spec.engines else scene.solver.engine
    sections = scene.spec.suite().random_input(scene, rng)
    solver = {"engine": engine, "duration": 1.0, "t_settle": 0.0, **sections.pop("solver", {})}
    res = mbsuite.run(scene.replace(solver=solver, **sections))
    assert res.t[-1] == pytest.approx(solver["duration"], abs=0.05)
    for name, sig in res.signals.items():
        assert np.all(np.isfinite(sig)), f"{ref}: {name} has NaN/inf"
    assert res.stats.get("warnings", {}) == {}, f"{ref}: MuJoCo warnings {res.stats['warnings']}"
    assert all(g() is None for g in (mujoco.get_mjcb_passive, mujoco.get_mjcb_act_dyn, mujoco.get_mjcb_control))
    assert all(math.isfinite(float(x)) for x in res.t)
