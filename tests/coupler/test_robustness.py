"""Regression tests of the robustness corpus' coupler findings: a non-coupler scene for `coupler dynamics`, and the
file checks the engines' loaders run on a coupler model file (`filechecks.check_model_file`)."""

from __future__ import annotations

import pytest

from mbsuite.cli import main
from mbsuite.engines import mujoco_engine as me
from mbsuite.engines import pinocchio_engine as pe
from mbsuite.errors import ModelFileError
from mbsuite.models.coupler.filechecks import check_model_file
from mbsuite.paths import mjcf_path, urdf_path

L = "0.944253246252565"  # the shipped link length, as written in the files


def test_dynamics_of_a_non_coupler_scene_is_an_error_naming_scene_and_model(capsys):
    assert main(["coupler", "dynamics", "pantograph", "--json"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "scene 'pantograph' is a 'pantograph' scene" in err and "coupler scene" in err


@pytest.mark.parametrize("kind", ["single", "double"])
def test_shipped_files_pass_the_file_checks(kind):
    xml, urdf = mjcf_path(f"coupler_{kind}"), urdf_path(f"coupler_{kind}")
    check_model_file(xml, "mujoco", me.load_model(xml))
    check_model_file(xml, "pinocchio", pe.load_mjcf(xml))
    check_model_file(urdf, "urdf", pe.load_urdf(urdf))


def _copy(tmp_path, src, old, new):
    text = src.read_text()
    assert old in text
    out = tmp_path / src.name
    out.write_text(text.replace(old, new))
    return out


@pytest.mark.parametrize("engine", ["mujoco", "pinocchio"])
def test_mjcf_with_a_link_of_1_5_m_is_refused(tmp_path, engine):
    """The corpus' copy of coupler_single.xml whose link1 <connect> anchor says 1.5 m instead of 0.944 m: MuJoCo
    places the connect's second side at compile time, so only the stated geometry shows it."""
    f = _copy(tmp_path, mjcf_path("coupler_single"),
              f'<connect name="link1" body1="link1" body2="platform_b" anchor="0 0 {L}"/>',
              '<connect name="link1" body1="link1" body2="platform_b" anchor="0 0 1.5"/>')
    model = me.load_model if engine == "mujoco" else pe.load_mjcf
    try:
        m = model(f)
    except ModelFileError as exc:  # the loaders already run the check (once the hook is wired)
        msg = str(exc)
    else:
        with pytest.raises(ModelFileError) as err:
            check_model_file(f, engine, m)
        msg = str(err.value)
    assert str(f) in msg and "'link1'" in msg and "residual 0.5557 m" in msg


@pytest.mark.parametrize("kind, frame", [("single", "B_S2"), ("double", "BA_S2")])
def test_urdf_with_a_link_of_1_5_m_is_refused(tmp_path, kind, frame):
    f = _copy(tmp_path, urdf_path(f"coupler_{kind}"), f'frame_b="{frame}" length="{L}"',
              f'frame_b="{frame}" length="1.5"')
    try:
        m = pe.load_urdf(f)
    except ModelFileError as exc:
        msg = str(exc)
    else:
        with pytest.raises(ModelFileError) as err:
            check_model_file(f, "urdf", m)
        msg = str(err.value)
    assert str(f) in msg and "'link1'" in msg and "residual 0.5557 m" in msg


def test_check_model_file_names_wrong_stem_and_engine(tmp_path):
    xml = mjcf_path("coupler_single")
    m = me.load_model(xml)
    with pytest.raises(ModelFileError, match="valid names"):
        check_model_file(tmp_path / "other.xml", "mujoco", m)
    with pytest.raises(ModelFileError, match="unknown engine 'bullet'"):
        check_model_file(xml, "bullet", m)
