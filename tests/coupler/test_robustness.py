"""Regression tests of the robustness corpus' coupler findings: a non-coupler scene for `coupler dynamics`, and the
file checks the model declares for a coupler model file (`filechecks.check_model_file`, run by
`mbsuite.load_model_file`)."""

from __future__ import annotations

import re

import pytest

import mbsuite
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


def _refusal(f, body: str, checked_by: str, closures: int) -> str:
    """The loaders' message for link1 stated 1.5 m long instead of 0.944 m: a gap of 1.5 - 0.944253 = 0.5557 m."""
    return (f"{f}: loop closure 'link1' (body '{body}') does not assemble at the initial pose q = 0 ({checked_by}): "
            f"residual 0.5557 m > 1e-06 x link length 0.944253 m (1 of {closures} closures)")


@pytest.mark.parametrize("route, checked_by", [
    ("load_model_file mujoco", "MuJoCo"),
    # Pinocchio's MJCF loader compiles the file with MuJoCo first, handing it the same check
    ("load_model_file pinocchio", "MuJoCo"),
    # the check on Pinocchio's own frames, given the model the loader built without checks
    ("check_model_file pinocchio", "Pinocchio"),
])
def test_mjcf_with_a_link_of_1_5_m_is_refused(tmp_path, route, checked_by):
    """The corpus' copy of coupler_single.xml whose link1 <connect> anchor says 1.5 m instead of 0.944 m: MuJoCo
    places the connect's second side at compile time, so only the stated geometry shows it."""
    f = _copy(tmp_path, mjcf_path("coupler_single"),
              f'<connect name="link1" body1="link1" body2="platform_b" anchor="0 0 {L}"/>',
              '<connect name="link1" body1="link1" body2="platform_b" anchor="0 0 1.5"/>')
    with pytest.raises(ModelFileError, match=re.escape(_refusal(f, "link1", checked_by, 4))):
        if route == "check_model_file pinocchio":
            check_model_file(f, "pinocchio", pe.load_mjcf(f))
        else:
            mbsuite.load_model_file(f, route.split()[1])


@pytest.mark.parametrize("kind, frame, closures", [("single", "B_S2", 4), ("double", "BA_S2", 8)])
def test_urdf_with_a_link_of_1_5_m_is_refused(tmp_path, kind, frame, closures):
    f = _copy(tmp_path, urdf_path(f"coupler_{kind}"), f'frame_b="{frame}" length="{L}"',
              f'frame_b="{frame}" length="1.5"')
    with pytest.raises(ModelFileError, match=re.escape(_refusal(f, frame, "Pinocchio", closures))):
        mbsuite.load_model_file(f, "pinocchio")


def test_check_model_file_names_wrong_stem_and_engine(tmp_path):
    xml = mjcf_path("coupler_single")
    m = me.load_model(xml)
    with pytest.raises(ModelFileError, match="valid names"):
        check_model_file(tmp_path / "other.xml", "mujoco", m)
    with pytest.raises(ModelFileError, match="unknown engine 'bullet'"):
        check_model_file(xml, "bullet", m)
