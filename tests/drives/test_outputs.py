"""The drives' outputs: every `mbsuite drive ...` design command writes CSV with units in the header and
summary.json under `--out`, prints tables of at most 100 columns; the efficiency figure draws the curve in speed order
without the points that do not switch; the README's parameter table lists every DriveParams field."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import pytest

from mbsuite.cli import main
from mbsuite.limits import limits_table
from mbsuite.models.drives.params import DriveParams
from mbsuite.models.drives.plots import efficiency_figure

_DESIGN = {
    "tables": (["tables"], ["design_tables.csv", "design_tables.png"]),
    "srmin": (["srmin", "--P", "500", "--wmin", "50", "--wrip", "5", "--Jl", "0.1"], ["srmin.csv"]),
    "cadjs": (["cadjs", "--P", "500", "--srmin", "10,20", "--wmax", "500", "--vm", "100"], ["cadjs.csv", "cadjs.png"]),
    "springsz": (["springsz", "--K", "0.98", "--xmax", "5.09"], ["springsz.csv"]),
    "gains": (["gains", "--Jl", "0.0023", "--ts", "0.069", "--taul", "0.15", "--w0", "400", "--btotal", "2.5e-4"],
              ["gains.csv"]),
}


@pytest.mark.parametrize("name", sorted(_DESIGN))
def test_design_commands_out_contract(name, tmp_path, capsys):
    argv, files = _DESIGN[name]
    assert main(["drives", "design", *argv, "--out", str(tmp_path)]) == 0  # `drives` is the alias of `drive`
    text = capsys.readouterr().out
    assert max(len(line) for line in text.splitlines()) <= 100
    for f in [*files, "summary.json"]:
        assert (tmp_path / f).stat().st_size > 0, f
    with (tmp_path / files[0]).open() as fh:
        header = next(csv.reader(fh))
    numeric = [h for h in header if h not in ("table", "quantity", "unit", "clutch", "from", "to", "ours", "thesis")]
    assert numeric and all(h.endswith("]") for h in numeric), header  # every numeric column names its unit


def test_springsz_csv_values_are_the_design(tmp_path):
    """The CSV holds the numbers of (5.14)-(5.21) evaluated independently here: d = (32 K^2 x^2/(U sf^2 pi^2))^(1/6)
    with U = 1/8, sf = 0.25 * 2e9 Pa (E irrelevant for d), K = 0.98, x = 5.09: d = 3.704 mm."""
    out = tmp_path
    assert main(["drive", "design", "springsz", "--K", "0.98", "--xmax", "5.09", "--sigma-uts", "2e9", "--E", "207e9",
                 "--out", str(out)]) == 0
    row = dict(zip(*csv.reader((out / "springsz.csv").open()), strict=True))
    sf = 0.25 * 2e9
    d = (32 * 0.98**2 * 5.09**2 / (sf**2 * math.pi**2 / 8)) ** (1 / 6)
    assert float(row["d [m]"]) == pytest.approx(d, rel=1e-12)
    assert float(row["d [m]"]) == pytest.approx(3.704e-3, abs=5e-7)  # the rounded published-style figure


def test_efficiency_figure_orders_points_and_leaves_out_non_switching():
    """Points given in load order fold back in speed; the curve must be drawn by speed, and a point without a complete
    energy cycle (Sr = nan) must not be on the line."""
    pts = [{"tau_l": tl, "load_speed": sp, "efficiency": eff, "switching_rate": sr, "losses_W": {"brake": 1.0,
            "clutch": 2.0 * i}} for i, (tl, sp, eff, sr) in enumerate(
        [(0.0, 414.0, 0.0, 6.1), (0.1, 226.0, 0.72, 5.7), (0.25, 75.0, 0.57, 4.5), (0.3, 81.0, 0.85, math.nan)])]
    fig = efficiency_figure(pts, "test")
    ax0 = fig.axes[0]
    line = ax0.get_lines()[0]
    x = list(line.get_xdata())
    assert x == sorted(x) == [75.0, 226.0, 414.0]  # 81 rad/s (not switching) is not on the curve
    stall = ax0.get_lines()[1]
    assert list(stall.get_xdata()) == [81.0]
    labels = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    assert labels[0].startswith("clutch slip") and all("_" not in lab.split("(")[0] for lab in labels)


def test_readme_lists_every_parameter():
    readme = (Path(__file__).parents[2] / "mbsuite" / "models" / "drives" / "README.md").read_text()
    for key, *_ in limits_table(DriveParams):
        assert f"| `{key}` |" in readme, key


def test_drive_run_writes_what_mbsuite_run_writes(tmp_path):
    """`drive run --out` and `mbsuite run --out` name the same data alike (run.csv, one writer): the same scene gives
    the same file byte for byte; the drive command's summary.json holds the scene as run and its options, and
    `drive run summary.json` reruns it."""
    import json

    scene = tmp_path / "short.toml"
    text = (Path(__file__).parents[2] / "mbsuite/models/drives/scenes/step_up_pwm.toml").read_text()
    scene.write_text(text.replace("duration = 6.0", "duration = 0.3").replace("t_settle = 3.0", "t_settle = 0.1"))
    assert main(["drive", "run", str(scene), "--out", str(tmp_path / "a")]) == 0
    assert main(["run", str(scene), "--out", str(tmp_path / "b")]) == 0
    assert (tmp_path / "a" / "run.csv").read_bytes() == (tmp_path / "b" / "run.csv").read_bytes()
    s = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert s["scene"]["solver"]["duration"] == 0.3 and s["results"]["options"]["--error-estimate"] is False
    # the summary reruns the command: the same file again
    assert main(["drive", "run", str(tmp_path / "a" / "summary.json"), "--out", str(tmp_path / "c")]) == 0
    assert (tmp_path / "c" / "run.csv").read_bytes() == (tmp_path / "a" / "run.csv").read_bytes()


def test_drive_run_study_point_is_the_single_run(tmp_path, capsys):
    """`drive run --vary params.duty=0.3,0.5` (the sweep's machinery) gives at duty 0.3 what `drive run --set
    params.duty=0.3` gives (another route: one scene changed on the command line), and writes study.csv/png."""
    import json

    base = ["drive", "run", "drives/step_up_pwm", "--duration", "0.4"]
    assert main([*base, "--vary", "params.duty=0.3,0.5", "--workers", "1", "--json", "--out", str(tmp_path)]) == 0
    study = json.loads(capsys.readouterr().out)
    assert main([*base, "--set", "params.duty=0.3", "--json"]) == 0
    one = json.loads(capsys.readouterr().out)
    (point,) = [p for p in study["points"] if p["values"]["params.duty"] == 0.3]
    want = one["statistics"]["mean_load_speed"]
    assert point["results"]["statistics.mean_load_speed"] == want
    other = [p for p in study["points"] if p["values"]["params.duty"] == 0.5][0]
    assert other["results"]["statistics.mean_load_speed"] != want  # the axis acts
    assert (tmp_path / "study.csv").stat().st_size > 0 and (tmp_path / "study.png").stat().st_size > 10_000
    assert main([*base, "--set", "params.t_n=0.03"]) == 2  # PWM reads no dead time: refused, not ignored
    assert "t_n" in capsys.readouterr().err


def test_drive_efficiency_point_is_the_run_at_that_load(capsys):
    """`drive efficiency --loads 0.1` (without --error-estimate: once an internal error) gives at 0.1 N m the
    efficiency and load speed of `drive run --set params.tau_l=0.1` over the same window (another route: one run)."""
    import json

    base = ["drives/susd_100w_efficiency", "--duration", "0.3", "--json"]
    assert main(["drive", "efficiency", base[0], "--loads", "0.1", *base[1:]]) == 0
    (pt,) = json.loads(capsys.readouterr().out)["points"]
    assert main(["drive", "run", base[0], "--set", "params.tau_l=0.1", *base[1:]]) == 0
    cyc = json.loads(capsys.readouterr().out)["statistics"]
    assert pt["tau_l"] == 0.1 and pt["load_speed"] == pytest.approx(cyc["mean_load_speed"], rel=1e-12)
    assert pt["efficiency"] == pytest.approx(cyc["efficiency"], rel=1e-9)
