"""Every entry of the hard-case registry (mbsuite.hardcases) runs and all of its assertions hold."""

from __future__ import annotations

import pytest

from mbsuite import hardcases

CASES = [pytest.param(c, id=c.name, marks=([pytest.mark.slow] if c.slow else [])
                      + ([pytest.mark.xfail(strict=True, reason=c.expected_failure)] if c.expected_failure else []))
         for c in hardcases.registry()]


@pytest.mark.parametrize("case", CASES)
def test_hard_case(case):
    out = hardcases.run_case(case)
    assert out.passed, out.text()


def test_registry_is_complete_and_described():
    names = [c.name for c in hardcases.registry()]
    assert len(names) == len(set(names))
    for c in hardcases.registry():
        assert c.hard and c.scene and c.asserts, c.name
    # the situations the suite promises to cover: stick-slip (3 kinds), orifice dp -> 0 and choked,
    # coupler e_y -> 0 and e_y < R alpha,
    # phi_bc = pi/2, both clutches locked, mismatch engagement, over-large timesteps, 100 s drift, two IFToMM gates
    required = {"pantograph_stick_slip_2hz", "rotational_clutch_lock_unlock", "drives_load_reversal",
                "pantograph_orifice_dp0", "pantograph_orifice_choked", "coupler_ey_to_zero", "coupler_ey_below_R_alpha",
                "coupler_double_phibc90", "drives_both_clutches_locked", "drives_engagement_mismatch",
                "pantograph_over_large_timestep", "coupler_over_large_timestep", "drives_over_large_timestep",
                "pantograph_energy_drift_100s", "coupler_closure_drift_100s", "iftomm_drift_100s",
                "iftomm_fourbar_singular", "iftomm_bricard_overconstrained"}
    assert required <= set(names)


def test_a_failing_check_fails_the_case():
    """The runner does not swallow failures: a case whose bound is violated, or that raises, is reported FAIL."""
    bad = hardcases.HardCase("x", "none", "h", "s", "a", lambda ck: ck.le("value", 2.0, 1.0))
    out = hardcases.run_case(bad)
    assert not out.passed and "FAIL" in out.text()
    boom = hardcases.HardCase("y", "none", "h", "s", "a", lambda ck: 1 / 0)
    out = hardcases.run_case(boom)
    assert not out.passed and "ZeroDivisionError" in out.text()
    empty = hardcases.HardCase("z", "none", "h", "s", "a", lambda ck: None)
    assert not hardcases.run_case(empty).passed  # a case that checks nothing is not a pass
