"""Hard situations not in the hard-case registry, and bad input that must give clear errors.

The registry's pantograph cases (stick-slip at 2 Hz, the orifice at dp = 0 and choked, push-only contact, over-large
timesteps, 100 s energy drift; `mbsuite/models/pantograph/cases.py`) are run by `tests/suite/test_hardcases.py`
and hold the bounds: they are not re-tested here."""


import numpy as np
import pytest

from mbsuite import ModelFileError, SceneError
from mbsuite.engines.mujoco_engine import load_model
from mbsuite.engines.pinocchio_engine import load_mjcf, load_urdf
from mbsuite.models.pantograph.equations import PantographConfig, PantographODE
from mbsuite.models.pantograph.modelfiles import E_THETA_Q, q_to_theta, theta_to_q
from mbsuite.models.pantograph.mujoco import MujocoPantograph
from mbsuite.models.pantograph.reference import simulate


def test_energy_drift_without_damping_and_friction():
    """Damping and friction off, constant cylinder, fixed ram, 10 s: energy is conserved (E = 276.7 J above the datum,
    kinetic 0.05-0.1 rad/s on the joints). Measured |E - E0|: reference DOP853 rtol 1e-11 3.2e-11 J, MuJoCo RK4 5e-4 s
    5.0e-7 J, implicitfast 2.6e-3 J (semi-implicit Euler: an O(h) energy oscillation, 2.55e-3 J in the first 5 s and
    2.61e-3 J in the last 5). Bounds 9x, 6x, 3.8x those; implicitfast must not grow (last half <= 1.2 x first half).
    (The 100 s RK4 1 ms drift is the registry case `pantograph_energy_drift_100s`.)"""
    cfg = PantographConfig(cylinder="constant", viscous=False, coulomb=False)
    ode = PantographODE(config=cfg)
    x0 = ode.equilibrium()
    x0[3:6] = [0.05, -0.03, 0.1]
    E0 = ode.energy(x0, 1.58)
    sol = simulate(ode, lambda t: 1.58, 10.0, x0, method="DOP853", rtol=1e-11, atol=1e-13)
    drift = max(abs(ode.energy(sol.x[:, k], 1.58) - E0) for k in range(0, sol.t.size, 10))
    assert drift < 3e-10
    for integ, bound in (("rk4", 3e-6), ("implicitfast", 1e-2)):
        mp = MujocoPantograph(config=cfg, integrator=integ, timestep=5e-4)
        mp.set_static(theta_to_q(x0[:3]), 1.58)
        mp.data.qvel[:] = np.linalg.solve(E_THETA_Q, x0[3:6])
        tr = mp.stepper(every=200).run(20000)
        es = np.abs([ode.energy(np.r_[q_to_theta(q), E_THETA_Q @ v], 1.58) - E0
                     for q, v in zip(tr["qpos"], tr["qvel"], strict=True)])
        assert es.max() < bound, integ
        if integ == "implicitfast":
            assert es[50:].max() <= 1.2 * es[:50].max()


def test_malformed_model_files(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody><body><joint type='hinge'/></body></worldbody>")  # not closed
    with pytest.raises(ModelFileError, match="bad.xml"):
        load_model(bad)
    with pytest.raises(ModelFileError, match="bad.xml"):
        load_mjcf(bad)
    badu = tmp_path / "bad.urdf"
    badu.write_text("<robot name='x'><link name='a'/><joint name='j' type='revolute'>"
                    "<parent link='a'/></joint></robot>")
    with pytest.raises(ModelFileError, match="bad.urdf"):
        load_urdf(badu)
    with pytest.raises(ModelFileError, match="not found"):
        load_model(tmp_path / "missing.xml")


def test_unknown_effect_value_and_unreachable_height(lab_scene):
    with pytest.raises(SceneError, match="valid"):
        lab_scene.replace(effects={"contact": "magnetic"})
    from mbsuite import ParameterError

    with pytest.raises(ParameterError, match="cannot be reached"):
        lab_scene.replace(params={"y_op": 5.0})
