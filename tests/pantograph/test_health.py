"""Declared limits (parameters, scene inputs) and the health figures of every pantograph run."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from mbsuite import AccuracyError, ParameterError, SceneError, SolverError, load_scene, run, scene_from_dict
from mbsuite.limits import undeclared
from mbsuite.models.pantograph.cases import PantographStudy
from mbsuite.models.pantograph.equations import PantographConfig
from mbsuite.models.pantograph.health import STABILITY_FRACTION
from mbsuite.models.pantograph.inputs import operating_height
from mbsuite.models.pantograph.linearise import linear_model, omega_max
from mbsuite.models.pantograph.params import PantographParams
from mbsuite.trust.health import InaccurateResultWarning


def test_every_parameter_declares_its_range():
    assert list(undeclared(PantographParams)) == []


@pytest.mark.parametrize("field", ["alpha", "xf", "theta_e0", "m1", "ks", "r_laminar", "y_op"])
def test_nan_parameter_is_reported_as_that_parameter(field):
    with pytest.raises(ParameterError, match=rf"pantograph parameter {field} = nan is invalid; valid: "):
        PantographParams(**{field: math.nan})


@pytest.mark.parametrize("field,value", [("alpha", 4.0), ("r_laminar", 0.4), ("r_laminar", 1.0), ("gamma", 1.0),
                                         ("xf", math.inf)])
def test_out_of_range_parameter_is_named_with_its_range(field, value):
    with pytest.raises(ParameterError, match=rf"{field} = .* is invalid; valid: [\[(]"):
        PantographParams(**{field: value})


def test_cross_field_checks_remain():
    with pytest.raises(ParameterError, match="d2 = 2.5 lies beyond its link"):
        PantographParams(d2=2.5)
    with pytest.raises(ParameterError, match="y_op = 4.4 m cannot be reached"):
        PantographParams(y_op=4.4)
    # the laminar band must lie in subsonic flow: above the critical ratio (2/2.1)^11 = 0.584679 of gamma = 1.1
    with pytest.raises(ParameterError, match=r"r_laminar = 0.56 must exceed the critical pressure ratio 0.584679 of"):
        PantographParams(gamma=1.1, r_laminar=0.56)


def test_r_laminar_bound_is_the_critical_ratio_of_its_own_gamma():
    """gamma = 1.67 (monatomic gas): critical ratio (2/2.67)^(1.67/0.67) = 0.486669, below the thesis' 0.528 of air.
    A band edge between the two, 0.5, lies in subsonic flow and is accepted; 0.47 (inside the declared range, above
    its infimum 4/9 at gamma -> 2) lies in choked flow and is refused, the message naming both ratios."""
    g = 1.67
    assert (2.0 / (g + 1.0)) ** (g / (g - 1.0)) == pytest.approx(0.486669, abs=1e-6)
    assert PantographParams(gamma=g, r_laminar=0.5).r_laminar == 0.5
    with pytest.raises(ParameterError, match=r"r_laminar = 0.47 must exceed the critical pressure ratio 0.486669 of "
                                             r"gamma = 1.67"):
        PantographParams(gamma=g, r_laminar=0.47)
    # the declared range alone refuses only below 4/9 = critical_ratio(2), the valid gamma's open upper end
    with pytest.raises(ParameterError, match=r"r_laminar = 0.44 is invalid; valid: \(0.444444, 1\)"):
        PantographParams(gamma=1.99, r_laminar=0.44)


def test_input_defaults_are_part_of_the_scene():
    sc = scene_from_dict({"model": "pantograph"})
    assert sc.input == {"type": "sine", "amplitude": 1.85e-3, "frequency": 2.0, "initial": "equilibrium"}
    st = scene_from_dict({"model": "pantograph", "input": {"type": "step"}})
    assert st.input == {"type": "step", "height": 1e-3, "t_step": 0.1, "initial": "equilibrium"}


@pytest.mark.parametrize("inp,key", [
    ({"type": "step", "height": math.nan}, "input.height"),
    ({"type": "step", "height": 2.0}, "input.height"),
    ({"type": "step", "t_step": -0.1}, "input.t_step"),
    ({"frequency": math.nan}, "input.frequency"),
    ({"frequency": 0.0}, "input.frequency"),
    ({"frequency": -4.0}, "input.frequency"),
    ({"frequency": 150.0}, "input.frequency"),
    ({"frequency": math.inf}, "input.frequency"),
    ({"amplitude": math.nan}, "input.amplitude"),
    ({"amplitude": -1e-3}, "input.amplitude"),
    ({"amplitude": 1.0}, "input.amplitude"),
    ({"initial": "rest"}, "input.initial"),
    ({"type": "static", "initial": 3}, "input.initial"),
])
def test_bad_input_is_a_scene_error_naming_the_key(inp, key):
    with pytest.raises(SceneError, match=re.escape(key) + r" = .* (is invalid|is not a number); valid: "):
        scene_from_dict({"model": "pantograph", "input": inp})


def test_modes_height_is_checked(lab_scene):
    from mbsuite.models.pantograph.reports import modes_report

    with pytest.raises(SceneError, match="height = nan"):
        modes_report(lab_scene, height=math.nan)
    assert modes_report(lab_scene, height=1.5).data["linearised_at_height_m"] == 1.5


def test_omega_max_is_the_head_mode_and_cached(params):
    """omega_max (the largest |eigenvalue| of the hand-derived linearisation) against MuJoCo's own linearisation
    (mjd_transitionFD, implicit, h = 1e-4 s) at the same point: its fastest mode, the 19.40 Hz head mode, 2 pi f_n
    = 121.88 rad/s. Measured 1.2e-4 relative; bound 5e-4 (4x). A second call is a cache hit (the same read-only
    arrays)."""
    from mbsuite.models.pantograph.mujoco import MODES_TIMESTEP, MujocoPantograph, mujoco_modes

    cfg = PantographConfig()
    y = params.y_op + 1.85e-3
    mp = MujocoPantograph(integrator="implicit", timestep=MODES_TIMESTEP)
    fastest = max(2 * math.pi * m["f_n"] for m in mujoco_modes(mp, mp.equilibrium(y), y))
    assert omega_max(params, cfg, y) == pytest.approx(fastest, rel=5e-4)
    assert linear_model(params, cfg, y)[1] is linear_model(params, PantographConfig(coulomb=False), y)[1]


def _bad(**solver):
    """The settings of the reliability report: lab defaults, Coulomb off, 1 s from the equilibrium."""
    return scene_from_dict({"model": "pantograph", "effects": {"coulomb": False},
                            "solver": {"duration": 1.0, "t_settle": 0.0, **solver}})


@pytest.mark.parametrize("integrator,h", [("discrete", 0.1), ("discrete", 0.02), ("rk4", 0.02), ("euler", 0.02),
                                          ("implicitfast", 0.01)])
def test_inaccurate_settings_raise_accuracy_error(integrator, h):
    with pytest.raises(AccuracyError, match=r"stability_margin = [0-9.]+ exceeds its bound"):
        run(_bad(integrator=integrator, timestep=h))


def test_nyquist_ratio_refuses_a_step_too_coarse_for_the_input():
    """rk4 at 4 ms is stable and accurate for the modes (h omega = 0.49) but 30 Hz is sampled 4 times a period."""
    with pytest.raises(AccuracyError, match="nyquist_ratio = 0.24 exceeds its bound 0.1"):
        run(_bad(integrator="rk4", timestep=4e-3).replace(input={"frequency": 30.0}))


@pytest.mark.parametrize("integrator", ["rk4", "discrete"])
def test_allow_inaccurate_returns_the_result_with_a_warning(integrator):
    sc = _bad(integrator=integrator, timestep=0.02, allow_inaccurate=True)
    with pytest.warns(InaccurateResultWarning, match="stability_margin"):
        res = run(sc)
    assert res.warnings and res.warnings[0].startswith("INACCURATE: pantograph scene")
    assert "stability_margin" in res.warnings[0]
    assert not next(f for f in res.health if f.name == "stability_margin").ok
    assert all(np.all(np.isfinite(v)) for v in res.signals.values())


def test_diverging_setting_allowed_is_still_an_error_not_garbage():
    """discrete at 0.1 s with inaccuracy allowed: the run diverges and the core stops it (no result to keep)."""
    with pytest.raises(SolverError, match="outside its plausible range"):
        run(_bad(integrator="discrete", timestep=0.1, allow_inaccurate=True))


def test_excursion_flags_a_linkage_out_of_its_working_range():
    from mbsuite.models.pantograph.health import excursion

    th0 = np.array([0.4237, 0.4190, -0.0363])
    ok = excursion(th0 + np.array([[0.01, -0.01, 0.02]]), th0)
    assert ok.ok and ok.value == pytest.approx(0.01 / 0.4190, rel=1e-12)  # theta_2: 0.01 rad of 0.419 to 0
    assert not excursion(np.array([[-3207.0, 0.4, 0.0]]), th0).ok
    assert not excursion(np.array([[np.nan, 0.4, 0.0]]), th0).ok


@pytest.mark.parametrize("name", ["lab", "unilateral", "nonlinear_cylinder"])
@pytest.mark.parametrize("engine", ["mujoco", "reference"])
def test_shipped_scenes_report_healthy_figures(name, engine):
    res = run(load_scene(f"pantograph/{name}").replace(solver={"duration": 0.5, "t_settle": 0.25, "engine": engine}))
    names = {f.name for f in res.health}
    assert names == ({"stability_margin", "nyquist_ratio", "excursion"} if engine == "mujoco" else {"excursion"})
    assert all(f.ok for f in res.health) and res.warnings == []


def test_health_bounds_separate_accurate_from_inaccurate_settings(lab_scene):
    """The bounds against the true error (lab, Coulomb off, 4.25 Hz, 3 s; physics metric of the work-precision study
    against DOP853 rtol 1e-8, itself within 1e-6). Measured: rk4 10 ms (h omega 1.22, passes) 0.91 %, rk4 12 ms (1.46,
    refused) 2.5 %; discrete 80 us (0.0098, passes) 0.96 %, discrete 0.2 ms (0.024, refused) 2.4 %. Asserted: passing
    settings < 1.5 %, refused settings > 1.5 % (each a factor >= 1.5 from the measured value)."""
    st = PantographStudy(lab_scene, frequency=4.25, duration=3.0)
    ref = run(st.base.replace(solver={"engine": "reference", "method": "DOP853", "rtol": 1e-8, "atol": 1e-10}))
    p = lab_scene.build_params()
    w = omega_max(p, PantographConfig(), operating_height(lab_scene, p))
    for integ, h_ok, h_bad in (("rk4", 0.010, 0.012), ("discrete", 8e-5, 2e-4)):
        bound = STABILITY_FRACTION[integ] * {"rk4": 2.8, "discrete": 2.0}[integ]
        assert h_ok * w <= bound < h_bad * w
        good = run(st.base.replace(solver={"integrator": integ, "timestep": h_ok, "allow_inaccurate": False}))
        assert good.warnings == [] and st.physics_error(good, ref)[0] < 0.015, integ
        with pytest.raises(AccuracyError):
            run(st.base.replace(solver={"integrator": integ, "timestep": h_bad, "allow_inaccurate": False}))
        with pytest.warns(InaccurateResultWarning):
            bad = run(st.base.replace(solver={"integrator": integ, "timestep": h_bad}))
        assert st.physics_error(bad, ref)[0] > 0.015, integ
