"""Long coupler studies (run with `make test-slow` / `pytest -m slow tests/coupler`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import mbsuite
from mbsuite.models.coupler import analysis
from mbsuite.models.coupler.params import CouplerParams
from mbsuite.models.coupler.pinocchio import PinCoupler, single_revolution_pin
from mbsuite.models.coupler.single import single_revolution
from mbsuite.scenes import load_scene

pytestmark = pytest.mark.slow


def test_full_criteria_grid_trends():
    rep = analysis.criteria_report()
    s = rep.data["single"]

    def get(g, ey, a, k):
        return next(r[k] for r in s if r["gamma"] == g and r["e_y"] == ey and r["alpha_b"] == a)

    for a in analysis.ALPHAS[1:]:
        for ey in analysis.EYS:
            c1 = [get(g, ey, a, "c1") for g in (0.11, 0.297, 0.391)]
            assert c1[0] < c1[1] < c1[2]  # slimmer platforms are more homokinetic (Sect. 3.4)
            c2 = [get(g, ey, a, "c2") for g in (0.11, 0.297, 0.391)]
            assert c2[0] < c2[1] < c2[2]
        for g in (0.11, 0.297, 0.391):
            c1e = [get(g, ey, a, "c1") for ey in analysis.EYS]
            assert max(c1e) / min(c1e) < 1 + 1e-9  # c1 does not depend on e_y (Sect. 3.4; measured equal to 1e-15)
            c2e = [get(g, ey, a, "c2") for ey in analysis.EYS]
            assert c2e[0] < c2e[1] < c2e[2]
            assert get(g, 0.1, a, "c4") > 5 * get(g, 0.1, a, "c3")
    d = rep.data["double"]
    for r in d:
        if r["phi_bc"] == 0.0 and math.isfinite(r["c5"]):
            assert r["c5"] < 1e-12  # full homokineticity at phi_bc = 0 for any lateral shift
    for z in (0.04, 0.08):
        c5 = [next(r["c5"] for r in d if r["l_b"] == lb and r["phi_bc"] > 1 and r["z_c"] == z)
              for lb in (1.0, 2.0, 4.0)]
        assert c5[0] > c5[1] > c5[2]  # the longer the middle shaft the better (Sect. 4.3)


def test_dense_revolution_pinocchio_widest_platform_largest_inclination():
    p = CouplerParams(gamma=0.391, e_y=0.1)
    rev = single_revolution(p, 0.07, 0.0, n=361)
    pr = single_revolution_pin(PinCoupler.build("single", p), 0.07, 0.0, rev.phi_a, rev.u[0])
    assert np.max(np.abs(pr - rev.u)) < 3e-12  # measured 4.1e-13


def test_closure_residual_scales_with_solref_squared():
    base = load_scene("coupler/double_lateral").replace(effects={"gravity": False}, solver={"duration": 1.5})
    r1 = mbsuite.run(base.replace(params={"solref_timeconst": 1e-3}))
    r2 = mbsuite.run(base.replace(params={"solref_timeconst": 2e-3}))
    ratio = r2.statistics["closure_residual_max"] / r1.statistics["closure_residual_max"]
    assert ratio == pytest.approx(4.0, rel=0.2)
