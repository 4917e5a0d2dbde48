"""Regression tests of the robustness corpus' IFToMM findings: the file checks the model declares for an IFToMM model
file (`modelfiles.check_model_file`, run by `mbsuite.load_model_file` and by both paths of `mbsuite.run`), e.g. a
four-bar whose rocker pivot moved to 5 m (the loop cannot close)."""

from __future__ import annotations

import re
import shutil

import pytest

import mbsuite
from mbsuite.engines import mujoco_engine as me
from mbsuite.engines import pinocchio_engine as pe
from mbsuite.errors import ModelFileError
from mbsuite.models.iftomm.modelfiles import check_model_file
from mbsuite.paths import mjcf_path, models_root


@pytest.mark.parametrize("mechanism", ["fourbar", "bricard"])
def test_shipped_files_pass_the_file_checks(mechanism):
    f = mjcf_path(f"iftomm_{mechanism}")
    check_model_file(f, "mujoco", me.load_model(f))
    check_model_file(f, "pinocchio", pe.load_mjcf(f))


@pytest.mark.parametrize("route, engine, checked_by", [
    ("load_model_file", "mujoco", "MuJoCo"),
    # Pinocchio's MJCF loader compiles the file with MuJoCo first, handing it the same check
    ("load_model_file", "pinocchio", "MuJoCo"),
    ("run", "mujoco", "MuJoCo"),
    # the Pinocchio path checks its own frames before it builds the MuJoCo model it borrows the closures from
    ("run", "reference", "Pinocchio"),
])
def test_fourbar_with_the_rocker_pivot_at_5_m_is_refused(tmp_path, monkeypatch, route, engine, checked_by):
    """The rocker pivot 4 m from its stated place (1, 0): the closure gap at q = 0 is exactly 4 m."""
    for sub in ("mjcf", "models_urdf"):
        shutil.copytree(models_root() / sub, tmp_path / sub)
    f = tmp_path / "mjcf" / "iftomm_fourbar.xml"
    old = '<body name="rocker" pos="1 0 0">'
    assert old in f.read_text()
    f.write_text(f.read_text().replace(old, '<body name="rocker" pos="5 0 0">'))
    msg = (f"{f}: loop closure 'C' (body 'rocker') does not assemble at the initial pose q = 0 ({checked_by}): "
           "residual 4 m > 1e-06 x bar length 1 m")
    with pytest.raises(ModelFileError, match=re.escape(msg)):
        if route == "load_model_file":
            mbsuite.load_model_file(f, engine)
        else:
            monkeypatch.setenv("MBSUITE_MODELS_DIR", str(tmp_path))
            mbsuite.run(mbsuite.load_scene("iftomm/fourbar").replace(solver={"duration": 0.1}), engine=engine)


def test_check_model_file_names_wrong_stem_and_engine(tmp_path):
    f = mjcf_path("iftomm_fourbar")
    m = me.load_model(f)
    with pytest.raises(ModelFileError, match="valid names"):
        check_model_file(tmp_path / "fourbar.xml", "mujoco", m)
    with pytest.raises(ModelFileError, match="unknown engine 'bullet'"):
        check_model_file(f, "bullet", m)
