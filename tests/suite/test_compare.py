"""`mbsuite compare A B`: two short EN 50318 passages at 150 and 160 km/h side by side. Every difference is the one
computed here from the two summary.json files read directly; units are the declared ones; the signals are overlaid;
summaries of different kinds, or sharing no headline, are refused (exit 2); a headline or a signal in one summary and
not in the other is named."""

from __future__ import annotations

import contextlib
import csv
import io
import json
import shutil
from pathlib import Path

import pytest

from mbsuite.cli import main

#: a 4-span line, the run over 200 m, the statistics over 90-150 m: about 2 s a passage
SHORT = ["--set", "params.n_spans=4", "--set", "params.x_end=200", "--set", "params.window_start=90",
         "--set", "params.window_end=150"]
STATS = {"Fm": "N", "sigma": "N", "stat_max": "N", "stat_min": "N", "max": "N", "min": "N", "uplift_mm": "mm",
         "loss_pct": "%"}


def _quiet(argv: list[str]) -> int:
    with contextlib.redirect_stdout(io.StringIO()):
        return main(argv)


@pytest.fixture(scope="module")
def passages(tmp_path_factory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("passages")
    for kmh in (150, 160):
        assert _quiet(["catenary", "catenary/en50318", "--speed", str(kmh), *SHORT, "--out", str(root / str(kmh))]) == 0
    return root / "150", root / "160"


def _results(folder: Path) -> dict:
    return json.loads((folder / "summary.json").read_text())["results"]


def test_two_speeds_differences_are_the_summaries(passages, tmp_path, capsys):
    a, b = passages
    out = tmp_path / "cmp"
    assert main(["compare", str(a), str(b / "summary.json"), "--json", "--out", str(out)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["kind"] == "catenary" and data["scene_differences"] == {"input.speed": [150.0, 160.0]}
    ra, rb = _results(a)["runs"]["slack"], _results(b)["runs"]["slack"]
    rows = {h["name"]: h for h in data["headlines"]}
    for name, unit in STATS.items():
        va, vb = ra["statistics"][name], rb["statistics"][name]
        row = rows[f"slack.{name}"]
        assert row["unit"] == unit and row["values"] == [va, vb]
        assert row["differences"] == [vb - va]  # hand-computed from the two files
        assert row["relative"] == [None if va == 0 else (vb - va) / abs(va)]
    static = rows["slack.static_contact_force"]
    assert static["unit"] == "N" and static["differences"] == [rb["static_contact_force"] - ra["static_contact_force"]]
    assert not data["only_in"] and not data["missing_signals"]
    (plan,) = data["signals"]
    assert plan["axis"] == ["x", "m"] and plan["file"] == "contact_force_reference2mass_slack_*.csv"
    assert plan["signals"] == ["force", "force_filtered_20Hz", "head_height", "wire_height"]
    table = list(csv.reader((out / "compare.csv").open()))
    assert table[0] == ["headline", "unit", "A", "B", "B - A", "(B - A)/|A| (%)"]
    fm = next(r for r in table if r[0] == "slack.Fm")
    assert float(fm[4]) == rb["statistics"]["Fm"] - ra["statistics"]["Fm"]
    assert (out / "compare_signals.png").stat().st_size > 20_000


def test_table_names_the_runs_and_their_difference(passages, capsys):
    a, b = passages
    assert main(["compare", str(a), str(b)]) == 0
    text = capsys.readouterr().out
    ra, rb = _results(a)["runs"]["slack"], _results(b)["runs"]["slack"]
    line = next(ln for ln in text.splitlines() if ln.split()[:1] == ["slack.sigma"])
    assert line.split()[1] == "N" and line.split()[4] == f"{rb['statistics']['sigma'] - ra['statistics']['sigma']:.6g}"
    assert "scene differences: input.speed: A 150.0, B 160.0" in text and "--speed 160" in text


def test_a_missing_headline_and_missing_signals_are_named(passages, tmp_path, capsys):
    a, b = passages
    c = tmp_path / "c"
    shutil.copytree(b, c)
    body = json.loads((c / "summary.json").read_text())
    del body["results"]["runs"]["slack"]["statistics"]["uplift_mm"]
    (c / "summary.json").write_text(json.dumps(body))
    (csv_file,) = c.glob("contact_force_*.csv")
    rows = list(csv.reader(csv_file.open()))
    with csv_file.open("w", newline="") as fh:
        csv.writer(fh).writerows([r[:-1] for r in rows])  # wire_height left out
    assert main(["compare", str(a), str(c)]) == 0
    text = capsys.readouterr().out
    assert "only in A: slack.uplift_mm" in text
    assert "signal 'wire_height' of contact_force_reference2mass_slack_*.csv missing in B" in text
    csv_file.unlink()
    assert main(["compare", str(a), str(c), "--json"]) == 0
    missing = json.loads(capsys.readouterr().out)["missing_signals"]
    assert any("no signal file" in m and "B's summary.json" in m for m in missing), missing


def test_summaries_of_different_kinds_or_without_common_headlines_are_refused(passages, tmp_path, capsys):
    a, b = passages
    eq = tmp_path / "eq"
    assert _quiet(["equilibrium", "pantograph", "--out", str(eq)]) == 0
    assert main(["compare", str(a), str(eq)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("mbsuite: error: cannot compare") and "`catenary`" in err and "`equilibrium`" in err
    c = tmp_path / "c"
    c.mkdir()
    body = json.loads((b / "summary.json").read_text())
    body["results"]["runs"] = {"linear": body["results"]["runs"]["slack"]}
    (c / "summary.json").write_text(json.dumps(body))
    assert main(["compare", str(a), str(c)]) == 2
    err = capsys.readouterr().err
    assert "share no headline" in err and "slack.Fm" in err and "linear.Fm" in err
    assert main(["compare", str(a)]) == 2 and "two summaries or more" in capsys.readouterr().err
    assert main(["compare", str(a), str(tmp_path / "nosuch")]) == 2 and "nosuch" in capsys.readouterr().err
    assert main(["compare", str(a), str(b), "--out", str(b)]) == 2
    assert "overwrite" in capsys.readouterr().err


def test_informative_keys_near_zero_references_and_a_line_file_are_read_as_such(passages, tmp_path, capsys):
    """A catenary passage's `solver.duration` (informative: it runs from x_start to x_end) is no scene difference; a
    first value near zero (|A| <= 1e-9 of the row's magnitude) has the absolute difference and no relative one (no
    huge %); a run of a line file alone reads "line file PATH", not "scene catenary/<stem>"."""
    a, b = passages
    copies = []
    for src, name, loss in ((a, "ra", 1e-15), (b, "rb", 0.5)):
        dst = tmp_path / name
        shutil.copytree(src, dst)
        s = json.loads((dst / "summary.json").read_text())
        s["scene"]["solver"]["duration"] = 6.1 if name == "ra" else 10.4
        s["results"]["runs"]["slack"]["statistics"]["loss_pct"] = loss
        if name == "rb":
            s["scene"]["name"] = "mine"
            s["scene"]["line"] = {"file": "/lines/mine.toml", "kind": "file"}
        (dst / "summary.json").write_text(json.dumps(s))
        copies.append(dst)
    assert main(["compare", *map(str, copies), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert "solver.duration" not in data["scene_differences"] and "input.speed" in data["scene_differences"]
    loss = next(h for h in data["headlines"] if h["name"] == "slack.loss_pct")
    assert loss["differences"] == [0.5 - 1e-15] and loss["relative"] == [None]
    assert [s["ran"] for s in data["summaries"]] == ["scene catenary/en50318", "line file /lines/mine.toml (catenary)"]
    assert main(["compare", *map(str, copies)]) == 0
    text = capsys.readouterr().out
    assert "(line file /lines/mine.toml (catenary))" in text and "solver.duration" not in text
