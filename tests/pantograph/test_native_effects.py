"""The engine plugins (C, `native/pantograph.c`) against their readable Python twins (`python_effects.py`, MuJoCo
callbacks), on every shipped pantograph scene and on the effect variants the scenes do not reach (exact chain wrap,
elbow damping be > 0):

- the effects' outputs (generalised forces qfrc_passive + qfrc_actuator and the cylinder state derivative) at every
  10th state of the scene's trajectory agree to 1e-12 of their scale: the same equations, to rounding;
- whole trajectories (2 s, 2000 RK4 steps from the same equilibrium) agree to 1e-10 of each state's scale: rounding
  accumulated over the run (measured: at most 1.1e-11, on the unilateral scene whose contact losses amplify it)."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest

from mbsuite import load_scene
from mbsuite.engines.mujoco_engine import callbacks
from mbsuite.models.pantograph.inputs import config_of, input_of
from mbsuite.models.pantograph.mujoco import MujocoPantograph
from mbsuite.models.pantograph.python_effects import PythonEffects
from mbsuite.scenes import shipped_scenes

CASES = [(s, {}, {}) for s in shipped_scenes()["pantograph"]] + [
    ("lab", {"elbow_kinematics": "exact"}, {}),
    ("lab", {}, {"be": 50.0}),
    ("nonlinear_cylinder", {"coulomb": False}, {"be": 20.0}),
]


def _scene(name, effects, params, duration=2.0):
    return load_scene(f"pantograph/{name}").replace(effects=effects, params=params,
                                                    solver={"duration": duration, "t_settle": duration / 2})


def _paths(scene):
    p, cfg, s = scene.build_params(), config_of(scene), scene.solver
    native = MujocoPantograph(p, cfg, s.integrator, s.timestep)
    python = MujocoPantograph(p, cfg, s.integrator, s.timestep, plugins=False)
    return native, python, PythonEffects(p, cfg).callbacks()


def _effect_outputs(mp, q, v, act, ctrl):
    m, d = mp.model, mp.data
    d.qpos[:], d.qvel[:], d.ctrl[:] = q, v, ctrl
    if m.na:
        d.act[:] = act
    mujoco.mj_forward(m, d)
    return d.qfrc_passive + d.qfrc_actuator, d.act_dot.copy()


@pytest.mark.parametrize("name,effects,params", CASES, ids=lambda x: str(x))
def test_native_effects_equal_python_twins(name, effects, params):
    scene = _scene(name, effects, params)
    native, python, cbs = _paths(scene)
    u = input_of(scene, scene.build_params())
    a = native.simulate(u, scene.solver.duration)
    rows = range(0, a.t.size, 10)
    acts = a["act"].reshape(a.t.size, -1) if "act" in a.channels else np.zeros((a.t.size, 0))
    states = [(a["qpos"][k], a["qvel"][k], acts[k], [u(a.t[k]), 0.0]) for k in rows]
    out_n = [_effect_outputs(native, *x) for x in states]  # callbacks are process-global: never both at once
    with callbacks(**cbs):
        b = python.simulate(u, scene.solver.duration)
        out_p = [_effect_outputs(python, *x) for x in states]
    f_n, f_p = np.array([o[0] for o in out_n]), np.array([o[0] for o in out_p])
    assert np.max(np.abs(f_n - f_p)) <= 1e-12 * np.max(np.abs(f_p))
    if native.model.na:
        r_n, r_p = np.array([o[1] for o in out_n]), np.array([o[1] for o in out_p])
        assert np.max(np.abs(r_n - r_p)) <= 1e-12 * np.max(np.abs(r_p))
    assert a.steps == b.steps == 2000 and a.warnings == b.warnings == {}
    for ch in ("qpos", "qvel", "act"):
        if ch in a.channels:
            assert np.max(np.abs(a[ch] - b[ch])) <= 1e-10 * np.max(np.abs(b[ch])), ch


def test_a_wrong_twin_is_caught():
    """The comparison can fail: the elbow stiffness of the Python twin off by 1e-6 moves the trajectory by far more
    than the tolerances above."""
    scene = _scene("lab", {}, {}, duration=0.5)
    native, python, _ = _paths(scene)
    p = scene.build_params()
    u = input_of(scene, p)
    a = native.simulate(u, 0.5)
    with callbacks(**PythonEffects(dataclasses.replace(p, ke=p.ke * (1 + 1e-6)), config_of(scene)).callbacks()):
        b = python.simulate(u, 0.5, native.equilibrium())
    assert np.max(np.abs(a["qvel"] - b["qvel"])) > 1e-4 * np.max(np.abs(b["qvel"]))
