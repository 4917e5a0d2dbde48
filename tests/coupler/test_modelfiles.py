"""Shipped model files = generated baseline; MjSpec / Pinocchio edits = generated variants; variants are consistent."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from mbsuite.errors import ModelFileError
from mbsuite.models.coupler import modelfiles as mf
from mbsuite.models.coupler.jacobian import single_jacobian
from mbsuite.models.coupler.mujoco import mjspec_variant
from mbsuite.models.coupler.params import CouplerParams
from mbsuite.models.coupler.pinocchio import PinCoupler, load_model, pin_variant
from mbsuite.models.coupler.single import ramp_single
from mbsuite.paths import mjcf_path, urdf_path

VARIANT = CouplerParams(gamma=0.11, e_y=0.2, l_b=3.0, phi_bc=math.pi / 2, R=1.3, i_shaft_a=7.0, i_shaft_c=45.0,
                        m_link=3.0, link_radius=0.03, m_shaft_b=100.0, i_shaft_b_axial=25.0, i_shaft_b_trans=45.0)
KINDS = ["single", "double"]

FIELDS = ("body_pos", "body_quat", "body_ipos", "body_iquat", "body_mass", "body_inertia", "body_parentid",
          "jnt_type", "jnt_axis", "jnt_pos", "jnt_bodyid", "dof_damping", "site_pos", "site_bodyid", "geom_size",
          "geom_pos", "eq_type", "eq_obj1id", "eq_obj2id", "eq_data")


def _compare(m1: mujoco.MjModel, m2: mujoco.MjModel, atol: float = 1e-12) -> None:
    assert (m1.nq, m1.nv, m1.nbody, m1.neq, m1.nsite) == (m2.nq, m2.nv, m2.nbody, m2.neq, m2.nsite)
    for f in FIELDS:
        a, b = getattr(m1, f), getattr(m2, f)
        if f == "body_quat" or f == "body_iquat":  # q and -q are the same rotation
            s = np.sign(np.sum(a * b, axis=1))[:, None]
            b = b * np.where(s == 0, 1, s)
        np.testing.assert_allclose(a, b, atol=atol, rtol=0, err_msg=f)


@pytest.mark.parametrize("kind", KINDS)
def test_shipped_files_equal_generated_baseline(kind):
    p = CouplerParams()
    assert urdf_path(f"coupler_{kind}").read_text() == mf.urdf_text(p, kind)
    assert mjcf_path(f"coupler_{kind}").read_text() == mf.mjcf_text(p, kind)
    _compare(mujoco.MjModel.from_xml_path(str(mjcf_path(f"coupler_{kind}"))), mjspec_variant(p, kind).compile())


@pytest.mark.parametrize("kind", KINDS)
def test_mjspec_edit_equals_generated_variant(kind):
    edited = mjspec_variant(VARIANT, kind).compile()
    generated = mujoco.MjModel.from_xml_string(mf.mjcf_text(VARIANT, kind))
    _compare(edited, generated)
    # and the variant differs from the baseline (the edit did something)
    base = mujoco.MjModel.from_xml_path(str(mjcf_path(f"coupler_{kind}")))
    assert np.max(np.abs(base.site_pos - edited.site_pos)) > 0.05
    # the edited variant is assembled at qpos0
    d = mujoco.MjData(edited)
    mujoco.mj_forward(edited, d)
    assert np.max(np.abs(d.efc_pos)) < 1e-12


@pytest.mark.parametrize("kind", KINDS)
def test_pinocchio_edit_equals_generated_variant(kind):
    base, _ = load_model(kind)
    edited, cl = pin_variant(base, VARIANT, kind)
    generated, cl2 = load_model(kind, VARIANT)
    assert cl == cl2
    q = pin.randomConfiguration(generated, -np.ones(generated.nq), np.ones(generated.nq))
    d1, d2 = edited.createData(), generated.createData()
    pin.framesForwardKinematics(edited, d1, q)
    pin.framesForwardKinematics(generated, d2, q)
    for f in generated.frames:
        i = edited.getFrameId(f.name)
        assert np.allclose(d1.oMf[i].homogeneous, d2.oMf[generated.getFrameId(f.name)].homogeneous, atol=1e-12), f.name


def test_variant_kinematics_pinocchio_matches_reference():
    p = VARIANT
    pc = PinCoupler.build("single", p, edit=True)
    sp = ramp_single(p, 1.1, 0.08, 0.05)
    q = pc.q_of({"phi_a": 1.1, "alpha_bx": 0.08, "alpha_bz": 0.05,
                 **dict(zip(("phi_b", "x_b", "y_b", "z_b"), sp.u, strict=True))})
    assert np.max(np.abs(pc.residual(q))) < 1e-12
    assert np.max(np.abs(pc.mechanism_jacobian(q) - single_jacobian(p, sp))) < 1e-14  # measured 2.2e-16


def test_urdf_states_every_closure_by_named_frames():
    cl = mf.closures_from_urdf(urdf_path("coupler_double"))
    assert [c.name for c in cl] == [f"link{k}" for k in range(1, 9)]
    assert cl[0].frame_a == "A_S1" and cl[0].frame_b == "BA_S2" and cl[7].frame_b == "BC_S1"
    assert all(c.length == pytest.approx(CouplerParams().link_length, abs=1e-14) for c in cl)


def test_malformed_files_raise(tmp_path):
    bad = tmp_path / "x.urdf"
    bad.write_text("<robot name='x'><link name='world'/></robot>")
    with pytest.raises(ModelFileError, match="closure"):
        mf.closures_from_urdf(bad)
    with pytest.raises(ModelFileError, match="kind"):
        mf.urdf_text(CouplerParams(), "triple")


def _physics_only(path) -> mujoco.MjModel:
    """The model file with every visual-only element removed (geoms, lights, cameras, materials, textures)."""
    spec = mujoco.MjSpec.from_file(str(path))
    for lst in (spec.geoms, spec.lights, spec.cameras, spec.materials, spec.textures):
        for el in list(lst):
            spec.delete(el)
    return spec.compile()


@pytest.mark.parametrize("kind", KINDS)
def test_visual_elements_change_no_physics(kind):
    """Floor, light, camera, platform discs, shafts and link rods are visual only: the shipped model and the same
    model stripped of them have identical masses, inertias, mass matrix and a bitwise-identical 200-step trajectory
    (from a perturbed assembled pose with an input speed)."""
    path = mjcf_path(f"coupler_{kind}")
    full = mujoco.MjModel.from_xml_path(str(path))
    bare = _physics_only(path)
    assert full.ngeom > 0 and bare.ngeom == 0 and full.ncam == 1 and full.nlight == 1
    assert np.all(full.geom_contype == 0) and np.all(full.geom_conaffinity == 0)
    for f in ("body_mass", "body_inertia", "body_ipos", "dof_damping"):
        np.testing.assert_array_equal(getattr(full, f), getattr(bare, f), err_msg=f)
    ds = []
    for m in (full, bare):
        d = mujoco.MjData(m)
        d.qvel[0] = 3.0  # shaft a spinning
        mujoco.mj_forward(m, d)
        ds.append(d)
    mass = [np.zeros((m.nv, m.nv)) for m in (full, bare)]
    for m, d, M in zip((full, bare), ds, mass, strict=True):
        mujoco.mj_fullM(m, d, M)
    np.testing.assert_array_equal(mass[0], mass[1])
    for _ in range(200):
        for m, d in zip((full, bare), ds, strict=True):
            mujoco.mj_step(m, d)
    np.testing.assert_array_equal(ds[0].qpos, ds[1].qpos)
    np.testing.assert_array_equal(ds[0].qvel, ds[1].qvel)
    assert np.max(np.abs(ds[0].qpos)) > 1e-3  # it moved


@pytest.mark.parametrize("kind", KINDS)
def test_platform_discs_follow_the_design(kind):
    """Each platform carries a disc of radius DISC_RADIUS x R whose face lies in the platform's joint plane (all four
    joint sites of that platform at distance R from the disc axis, on its face), also for an MjSpec variant."""
    for p in (CouplerParams(), VARIANT):
        m = mjspec_variant(p, kind).compile()
        d = mujoco.MjData(m)
        mujoco.mj_kinematics(m, d)
        names = {"A": "platform_a_disc"} | ({"B": "platform_b_disc"} if kind == "single" else
                                             {"BA": "platform_ba_disc", "BC": "platform_bc_disc",
                                              "C": "platform_c_disc"})
        for prefix, gname in names.items():
            g = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, gname)
            assert m.geom_size[g, 0] == pytest.approx(mf.DISC_RADIUS * p.R, rel=1e-12)
            axis = d.geom_xmat[g].reshape(3, 3)[:, 2]
            for k in range(4):
                s = d.site_xpos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"{prefix}_S{k + 1}")]
                rel = s - d.geom_xpos[g]
                along = float(rel @ axis)
                assert abs(abs(along) - m.geom_size[g, 1]) < 1e-12  # on a face: half thickness from the centre
                assert np.linalg.norm(rel - along * axis) == pytest.approx(p.R, rel=1e-12)
