"""Scenes build only what they ask for; off effects install nothing and change nothing; bad scenes are clear errors."""

import zlib

import mujoco
import numpy as np
import pytest

from mbsuite import SceneError, load_scene, run, scene_from_dict
from mbsuite.engines import native
from mbsuite.engines.core import Channel, Stepper
from mbsuite.models.pantograph.equations import PantographConfig
from mbsuite.models.pantograph.inputs import InputSignal
from mbsuite.models.pantograph.mujoco import MujocoPantograph
from mbsuite.paths import mjcf_path


def _steps(model, n, q0):
    """n steps of the native core from q0 at rest under a slowly varying ram; every state recorded."""
    d = mujoco.MjData(model)
    d.qpos[:] = q0
    ctrl = 1.58 + 1e-3 * np.sin(0.01 * np.arange(n))
    st = Stepper(model, d, [Channel("q", "qpos", 0, 3), Channel("v", "qvel", 0, 3)])
    tr = st.run(n, ctrl=ctrl, ctrl_idx=[0])
    return np.hstack([tr["q"], tr["v"]])


def test_plugins_only_for_effects_that_need_them():
    """The effects that need code are engine plugins, present only when the scene asks for them; an effect that is
    off adds no plugin and no state."""
    off = MujocoPantograph(config=PantographConfig(cylinder="constant", elbow="rigid"))
    assert off.model.nplugin == 0 and off.model.na == 0
    lab = MujocoPantograph(config=PantographConfig())
    names = {mujoco.mj_id2name(lab.model, mujoco.mjtObj.mjOBJ_PLUGIN, i) for i in range(lab.model.nplugin)}
    assert names == {"cylinder", "elbow"} and lab.model.na == 1
    assert MujocoPantograph(config=PantographConfig(cylinder="constant")).model.na == 0  # no state added
    assert MujocoPantograph(config=PantographConfig(elbow="rigid")).model.nplugin == 1


def test_shipped_scene_runs_install_no_python_callback(lab_scene, monkeypatch):
    """No MuJoCo Python callback is ever installed by a run (they are process-global and hold the GIL)."""
    calls = []
    for name in ("passive", "act_dyn", "act_gain", "act_bias", "control", "sensor"):
        setter = f"set_mjcb_{name}"
        monkeypatch.setattr(mujoco, setter, lambda fn, name=name: calls.append(name))
    for eff in ({}, {"cylinder": "nonlinear"}, {"elbow": "rigid", "cylinder": "constant"}):
        run(lab_scene.replace(effects=eff, solver={"duration": 0.2, "t_settle": 0.1}))
    assert calls == []
    assert mujoco.get_mjcb_passive() is None and mujoco.get_mjcb_act_dyn() is None


@pytest.mark.parametrize("effect,edit", [
    ("gravity", lambda m: m.opt.gravity.__setitem__(slice(None), 0.0)),
    ("coulomb", lambda m: m.dof_frictionloss.__setitem__(slice(None), 0.0)),
    ("viscous", lambda m: m.dof_damping.__setitem__(slice(None), 0.0)),
])
def test_off_effect_bit_identical_to_model_built_without_it(effect, edit):
    """Builder with the effect off vs the shipped MJCF compiled directly and edited by hand: bit-identical steps."""
    cfg = PantographConfig(**{effect: False})
    mp = MujocoPantograph(config=cfg)
    native.load()
    raw = mujoco.MjModel.from_xml_path(str(mjcf_path("pantograph")))
    raw.opt.integrator = mp.model.opt.integrator
    edit(raw)
    q0 = mp.equilibrium()
    assert np.array_equal(_steps(mp.model, 400, q0), _steps(raw, 400, q0))


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
    with pytest.raises(SceneError, match=r"solver.integrator = .leapfrog. .* valid: one of \[.euler."):
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
