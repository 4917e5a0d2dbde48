"""The drives' MJCF files: visible and framed (light, floor, named camera, a disc on every rotor), and the visuals
change no physics: the file with every visual element removed compiles to the same masses and inertias, the same
mass matrix and, stepped with the same controls and an active lock, the same trajectory bit for bit."""

from __future__ import annotations

import re

import mujoco
import numpy as np
import pytest

from mbsuite.engines.mujoco_engine import full_inertia
from mbsuite.paths import mjcf_path

FILES = ["drive_step_up", "drive_step_up_down", "coupled_clutches", "drive_msl_friction", "drive_msl_one_way_clutch",
         "drive_msl_one_way_clutch_disengaged", "drive_msl_simple_gear_shift"]


def _strip_visuals(xml: str) -> str:
    """The file without its visual elements: visual/asset/default blocks, lights, cameras and class="visual" geoms."""
    for block in ("visual", "asset", "default"):
        xml = re.sub(rf"\n  <{block}>.*?\n  </{block}>", "", xml, count=1, flags=re.S)
    return re.sub(r'\n *<(?:light|camera) [^>]*/>|\n *<geom [^>]*class="visual"[^>]*/>', "", xml)


def _rollout(m: mujoco.MjModel, n: int = 400) -> np.ndarray:
    d = mujoco.MjData(m)
    rng = np.random.default_rng(7)
    d.qvel[:] = rng.normal(size=m.nv)
    if m.neq:
        d.eq_active[0] = 1  # one lock active: the equality solver runs too
    out = []
    for k in range(n):
        d.ctrl[:] = rng.normal(size=m.nu) if k % 50 == 0 else d.ctrl
        mujoco.mj_step(m, d)
        out.append(np.concatenate([d.qpos, d.qvel, d.qfrc_constraint]))
    return np.array(out)


@pytest.mark.parametrize("name", FILES)
def test_visuals_present(name):
    path = mjcf_path(name)
    m = mujoco.MjModel.from_xml_path(str(path))
    assert m.nlight >= 1 and mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_CAMERA, "overview") >= 0
    floor = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    assert floor >= 0 and m.geom_type[floor] == mujoco.mjtGeom.mjGEOM_PLANE
    for b in range(1, m.nbody):  # every rotor has a disc (a cylinder) of its own
        kinds = m.geom_type[m.geom_bodyid == b]
        assert mujoco.mjtGeom.mjGEOM_CYLINDER in kinds, mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)
    assert np.all(m.geom_contype == 0) and np.all(m.geom_conaffinity == 0)  # no contact can ever arise
    # the floor lies below every geom of the mechanism (the rotor axis is z)
    others = [g for g in range(m.ngeom) if g != floor]
    assert np.all(m.geom_pos[others, 2] > m.geom_pos[floor, 2])


@pytest.mark.parametrize("name", FILES)
def test_visuals_change_no_physics(name):
    xml = mjcf_path(name).read_text()
    bare = _strip_visuals(xml)
    assert "<geom" not in bare and "<light" not in bare and "<camera" not in bare  # the strip is complete
    a, b = mujoco.MjModel.from_xml_string(xml), mujoco.MjModel.from_xml_string(bare)
    for attr in ("body_mass", "body_inertia", "body_ipos", "dof_damping", "dof_armature", "tendon_stiffness"):
        assert np.array_equal(getattr(a, attr), getattr(b, attr)), attr
    da, db = mujoco.MjData(a), mujoco.MjData(b)
    da.qpos[:] = db.qpos[:] = np.linspace(0.3, 1.7, a.nq)
    mujoco.mj_forward(a, da)
    mujoco.mj_forward(b, db)
    assert np.array_equal(full_inertia(a, da), full_inertia(b, db))
    assert np.array_equal(_rollout(a), _rollout(b))  # bit for bit, contact-free in both
