"""EN 50318:2002 acceptance of the reference scene (catenary.md): every statistic inside the published range with no
parameter changed from the specification; the linear-dropper scene beside it; scenes and CLI."""

from __future__ import annotations

import json

import pytest

from mbsuite.cli import main
from mbsuite.errors import SceneError
from mbsuite.models.catenary.analysis import run_scene, simulate
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.stats import ACCEPTED_RANGES
from mbsuite.scenes import load_scene


def _assert_inside(stats, speed):
    bad = {k: (stats[k], lo, hi) for k, (lo, hi) in ACCEPTED_RANGES[speed].items() if not lo <= stats[k] <= hi}
    assert not bad, f"statistics outside the EN 50318 ranges at {speed} km/h: {bad}"


@pytest.mark.parametrize("speed", [250, 300])
def test_en50318_reference_scene_inside_ranges_coarse(speed):
    """Default-suite check on the 0.5 m mesh (within 0.5 N / 0.5 mm of the finest level, README convergence table):
    the specification's parameters, only the element length chosen."""
    run = simulate(CatenaryParams(element_length=0.5), speed, 1e-4)
    _assert_inside(run.stats, speed)
    assert run.stats["loss_events"] == []


@pytest.mark.slow
@pytest.mark.parametrize("speed", [250, 300])
def test_en50318_reference_scene_inside_ranges_shipped_scene(speed):
    run = run_scene(load_scene("catenary"), speed_kmh=speed)
    assert run.params == CatenaryParams(element_length=run.params.element_length)  # nothing but the mesh changed
    _assert_inside(run.stats, speed)


@pytest.mark.slow
@pytest.mark.parametrize("speed", [250, 300])
def test_linear_droppers_give_sigma_far_above_the_range(speed):
    """catenary.md: 'with linear (bilateral) droppers the same model gives a sigma far above the range'."""
    run = simulate(CatenaryParams(element_length=0.5), speed, 1e-4, dropper_law="linear")
    assert run.stats["sigma"] > ACCEPTED_RANGES[speed]["sigma"][1] + 5.0


def test_shipped_scenes_validate_and_unknown_effect_is_an_error(tmp_path):
    sc = load_scene("catenary")
    assert sc.effects == {"droppers": "slack", "pantograph": "reference2mass", "contact": "unilateral"}
    assert load_scene("catenary/en50318_linear").effects["droppers"] == "linear"
    bad = tmp_path / "bad.toml"
    bad.write_text('model = "catenary"\n[effects]\ndroppers = "elastic"\n')
    with pytest.raises(SceneError, match="slack"):
        load_scene(bad)
    bad.write_text('model = "catenary"\n[params]\ndropper_positions = [5.0, 61.0]\n')
    with pytest.raises(Exception, match="outside its span"):
        load_scene(bad)


def test_cli_catenary_json_and_files(tmp_path, capsys):
    scene = tmp_path / "short.toml"
    scene.write_text(
        'model = "catenary"\n[params]\nn_spans = 2\nelement_length = 0.5\nx_end = 110.0\nwindow_start = 50.0\n'
        'window_end = 100.0\n[input]\ntype = "passage"\nspeed = 200.0\n[solver]\ntimestep = 2e-4\n')
    out = tmp_path / "out"
    assert main(["catenary", str(scene), "--speed", "220", "--json", "--out", str(out), "--with-linear"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["speed_kmh"] == 220.0 and set(data["runs"]) == {"slack", "linear"}
    assert 90 < data["runs"]["slack"]["statistics"]["Fm"] < 130
    names = {p.name for p in out.iterdir()}
    assert {"summary.json", "force_uplift_reference2mass_220kmh.png",
            "contact_force_reference2mass_slack_220kmh.csv", "contact_force_reference2mass_linear_220kmh.csv"} <= names
    header = (out / "contact_force_reference2mass_slack_220kmh.csv").read_text().splitlines()[0]
    assert header.startswith("t [s],x [m],force [N],force_filtered_20Hz [N]")
    # bad input through the CLI: a clear error, exit code 2
    assert main(["catenary", str(scene), "--speed", "500"]) == 2
    assert "wave speed" in capsys.readouterr().err
