"""IFToMM gates: declared limits, resolved input default, health figures, visual elements. (A model file refused at
load: `test_robustness.py`.)"""

from __future__ import annotations

import numpy as np
import pytest

import mbsuite
from mbsuite.limits import undeclared
from mbsuite.models.iftomm.params import IftommParams
from mbsuite.paths import mjcf_path


def test_params_declared_and_rate_default_shown():
    assert undeclared(IftommParams) == []
    sc = mbsuite.scene_from_dict({"model": "iftomm", "effects": {"mechanism": "bricard"}})
    assert sc.input == {"type": "initial", "rate": 0.0}


def test_health_figures_short_runs():
    sc = mbsuite.load_scene("iftomm/fourbar").replace(solver={"duration": 2.0})
    r = mbsuite.run(sc)
    names = [f.name for f in r.health]
    assert names == ["closure_residual", "energy_drift"] and all(f.ok for f in r.health)
    # energy scale: E_kin(0) = (5/3) 6^2 / 2 = 30 J plus m g L for the three bars (29.43 J)
    assert r.statistics["energy_scale"] == pytest.approx(30.0 + 3 * 9.81, rel=1e-12)


@pytest.mark.parametrize("mechanism", ["fourbar", "bricard"])
def test_visual_elements_change_no_physics(mechanism):
    """Floor, light, camera and bar capsules are visual only: the shipped file and the same file stripped of them
    compile to the same masses and inertias, and 300 steps from a moving state are bitwise identical."""
    import mujoco

    path = mjcf_path(f"iftomm_{mechanism}")
    spec = mujoco.MjSpec.from_file(str(path))
    for lst in (spec.geoms, spec.lights, spec.cameras, spec.materials, spec.textures):
        for el in list(lst):
            spec.delete(el)
    full, bare = mujoco.MjModel.from_xml_path(str(path)), spec.compile()
    assert full.ncam == 1 and full.nlight == 1 and bare.ngeom == 0 < full.ngeom
    assert np.all(full.geom_contype == 0) and np.all(full.geom_conaffinity == 0)
    np.testing.assert_array_equal(full.body_mass, bare.body_mass)
    np.testing.assert_array_equal(full.body_inertia, bare.body_inertia)
    ds = [mujoco.MjData(m) for m in (full, bare)]
    for d in ds:
        d.qvel[0] = 2.0
    for _ in range(300):
        for m, d in zip((full, bare), ds, strict=True):
            mujoco.mj_step(m, d)
    np.testing.assert_array_equal(ds[0].qpos, ds[1].qpos)
    assert np.max(np.abs(ds[0].qpos)) > 1e-2
