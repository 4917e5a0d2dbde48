"""Reproducible outputs: summary.json holds what reruns a command (the scene as run, the command, the versions, the
checkout's commit) and `mbsuite run summary.json` reruns it; `SimResult.to_pandas()` names columns by signal; the
command line's values are blamed on the command line and change what the scene says of itself."""

from __future__ import annotations

import argparse
import csv
import json

import numpy as np

import mbsuite
from mbsuite.cli import main
from mbsuite.results import SimResult


def test_to_pandas_names_columns_by_signal():
    pd = __import__("pytest").importorskip("pandas")
    t = np.array([0.0, 0.5, 1.0])
    res = SimResult(t, {"F1": np.array([1.0, 2.0, 3.0]), "y_d": np.array([0.1, 0.2, 0.3])},
                    {"F1": "N", "y_d": "m"}, "test")
    df = res.to_pandas()
    assert list(df.columns) == ["F1", "y_d"] and df.index.name == "t"
    assert df["F1"].tolist() == [1.0, 2.0, 3.0] and df.index.tolist() == t.tolist()
    assert df.attrs["units"] == {"t": "s", "F1": "N", "y_d": "m"}
    assert isinstance(df, pd.DataFrame)


def _rows(path) -> list[list[str]]:
    return list(csv.reader(path.open()))


def test_run_summary_json_reruns_the_run(tmp_path, capsys):
    """A run with command-line solver settings writes a summary that `mbsuite run summary.json` reruns to the same
    numbers, and that equals the run of the scene changed the same way in Python (an independent route)."""
    first = tmp_path / "first"
    assert main(["run", "coupler", "--max-steps", "2e6", "--allow-inaccurate", "--out", str(first)]) == 0
    summary = json.loads((first / "summary.json").read_text())
    assert summary["scene"]["solver"]["max_steps"] == 2e6 and summary["scene"]["solver"]["allow_inaccurate"]
    assert summary["versions"]["mbsuite"] == mbsuite.__version__ and summary["versions"]["mujoco"]
    assert summary["command"]["argv"][:2] == ["run", "coupler"] and summary["command"]["options"]["max_steps"] == 2e6
    if summary["checkout"] is not None:  # run from a checkout: its commit
        assert len(summary["checkout"]["commit"]) == 40
    capsys.readouterr()
    assert main(["run", str(first / "summary.json"), "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["signals"] == summary["results"]["signals"] and again["solver"] == summary["scene"]["solver"]
    res = mbsuite.run(mbsuite.load_scene("coupler").replace(solver={"max_steps": 2e6, "allow_inaccurate": True}))
    header, *body = _rows(first / "run.csv")
    name = next(iter(res.signals))
    col = next(i for i, h in enumerate(header) if h.split(" [")[0] == name)
    assert [float(r[col]) for r in body] == res.signals[name].tolist()


def test_a_summary_without_a_scene_says_which_command_wrote_it(tmp_path, capsys):
    p = tmp_path / "summary.json"
    p.write_text(json.dumps({"scene": None, "command": {"argv": ["list"]}}))
    assert main(["run", str(p)]) == 2
    err = capsys.readouterr().err
    assert "records no scene" in err and "mbsuite list" in err
    p.write_text("not json")
    assert main(["run", str(p)]) == 2
    assert "not a summary.json" in capsys.readouterr().err


def _catenary_args(**kw) -> argparse.Namespace:
    base = {"scene": "catenary/eppinger_lab", "engine": None, "timestep": None, "element_length": None, "speed": None,
            "allow_inaccurate": False, "max_steps": None, "spacings": None}
    return argparse.Namespace(**{**base, **kw})


def test_catenary_speed_from_the_command_line():
    """`--speed 280`: the scene's description says 280 km/h, not the file's 250; `--speed -250` is blamed on the
    command line, not on the scene file."""
    from mbsuite.models.catenary.cli import _scene

    file_scene = mbsuite.load_scene("catenary/eppinger_lab")
    assert "at 250 km/h" in file_scene.description
    scene = _scene(_catenary_args(speed=280.0))
    assert scene.input["speed"] == 280.0 and "at 280 km/h" in scene.description and "250 km/h" not in \
        scene.description


def test_catenary_negative_speed_is_blamed_on_the_command_line(capsys):
    assert main(["catenary", "--speed", "-250"]) == 2
    err = capsys.readouterr().err
    assert "--speed" in err and "command line" in err and ".toml" not in err


def test_plot_gives_each_signal_a_panel_it_fills():
    """`SimResult.plot()`: a ~100 N contact force does not share an axis with a ~8.7 kN cylinder force; signals of one
    unit whose ranges are comparable (within 10x of the panel's range) share one; a constant joins a panel holding its
    value; a small swing about a large offset gets its own (the grouping worked out by hand)."""
    t = np.linspace(0.0, 1.0, 201)
    wave = np.sin(2 * np.pi * 5 * t)
    sig = {"contact_force": 100 + 100 * wave, "a": 0.5 + 0.5 * wave, "cylinder_force": 8735 + 95 * wave,
           "b": 0.25 + 0.25 * wave, "c": np.full_like(t, 0.3), "d": 5 + 0.005 * wave}
    units = {"contact_force": "N", "cylinder_force": "N", "a": "m", "b": "m", "c": "m", "d": "m"}
    res = SimResult(t, sig, units, "test")
    expected = [["contact_force"], ["a", "b", "c"], ["cylinder_force"], ["d"]]
    assert res.panels() == expected
    fig = res.plot()
    assert [[line.get_label() for line in ax.get_lines()] for ax in fig.axes] == expected
