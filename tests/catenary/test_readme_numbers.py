"""The READMEs quote the Eppinger pantograph's EN 50318 statistics at 250 km/h in several tables: on the MuJoCo path
(`eppinger_lab`) the catenary README's shipped-pair table and the leading pantograph of its two-pantograph train; on
the hand-derived path (`en50318_eppinger`) the same two tables' hand-derived rows and the pantograph README's table
of the lumped fits under the wire. Every such row is held to the run it quotes, to the two decimals it prints, so
that the tables cannot drift apart or from the code. A documentation check, not a physics one (the physics of these
numbers is tested against the 2-mass reference and between the two paths elsewhere)."""

from __future__ import annotations

from pathlib import Path

import pytest

from mbsuite.models.catenary.analysis import scene_config
from mbsuite.models.catenary.train import run_passage
from mbsuite.scenes import load_scene

MODELS = Path(__file__).resolve().parents[2] / "mbsuite" / "models"
README = MODELS / "catenary" / "README.md"
PANTOGRAPH_README = MODELS / "pantograph" / "README.md"
COLUMNS = ("Fm", "sigma", "stat_max", "stat_min", "max", "min", "uplift_mm")
#: the path's word in the tables -> the scene its rows quote (both at 250 km/h, 0.5 m, 1e-4 s)
SCENES = {"MuJoCo": "catenary/eppinger_lab", "hand-derived": "catenary/en50318_eppinger"}


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def _number(text: str) -> float:
    return float(text.replace("−", "-").replace("*", ""))


def _quoted(path: str) -> dict[str, list[float]]:
    """The rows at 250 km/h of the path `path` ("MuJoCo" or "hand-derived"), by where they stand."""
    out = {}
    for line in README.read_text(encoding="utf-8").splitlines():
        c = _cells(line)
        if len(c) == 10 and c[0] == path:  # path | static | Fm | σ | Fm+3σ | Fm−3σ | max | min | uplift | loss
            out["catenary README, shipped pair"] = [_number(x) for x in c[2:9]]
        if len(c) == 13 and c[0] == f"Eppinger × 2, {path}" and c[1] == "250" and c[2] == "leading":
            out["catenary README, train's leading pantograph"] = [_number(x) for x in c[3:10]]
    if path == "hand-derived":  # km/h | pantograph | Fm | σ | Fm+3σ | Fm−3σ | max | min | uplift | loss
        for line in PANTOGRAPH_README.read_text(encoding="utf-8").splitlines():
            c = _cells(line)
            if len(c) == 10 and c[0] == "250" and c[1] == "Eppinger multibody":
                out["pantograph README, fits under the wire"] = [_number(x) for x in c[2:9]]
    return out


@pytest.mark.parametrize("path", sorted(SCENES))
def test_readme_eppinger_tables_quote_the_run(path):
    quoted = _quoted(path)
    expected = {"catenary README, shipped pair", "catenary README, train's leading pantograph"}
    if path == "hand-derived":
        expected.add("pantograph README, fits under the wire")
    assert set(quoted) == expected, quoted
    scene = load_scene(SCENES[path]).replace(input={"speed": 250.0})
    stats = run_passage(scene_config(scene, scene.solver.engine)).stats[0]
    run = [float(stats[k]) for k in COLUMNS]
    for where, row in quoted.items():
        assert row == pytest.approx(run, abs=0.0051), (where, dict(zip(COLUMNS, run, strict=True)))
