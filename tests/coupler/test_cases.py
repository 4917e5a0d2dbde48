"""The coupler's suite declarations (`SPEC.cases`): the hard cases' strict error checks and random input.

Every hard case runs once, in `tests/suite/test_hardcases.py` (`pytest tests/suite/test_hardcases.py -k coupler`);
the work-precision study runs in `test_workprecision.py`."""

from __future__ import annotations

import zlib

import numpy as np
import pytest

from mbsuite import hardcases
from mbsuite.errors import SceneError, SolverError
from mbsuite.hardcases import Checker
from mbsuite.models.coupler import SPEC
from mbsuite.models.coupler.cases import _raises_exactly
from mbsuite.scenes import load_scene

CASES = SPEC.suite()


def test_spec_points_at_this_module():
    assert SPEC.cases == "mbsuite.models.coupler.cases" and CASES.__name__ == SPEC.cases
    names = [c.name for c in CASES.HARD_CASES]
    assert len(names) == len(set(names)) and all(c.model == "coupler" for c in CASES.HARD_CASES)
    assert {"coupler_ey_to_zero", "coupler_ey_below_R_alpha", "coupler_double_phibc90", "coupler_over_large_timestep",
            "coupler_rk4_at_solref_limit", "coupler_closure_drift_100s"} == set(names)
    for c in CASES.HARD_CASES:
        assert c.hard and c.scene and c.asserts and not c.expected_failure, c.name


def test_strict_error_check_fails_on_any_other_outcome():
    """`_raises_exactly` passes only on the named type with every phrase: a result, another type or a missing phrase
    is a failed check (so a case expecting an error cannot pass by returning)."""
    def boom(exc, msg):
        def f():
            raise exc(msg)
        return f

    outcomes = [(boom(SolverError, "torque_in out of range; use implicitfast"), True),
                (boom(SolverError, "torque_in out of range"), False),  # a phrase missing
                (boom(SceneError, "torque_in out of range; use implicitfast"), False),  # another type
                (lambda: 1.0, False)]  # no error: a result
    for fn, want in outcomes:
        ck = Checker()
        _raises_exactly(ck, "x", fn, SolverError, ("torque_in", "use implicitfast"))
        assert [c.ok for c in ck.checks] == [want]


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
    # running the scenes under these inputs is tests/suite/test_menagerie.py's job (every shipped scene, 1 s)
