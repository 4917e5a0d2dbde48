"""The health figures themselves, each against a hand computation: the stability margin h * omega_max and its bound
(a fraction of the integrator's stability limit on the imaginary axis), the Nyquist ratio f / (1 / 2h), the verdict
(`ok`: finite and within the bound) and `judge` (the first figure past its bound, or the warnings when allowed)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from mbsuite.trust.health import AccuracyError, Figure, InaccurateResultWarning, judge, nyquist_ratio, stability_margin


@pytest.mark.parametrize("integrator, limit", [("rk4", 2.8), ("euler", 2.0), ("implicit", 1.0)])
@pytest.mark.parametrize("h, omega", [(1e-3, 350.0), (2.5e-4, 4000.0)])
def test_stability_margin_is_h_times_omega_against_half_the_limit(integrator, limit, h, omega):
    """h omega_max, e.g. 1 ms x 350 rad/s = 0.35; bound 0.5 x the limit of h |lambda| on the imaginary axis
    (classical RK4: |R(i x)| <= 1 up to x = 2 sqrt 2 = 2.83, table value 2.8; explicit Euler is unstable on the axis,
    the suite uses 2; the implicit integrators 1 for accuracy). The fix names the step that meets the bound."""
    f = stability_margin(h, omega, integrator)
    assert f.value == pytest.approx(h * omega, rel=1e-15)
    assert f.bound == pytest.approx(0.5 * limit, rel=1e-15)
    assert f.ok == (h * omega <= 0.5 * limit)
    assert f"{0.5 * limit / omega:.3g} s" in f.fix
    # RK4's limit from its amplification polynomial R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24 on z = i x
    x = np.linspace(0.0, 3.0, 30001)
    z = 1j * x
    stable = np.abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24) <= 1 + 1e-12
    assert x[stable][-1] == pytest.approx(2 * math.sqrt(2), abs=1e-4)


def test_stability_margin_past_half_the_limit_is_not_ok():
    """RK4 at h = 1 ms: omega_max 1500 rad/s gives 1.5 > 1.4 (not ok); 1300 rad/s gives 1.3 (ok)."""
    assert not stability_margin(1e-3, 1500.0, "rk4").ok
    assert stability_margin(1e-3, 1300.0, "rk4").ok
    assert stability_margin(1e-3, 1500.0, "rk4", fraction=0.6).ok  # bound 1.68


@pytest.mark.parametrize("h, f_in, expect", [(1e-3, 4.25, 8.5e-3), (1e-3, 50.0, 0.1), (2e-3, 40.0, 0.16)])
def test_nyquist_ratio_is_the_input_frequency_over_the_nyquist_rate(h, f_in, expect):
    """f / f_N with f_N = 1 / (2 h): 4.25 Hz at 1 ms (f_N = 500 Hz) is 8.5e-3; 40 Hz at 2 ms (f_N = 250 Hz) is
    0.16 > 0.1 (fewer than 10 steps per half period); the fix names h = 0.1 / (2 f)."""
    fig = nyquist_ratio(h, f_in)
    assert fig.value == pytest.approx(expect, rel=1e-14)
    assert fig.bound == 0.1 and fig.ok == (expect <= 0.1 + 1e-15)
    assert f"{0.1 / (2 * f_in):.3g} s" in fig.fix


def test_a_figure_is_ok_only_finite_and_within_its_bound():
    assert Figure("x", 1.0, 1.0).ok and not Figure("x", math.nextafter(1.0, 2.0), 1.0).ok
    assert not Figure("x", math.nan, 1.0).ok and not Figure("x", math.inf, math.inf).ok


def test_judge_raises_the_first_figure_past_its_bound_or_warns_when_allowed():
    figs = [Figure("a", 0.5, 1.0), Figure("b", 3.0, 2.0, "m", "doc b", "fix b"), Figure("c", math.nan, 1.0)]
    with pytest.raises(AccuracyError, match=r"run: b = 3 m exceeds its bound 2 m \(doc b\); fix b \(and 1 more\)"):
        judge(figs, what="run")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        msgs = judge(figs, allow_inaccurate=True)
    assert [m.split(" = ")[0] for m in msgs] == ["INACCURATE: b", "INACCURATE: c"]
    assert [w.category for w in caught] == [InaccurateResultWarning] * 2
    assert judge(figs[:1]) == []
