"""Regression tests of the robustness corpus' IFToMM findings: the file checks the model hands to the loaders for
an IFToMM model file (`modelfiles.check_model_file`), e.g. a four-bar whose rocker pivot moved to 5 m (the loop
cannot close)."""

from __future__ import annotations

import pytest

from mbsuite.engines import mujoco_engine as me
from mbsuite.engines import pinocchio_engine as pe
from mbsuite.errors import ModelFileError
from mbsuite.models.iftomm.modelfiles import check_model_file
from mbsuite.paths import mjcf_path


@pytest.mark.parametrize("mechanism", ["fourbar", "bricard"])
def test_shipped_files_pass_the_file_checks(mechanism):
    f = mjcf_path(f"iftomm_{mechanism}")
    check_model_file(f, "mujoco", me.load_model(f))
    check_model_file(f, "pinocchio", pe.load_mjcf(f))


@pytest.mark.parametrize("engine", ["mujoco", "pinocchio"])
def test_fourbar_with_the_rocker_pivot_at_5_m_is_refused(tmp_path, engine):
    text = mjcf_path("iftomm_fourbar").read_text()
    old = '<body name="rocker" pos="1 0 0">'
    assert old in text
    f = tmp_path / "iftomm_fourbar.xml"
    f.write_text(text.replace(old, '<body name="rocker" pos="5 0 0">'))
    load = me.load_model if engine == "mujoco" else pe.load_mjcf
    try:
        m = load(f)
    except ModelFileError as exc:  # the loaders already run the check (once the hook is wired)
        msg = str(exc)
    else:
        with pytest.raises(ModelFileError) as err:
            check_model_file(f, engine, m)
        msg = str(err.value)
    assert str(f) in msg and "loop closure 'C'" in msg and "'rocker'" in msg and "residual 4 m" in msg


def test_check_model_file_names_wrong_stem_and_engine(tmp_path):
    f = mjcf_path("iftomm_fourbar")
    m = me.load_model(f)
    with pytest.raises(ModelFileError, match="valid names"):
        check_model_file(tmp_path / "fourbar.xml", "mujoco", m)
    with pytest.raises(ModelFileError, match="unknown engine 'bullet'"):
        check_model_file(f, "bullet", m)
