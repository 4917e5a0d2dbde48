"""The coupler's suite declarations (`SPEC.cases`): hard cases, work-precision study, random input."""

from __future__ import annotations

import zlib

import numpy as np
import pytest

import mbsuite
from mbsuite import hardcases
from mbsuite.analysis.workprecision import Study
from mbsuite.models.coupler import SPEC
from mbsuite.scenes import load_scene

CASES = SPEC.suite()

PARAMS = [pytest.param(c, id=c.name, marks=([pytest.mark.slow] if c.slow else [])) for c in CASES.HARD_CASES]


def test_spec_points_at_this_module():
    assert SPEC.cases == "mbsuite.models.coupler.cases" and CASES.__name__ == SPEC.cases
    names = [c.name for c in CASES.HARD_CASES]
    assert len(names) == len(set(names)) and all(c.model == "coupler" for c in CASES.HARD_CASES)
    assert {"coupler_ey_to_zero", "coupler_ey_below_R_alpha", "coupler_double_phibc90", "coupler_over_large_timestep",
            "coupler_rk4_at_solref_limit", "coupler_closure_drift_100s"} == set(names)
    for c in CASES.HARD_CASES:
        assert c.hard and c.scene and c.asserts and not c.expected_failure, c.name


@pytest.mark.parametrize("case", PARAMS)
def test_hard_case(case):
    out = hardcases.run_case(case)
    assert out.passed, out.text()


def test_timestep_cases_assert_what_happens():
    """Both cases check one outcome each, strictly: the error (type and message) where the run is refused, the
    physics where it runs. A wrong message fails them."""
    cases = {c.name: c for c in CASES.HARD_CASES}
    for name, n_err in (("coupler_over_large_timestep", 2), ("coupler_rk4_at_solref_limit", 1)):
        out = hardcases.run_case(cases[name])
        errs = [c for c in out.checks if "Error" in str(c.value)]
        assert len(errs) == n_err and all(c.ok for c in errs), out.text()
        assert any("closure residual" in c.what for c in out.checks)  # the run that works is checked too


def test_random_input_is_admissible_and_reproducible():
    for name in sorted(SPEC.scene_files()):
        sc = load_scene(f"coupler/{name}")
        a = CASES.random_input(sc, np.random.default_rng(zlib.crc32(name.encode())))
        b = CASES.random_input(sc, np.random.default_rng(zlib.crc32(name.encode())))
        assert a == b and set(a) == {"input"}
        new = sc.replace(**a)  # validated against the spec
        for k in ("omega", "load_torque"):
            assert 0.5 <= new.input[k] / sc.input[k] <= 1.5
        assert new.input["z_c"] / sc.input["z_c"] == pytest.approx(1.0, abs=0.2)
    sc = load_scene("coupler/double_inclined")
    res = mbsuite.run(sc.replace(**CASES.random_input(sc, np.random.default_rng(1)),
                                 solver={"duration": 0.6, "t_settle": 0.3}))
    assert res.stats["warnings"] == {} and all(np.all(np.isfinite(v)) for v in res.signals.values())


def test_workprecision_study_quick():
    """The study's errors fall as the settings tighten (FPP tolerance; MuJoCo timestep)."""
    st = CASES.workprecision_study(load_scene("coupler/double_lateral"), quick=True)
    assert isinstance(st, Study)
    ref, info = st.reference()
    assert "least_squares" in info["reference"]
    rows = {}
    for s in st.settings():
        res = s.run()
        rows[(s.engine, s.method, s.setting)] = (st.state_error(res, ref), *st.physics_error(res, ref))
    loose, tight = rows[("fpp", "gauss-newton", "tol 0.0001, 37 steps")], rows[("fpp", "gauss-newton",
                                                                               "tol 1e-08, 37 steps")]
    assert tight[1] < 1e-3 * loose[1]
    assert tight[2]["closure_residual"] <= 1e-8  # the Gauss-Newton tolerance bounds the residual
    a, b = rows[("mujoco", "implicitfast", 1e-3)], rows[("mujoco", "implicitfast", 5e-4)]
    assert b[0] < a[0]
