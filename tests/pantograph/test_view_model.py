"""The `mujoco_model` hook (`mbsuite view`): the MuJoCo model of exactly the scene's effects, in the run's initial
state."""

import mujoco
import numpy as np
import pytest

from mbsuite import load_scene, run
from mbsuite.models.pantograph.modelfiles import q_to_theta


@pytest.mark.parametrize(("scene_name", "effects", "nplugin", "na"), [
    ("pantograph", {}, 2, 1),                                                     # linear cylinder + compliant elbow
    ("pantograph/nonlinear_cylinder", {}, 2, 1),
    ("pantograph", {"cylinder": "constant"}, 1, 0),                               # elbow plugin only
    ("pantograph", {"cylinder": "constant", "elbow": "rigid"}, 0, 0),             # no plugin, a joint equality
])
def test_view_model_holds_the_scene_effects_and_the_runs_initial_state(scene_name, effects, nplugin, na):
    scene = load_scene(scene_name)
    scene = scene.replace(effects=effects, outputs=["theta1", "theta2", "thetah", "y_w"],
                          solver={"duration": 2e-3, "t_settle": 0.0, "sample_dt": scene.solver.timestep})
    m, d = scene.spec.mujoco_model(scene)
    assert isinstance(m, mujoco.MjModel) and isinstance(d, mujoco.MjData)
    assert m.nplugin == nplugin and m.na == na
    assert m.neq == (1 if effects.get("elbow") == "rigid" else 0)
    assert m.opt.timestep == scene.solver.timestep
    assert d.time == 0.0 and np.all(d.qvel == 0.0)
    # the run (same scene, MuJoCo) starts where the viewer's data is: its first sample is the same state
    res = run(scene)
    th = q_to_theta(d.qpos)
    assert res.t[0] == 0.0
    for i, name in enumerate(("theta1", "theta2", "thetah")):
        assert res[name][0] == pytest.approx(th[i], abs=1e-12)
    assert d.ctrl[0] == pytest.approx(res["y_w"][0], abs=1e-15)
    # ... and it is an equilibrium of MuJoCo's forces (friction off: the static balance alone). Measured max |qacc|
    # 8.24e-12 rad/s^2 (every case here and the unilateral scene); bound 5e-11 (6x); a 1e-9 rad error in q1 gives
    # 2e-5. (The rigid elbow's soft equality makes its force from the acceleration itself: there the first sample of
    # the run is the check.)
    if m.neq == 0:
        m.dof_frictionloss[:] = 0.0
        mujoco.mj_forward(m, d)
        assert np.max(np.abs(d.qacc)) < 5e-11
