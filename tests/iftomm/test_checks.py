"""IFToMM gates: declared limits, resolved input default, model files checked at load, health figures."""

from __future__ import annotations

import shutil

import pytest

import mbsuite
from mbsuite.errors import ModelFileError
from mbsuite.limits import undeclared
from mbsuite.models.iftomm.params import IftommParams


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
    name = "MuJoCo" if engine == "mujoco" else "Pinocchio"
    with pytest.raises(ModelFileError, match=rf"{f}: loop closure 'C' \(body 'rocker'\).*\({name}\): residual 4 m"):
        mbsuite.run(sc, engine=engine)


def test_health_figures_short_runs():
    sc = mbsuite.load_scene("iftomm/fourbar").replace(solver={"duration": 2.0})
    r = mbsuite.run(sc)
    names = [f.name for f in r.health]
    assert names == ["closure_residual", "energy_drift"] and all(f.ok for f in r.health)
    # energy scale: E_kin(0) = (5/3) 6^2 / 2 = 30 J plus m g L for the three bars (29.43 J)
    assert r.stats["energy_scale"] == pytest.approx(30.0 + 3 * 9.81, rel=1e-12)
