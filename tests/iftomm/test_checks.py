"""IFToMM gates: declared limits, resolved input default, model files checked at load, health figures."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

import mbsuite
from mbsuite.errors import ModelFileError
from mbsuite.limits import undeclared
from mbsuite.models.iftomm.params import IftommParams
from mbsuite.paths import mjcf_path


def test_params_declared_and_rate_default_shown():
    assert undeclared(IftommParams) == []
    sc = mbsuite.scene_from_dict({"model": "iftomm", "effects": {"mechanism": "bricard"}})
    assert sc.input == {"type": "initial", "rate": 0.0}


@pytest.mark.parametrize("engine", ["mujoco", "reference"])
def test_moved_rocker_pivot_refused(tmp_path, monkeypatch, engine):
    from mbsuite.paths import models_root

    for sub in ("mjcf", "models_urdf"):
        shutil.copytree(models_root() / sub, tmp_path / sub)
    f = tmp_path / "mjcf" / "iftomm_fourbar.xml"
    f.write_text(f.read_text().replace('<body name="rocker" pos="1 0 0">', '<body name="rocker" pos="5 0 0">'))
    monkeypatch.setenv("MBSUITE_MODELS_DIR", str(tmp_path))
    sc = mbsuite.load_scene("iftomm/fourbar").replace(solver={"duration": 0.1})
    # the Pinocchio path loads the file through MuJoCo's stricter parser first, whose check fires first
    name = "MuJoCo" if engine == "mujoco" else "(?:MuJoCo|Pinocchio)"
    with pytest.raises(ModelFileError, match=rf"{f}: loop closure 'C' \(body 'rocker'\).*\({name}\): residual 4 m"):
        mbsuite.run(sc, engine=engine)


def test_health_figures_short_runs():
    sc = mbsuite.load_scene("iftomm/fourbar").replace(solver={"duration": 2.0})
    r = mbsuite.run(sc)
    names = [f.name for f in r.health]
    assert names == ["closure_residual", "energy_drift"] and all(f.ok for f in r.health)
    # energy scale: E_kin(0) = (5/3) 6^2 / 2 = 30 J plus m g L for the three bars (29.43 J)
    assert r.stats["energy_scale"] == pytest.approx(30.0 + 3 * 9.81, rel=1e-12)


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
