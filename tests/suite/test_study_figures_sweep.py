"""The figures a sweep reports (`mbsuite sweep`: per point and signal the min, max and mean in the table, and with
the final value in `sweep.csv` / summary.json) against a signal known in closed form: the pantograph's ram, y_w(t) =
y_op + A (1 - cos 2 pi f t), an input of the run, not a response, so its statistics over the sampled run are hand
numbers."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import mbsuite
from mbsuite.cli import main


def test_sweep_statistics_of_the_ram_equal_the_closed_form(tmp_path, capsys):
    """Hand case: f = 5 Hz, 1 s sampled every 1 ms (1001 samples, 200 per period, five whole periods): y_w = y_op +
    A (1 - cos 2 pi 5 t_k) has min y_op (t = 0), max y_op + 2 A (t = 0.1 s), final y_op (t = 1 s) and mean y_op +
    A (1 - 1/1001) (the cosines of the first 1000 samples sum to 0, the last adds 1), with y_op = 1.58 m, the lab
    scene's operating height; A = 1 mm and 2 mm. The printed table (5 significant digits), `sweep.csv` and
    summary.json (1e-12 m: the sampled closed form in floating point) give these numbers, and the hand sums agree
    with numpy's of the closed form at the run's own sample times."""
    y_op = mbsuite.load_scene("pantograph/lab").build_params().y_op
    assert y_op == 1.58
    out = tmp_path / "sweep"
    assert main(["sweep", "pantograph/lab", "--set", "input.frequency=5", "--set", "solver.duration=1",
                 "--set", "solver.t_settle=0.5", "--vary", "input.amplitude=1e-3,2e-3", "--signals", "y_w",
                 "--workers", "1", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    data = json.loads((out / "summary.json").read_text())["results"]
    assert data["axes"] == {"input.amplitude": [0.001, 0.002]} and data["units"]["y_w"] == "m"
    t = np.arange(1001) * 1e-3
    hand = {}
    for amp in (1e-3, 2e-3):
        y = y_op + amp * (1.0 - np.cos(2 * np.pi * 5.0 * t))
        hand[amp] = {"min": y_op, "max": y_op + 2 * amp, "mean": y_op + amp * (1 - 1 / 1001), "final": y_op}
        assert [y.min(), y.max(), y.mean(), y[-1]] == pytest.approx(list(hand[amp].values()), abs=1e-12)
    for p in data["points"]:
        amp = p["values"]["input.amplitude"]
        assert p["signals"]["y_w"] == pytest.approx(hand[amp], abs=1e-12)
    rows = [ln.split() for ln in text.split("\nwrote")[0].splitlines()[2:]]
    assert [r[1:3] for r in rows] == [["y_w", "m"], ["y_w", "m"]]
    for r in rows:
        amp = float(r[0])
        assert [float(v) for v in r[3:6]] == pytest.approx([hand[amp][k] for k in ("min", "max", "mean")], rel=5e-6)
    with (out / "sweep.csv").open() as fh:
        table = list(csv.DictReader(fh))
    assert list(table[0]) == ["input.amplitude [m]", "y_w_min [m]", "y_w_max [m]", "y_w_mean [m]"]
    for r, p in zip(table, data["points"], strict=True):
        amp = float(r["input.amplitude [m]"])
        assert [float(r[f"y_w_{k} [m]"]) for k in ("min", "max", "mean")] == [p["signals"]["y_w"][k]
                                                                             for k in ("min", "max", "mean")]
        assert float(r["y_w_max [m]"]) - float(r["y_w_min [m]"]) == pytest.approx(2 * amp, abs=1e-12)
