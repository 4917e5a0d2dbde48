"""Design grids through the sweep API: every point equals the single passage it stands for; bad grids are refused."""

from __future__ import annotations

import pytest

import mbsuite
from mbsuite.errors import ParameterError
from mbsuite.models.catenary.analysis import run_scene
from mbsuite.models.catenary.design import design_grid, plot_grid


def _short():
    return mbsuite.load_scene("catenary").replace(params={"n_spans": 3, "x_end": 100.0, "window_start": 40.0,
                                                         "window_end": 90.0})


def test_grid_points_are_the_passages_they_stand_for(tmp_path):
    """2 speeds x 2 head masses on two worker processes: each point's statistics equal a direct run of the scene with
    that speed and head mass (the pool changes nothing: bit-equal), sigma/Fm is their ratio, the grid states their
    element length and time step, and the plot is written."""
    scene = _short()
    grid = design_grid(scene, [200.0, 300.0], {"m1": [7.2, 10.8]}, workers=2, progress=False)
    assert [(p["speed_kmh"], p["m1"]) for p in grid["points"]] == [(200.0, 7.2), (200.0, 10.8), (300.0, 7.2),
                                                                   (300.0, 10.8)]
    run = run_scene(scene, speed_kmh=300.0, m1=10.8)
    direct = run.stats
    # the grid states the resolution its points ran at (that of the direct run)
    assert grid["resolution"] == {"element_length": run.params.element_length, "timestep": run.dt}
    pt = grid["points"][3]
    for k in ("Fm", "sigma", "stat_min", "max", "min", "uplift_mm", "loss_pct"):
        assert pt[k] == direct[k], k
    assert pt["sigma_over_Fm"] == pytest.approx(direct["sigma"] / direct["Fm"], rel=1e-15)
    assert pt["sigma_pass"] == (direct["sigma"] <= 0.3 * direct["Fm"])
    (png,) = plot_grid(grid, tmp_path)
    assert png.is_file() and png.stat().st_size > 10_000


def test_bad_grids_name_the_value():
    scene = _short()
    with pytest.raises(ParameterError, match="head_mass"):
        design_grid(scene, [250.0], {"head_mass": [7.0]})
    with pytest.raises(ParameterError, match="m1"):
        design_grid(scene, [250.0], {"m1": [7.2, -1.0]})
    with pytest.raises(ParameterError, match=r"speeds\[0\] = 0.0 in the catenary design grid is invalid; valid: "
                                             r"\(0, 1000\) km/h"):
        design_grid(scene, [0.0], {"m1": [7.2]})
