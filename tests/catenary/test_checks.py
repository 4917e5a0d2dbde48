"""The catenary's input checks: declared parameter ranges, the scene's speed, the size guard and the health figure."""

from __future__ import annotations

import dataclasses
import math
import warnings

import pytest

import mbsuite
from mbsuite import load_scene
from mbsuite.errors import ParameterError, SceneError
from mbsuite.limits import limit_of, undeclared
from mbsuite.models.catenary import train
from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.config import CriticalSpeedWarning, passage_size
from mbsuite.models.catenary.fe import build_nodes
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.trust.health import AccuracyError, InaccurateResultWarning

SHORT = {"n_spans": 2, "element_length": 0.5, "x_end": 100.0, "window_start": 40.0, "window_end": 80.0}


def test_every_scalar_parameter_declares_its_range():
    # lists checked by code (droppers inside the span, sorted; windows [start, end] inside the run: test_overlap.py)
    # and a `Line` (checked by its own dataclasses)
    assert undeclared(CatenaryParams) == ["dropper_positions", "windows", "line"]


@pytest.mark.parametrize("name", [f.name for f in dataclasses.fields(CatenaryParams)
                                  if f.name not in ("dropper_positions", "windows", "line")])
def test_nan_inf_and_out_of_range_parameters_raise_naming_the_field(name):
    lim = limit_of(CatenaryParams, name)
    bad = [math.nan, math.inf, -math.inf, True]
    if lim.lo is not None:
        bad.append(lim.lo if lim.lo_open else lim.lo - max(1.0, abs(lim.lo)))
    if lim.hi is not None:
        bad.append(lim.hi * 2 + 1)
    for v in bad:
        with pytest.raises(ParameterError, match=rf"catenary parameter {name} = "):
            CatenaryParams(**{name: v})


def test_integral_counts_are_integers():
    with pytest.raises(ParameterError, match=r"n_spans = 2\.5 is invalid; valid: integer in \[1, 1000\]"):
        CatenaryParams(n_spans=2.5)
    assert CatenaryParams(**{**SHORT, "n_spans": 2.0}).n_spans == 2  # an integral float is taken as the integer


@pytest.mark.parametrize("bad", [0.0, -100.0, math.nan, math.inf, 5000.0, "fast"])
def test_scene_speed_is_checked_naming_the_key(bad):
    with pytest.raises(SceneError, match=r"input\.speed\b.* = .*(invalid|not a number)"):
        load_scene("catenary").replace(input={"speed": bad})


# ------------------------------------------------------------------------------------------------ size guard
def test_passage_size_is_the_mesh_and_step_count_of_a_real_passage():
    """The estimate is computed without building anything; here it is held against the mesh the FE model builds
    and the steps a passage takes (closed form: distance / (V dt))."""
    p = CatenaryParams(**SHORT)
    elements, steps = passage_size(p, 250 / 3.6, 2e-4)
    built = 2 * (build_nodes(p)[0].size - 1)  # elements of both wires as meshed
    assert elements <= built <= elements + 2 * 2 * len(p.dropper_positions) * p.n_spans  # key points add a few
    assert steps == math.ceil(100.0 / (250 / 3.6 * 2e-4))  # 7200
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = simulate(p, 250.0, 2e-4)
    assert abs(run.timing["steps"] - steps) <= 1


def test_tiny_elements_are_refused_before_anything_is_built(monkeypatch):
    """element_length 1e-4 m (once a hang): refused at once with the element and step counts, nothing assembled."""
    def boom(*_a, **_k):
        raise AssertionError("assembled a mesh the size guard should have refused")

    monkeypatch.setattr(train, "assemble", boom)
    scene = load_scene("catenary").replace(params={"element_length": 1e-4})
    with pytest.raises(SceneError, match="element-steps exceed params.max_element_steps") as err:
        mbsuite.run(scene)  # refused before anything is assembled (`assemble` above would raise)
    msg = str(err.value)
    # 2 wires x ceil(600 m / 1e-4 m) elements; ceil(420 m / (250/3.6 m/s x 2e-4 s)) steps
    assert "12,000,000 elements" in msg and "30,240 steps" in msg
    # the guard can be raised: then the mesh is built (accepting a step far past the FE wave resolution)
    raised = scene.replace(params={"max_element_steps": 1e12}, solver={"allow_inaccurate": True})
    with pytest.raises(AssertionError, match="assembled"):
        mbsuite.run(raised)


def test_passage_steps_are_held_to_solver_max_steps(monkeypatch):
    monkeypatch.setattr(train, "assemble", lambda *_a, **_k: pytest.fail("built past the step guard"))
    # solver.duration is informative for a passage (6.1 s in the scene); the passage's own step count is what counts
    scene = load_scene("catenary").replace(solver={"max_steps": 10_000, "duration": 1.0})
    with pytest.raises(SceneError, match=r"30,240 steps.*exceeds solver\.max_steps = 1e\+04"):
        mbsuite.run(scene)


# ------------------------------------------------------------------------------------------------ health
def test_speed_ratio_is_a_health_figure_and_near_critical_runs_are_not_trusted():
    scene = load_scene("catenary").replace(params=SHORT, input={"speed": 200.0})
    res = mbsuite.run(scene)
    (fig,) = [f for f in res.health if f.name == "speed_ratio"]
    assert fig.value == pytest.approx((200 / 3.6) / math.sqrt(20000.0 / 1.35), rel=1e-12)  # V / sqrt(T / rho)
    assert fig.bound == 0.9 and fig.ok
    c_kmh = 3.6 * math.sqrt(20000.0 / 1.35)  # 438.1 km/h
    fast = scene.replace(input={"speed": 0.95 * c_kmh}, params={"x_end": 60.0, "window_start": 20.0,
                                                                 "window_end": 50.0})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CriticalSpeedWarning)
        with pytest.raises(AccuracyError, match=r"speed_ratio = 0\.95 exceeds its bound 0\.9"):
            mbsuite.run(fast)
        with pytest.warns(InaccurateResultWarning, match="speed_ratio"):
            kept = mbsuite.run(fast.replace(solver={"allow_inaccurate": True}))
    assert any("speed_ratio" in w for w in kept.warnings)
