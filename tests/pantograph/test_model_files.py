"""The shipped URDF and MJCF: generated from Table 3-I, loadable by both engines, and in agreement with each other."""

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from mbsuite.engines import mujoco_engine as mje
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
    """The keyframe (written from the hand-derived equilibrium) is a rest state of MuJoCo's own forces: at the key's
    qpos/act/ctrl, zero velocity, the generalized acceleration of the friction-free model vanishes. Independent of the
    generator: MuJoCo evaluates gravity, the head tendon, the elbow and cylinder plugins and the catenary actuator.
    Measured max |qacc| 2.6e-12 rad/s^2; bound 2e-11 (7.8x; a 1e-9 rad error in q1 of the key gives 2e-5 rad/s^2)."""
    m = mujoco.MjModel.from_xml_path(str(mjcf_path("pantograph")))
    m.dof_frictionloss[:] = 0.0  # at rest, Coulomb friction may hold any residual: test the friction-free balance
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("operating").id)
    mujoco.mj_forward(m, d)
    assert np.max(np.abs(d.qacc)) < 2e-11
    assert m.key("operating").ctrl[0] == PantographParams().y_op


def _strip_visuals(xml: str) -> str:
    """The MJCF with every geom, camera, light, texture, material and the <visual> block removed."""
    import xml.etree.ElementTree as ET

    root = ET.fromstring(xml)
    for parent in list(root.iter()):
        for child in list(parent):
            if child.tag in ("geom", "camera", "light", "visual", "asset"):
                parent.remove(child)
    return ET.tostring(root, encoding="unicode")


def test_visuals_change_no_physics():
    """Floor, lights, camera and geoms are for looking only: the model without any of them has the same mass matrix
    and the same 0.2 s trajectory from a perturbed keyframe, bitwise (RK4, the default integrator)."""
    text = mjcf_path("pantograph").read_text()
    bare = _strip_visuals(text)
    assert "<geom" not in bare and "<camera" not in bare
    runs = []
    for xml in (text, bare):
        m = mujoco.MjModel.from_xml_string(xml)
        m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
        d = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, d, 0)
        d.qpos[0] += 0.01
        d.ctrl[0] += 0.002
        mujoco.mj_forward(m, d)
        M = mje.full_inertia(m, d)
        traj = []
        for _ in range(400):
            mujoco.mj_step(m, d)
            traj.append(np.concatenate([d.qpos, d.qvel, d.act]))
        runs.append((M, np.array(traj), m.body_mass.copy(), m.body_inertia.copy()))
    (M0, x0, bm0, bi0), (M1, x1, bm1, bi1) = runs
    assert np.array_equal(M0, M1) and np.array_equal(bm0, bm1) and np.array_equal(bi0, bi1)
    assert np.array_equal(x0, x1)
    assert np.ptp(x0[:, 0]) > 1e-3  # the trajectory moves: the comparison is not of two rest states


def test_model_file_is_lit_with_a_camera_and_a_non_colliding_floor():
    m = mujoco.MjModel.from_xml_path(str(mjcf_path("pantograph")))
    assert m.ncam >= 1 and m.camera("side") is not None and m.nlight >= 1
    floor = m.geom("floor")
    assert floor.type[0] == mujoco.mjtGeom.mjGEOM_PLANE
    assert np.all(m.geom_contype == 0) and np.all(m.geom_conaffinity == 0)
