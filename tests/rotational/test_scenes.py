"""The rotational model's scenes: registered with both paths, the smallest scene (the model and its example) loads
and runs, the old `drives/<example>` names load their new home with a DeprecationWarning, a scene setting what the
examples do not read is refused when it loads, and every shipped scene closes its energy balance on MuJoCo."""

from __future__ import annotations

import pytest

import mbsuite
from mbsuite.components.rotational.energy import energy_balance
from mbsuite.engines import mujoco_engine
from mbsuite.errors import SceneError
from mbsuite.models.rotational.analysis import simulate_scene
from mbsuite.registry import get_model
from mbsuite.scenes import load_scene, scene_from_dict

EXAMPLES = sorted(get_model("rotational").scene_files())


def test_spec_and_scenes_registered():
    spec = get_model("rotational")
    assert set(spec.paths) == {"reference", "mujoco"}
    assert set(EXAMPLES) == set(spec.effects["example"].choices)


def test_smallest_scene_runs():
    """`model = "rotational"` and `[effects] example = "coupled_clutches"`: nothing else to say. J4 ends on the
    Dymola result's 2.463 rad/s (measured difference 4.7e-5 rad/s, the reference's accuracy: bound 1e-3)."""
    res = mbsuite.run(scene_from_dict({"model": "rotational", "effects": {"example": "coupled_clutches"}}))
    assert abs(res.stats["final"]["J4.w"] - 2.4632) < 1e-3


@pytest.mark.parametrize("name", EXAMPLES)
def test_old_drives_names_load_the_new_scene(name):
    with pytest.warns(DeprecationWarning, match=f"rotational/{name}"):
        sc = load_scene(f"drives/{name}")
    assert sc.model == "rotational" and sc.effects["example"] == name


def test_what_the_examples_do_not_read_is_refused_at_load():
    """The examples carry the MSL's parameters, sources and friction: a parameter or a drives effect is an unknown
    key of the scene, named when it loads."""
    with pytest.raises(SceneError, match="J_m"):
        scene_from_dict({"model": "rotational", "effects": {"example": "msl_friction"}, "params": {"J_m": 2.0}})
    with pytest.raises(SceneError, match="controller"):
        scene_from_dict({"model": "rotational", "effects": {"example": "msl_friction", "controller": "pwm"}})


@pytest.mark.parametrize("name", EXAMPLES)
def test_shipped_scenes_close_their_energy_balance(name):
    """Every shipped scene on MuJoCo over 0.7 s (the examples start moving late): input - output - losses - stored
    energy change <= 7.2e-8 of the energy turnover (measured, msl_friction); bound 5e-7, 7x. No MuJoCo warning, no
    callback left installed."""
    sc = load_scene(f"rotational/{name}").replace(solver={"engine": "mujoco", "duration": 0.7})
    res, sys_ = simulate_scene(sc)
    bal = energy_balance(sys_, res)
    assert max(abs(bal.input), abs(bal.output), abs(bal.stored)) > 1e-3  # the scene moved: a balance to check
    assert abs(bal.relative) < 5e-7, bal
    assert res.stats["warnings"] == {}
    assert not mujoco_engine.active_callbacks()
