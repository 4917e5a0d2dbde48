"""The READMEs quote the Eppinger pantograph's EN 50318 statistics at 250 km/h in several tables: on the MuJoCo path
(`eppinger_lab`) the catenary README's shipped-pair table and the leading pantograph of its two-pantograph train; on
the hand-derived path (`en50318_eppinger`) the same two tables' hand-derived rows and the pantograph README's table
of the lumped fits under the wire. Every such row is held to the run it quotes, to the two decimals it prints, so
that the tables cannot drift apart or from the code. A documentation check, not a physics one (the physics of these
numbers is tested against the 2-mass reference and between the two paths elsewhere). The catenary README's quality
table of every shipped scene is held to its runs the same way (slow)."""

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


# --- the quality table of every shipped scene (slow: twelve passages) -----------------------------------------------
#: the quality table's columns after scene | km/h | pantograph, in `quality.CRITERIA` order, then the verdict
QUALITY_COLUMNS = ("mean_force", "sigma", "stat_min", "contact_loss", "arcing_nq", "uplift")


def _quality_rows() -> dict[tuple[str, float], list[list[str]]]:
    """The README's quality-table rows by (scene, speed): each pantograph's cells (a train: "a / b" split)."""
    out: dict[tuple[str, float], list[list[str]]] = {}
    for line in README.read_text(encoding="utf-8").splitlines():
        c = _cells(line)
        if len(c) == 10 and c[0].startswith("`") and c[1].replace(".", "").isdigit():
            cells = c[3:10]
            n = len(cells[0].split(" / "))
            per = [[x.split(" / ")[k] if " / " in x else x for x in cells] for k in range(n)]
            out[(c[0].strip("`"), float(c[1]))] = per
    return out


def _value(cell: str) -> tuple[float, bool]:
    """A cell's number and whether it is marked failed (✗); a band or limit in brackets is dropped."""
    text = cell.split("[")[0].strip()
    return _number(text.replace("✗", "").strip()), "✗" in text


@pytest.mark.slow
def test_readme_quality_table_quotes_the_runs():
    """Every row of the catenary README's quality table against its scene run at its speed (AC criteria), to the two
    decimals it prints, with its failed marks and verdict (the table `scripts/catenary_quality.py` prints)."""
    from mbsuite.models.catenary.analysis import run_scene, run_train_scene
    from mbsuite.models.catenary.quality import CRITERIA, criteria_from
    from mbsuite.models.catenary.reports import quality_of, train_assessments

    assert tuple(CRITERIA) == QUALITY_COLUMNS
    rows = _quality_rows()
    assert len(rows) >= 12, sorted(rows)
    for (name, speed), quoted in sorted(rows.items()):
        scene = load_scene(f"catenary/{name}")
        crit = criteria_from(scene.sections.get("quality"))
        if "train" in scene.sections:
            qs = train_assessments(run_train_scene(scene, speed_kmh=speed), crit)
        else:
            qs = [quality_of(run_scene(scene, speed_kmh=speed), crit)]
        assert len(qs) == len(quoted), (name, speed)
        for q, cells in zip(qs, quoted, strict=True):
            for c, cell in zip(QUALITY_COLUMNS, cells[:6], strict=True):
                value, failed = _value(cell)
                row = q["rows"][c]
                assert value == pytest.approx(row["value"], abs=0.0051), (name, speed, c, row["value"])
                assert failed == (not row["pass"]), (name, speed, c, row)
            assert cells[6] == ("pass" if q["pass"] else "fail"), (name, speed, q["pass"])
