"""Scenes build only what they ask for; off effects install nothing and change nothing; bad scenes are clear errors."""

import zlib

import mujoco
import numpy as np
import pytest

from mbsuite import SceneError, load_scene, run, scene_from_dict
from mbsuite.engines.mujoco_engine import active_callbacks, callbacks
from mbsuite.models.pantograph.analysis import InputSignal
from mbsuite.models.pantograph.mujoco import MujocoPantograph
from mbsuite.models.pantograph.reference import PantographConfig
from mbsuite.paths import mjcf_path


def _step_raw(model, n, callbacks_kw, q0):
    d = mujoco.MjData(model)
    d.qpos[:] = q0
    d.ctrl[0] = 1.58
    out = []
    with callbacks(**callbacks_kw):
        for k in range(n):
            d.ctrl[0] = 1.58 + 1e-3 * np.sin(0.01 * k)
            mujoco.mj_step(model, d)
            out.append(d.qpos.copy())
    return np.array(out)


def test_callbacks_only_for_effects_that_need_them():
    assert MujocoPantograph(config=PantographConfig(cylinder="constant", elbow="rigid")).callback_set() == {
        "passive": None, "act_dyn": None}
    lab = MujocoPantograph(config=PantographConfig())
    assert lab.callback_set()["act_dyn"] is not None and lab.callback_set()["passive"] is not None
    assert MujocoPantograph(config=PantographConfig(cylinder="constant")).model.na == 0  # no state added
    assert lab.model.na == 1


def test_no_callback_left_installed_after_runs(lab_scene):
    run(lab_scene.replace(solver={"duration": 0.2, "t_settle": 0.1}))
    assert active_callbacks() == {}
    assert mujoco.get_mjcb_passive() is None and mujoco.get_mjcb_act_dyn() is None


def test_rigid_constant_scene_runs_with_no_callback_installed(lab_scene, monkeypatch):
    seen = []
    orig = mujoco.mj_step

    def spy(m, d, *a):
        seen.append((mujoco.get_mjcb_passive(), mujoco.get_mjcb_act_dyn()))
        return orig(m, d, *a)

    monkeypatch.setattr(mujoco, "mj_step", spy)
    sc = lab_scene.replace(effects={"elbow": "rigid", "cylinder": "constant"}, solver={"duration": 0.05, "t_settle":
    0.0})
    run(sc)
    assert seen and all(s == (None, None) for s in seen)


@pytest.mark.parametrize("effect,edit", [
    ("cylinder", None),  # the shipped file holds the constant cylinder: identical model
    ("gravity", lambda m: m.opt.gravity.__setitem__(slice(None), 0.0)),
    ("coulomb", lambda m: m.dof_frictionloss.__setitem__(slice(None), 0.0)),
    ("viscous", lambda m: m.dof_damping.__setitem__(slice(None), 0.0)),
])
def test_off_effect_bit_identical_to_model_built_without_it(effect, edit):
    """Builder with the effect off vs the shipped MJCF compiled directly and edited by hand: bit-identical steps."""
    off = {"cylinder": "constant", "gravity": False, "coulomb": False, "viscous": False}[effect]
    cfg = PantographConfig(**{"cylinder": "constant", effect: off})
    mp = MujocoPantograph(config=cfg)
    raw = mujoco.MjModel.from_xml_path(str(mjcf_path("pantograph")))
    if edit:
        edit(raw)
    q0 = mp.equilibrium()
    a = _step_raw(mp.model, 400, mp.callback_set(), q0)
    b = _step_raw(raw, 400, {"passive": mp._elbow_passive}, q0)
    assert np.array_equal(a, b)


def test_unknown_effect_and_keys_list_valid_ones(lab_scene):
    d = lab_scene.to_dict()
    with pytest.raises(SceneError, match="valid effects: .*cylinder"):
        scene_from_dict({**d, "effects": {"turbo": True}})
    with pytest.raises(SceneError, match="valid values"):
        scene_from_dict({**d, "effects": {"cylinder": "hydraulic"}})
    with pytest.raises(SceneError, match="valid keys"):
        scene_from_dict({**d, "colour": "red"})
    with pytest.raises(SceneError, match="valid parameters"):
        scene_from_dict({**d, "params": {"mass": 3.0}})
    with pytest.raises(SceneError, match="valid integrators"):
        scene_from_dict({**d, "solver": {"integrator": "leapfrog"}})
    with pytest.raises(SceneError, match="valid signals"):
        scene_from_dict({**d, "outputs": {"signals": ["F7"]}})
    with pytest.raises(SceneError, match="shipped scenes"):
        load_scene("pantograph/nope")


def test_negative_mass_in_scene_is_named(lab_scene, tmp_path):
    from mbsuite import ParameterError

    p = tmp_path / "bad.toml"
    p.write_text('model = "pantograph"\n[params]\nm2 = -25.2\n')
    with pytest.raises(ParameterError, match="m2"):
        load_scene(p)
    p.write_text('model = "pantograph"\n[effects\n')
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(p)


@pytest.mark.parametrize("name", ["lab", "unilateral", "nonlinear_cylinder"])
def test_every_shipped_scene_steps_without_warnings(name):
    """The menagerie's test applied to ours: 1 s under a random admissible input, zero MuJoCo warnings."""
    rng = np.random.default_rng(zlib.crc32(name.encode()))  # reproducible (str hash is salted per process)
    sc = load_scene(f"pantograph/{name}").replace(
        input={"frequency": float(rng.uniform(1.0, 30.0))}, solver={"duration": 1.0, "t_settle": 0.5})
    res = run(sc)
    assert res.stats["warnings"] == {}
    assert all(np.all(np.isfinite(v)) for v in res.signals.values())


def test_input_signal_is_the_thesis_ram():
    u = InputSignal("sine", 1.58, 1.85e-3, 2.0)
    assert u(0.0) == 1.58 and u(0.25) == pytest.approx(1.58 + 3.7e-3)
