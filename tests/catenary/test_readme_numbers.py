"""The catenary README quotes the Eppinger pantograph's EN 50318 statistics at 250 km/h in two tables (the shipped
pair `eppinger_lab` / `en50318_eppinger`, and the leading pantograph of the two-pantograph train): both are held to
the run they quote, to the two decimals they print, so that the tables cannot drift apart or from the code. A
documentation check, not a physics one (the physics of these numbers is tested against the 2-mass reference and the
hand-derived path elsewhere)."""

from __future__ import annotations

from pathlib import Path

import pytest

from mbsuite.models.catenary.analysis import scene_config
from mbsuite.models.catenary.train import run_passage
from mbsuite.scenes import load_scene

README = Path(__file__).resolve().parents[2] / "mbsuite" / "models" / "catenary" / "README.md"
COLUMNS = ("Fm", "sigma", "stat_max", "stat_min", "max", "min", "uplift_mm")


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def _number(text: str) -> float:
    return float(text.replace("−", "-").replace("*", ""))


def _quoted() -> dict[str, list[float]]:
    """The README's MuJoCo rows at 250 km/h: the shipped pair's table and the train's leading pantograph."""
    out = {}
    for line in README.read_text(encoding="utf-8").splitlines():
        c = _cells(line)
        if len(c) == 10 and c[0] == "MuJoCo":  # path | static | Fm | σ | Fm+3σ | Fm−3σ | max | min | uplift | loss
            out["eppinger_lab"] = [_number(x) for x in c[2:9]]
        if len(c) == 13 and c[0] == "Eppinger × 2, MuJoCo" and c[1] == "250" and c[2] == "leading":
            out["train leading"] = [_number(x) for x in c[3:10]]
    return out


def test_readme_eppinger_tables_quote_the_run():
    quoted = _quoted()
    assert set(quoted) == {"eppinger_lab", "train leading"}, quoted
    scene = load_scene("catenary/eppinger_lab").replace(input={"speed": 250.0})
    stats = run_passage(scene_config(scene, scene.solver.engine)).stats[0]
    run = [float(stats[k]) for k in COLUMNS]
    for where, row in quoted.items():
        assert row == pytest.approx(run, abs=0.0051), (where, dict(zip(COLUMNS, run, strict=True)))
