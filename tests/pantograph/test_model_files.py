"""The shipped URDF and MJCF: generated from Table 3-I, loadable by both engines, and in agreement with each other."""

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from mbsuite.models.pantograph.modelfiles import mjcf_text, theta_to_q, urdf_text
from mbsuite.models.pantograph.params import PantographParams
from mbsuite.paths import mjcf_path, urdf_path

FRAMES = ("contact_point", "elbow_pinion", "cylinder_lever")


@pytest.fixture(autouse=True, scope="module")
def _plugins():
    """The shipped MJCF holds the lab effects as mbsuite engine plugins: the one documented call registers them."""
    import mbsuite.native

    mbsuite.native.load()
# Pinocchio 4.1's MJCF parser keeps no sites of the fixed root body ("origin", "chain_base"): those are compared
# between the URDF and MuJoCo only.


def test_shipped_files_equal_generator():
    assert urdf_path("pantograph").read_text() == urdf_text(PantographParams())
    assert mjcf_path("pantograph").read_text() == mjcf_text(PantographParams())


def test_urdf_and_mjcf_agree_masses_inertias_and_frames(random_thetas):
    mu = pin.buildModelFromUrdf(str(urdf_path("pantograph")))
    mm = pin.buildModelFromMJCF(str(mjcf_path("pantograph")))
    assert mu.nq == mm.nq == 3 and list(mu.names) == list(mm.names)
    p = PantographParams()
    for j, (m, d, I) in enumerate([(p.m1, p.d1, p.I1), (p.m2, p.d2, p.I2), (p.mh, p.dh, p.Ih)], start=1):
        for model in (mu, mm):
            Y = model.inertias[j]
            assert Y.mass == pytest.approx(m, rel=1e-14)
            assert np.allclose(Y.lever, [d, 0, 0], atol=1e-14)
            assert Y.inertia[1, 1] == pytest.approx(I, rel=1e-14)  # planar moment about the hinge axis (y)
    du, dm = mu.createData(), mm.createData()
    for th in random_thetas[:30]:
        q = theta_to_q(th)
        pin.framesForwardKinematics(mu, du, q)
        pin.framesForwardKinematics(mm, dm, q)
        for f in FRAMES:
            a = du.oMf[mu.getFrameId(f)].translation
            b = dm.oMf[mm.getFrameId(f)].translation
            assert np.allclose(a, b, atol=1e-14), f


def test_mujoco_sites_equal_pinocchio_frames(random_thetas):
    m = mujoco.MjModel.from_xml_path(str(mjcf_path("pantograph")))
    d = mujoco.MjData(m)
    mu = pin.buildModelFromUrdf(str(urdf_path("pantograph")))
    du = mu.createData()
    for th in random_thetas[:30]:
        d.qpos[:] = theta_to_q(th)
        mujoco.mj_kinematics(m, d)
        pin.framesForwardKinematics(mu, du, d.qpos.copy())
        for f in (*FRAMES, "chain_base"):
            site = d.site(f).xpos
            assert np.allclose(site, du.oMf[mu.getFrameId(f)].translation, atol=1e-14), f


def test_keyframe_holds_the_equilibrium():
    from mbsuite.models.pantograph.reference import PantographODE

    m = mujoco.MjModel.from_xml_path(str(mjcf_path("pantograph")))
    assert np.allclose(m.key("operating").qpos, theta_to_q(PantographODE().equilibrium()[:3]), atol=1e-14)
