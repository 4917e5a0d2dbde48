"""The menagerie test applied to mbsuite: every shipped scene of every model steps 1 s under random admissible inputs
(on its MuJoCo path where it has one) with no NaN/inf and zero MuJoCo warnings."""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest

import mbsuite
from mbsuite.engines import mujoco_engine
from mbsuite.scenes import shipped_scenes

SCENES = [f"{m}/{s}" for m, ss in sorted(shipped_scenes().items()) for s in ss]


def random_inputs(scene: mbsuite.Scene, rng: np.random.Generator) -> dict:
    """Admissible random changes of a scene's input (and, for the catenary, a 1 s stretch of line)."""
    inp = dict(scene.input)
    sections: dict = {}
    if scene.model == "pantograph":
        if inp.get("type") == "sine":
            inp.update(amplitude=float(inp.get("amplitude", 1.85e-3)) * rng.uniform(0.5, 1.0),
                       frequency=rng.uniform(1.0, 12.0))
        elif inp.get("type") == "catenary":
            inp["speed"] = rng.uniform(150.0, 300.0)
    elif scene.model == "coupler":
        for k in ("omega", "load_torque"):
            if k in inp:
                inp[k] = float(inp[k]) * rng.uniform(0.5, 1.5)
        for k in ("z_c", "x_c", "alpha_cx", "alpha_cz"):
            if k in inp:
                inp[k] = float(inp[k]) * rng.uniform(0.8, 1.2)
    elif scene.model == "drives":
        if "value" in inp:
            inp["value"] = float(inp["value"]) * rng.uniform(0.5, 1.0)
        if "profile" in inp:
            s = rng.uniform(0.5, 1.0)
            inp["profile"] = [[t, r * s] for t, r in inp["profile"]]
    elif scene.model == "iftomm":
        inp["rate"] = rng.uniform(-8.0, 8.0) if scene.effects["mechanism"] == "fourbar" else rng.uniform(-1.0, 1.0)
    elif scene.model == "catenary":
        v = rng.uniform(150.0, 300.0)
        inp["speed"] = v
        length = v / 3.6 * 1.0  # 1 s of travel
        x0 = float(scene.build_params().x_start)
        sections["params"] = {"x_end": x0 + length, "window_start": x0 + 0.2 * length,
                              "window_end": x0 + 0.9 * length}
    sections["input"] = inp
    return sections


@pytest.mark.parametrize("ref", SCENES)
def test_scene_steps_one_second_without_warnings(ref):
    scene = mbsuite.load_scene(ref)
    rng = np.random.default_rng(zlib.crc32(ref.encode()))
    engine = "mujoco" if "mujoco" in scene.spec.engines else scene.solver.engine
    sections = random_inputs(scene, rng)
    solver = {"engine": engine, "duration": 1.0, "t_settle": 0.0}
    if scene.model == "catenary":
        from mbsuite.models.catenary.analysis import run_scene, to_simresult

        if scene.effects["pantograph"] != "eppinger":
            solver["engine"] = "reference"  # the catenary is FE code; only the Eppinger pantograph has a MuJoCo path
        sc = scene.replace(solver=solver, **sections)
        res = to_simresult(run_scene(sc), sc)
    else:
        sc = scene.replace(solver=solver, **sections)
        res = mbsuite.run(sc)
    assert res.t[-1] == pytest.approx(1.0, abs=0.05) or scene.model == "catenary"
    for name, sig in res.signals.items():
        assert np.all(np.isfinite(sig)), f"{ref}: {name} has NaN/inf"
    assert res.stats.get("warnings", {}) == {}, f"{ref}: MuJoCo warnings {res.stats['warnings']}"
    assert not mujoco_engine.active_callbacks()  # nothing left installed after the run
    assert all(math.isfinite(float(x)) for x in res.t)
